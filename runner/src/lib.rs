//! What a runner links: a run plan built into the runtime and run, with the module
//! types of the standard library and of the libraries linked in. No compiler.
//!
//! The `ferroc` CLI checks a model, plans it and compares the manifests with the
//! module types the runner registers (which the runner describes: [`describe`]); then
//! it writes the run plan ([`plan`]) to a temporary file and starts the runner with
//! `run --plan FILE`. The runner reads the plan, deletes the file, and runs it
//! ([`run`]). The CLI runs a model that needs only the standard library through the
//! same [`run::run`] in its own process.
//!
//! Modules: `plan` (the plan's form, its header and version), `build` (plan →
//! Builder calls), `from_plan` (a plan's pieces as the runtime takes them), `record`
//! (`--log-dir`, `--record`), `run` (the run), `output` (writing standard output).

#![forbid(unsafe_code)]

use ferroc_runtime::builder::Registry;
use ferroc_runtime::module::Interface;
use std::ffi::OsString;
use std::path::Path;
use std::process::ExitCode;

/// `eprintln!` that does not panic when standard error is closed or full (see
/// `ferroc_runtime::console::stderr_line`); it shadows std's in this whole crate.
macro_rules! eprintln {
    ($($arg:tt)*) => {
        ferroc_runtime::console::stderr_line(format_args!($($arg)*))
    };
}

pub mod build;
pub mod from_plan;
pub mod output;
pub mod plan;
pub mod record;
pub mod run;
pub mod summary;

pub use ferroc_runtime;
pub use mimalloc;

/// The module types built into every runner and into `ferroc` itself: the standard
/// library's. A runner adds those of the libraries it links.
pub fn registry() -> Registry {
    let mut registry = Registry::new();
    ferroc_std::register(&mut registry);
    registry
}

/// The interfaces of every module type in `registry`, in name order: what a runner
/// answers to `describe`, and what the CLI compares with the manifests.
pub fn interfaces(registry: &Registry) -> Vec<Interface> {
    let mut names: Vec<&str> = registry.names().collect();
    names.sort_unstable();
    names
        .into_iter()
        .filter_map(|n| registry.interface(n))
        .collect()
}

/// `describe`: the interfaces as one JSON array on standard output.
pub fn describe(registry: &Registry) -> ExitCode {
    match serde_json::to_vec(&interfaces(registry)) {
        Ok(mut text) => {
            text.push(b'\n');
            output::stdout_then(&text, ExitCode::SUCCESS)
        }
        Err(e) => {
            eprintln!("error: cannot describe the module types: {e}");
            ExitCode::from(2)
        }
    }
}

/// The `main` of a generated runner: `registry` holds the standard library's types and
/// those of the libraries linked in.
pub fn main(registry: Registry) -> ExitCode {
    main_from(registry, std::env::args_os().skip(1).collect())
}

/// [`main`] with these arguments (without the program's name): `describe`, or
/// `run --plan FILE`. Anything else is refused: runners are started by `ferroc`.
pub fn main_from(registry: Registry, args: Vec<OsString>) -> ExitCode {
    main_with(registry, args, None)
}

/// The `main` of the runner of a model whose parts are ROS 2 nodes: [`main`] with
/// `network` opening the nodes (`ferroc_zenoh::ros2::network`).
pub fn main_ros2(registry: Registry, network: run::Ros2Network) -> ExitCode {
    main_with(
        registry,
        std::env::args_os().skip(1).collect(),
        Some(network),
    )
}

/// [`main_from`] with the ROS 2 network, if this runner has one.
pub fn main_with(
    registry: Registry,
    args: Vec<OsString>,
    ros2: Option<run::Ros2Network>,
) -> ExitCode {
    let args: Vec<&std::ffi::OsStr> = args.iter().map(OsString::as_os_str).collect();
    match args.as_slice() {
        [command] if *command == "describe" => describe(&registry),
        [command, flag, file] if *command == "run" && *flag == "--plan" => {
            match plan::read(Path::new(file)) {
                Ok(plan) => run::run_with(plan, &registry, ros2),
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::from(2)
                }
            }
        }
        _ => {
            eprintln!(
                "error: this program is a ferroc runner: it takes `describe` or `run --plan FILE` from `ferroc`\n  \
                 help: run your model with `ferroc run MODEL` (ferroc {})",
                plan::FERROC
            );
            ExitCode::from(2)
        }
    }
}
