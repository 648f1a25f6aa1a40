//! B5 — the bundle (benchmarks.md): the control loop of B2 (`models/control_loop.xml`)
//! built by `ferroc bundle` as a statically wired program, against the same model run
//! by `ferroc run` (runtime-constructed). Wall time of each process is compared (the
//! summaries' "after X s" has only 0.1 s resolution); `ferroc run`'s includes checking
//! the model, a few milliseconds, which is measured and subtracted. Rounds alternate
//! the two programs.

use crate::options::Options;
use std::path::{Path, PathBuf};
use std::process::Command;

const DEFAULT_CYCLES: u64 = 20_000_000;
const DEFAULT_ROUNDS: u64 = 3;
const MODEL: &str = "models/control_loop.xml";

/// Runs B5 and prints its lines. Returns the process exit code.
pub fn run(args: &[String]) -> u8 {
    let (cycles, rounds) =
        match Options::cycles_and_rounds("b5", args, DEFAULT_CYCLES, DEFAULT_ROUNDS) {
            Ok(v) => v,
            Err(e) => {
                eprintln!("{e}");
                return 2;
            }
        };
    match measure(cycles, rounds) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("b5: {e}");
            1
        }
    }
}

fn measure(cycles: u64, rounds: u64) -> Result<(), String> {
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let ferroc = crate::b1::ferroc_binary()?;
    let release = crate::b1::profile_dir()
        .file_name()
        .is_some_and(|n| n == "release");
    if !release {
        println!("b5: warning: not a release build; figures are meaningless (use --release)");
    }
    build_bundle(&ferroc, &workspace, release)?;
    let program: PathBuf = crate::b1::profile_dir().join("control_loop-bench");
    let n = cycles.to_string();
    let mut bundled = Vec::new();
    let mut runtime = Vec::new();
    let mut checking = Vec::new();
    for _ in 0..rounds {
        checking.push(seconds_of_check(&ferroc, &workspace)?);
        bundled.push(seconds(
            Command::new(&program).args(["--cycles", &n, "-q"]),
        )?);
        runtime.push(seconds(
            Command::new(&ferroc)
                .current_dir(&workspace)
                .args(["run", MODEL, "--cycles", &n, "-q"]),
        )?);
    }
    let best = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let check = best(&checking);
    let (b, r) = (best(&bundled), best(&runtime) - check);
    println!(
        "b5: checking the model takes {:.1} ms, subtracted from ferroc run",
        check * 1e3
    );
    let rate = |s: f64| cycles as f64 / s / 1e6;
    println!(
        "b5: bundle  {:.2} M cycles/s ({:.1} ns/cycle), best of {rounds}",
        rate(b),
        b * 1e9 / cycles as f64
    );
    println!(
        "b5: ferroc run {:.2} M cycles/s ({:.1} ns/cycle), best of {rounds}",
        rate(r),
        r * 1e9 / cycles as f64
    );
    let ratio = rate(b) / rate(r);
    println!(
        "b5: target: the bundle at least as fast as ferroc run: {} (bundle / run = {ratio:.3}; \
         within 2 % counts as equal, both run the same Builder calls)",
        if ratio >= 0.98 { "met" } else { "NOT met" }
    );
    println!(
        "RESULT b5 bundle_cycles_per_s={:.0} runtime_cycles_per_s={:.0} ratio={ratio:.3} cycles={cycles} rounds={rounds}",
        rate(b) * 1e6,
        rate(r) * 1e6
    );
    Ok(())
}

/// Bundles the model and builds the bundle (in the shared target dir, release if
/// `release`).
fn build_bundle(ferroc: &Path, workspace: &Path, release: bool) -> Result<(), String> {
    let bundle = crate::b1::target_dir()
        .join("bench-models")
        .join("b5-bundle");
    let out = Command::new(ferroc)
        .current_dir(workspace)
        .args(["bundle", MODEL, "--force", "-o"])
        .arg(&bundle)
        .output()
        .map_err(|e| format!("cannot run {}: {e}", ferroc.display()))?;
    if !out.status.success() {
        return Err(format!(
            "ferroc bundle failed:\n{}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    println!(
        "b5: bundled {MODEL} into {}; building it (release, shared target dir)",
        bundle.display()
    );
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let status = Command::new(cargo)
        .current_dir(&bundle)
        .env("CARGO_TARGET_DIR", crate::b1::target_dir())
        .args(["build", "--offline", "--quiet"])
        .args(if release { &["--release"][..] } else { &[][..] })
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err(format!("building the bundle failed ({status})"));
    }
    Ok(())
}

/// Wall time of a program that must succeed and end with the runtime's summary.
fn seconds(command: &mut Command) -> Result<f64, String> {
    let started = std::time::Instant::now();
    let out = command
        .output()
        .map_err(|e| format!("cannot run {command:?}: {e}"))?;
    let took = started.elapsed().as_secs_f64();
    let err = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() || !err.contains("stopped (cycle limit reached)") {
        return Err(format!("{command:?} failed:\n{err}"));
    }
    Ok(took)
}

/// Wall time of `ferroc check` on the model (part of every `ferroc run`).
fn seconds_of_check(ferroc: &Path, workspace: &Path) -> Result<f64, String> {
    let started = std::time::Instant::now();
    let out = Command::new(ferroc)
        .current_dir(workspace)
        .args(["check", MODEL, "--format", "short"])
        .output()
        .map_err(|e| format!("cannot run {}: {e}", ferroc.display()))?;
    if !out.status.success() {
        return Err(format!("ferroc check {MODEL} failed"));
    }
    Ok(started.elapsed().as_secs_f64())
}
