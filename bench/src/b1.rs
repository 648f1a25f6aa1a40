//! B1 — checker scale: `ferroc check` against `xmllint --noout` on generated models.
//!
//! Both tools run as child processes of this one, on the same file, in the same run, so
//! the ratio stays meaningful on a shared, noisy machine (benchmarks.md). The checker
//! is the real `ferroc` binary, not a library call, so start-up, file reading and
//! report writing are part of the figure, as a user sees it.

use crate::generate::{findings_in, write_model, write_model_with_findings};
use crate::measure::{best_of, Run};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

/// Model sizes measured, smallest first; the last one is the RESULT line.
const SIZES: [usize; 3] = [1_000, 10_000, 100_000];
/// Size of the model with findings (one T107 per third group), checked in both the
/// default (human) format and `--format short`.
const FINDINGS_SIZE: usize = 100_000;
/// Repeats per measurement (best wall time wins; the machines are shared and noisy) ...
const RUNS: usize = 5;
/// ... unless the runs so far already took this long.
const BUDGET: Duration = Duration::from_secs(20);

/// One model size: the check and the baseline.
struct Row {
    n: usize,
    check: Run,
    /// `None` when xmllint is missing or failed.
    xmllint: Option<Run>,
}

/// Runs B1 and prints its lines. Returns the process exit code.
pub fn run() -> u8 {
    let ferroc = match ferroc_binary() {
        Ok(p) => p,
        Err(e) => {
            eprintln!("b1: {e}");
            return 1;
        }
    };
    let dir = target_dir().join("bench-models");
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("b1: cannot create {}: {e}", dir.display());
        return 1;
    }
    let xmllint = Command::new("xmllint")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !xmllint {
        println!(
            "b1: xmllint not found (Debian: apt-get install libxml2-utils); the baseline is NaN"
        );
    }
    println!("b1: checker {}", ferroc.display());
    let mut rows = Vec::new();
    for n in SIZES {
        match measure(&ferroc, &dir, n, xmllint) {
            Ok(row) => rows.push(row),
            Err(e) => {
                eprintln!("b1: N={n}: {e}");
                return 1;
            }
        }
    }
    let many = match measure_findings(&ferroc, &dir, FINDINGS_SIZE) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("b1: N={FINDINGS_SIZE} with findings: {e}");
            return 1;
        }
    };
    let secs = |r: &Run| r.wall.as_secs_f64();
    let check_s = |n: usize| {
        rows.iter()
            .find(|r| r.n == n)
            .map_or(f64::NAN, |r| secs(&r.check))
    };
    let growth = check_s(100_000) / check_s(10_000);
    println!("b1: growth 10k -> 100k: {growth:.1}x (target <= 12x)");
    let last = rows.last().expect("three sizes");
    let x = last.xmllint.as_ref().map_or(f64::NAN, secs);
    println!(
        "RESULT b1 modules={} check_s={:.3} xmllint_s={x:.3} ratio={:.2} peak_mib={:.1} growth_10k_100k={growth:.2} check_cpu_s={:.3} findings={} findings_short_s={:.3} findings_human_s={:.3} human_vs_short={:.2}",
        last.n,
        secs(&last.check),
        secs(&last.check) / x,
        mib(last.check.peak_rss),
        last.check.cpu.as_secs_f64(),
        many.findings,
        secs(&many.short),
        secs(&many.human),
        secs(&many.human) / secs(&many.short),
    );
    0
}

/// Generates, writes and measures one size; `Err` when the model does not check clean.
fn measure(ferroc: &Path, dir: &Path, n: usize, xmllint: bool) -> Result<Row, String> {
    let file = dir.join(format!("b1-{n}.xml"));
    let size =
        write_model(&file, n).map_err(|e| format!("cannot write {}: {e}", file.display()))?;
    let log = dir.join(format!("b1-{n}.check.log"));
    let check = best_of(
        || {
            let mut c = Command::new(ferroc);
            c.arg("check").arg(&file).args(["--format", "short"]);
            c
        },
        &log,
        RUNS,
        BUDGET,
    )
    .map_err(|e| format!("cannot run {}: {e}", ferroc.display()))?;
    if check.code != Some(0) {
        let out = std::fs::read_to_string(&log).unwrap_or_default();
        let head: Vec<&str> = out.lines().take(20).collect();
        return Err(format!(
            "ferroc check {} failed (exit {:?}); first findings ({} lines in {}):\n{}",
            file.display(),
            check.code,
            out.lines().count(),
            log.display(),
            head.join("\n")
        ));
    }
    let xmllint = if xmllint {
        let xlog = dir.join(format!("b1-{n}.xmllint.log"));
        let make = || {
            let mut c = Command::new("xmllint");
            c.arg("--noout").arg(&file);
            c
        };
        match best_of(make, &xlog, RUNS, BUDGET) {
            Ok(r) if r.code == Some(0) => Some(r),
            other => {
                println!(
                    "b1: N={n}: xmllint failed ({other:?}, see {}); baseline NaN",
                    xlog.display()
                );
                None
            }
        }
    } else {
        None
    };
    let c = check.wall.as_secs_f64();
    let x = xmllint.as_ref().map_or(f64::NAN, |r| r.wall.as_secs_f64());
    println!(
        "b1 N={n:>6}  file={:6.1} MiB  check={c:7.3} s (cpu {:6.3} s)  xmllint={x:6.3} s  ratio={:6.2}  peak={:7.1} MiB",
        mib(size as u64),
        check.cpu.as_secs_f64(),
        c / x,
        mib(check.peak_rss)
    );
    Ok(Row { n, check, xmllint })
}

/// The model with findings, checked in both formats.
struct Findings {
    findings: usize,
    short: Run,
    human: Run,
}

/// Checks the model with findings in `--format short` and in the default human format:
/// the human format renders a snippet per finding, and must cost what the snippets cost
/// (target: within 2 × of short). Exit code 0 is expected: the findings are warnings.
fn measure_findings(ferroc: &Path, dir: &Path, n: usize) -> Result<Findings, String> {
    let file = dir.join(format!("b1-{n}-findings.xml"));
    write_model_with_findings(&file, n)
        .map_err(|e| format!("cannot write {}: {e}", file.display()))?;
    let findings = findings_in(n);
    let run = |format: &str| {
        let log = dir.join(format!("b1-{n}-findings.{format}.log"));
        let check = best_of(
            || {
                let mut c = Command::new(ferroc);
                c.arg("check").arg(&file).args(["--format", format]);
                c
            },
            &log,
            RUNS,
            BUDGET,
        )
        .map_err(|e| format!("cannot run {}: {e}", ferroc.display()))?;
        let out = std::fs::read_to_string(&log).unwrap_or_default();
        let seen = out.matches("T107").count();
        if check.code != Some(0) || seen < findings {
            return Err(format!(
                "ferroc check --format {format} {}: exit {:?}, {seen} of {findings} T107 findings printed (see {})",
                file.display(),
                check.code,
                log.display()
            ));
        }
        Ok(check)
    };
    let short = run("short")?;
    let human = run("human")?;
    let (s, h) = (short.wall.as_secs_f64(), human.wall.as_secs_f64());
    println!(
        "b1 N={n:>6}  with {findings} findings: short={s:7.3} s (cpu {:6.3} s)  human={h:7.3} s (cpu {:6.3} s)  human/short={:5.2} (target <= 2)",
        short.cpu.as_secs_f64(),
        human.cpu.as_secs_f64(),
        h / s
    );
    Ok(Findings {
        findings,
        short,
        human,
    })
}

fn mib(bytes: u64) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

/// `target/<profile>`: the folder of this executable.
pub(crate) fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap_or_default();
    exe.parent().map(Path::to_path_buf).unwrap_or_default()
}

/// `target`: models go to `target/bench-models`, out of the source tree.
pub(crate) fn target_dir() -> PathBuf {
    let p = profile_dir();
    p.parent().map(Path::to_path_buf).unwrap_or(p)
}

/// The `ferroc` binary next to this executable, built first when it is missing or
/// older than this executable. Cargo relinks the bench whenever ferroc-compiler
/// changes but does not rebuild the `ferroc` binary for `-p ferroc-bench`, so without
/// the age test a compiler fix would be measured with the old checker.
pub(crate) fn ferroc_binary() -> Result<PathBuf, String> {
    let dir = profile_dir();
    let ferroc = dir.join(format!("ferroc{}", std::env::consts::EXE_SUFFIX));
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let own = std::env::current_exe().ok().and_then(|p| modified(&p));
    let stale = match (modified(&ferroc), own) {
        (None, _) => true,
        (Some(f), Some(o)) => f < o,
        (Some(_), None) => false,
    };
    if !stale {
        return Ok(ferroc);
    }
    let release = dir.file_name().is_some_and(|n| n == "release");
    if !release {
        println!(
            "b1: warning: not a release build; figures are meaningless (use cargo run --release)"
        );
    }
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let profile: &[&str] = if release { &["--release"] } else { &[] };
    println!(
        "b1: {} is missing or older than the benchmark; running cargo build {}--bin ferroc",
        ferroc.display(),
        if release { "--release " } else { "" }
    );
    let status = Command::new(cargo)
        .current_dir(workspace)
        .args(["build", "--bin", "ferroc"])
        .args(profile)
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() || !ferroc.exists() {
        return Err(format!(
            "building ferroc failed ({status}); expected {}",
            ferroc.display()
        ));
    }
    Ok(ferroc)
}
