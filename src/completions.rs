//! `ferroc completions SHELL`: a completion script generated from the clap definitions
//! by clap_complete, so it always knows every command and option this ferroc has.

use crate::output;
use clap::CommandFactory;
use clap_complete::Shell;
use std::process::ExitCode;

pub const LONG_ABOUT: &str = "Print a completion script for SHELL on standard output, \
generated from ferroc's own command definitions (every command, option and choice of this \
version). Install it where your shell looks for completions, then start a new shell:\n\n  \
bash: ~/.local/share/bash-completion/completions/ferroc\n  \
zsh: a file named _ferroc in a folder on $fpath (e.g. ~/.zfunc, with fpath+=~/.zfunc before compinit)\n  \
fish: ~/.config/fish/completions/ferroc.fish\n\n\
Examples:\n  ferroc completions bash > ferroc.bash\n  ferroc completions zsh > _ferroc\n  \
ferroc completions fish > ferroc.fish";

#[derive(clap::Args)]
pub struct CompletionsArgs {
    /// The shell the script is for
    #[arg(value_enum)]
    shell: Shell,
}

pub fn run(args: &CompletionsArgs) -> ExitCode {
    let mut script = Vec::new();
    clap_complete::generate(
        args.shell,
        &mut crate::Cli::command(),
        "ferroc",
        &mut script,
    );
    output::stdout_then(&script, ExitCode::SUCCESS)
}
