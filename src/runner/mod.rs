//! `ferroc run` and `ferroc types` for libraries not built into ferroc.
//!
//! ferroc links only the standard library. A model using other libraries runs in a
//! runner: a small program, generated and built by cargo once per set of libraries
//! (`program.rs`), that links exactly their crates (found from the manifests'
//! `rust-crate`, `crates.rs`) and the run itself (`ferroc_runner`), no compiler.
//! ferroc checks the model first (errors stop here, before any build), asks the
//! runner which module types it registers (`describe`) to compare them with the
//! manifests, plans the model and hands the runner the plan (a temporary file the
//! runner deletes when it has read it, docs/writing-modules.md); the runner replaces this
//! process. `run --inspect` uses the inspecting kind of runner (`program::Kind`),
//! which checks the model itself: its structural edits need the compiler.

pub mod build;
pub mod cache;
pub mod checkout;
pub mod crates;
mod failure;
pub mod program;

use crates::LibraryCrate;
use ferroc_host::run::{Interfaces, RunArgs};
use ferroc_host::types::TypesArgs;
use program::Kind;
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
    // ROS 2 nodes need Zenoh, which ferroc and the plain runner do not link.
    let ros2 =
        (result.app.as_ref()).is_some_and(|app| app.ros2.nodes.iter().any(|n| !n.is_external()));
    if crates.is_empty() && !ros2 {
        let registry = ferroc_host::run::registry();
        return ferroc_host::run::run_checked(args, &result, &registry);
    }
    if args.inspect.is_some() {
        let argv: Vec<OsString> = std::env::args_os().skip(1).collect();
        let kind = if ros2 {
            Kind::InspectRos2
        } else {
            Kind::Inspect
        };
        return hand_over(&crates, kind, argv, args.verbose);
    }
    let kind = if ros2 { Kind::Ros2 } else { Kind::Plain };
    let exe = match program::ensure(&crates, kind, args.verbose) {
        Ok(exe) => exe,
        Err(code) => return code,
    };
    let interfaces = match describe(&exe) {
        Ok(i) => i,
        Err(code) => return code,
    };
    let run_plan = match ferroc_host::run::plan_run(&args, &result, &interfaces) {
        Ok((_, run_plan)) => run_plan,
        Err(code) => return code,
    };
    let file = match ferroc_runner::plan::write_temporary(&run_plan) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let code = exec(
        &exe,
        vec!["run".into(), "--plan".into(), file.clone().into()],
    );
    // Only when the runner did not start (it deletes the plan once read).
    let _ = std::fs::remove_file(&file);
    code
}

/// The module types a runner registers, as it describes them; on failure the cause is
/// reported (exit code 2).
fn describe(exe: &Path) -> Result<Interfaces, ExitCode> {
    let failed = |why: String| {
        eprintln!(
            "error: the runner {} did not describe its module types: {why}\n  \
             help: delete it to have it built again",
            exe.display()
        );
        ExitCode::from(2)
    };
    let output = std::process::Command::new(exe)
        .arg("describe")
        .stdin(std::process::Stdio::null())
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| failed(e.to_string()))?;
    if !output.status.success() {
        return Err(failed(output.status.to_string()));
    }
    let list: Vec<ferroc_runtime::module::Interface> =
        serde_json::from_slice(&output.stdout).map_err(|e| failed(e.to_string()))?;
    Ok(Interfaces::from_iter(ferroc_host::run::interface_list(
        list,
    )))
}

/// `ferroc types`: the libraries on the lib path (or those asked for) in a runner; in
/// this process when there are none but the standard library.
pub fn types(mut args: TypesArgs) -> ExitCode {
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
    if args.libraries().is_empty() && !names.is_empty() {
        // Export and list what the lib path holds, not every library linked in.
        args.set_libraries(names);
    }
    let interfaces = if crates.is_empty() {
        ferroc_host::run::interfaces_of(&ferroc_host::run::registry())
    } else {
        let exe = match program::ensure(&crates, Kind::Plain, args.verbose()) {
            Ok(exe) => exe,
            Err(code) => return code,
        };
        match describe(&exe) {
            Ok(i) => i,
            Err(code) => return code,
        }
    };
    ferroc_host::types::run(args, &interfaces)
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
fn hand_over(crates: &[LibraryCrate], kind: Kind, argv: Vec<OsString>, verbose: bool) -> ExitCode {
    let exe = match program::ensure(crates, kind, verbose) {
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
