//! `ferroc run` ([`run`]) and `ferroc types` ([`types`]) with any set of module types.
//!
//! The `ferroc` CLI links only the standard library (`ferroc_std`); for a model using
//! other libraries it generates a small runner program that links exactly their crates
//! (src/runner/). A runner with `--inspect` calls [`main`] with a registry of their
//! types and runs the same code as the CLI.
//!
//! What a runner links is `ferroc_runner` (no compiler): this crate is the CLI's side
//! of a run, which checks and plans the model and compares the manifests with the
//! code, and the `--inspect` runner's (structural edits check the edited model).
//!
//! Modules: `check_first` (a command checks its model first and stops on errors),
//! `from_plan` (the compiler's plan as a run plan), `run` (the command), `inspect` and
//! `edit` (`--inspect`: serving the inspector, structural edits as model edits),
//! `interface` (manifest ↔ code comparison), `types` (`ferroc types`), `sources`
//! (spans as `FILE:LINE:COL`, the model's text).

#![forbid(unsafe_code)]

use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_runtime::builder::Registry;
use std::path::PathBuf;
use std::process::ExitCode;

/// `eprintln!` that does not panic when standard error is closed or full (see
/// `ferroc_runtime::console::stderr_line`); it shadows std's in this whole crate.
macro_rules! eprintln {
    ($($arg:tt)*) => {
        ferroc_runtime::console::stderr_line(format_args!($($arg)*))
    };
}

pub mod check_first;
pub mod edit;
pub mod from_plan;
pub mod inspect;
pub mod interface;
pub mod run;
pub mod sources;
pub mod types;

pub use ferroc_runner::output;
pub use ferroc_runner::{self, ferroc_runtime, mimalloc};

/// The standard library's manifest, built into the tool.
pub const FERROC_STD: &str = include_str!("../../components/ferroc_std.lib.xml");

/// Loader options shared by every command that reads models.
pub fn loader_options(lib_path: &[PathBuf], allow_outside_includes: bool) -> Options {
    let mut lib_path = lib_path.to_vec();
    if let Ok(env) = std::env::var("FERROC_LIB_PATH") {
        lib_path.extend(std::env::split_paths(&env));
    }
    Options {
        lib_path,
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: FERROC_STD.into(),
        }],
        allow_outside_includes,
        ..Options::default()
    }
}

/// The command an inspecting runner answers: `run`, with `ferroc`'s arguments.
#[derive(clap::Parser)]
#[command(
    name = "ferroc",
    about = "A ferroc runner: runs models with the module types linked in, inspected"
)]
struct Runner {
    #[command(subcommand)]
    command: RunnerCommand,
    /// ferroc's `--color` (its command line is handed on as it is); a runner prints
    /// nothing in colour
    #[arg(long, global = true, hide = true)]
    color: Option<String>,
}

#[derive(clap::Subcommand)]
enum RunnerCommand {
    Run(run::RunArgs),
}

/// The `main` of a generated runner for `ferroc run --inspect`: `registry` holds the
/// standard library's types and those of the libraries linked in. `ferroc` passes its
/// own command line on.
pub fn main(registry: Registry) -> ExitCode {
    main_from(registry, std::env::args_os())
}

/// The `main` of the inspecting runner of a model whose parts are ROS 2 nodes: [`main`]
/// with `network` opening the nodes (`ferroc_zenoh::ros2::network::network`) on a
/// Zenoh session of their own, beside the inspection server's.
pub fn main_ros2(registry: Registry, network: ferroc_runner::run::Ros2Network) -> ExitCode {
    let runner = <Runner as clap::Parser>::parse_from(std::env::args_os());
    match runner.command {
        RunnerCommand::Run(args) => run::run_with(args, &registry, Some(network)),
    }
}

/// [`main`] with these arguments (the first is the program's name).
pub fn main_from(
    registry: Registry,
    args: impl IntoIterator<Item = std::ffi::OsString>,
) -> ExitCode {
    let runner = <Runner as clap::Parser>::parse_from(args);
    match runner.command {
        RunnerCommand::Run(args) => run::run(args, &registry),
    }
}
