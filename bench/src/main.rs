//! `ferroc-bench`: the benchmarks of the shared design's benchmarks.md.
//!
//! `cargo run --release -p ferroc-bench -- <id>`; each benchmark prints one line per
//! measurement and ends with one `RESULT <id> key=value ...` line for scripts.
//! Arguments are parsed by hand: there are only a few, and the bench stays light.

mod b1;
mod generate;
mod measure;

use std::process::ExitCode;

const HELP: &str = "\
ferroc-bench: ferroc's benchmarks (design: benchmarks.md)

Usage: cargo run --release -p ferroc-bench -- <ID>
       cargo run --release -p ferroc-bench -- gen <N> [FILE]

IDs:
  b1    checker scale: `ferroc check` vs `xmllint --noout` on generated models of
        1,000 / 10,000 / 100,000 modules (wall time, ratio, peak RSS, growth)
  b2    control loop            (not implemented yet)
  b3    image fan-out           (not implemented yet)
  b4    latency                 (not implemented yet)
  b5    bundle                  (not implemented yet)
  all   every implemented benchmark (b1)
  gen   write the B1 model with N modules to FILE (default: standard output),
        e.g. to profile the checker on it

b1 runs the `ferroc` binary next to its own executable (target/release/ferroc) and
builds it first when it is missing or older than the benchmark. Models and logs go to
target/bench-models/. Always use --release: debug figures are meaningless.

Each benchmark ends with one line `RESULT <id> key=value ...`.
Exit codes: 0 done, 1 a benchmark failed, 2 usage error or not implemented.";

/// Benchmarks that exist in the design but not here yet, with what they measure.
const PLANNED: [(&str, &str); 4] = [
    ("b2", "B2 control loop"),
    ("b3", "B3 image fan-out"),
    ("b4", "B4 latency"),
    ("b5", "B5 bundle"),
];

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(id) = args.first() else {
        eprintln!("{HELP}");
        return ExitCode::from(2);
    };
    match id.as_str() {
        "-h" | "--help" | "help" => {
            println!("{HELP}");
            ExitCode::SUCCESS
        }
        "b1" | "all" => ExitCode::from(b1::run()),
        "gen" => gen(&args[1..]),
        other => match PLANNED.iter().find(|(k, _)| *k == other) {
            Some((_, what)) => {
                eprintln!("{other}: not implemented yet: see issue \"{what}\" (benchmarks.md)");
                ExitCode::from(2)
            }
            None => {
                eprintln!("unknown benchmark `{other}`\n\n{HELP}");
                ExitCode::from(2)
            }
        },
    }
}

/// `gen N [FILE]`: the B1 model, for profiling the checker by hand.
fn gen(args: &[String]) -> ExitCode {
    let Some(n) = args
        .first()
        .and_then(|a| a.replace('_', "").parse::<usize>().ok())
    else {
        eprintln!("gen needs a module count: gen 10000 [FILE]");
        return ExitCode::from(2);
    };
    let text = generate::generate(n);
    let written = match args.get(1) {
        Some(file) => std::fs::write(file, text),
        None => std::io::Write::write_all(&mut std::io::stdout().lock(), text.as_bytes()),
    };
    match written {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gen: {e}");
            ExitCode::from(1)
        }
    }
}
