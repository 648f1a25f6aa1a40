//! `ferroc man`: manual pages generated from the clap definitions by clap_mangen, one
//! for ferroc and one per command (`ferroc-run.1`, `ferroc-import-finroc.1`), so they
//! say what `--help` says.

use crate::output;
use clap::CommandFactory;
use ferroc_compiler::diagnostic::{did_you_mean, escape_controls};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

pub const LONG_ABOUT: &str = "Print the manual page (roff, section 1) of ferroc, or of the \
command named (`ferroc man run`, `ferroc man import finroc`), on standard output; read one \
with `man -l FILE`. With --dir, write every page instead: ferroc.1 and one per command \
(ferroc-check.1, ferroc-import-finroc.1, …), replacing pages of those names; for a system \
install, --dir /usr/local/share/man/man1.\n\n\
Examples:\n  ferroc man > ferroc.1\n  ferroc man import finroc > ferroc-import-finroc.1\n  \
ferroc man --dir man/man1";

#[derive(clap::Args)]
pub struct ManArgs {
    /// The command whose page to print (`run`, `import finroc`); none: ferroc's own
    #[arg(value_name = "COMMAND")]
    command: Vec<String>,
    /// Write every page into DIR (created if need be) instead of printing one
    #[arg(long, value_name = "DIR", conflicts_with = "command")]
    dir: Option<PathBuf>,
}

pub fn run(args: &ManArgs) -> ExitCode {
    let root = root();
    if let Some(dir) = &args.dir {
        return match write_all(root, dir) {
            Ok(n) => {
                eprintln!("wrote {n} manual pages to {}", dir.display());
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::from(2)
            }
        };
    }
    let mut page = root;
    for (i, name) in args.command.iter().enumerate() {
        let Some(sub) = page.find_subcommand(name).cloned() else {
            let known: Vec<&str> = page.get_subcommands().map(|c| c.get_name()).collect();
            let parent = ["ferroc"]
                .into_iter()
                .chain(args.command[..i].iter().map(String::as_str))
                .collect::<Vec<_>>()
                .join(" ");
            let help = match did_you_mean(name, known.iter().copied()) {
                Some(s) => format!("did you mean `{s}`?"),
                None => format!("its commands: {}", known.join(", ")),
            };
            eprintln!(
                "error: `{parent}` has no command `{}`\n  help: {help}",
                escape_controls(name)
            );
            return ExitCode::from(2);
        };
        page = sub;
    }
    let mut roff = Vec::new();
    match man_page(page).render(&mut roff) {
        Ok(()) => output::stdout_then(&roff, ExitCode::SUCCESS),
        Err(e) => {
            eprintln!("error: the manual page cannot be written: {e}");
            ExitCode::from(2)
        }
    }
}

/// ferroc's command, built: every command knows its page's name (`ferroc-run`).
fn root() -> clap::Command {
    let mut root = crate::Cli::command().disable_help_subcommand(true);
    root.build();
    root
}

fn man_page(command: clap::Command) -> clap_mangen::Man {
    clap_mangen::Man::new(command)
        .source(concat!("ferroc ", env!("CARGO_PKG_VERSION")))
        .manual("ferroc manual")
}

/// Writes the page of `command` and of every command below it into `dir`; gives how
/// many.
fn write_all(command: clap::Command, dir: &Path) -> Result<usize, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let mut written = 0;
    let mut todo = vec![command];
    while let Some(command) = todo.pop() {
        todo.extend(command.get_subcommands().cloned());
        let page = man_page(command);
        page.generate_to(dir).map_err(|e| {
            format!(
                "cannot write {}: {e}",
                dir.join(page.get_filename()).display()
            )
        })?;
        written += 1;
    }
    Ok(written)
}
