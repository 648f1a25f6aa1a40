//! B2 on Copper as a user gets it by default (`ring_default.ron`: no `logging`
//! section, so every CopperList goes to the unified log, with keyframes), the log
//! written to a file as Copper's examples set it up (`with_log_path`).
//! `--log-dir DIR`: where the log files go (default: the system's temporary folder;
//! run.sh also gives /dev/shm, a RAM file system, to separate Copper's own cost of
//! logging from the disk's). The files are removed after each round.

use copper_b2::{parse_args, report, timed_round};
use cu29::prelude::*;

#[copper_runtime(config = "ring_default.ron")]
struct DefaultRing {}

/// Slab of the memory-mapped log, as Copper's caterpillar example (1 GiB).
const SLAB_SIZE: Option<usize> = Some(1024 * 1024 * 1024);

fn main() {
    let (log_dir, rest) = take_log_dir(std::env::args().skip(1).collect());
    let (cycles, rounds) = parse_args(&rest, 2_000_000).unwrap_or_else(|e| {
        eprintln!(
            "copper_ring_default: {e}\nhelp: copper_ring_default [--cycles N] [--rounds R] [--log-dir DIR]"
        );
        std::process::exit(2)
    });
    let dir = log_dir.join(format!("copper-b2-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| fail(&format!("{}: {e}", dir.display())));
    let mut times = Vec::new();
    // One application (and log file) per round, so a round's log never outgrows the
    // disk of a small machine; the log of a finished round is removed.
    for round in 0..rounds {
        let log = dir.join(format!("ring{round}.copper"));
        let app = DefaultRing::builder()
            .with_log_path(&log, SLAB_SIZE)
            .and_then(|b| b.build())
            .unwrap_or_else(|e| fail(&e.to_string()));
        let mut running = app.start().unwrap_or_else(|e| fail(&e.to_string()));
        match timed_round(cycles, || running.run_one_iteration()) {
            Ok(t) => times.push(t),
            Err(e) => fail(&e),
        }
        drop(running.stop().unwrap_or_else(|e| fail(&e.to_string())));
        let bytes: u64 = std::fs::read_dir(&dir)
            .map(|d| {
                d.flatten()
                    .filter_map(|f| f.metadata().ok())
                    .map(|m| m.len())
                    .sum()
            })
            .unwrap_or(0);
        println!(
            "copper-b2 default: round {round}: log files {:.1} MB",
            bytes as f64 / 1e6
        );
        let _ = std::fs::remove_dir_all(&dir);
        let _ = std::fs::create_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&dir);
    let extra = format!(" log_dir={}", log_dir.display());
    report("default-logging", &extra, cycles, &times);
}

/// `--log-dir DIR` out of `args`; the system's temporary folder without it.
fn take_log_dir(mut args: Vec<String>) -> (std::path::PathBuf, Vec<String>) {
    match args.iter().position(|a| a == "--log-dir") {
        Some(i) if i + 1 < args.len() => {
            let dir = args.remove(i + 1);
            args.remove(i);
            (dir.into(), args)
        }
        _ => (std::env::temp_dir(), args),
    }
}

fn fail(message: &str) -> ! {
    eprintln!("copper_ring_default: {message}");
    std::process::exit(1)
}
