//! A run of a plan: recording set up, the application built and started, supervised
//! until its time or cycles are up or Ctrl-C / SIGTERM stops it.

use crate::plan::{RunOptions, RunPlan};
use ferroc_runtime::builder::{Lockstep, Registry, StartOptions};
use ferroc_runtime::link::transport::Network;
use ferroc_runtime::supervise;
use std::io::IsTerminal;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Runs `plan` with the module types of `registry`: the whole of a plain runner's run.
pub fn run(plan: RunPlan, registry: &Registry) -> ExitCode {
    run_with(plan, registry, None)
}

/// Makes the network a part's ROS 2 node speaks on: `ferroc_zenoh::ros2::network` in
/// the runner of a model with `<ros2>` (this crate links no Zenoh).
pub type Ros2Network = fn() -> Result<Arc<dyn Network>, String>;

/// [`run`], with `ros2` opening the network of the plan's ROS 2 nodes (without it, a
/// plan with a node is refused when it starts).
pub fn run_with(mut plan: RunPlan, registry: &Registry, ros2: Option<Ros2Network>) -> ExitCode {
    let registry = match prepare(&mut plan, registry) {
        Ok(r) => r,
        Err(code) => return code,
    };
    let seed = seed(&plan);
    let interrupted = interrupt_flag();
    let mut start = start_options(&plan.run);
    if let (false, Some(network)) = (plan.ros2.is_empty(), ros2) {
        match network() {
            Ok(n) => start.network = Some(n),
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
        }
    }
    let started = crate::build::build(&plan, &registry, seed, start);
    let running = match started {
        Ok(running) => running,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
    };
    let options = supervise_options(&plan.run);
    let (code, summary) = supervise::supervise_summarised(running, &interrupted, &options);
    crate::summary::finish(&plan, seed, &summary, code)
}

/// Before the application is built: recording configured (log folder, parts), and
/// `--record`'s recorders added to the plan and their type to a copy of `registry`
/// (exit code 2 when it cannot record).
pub fn prepare(plan: &mut RunPlan, registry: &Registry) -> Result<Registry, ExitCode> {
    crate::record::configure(plan);
    let mut registry = registry.clone();
    if let Err(e) = crate::record::add_recorders(plan, &mut registry) {
        eprintln!("error: {e}");
        return Err(ExitCode::from(2));
    }
    Ok(registry)
}

/// The run seed: the plan's (`--seed`, else the model's), else one chosen and printed;
/// recordings note it.
pub fn seed(plan: &RunPlan) -> u64 {
    let seed = supervise::run_seed(plan.seed);
    ferroc_std::recording::set_run_seed(seed);
    seed
}

/// How the application starts: `--cycles`, `--lockstep` with `--for` in model time.
pub fn start_options(run: &RunOptions) -> StartOptions {
    StartOptions {
        limit: run.cycles,
        lockstep: run.lockstep.then(|| Lockstep {
            periods: Vec::new(),
            until: run.duration,
        }),
        network: None,
    }
}

/// How it is supervised: `--for` in wall time, the live status line on a terminal.
pub fn supervise_options(run: &RunOptions) -> supervise::Options {
    supervise::Options {
        duration: run.duration.filter(|_| !run.lockstep),
        status_line: !run.quiet && std::io::stderr().is_terminal(),
    }
}

/// The flag Ctrl-C and SIGTERM set. Installed before any thread starts, so that a
/// signal never finds the default handler.
pub fn interrupt_flag() -> Arc<AtomicBool> {
    let interrupted = Arc::new(AtomicBool::new(false));
    let flag = interrupted.clone();
    if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst)) {
        eprintln!("warning: Ctrl-C will not stop cleanly: {e}");
    }
    interrupted
}
