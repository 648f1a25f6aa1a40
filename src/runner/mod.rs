//! `ferroc run` and `ferroc types` for libraries not built into ferroc.
//!
//! ferroc links only the standard library. A model using other libraries runs in a
//! runner: a small program, generated and built by cargo once per set of libraries
//! (`program.rs`), that links exactly their crates (found from the manifests'
//! `rust-crate`, `crates.rs`) and runs the same `ferroc_host` code as ferroc itself.
//! ferroc checks the model first (errors stop here, before any build), then hands its
//! own command line to the runner, which replaces this process.

pub mod build;
pub mod cache;
pub mod checkout;
pub mod crates;
mod failure;
pub mod program;

use crates::LibraryCrate;
use ferroc_host::run::RunArgs;
use ferroc_host::types::TypesArgs;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The checkout this ferroc was built from: a runner depends on its `host/` crate.
const CHECKOUT: &str = env!("CARGO_MANIFEST_DIR");

/// ferroc's sources: `FERROC_SOURCE` if set (an installed ferroc whose checkout moved),
/// else the checkout it was built from.
pub fn source_dir() -> PathBuf {
    std::env::var_os("FERROC_SOURCE")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(CHECKOUT))
}

/// `ferroc run`: in this process when the model needs only the standard library.
pub fn run(args: RunArgs) -> ExitCode {
    if let Err(code) = ferroc_host::run::cmdline_params(&args) {
        return code;
    }
    let checked =
        ferroc_host::check_first::without_errors_as(&args.model, &args.lib_path, args.lockstep);
    let result = match checked {
        Ok(r) => r,
        Err(code) => return code,
    };
    let crates = match crates::needed_by_model(&result) {
        Ok(c) => c,
        Err(problems) => return report(&problems),
    };
    if crates.is_empty() {
        let registry = ferroc_host::run::registry();
        return ferroc_host::run::run_checked(args, &result, &registry);
    }
    let argv: Vec<OsString> = std::env::args_os().skip(1).collect();
    hand_over(&crates, argv, args.verbose)
}

/// `ferroc types`: the libraries on the lib path (or those asked for) in a runner; in
/// this process when there are none but the standard library.
pub fn types(args: TypesArgs) -> ExitCode {
    let options = ferroc_host::loader_options(args.lib_path(), false);
    let mut names = manifests_on(&options.lib_path);
    if !args.libraries().is_empty() {
        names.retain(|n| args.libraries().contains(n));
    }
    let loaded = ferroc_compiler::load_manifests(&names, &options);
    let found: Vec<&str> = names
        .iter()
        .map(String::as_str)
        .filter(|n| loaded.libraries.by_name.contains_key(*n))
        .collect();
    let crates = match crates::find_all(found.iter().copied(), &loaded.libraries, &loaded.sources) {
        Ok(c) => c,
        Err(problems) => return report(&problems),
    };
    let mut argv: Vec<OsString> = std::env::args_os().skip(1).collect();
    if args.libraries().is_empty() && !names.is_empty() {
        // Export and list what the lib path holds, not every library linked in.
        for name in &names {
            argv.push("--library".into());
            argv.push(name.into());
        }
    }
    if crates.is_empty() {
        let argv = std::iter::once(OsString::from("ferroc")).chain(argv);
        return ferroc_host::main_from(ferroc_host::run::registry(), argv);
    }
    hand_over(&crates, argv, args.verbose())
}

/// The names of the `NAME.lib.xml` manifests in these folders, sorted, each once.
fn manifests_on(folders: &[PathBuf]) -> Vec<String> {
    let mut names: Vec<String> = folders
        .iter()
        .filter_map(|f| std::fs::read_dir(f).ok())
        .flat_map(|entries| entries.flatten())
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            let stem = name.strip_suffix(".lib.xml")?;
            (!stem.is_empty() && !stem.starts_with('.')).then(|| stem.to_string())
        })
        .collect();
    names.sort();
    names.dedup();
    names
}

fn report(problems: &[String]) -> ExitCode {
    for p in problems {
        eprintln!("{p}");
    }
    ExitCode::from(1)
}

/// Builds the runner if needed and runs it with `argv` in place of this process (same
/// process id: signals and the exit code are the runner's). `verbose`: cargo's output.
fn hand_over(crates: &[LibraryCrate], argv: Vec<OsString>, verbose: bool) -> ExitCode {
    let exe = match program::ensure(crates, verbose) {
        Ok(exe) => exe,
        Err(code) => return code,
    };
    exec(&exe, argv)
}

#[cfg(unix)]
fn exec(exe: &Path, argv: Vec<OsString>) -> ExitCode {
    use std::os::unix::process::CommandExt;
    let e = std::process::Command::new(exe).args(argv).exec();
    eprintln!("error: cannot start the runner {}: {e}", exe.display());
    ExitCode::from(2)
}

#[cfg(not(unix))]
fn exec(exe: &Path, argv: Vec<OsString>) -> ExitCode {
    match std::process::Command::new(exe).args(argv).status() {
        Ok(s) => ExitCode::from(s.code().unwrap_or(1).clamp(0, 255) as u8),
        Err(e) => {
            eprintln!("error: cannot start the runner {}: {e}", exe.display());
            ExitCode::from(2)
        }
    }
}
