//! B2 on Copper as a user gets it by default (`ring_default.ron`: no `logging`
//! section, so every CopperList goes to the unified log, with keyframes), the log
//! written to a file as Copper's examples set it up (`with_log_path`).
//! `--log PATH` (default: a file in the system's temporary folder, removed after).

use copper_b2::{parse_args, report, timed_round};
use cu29::prelude::*;

#[copper_runtime(config = "ring_default.ron")]
struct DefaultRing {}

/// Slab of the memory-mapped log, as Copper's caterpillar example (1 GiB).
const SLAB_SIZE: Option<usize> = Some(1024 * 1024 * 1024);

fn main() {
    let (cycles, rounds) = parse_args(2_000_000).unwrap_or_else(|e| {
        eprintln!("copper_ring_default: {e}\nhelp: copper_ring_default [--cycles N] [--rounds R]");
        std::process::exit(2)
    });
    let dir = std::env::temp_dir().join(format!("copper-b2-{}", std::process::id()));
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
    report("default-logging", cycles, &times);
}

fn fail(message: &str) -> ! {
    eprintln!("copper_ring_default: {message}");
    std::process::exit(1)
}
