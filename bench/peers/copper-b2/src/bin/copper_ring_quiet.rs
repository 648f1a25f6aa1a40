//! B2 on Copper with logging reduced as far as Copper allows (`ring_quiet.ron`: task
//! logging and keyframes off; no log file, the builder's no-op logger).

use copper_b2::{parse_args, report, timed_round};
use cu29::prelude::*;

#[copper_runtime(config = "ring_quiet.ron")]
struct QuietRing {}

fn main() {
    let (cycles, rounds) = parse_args(&std::env::args().skip(1).collect::<Vec<_>>(), 2_000_000)
        .unwrap_or_else(|e| {
            eprintln!("copper_ring_quiet: {e}\nhelp: copper_ring_quiet [--cycles N] [--rounds R]");
            std::process::exit(2)
        });
    let app = QuietRing::builder()
        .build()
        .unwrap_or_else(|e| fail(&e.to_string()));
    let mut running = app.start().unwrap_or_else(|e| fail(&e.to_string()));
    let mut times = Vec::new();
    for _ in 0..rounds {
        match timed_round(cycles, || running.run_one_iteration()) {
            Ok(t) => times.push(t),
            Err(e) => fail(&e),
        }
    }
    if let Err(e) = running.stop() {
        fail(&e.to_string());
    }
    report("logging-off", "", cycles, &times);
}

fn fail(message: &str) -> ! {
    eprintln!("copper_ring_quiet: {message}");
    std::process::exit(1)
}
