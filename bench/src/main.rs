//! `ferroc-bench`: the benchmarks of the shared design's benchmarks.md.
//!
//! `cargo run --release -p ferroc-bench -- <id>`; each benchmark prints one line per
//! measurement and ends with one `RESULT <id> key=value ...` line for scripts.
//! Arguments are parsed by hand: there are only a few, and the bench stays light.

mod b1;
mod b2;
mod b3;
mod b3_parts;
mod b4;
mod b4_large;
mod b4_parts;
mod b5;
mod cdr;
mod generate;
mod measure;
mod options;
mod ros2_twist;

use std::process::ExitCode;

const HELP: &str = "\
ferroc-bench: ferroc's benchmarks (design: benchmarks.md)

Usage: cargo run --release -p ferroc-bench -- <ID> [OPTIONS]
       cargo run --release -p ferroc-bench -- gen <N> [FILE] [--findings]

IDs:
  b1    checker scale: `ferroc check` vs `xmllint --noout` on generated models of
        1,000 / 10,000 / 100,000 modules (wall time, ratio, peak RSS, growth); then
        100,000 modules with 3,334 findings in the default (human) format against
        `--format short` (target: human within 2x of short)
  b2    control loop: five ring.Stage modules pass a 4x4 f64 matrix around a ring
        in one continuous thread container (Builder calls as `ferroc run` makes
        for models/control_loop.xml); baseline: the same reads and writes in a
        hand-written loop; diagnostics: one stage's port work alone
          --cycles N      cycles per variant and round (default 20000000)
          --rounds R      interleaved rounds, best reported (default 3)
  b3    image fan-out: a periodic producer publishes 1920x1080 RGB24 frames at 50 fps
        (memcpy into a pooled port buffer) to 1 / 7 / 15 data-triggered consumer
        containers: fps seen, CPU % of the process, peak RSS, each run in a child
        process; baseline: the memcpy alone, no ports; diagnostics: 15 containers
        (and 15 plain threads) woken without ports
          --seconds S     measured seconds per configuration (default 5)
          --rounds R      runs per configuration, interleaved (default 2; each
                          run adds 0.5 s warm-up; 6 configurations)
  b3-parts  image fan-out between part programs: the b3 producer (1920x1080 RGB
        ferroc_std.Image at 50 fps) in one program, 1 / 7 / 15 consumers each in its
        own; ferroc with and without shared memory and a bare Zenoh SHM publisher with
        as many subscriber programs, in the same run: fps of each consumer, CPU % of
        all programs, RSS of each (and growth over the window), p50/p99 latency from
        publish to the consumer's step; one RESULT line per configuration
          --frames N      measured frames per configuration (default 500, +50
                          warm-up; 10000 to see memory stay flat)
          --consumers L   consumer counts (default 1,7,15)
          --variants L    of ferroc-shm, ferroc-net, zenoh-shm (default all three)
  b4    latency in one process: 64-byte messages, publish -> a data-triggered
        container sees them; p50/p99/max against std::sync::mpsc, with the copy
        ports, the container without ports and plain threads (Wakeup wait with and
        without time limit, park/unpark) to split the wakeup into its parts;
        variants interleaved in rounds
          --messages N    recorded messages per variant (default 100000)
          --gap-us G      pause after each message was seen (default 20)
          --rounds R      rounds the messages are split into (default 20)
          --pin           publisher on CPU 0, receivers on CPU 1
  b4-parts  latency between two part programs over Zenoh: 64-byte values through a
        ferroc link (writer here, reader in a child process), p50/p99/max next to a
        bare Zenoh publisher/subscriber pair in the same run, rounds alternate
          --messages N    recorded values per variant (default 100000)
          --gap-us G      one value every G µs (default 100)
          --rounds R      rounds the values are split into (default 4)
  b4-large  latency of large values between two part programs: 64 B, 64 KB, 1 MB
        and 6.2 MB ferroc_std.Image values through a ferroc link with and without
        shared memory, next to a bare Zenoh pair with and without shared memory, in
        the same run (reader in a child process), p50/p99/max, rounds alternate
          --messages N    recorded values per size and variant (default 300)
          --rounds R      rounds the values are split into (default 2)
          --sizes LIST    only these sizes (bytes, comma-separated: 64,65536,...)
          --variants LIST only these variants (ferroc-shm,ferroc-copy,ferroc-net,
                          zenoh-shm,zenoh-net)
          --reader-wait W the reader's container waits: park (default), spin, adaptive, inline
  b5    bundle: `ferroc bundle models/control_loop.xml` (the B2 ring) built as a
        release program, against `ferroc run` of the same model; running time
        from their summaries, rounds alternate
          --cycles N      cycles per run (default 20000000)
          --rounds R      runs of each program (default 3)
  cdr   ROS 2's CDR as a running part writes it (ferroc-ros2's serde_cdr, straight
        from the serde value) against postcard of the same value (the codec of links
        between parts), and the dynamic-value CDR for reference: encoding and decoding
        a LaserScan of 720 ranges and an Odometry, ns per message, interleaved rounds
          --messages N    messages per variant and round (default 100000)
          --rounds R      rounds, best reported (default 5)
  ros2-twist  latency of a geometry_msgs/msg/Twist between two part programs as a
        ROS 2 topic (rmw_zenoh's wire, CDR from the value) against the same value
        through a plain ferroc link, same sessions, interleaved rounds
          --messages N    Twists per variant (default 40000)
          --gap-us G      one every G µs (default 200)
          --rounds R      rounds, alternating the variants (default 4)
  all   every benchmark (b1 to b5) with default options
  gen   write the B1 model with N modules to FILE and its manifest b1.lib.xml next to
        it (default: the model alone to standard output),
        e.g. to profile the checker on it; --findings: the model with findings

b1 runs the `ferroc` binary next to its own executable (target/release/ferroc) and
builds it first when it is missing or older than the benchmark. Models and logs go to
target/bench-models/. Always use --release: debug figures are meaningless.

Each benchmark ends with one line `RESULT <id> key=value ...` (b3-parts: one per
configuration).
Exit codes: 0 done, 1 a benchmark failed, 2 usage error or not implemented.";

/// Benchmarks that exist in the design but not here yet, with what they measure.
const PLANNED: [(&str, &str); 0] = [];

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(id) = args.first() else {
        eprintln!("{HELP}");
        return ExitCode::from(2);
    };
    // `ferroc-bench b4-large --help`: every benchmark's options are in the one help text.
    if args.iter().any(|a| a == "--help" || a == "-h") {
        println!("{HELP}");
        return ExitCode::SUCCESS;
    }
    match id.as_str() {
        "help" => {
            println!("{HELP}");
            ExitCode::SUCCESS
        }
        "b1" => no_options("b1", &args[1..]).unwrap_or_else(|| ExitCode::from(b1::run())),
        "b2" => ExitCode::from(b2::run(&args[1..])),
        "b3" => ExitCode::from(b3::run(&args[1..])),
        "b3-parts" => ExitCode::from(b3_parts::run(&args[1..])),
        b3_parts::CHILD_ARG => ExitCode::from(b3_parts::child(&args[1..])),
        "b4" => ExitCode::from(b4::run(&args[1..])),
        "b4-parts" => ExitCode::from(b4_parts::run(&args[1..])),
        b4_parts::CHILD_ARG => ExitCode::from(b4_parts::child(&args[1..])),
        "b4-large" => ExitCode::from(b4_large::run(&args[1..])),
        b4_large::CHILD_ARG => ExitCode::from(b4_large::child(&args[1..])),
        "b5" => ExitCode::from(b5::run(&args[1..])),
        "cdr" => ExitCode::from(cdr::run(&args[1..])),
        "ros2-twist" => ExitCode::from(ros2_twist::run(&args[1..])),
        ros2_twist::CHILD_ARG => ExitCode::from(ros2_twist::child(&args[1..])),
        "all" => no_options("all", &args[1..]).unwrap_or_else(all),
        "gen" => gen(&args[1..]),
        b3::CHILD_ARG => ExitCode::from(b3::child(&args[1..])),
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

/// Every implemented benchmark in turn; the exit code of the first that failed.
fn all() -> ExitCode {
    let codes = [
        b1::run(),
        b2::run(&[]),
        b3::run(&[]),
        b4::run(&[]),
        b5::run(&[]),
    ];
    ExitCode::from(codes.into_iter().find(|&c| c != 0).unwrap_or(0))
}

/// `Some(exit 2)` with a message when a benchmark without options got some.
fn no_options(id: &str, rest: &[String]) -> Option<ExitCode> {
    let first = rest.first()?;
    eprintln!("{id} takes no options (got `{first}`); see --help");
    Some(ExitCode::from(2))
}

/// `gen N [FILE]`: the B1 model, for profiling the checker by hand.
fn gen(args: &[String]) -> ExitCode {
    // `--findings`: the model of B1's many-findings case (one T107 per third group).
    let findings = args.iter().any(|a| a == "--findings");
    let args: Vec<String> = args
        .iter()
        .filter(|a| *a != "--findings")
        .cloned()
        .collect();
    let Some(n) = args
        .first()
        .and_then(|a| a.replace('_', "").parse::<usize>().ok())
    else {
        eprintln!("gen needs a module count: gen 10000 [FILE]");
        return ExitCode::from(2);
    };
    // The model names the `b1` manifest by a path relative to itself.
    let written = match args.get(1) {
        Some(file) if findings => {
            generate::write_model_with_findings(std::path::Path::new(file), n).map(|_| ())
        }
        Some(file) => generate::write_model(std::path::Path::new(file), n).map(|_| ()),
        None => {
            eprintln!(
                "gen: the model needs {} (ferroc-bench/src/generate/) in its folder; give FILE to have it written",
                generate::MANIFEST_FILE
            );
            std::io::Write::write_all(
                &mut std::io::stdout().lock(),
                if findings {
                    generate::generate_with_findings(n)
                } else {
                    generate::generate(n)
                }
                .as_bytes(),
            )
        }
    };
    match written {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gen: {e}");
            ExitCode::from(1)
        }
    }
}
