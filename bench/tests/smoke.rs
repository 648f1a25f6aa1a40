//! Smoke tests of the benchmark binary: short runs end with one well-formed RESULT line,
//! and bad arguments are usage errors (exit 2), never panics. No wall-clock assertions:
//! the figures themselves are not checked.

use std::process::{Command, Output};

fn bench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ferroc-bench"))
        .args(args)
        .output()
        .expect("the benchmark binary runs")
}

/// The one `RESULT <id>` line of a successful run, as key=value pairs.
fn result_line(out: &Output, id: &str) -> Vec<(String, String)> {
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "exit {:?}\nstdout:\n{stdout}\nstderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let results: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("RESULT "))
        .collect();
    assert_eq!(results.len(), 1, "exactly one RESULT line:\n{stdout}");
    let mut words = results[0].split_whitespace();
    assert_eq!(words.nth(1), Some(id), "{}", results[0]);
    words
        .map(|w| {
            let (k, v) = w.split_once('=').expect("key=value");
            (k.to_string(), v.to_string())
        })
        .collect()
}

fn has_keys(kv: &[(String, String)], keys: &[&str]) {
    for k in keys {
        assert!(kv.iter().any(|(key, _)| key == k), "no `{k}` in {kv:?}");
    }
}

#[test]
fn b4_short_run_prints_a_result_line() {
    let out = bench(&["b4", "--messages", "1000", "--rounds", "2", "--gap-us", "5"]);
    let kv = result_line(&out, "b4");
    has_keys(
        &kv,
        &[
            "p50_us",
            "p99_us",
            "max_us",
            "messages",
            "scope",
            "mpsc_p50_us",
            "spin_p50_us",
            "adaptive_p99_us",
            "wait_spin_cpu_pct",
            "park_cpu_pct",
        ],
    );
    assert!(kv.contains(&("scope".into(), "process".into())));
    assert!(kv.contains(&("messages".into(), "1000".into())));
}

#[test]
fn b3_short_run_prints_a_result_line() {
    let out = bench(&["b3", "--seconds", "0.4", "--rounds", "1"]);
    let kv = result_line(&out, "b3");
    has_keys(
        &kv,
        &[
            "consumers",
            "fps",
            "cpu_pct",
            "cpu_ratio_vs_1",
            "rss_mib",
            "baseline_cpu_pct",
            "cpu_ratio_vs_baseline",
        ],
    );
    assert!(kv.contains(&("consumers".into(), "15".into())));
}

#[test]
fn bad_arguments_are_usage_errors() {
    for args in [
        &["b3", "--seconds", "abc"][..],
        &["b3", "--seconds", "0"],
        &["b3", "--frames", "3"],
        &["b3", "--seconds", "1", "--rounds", "10"],
        &["b4", "--messages"],
        &["b4", "--messages", "-5"],
        &["b4", "--pin=yes"],
        &["b4", "1000"],
        &["b1", "--fast"],
        &["all", "--seconds", "1"],
        &["b9"],
        &["__b3-child", "nonsense", "1"],
        &[],
    ] {
        let out = bench(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(!stderr.trim().is_empty(), "{args:?}: no message");
    }
}

#[test]
fn help_lists_b3_and_b4() {
    // After a benchmark's id too: `--help` there was once refused as an option
    // without a value.
    for args in [
        &["--help"][..],
        &["b4-large", "--help"],
        &["b3-parts", "-h"],
    ] {
        let out = bench(args);
        assert!(out.status.success(), "{args:?}");
        let text = String::from_utf8_lossy(&out.stdout);
        for needle in ["b3 ", "b4 ", "b4-large", "--seconds", "--messages", "--pin"] {
            assert!(
                text.contains(needle),
                "{args:?}: help without `{needle}`:\n{text}"
            );
        }
    }
}

#[test]
fn b2_short_run_prints_the_keys_of_benchmarks_md() {
    let out = bench(&["b2", "--cycles", "1000", "--rounds", "1"]);
    let kv = result_line(&out, "b2");
    has_keys(&kv, &["cycles_per_s", "baseline_cycles_per_s", "ratio"]);
    let rate: f64 = kv
        .iter()
        .find(|(k, _)| k == "cycles_per_s")
        .and_then(|(_, v)| v.parse().ok())
        .expect("cycles_per_s is a number");
    assert!(rate > 0.0, "cycles_per_s {rate}");
}

#[test]
fn b4_large_short_run_prints_every_size_and_variant() {
    let out = bench(&["b4-large", "--messages", "3", "--rounds", "1"]);
    let kv = result_line(&out, "b4-large");
    for size in ["64", "65536", "1048576", "6220800"] {
        for variant in ["ferroc_shm", "ferroc_net", "zenoh_shm", "zenoh_net"] {
            has_keys(&kv, &[&format!("s{size}_{variant}_p50_us")]);
        }
    }
    let bad = bench(&["b4-large", "--rounds", "0"]);
    assert_eq!(bad.status.code(), Some(2));
}

#[test]
fn b3_parts_short_run_prints_a_result_line_per_configuration() {
    let out = bench(&["b3-parts", "--frames", "5", "--consumers", "1,2"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "exit {:?}\nstdout:\n{stdout}\nstderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let results: Vec<&str> = (stdout.lines())
        .filter(|l| l.starts_with("RESULT b3-parts "))
        .collect();
    assert_eq!(
        results.len(),
        6,
        "2 consumer counts x 3 variants:\n{stdout}"
    );
    for (i, line) in results.iter().enumerate() {
        let kv: Vec<(String, String)> = (line.split_whitespace().skip(2))
            .map(|w| {
                let (k, v) = w.split_once('=').expect("key=value");
                (k.to_string(), v.to_string())
            })
            .collect();
        has_keys(
            &kv,
            &[
                "variant",
                "consumers",
                "fps_mean",
                "fps_min",
                "cpu_pct",
                "rss_producer_mib",
                "rss_consumer_max_mib",
                "rss_growth_max_mib",
                "anon_growth_max_mib",
                "p50_us",
                "p99_us",
            ],
        );
        let consumers = if i < 3 { "1" } else { "2" };
        assert!(
            kv.contains(&("consumers".into(), consumers.into())),
            "{line}"
        );
    }
    for bad in [
        &["b3-parts", "--consumers", "0"][..],
        &["b3-parts", "--variants", "ferroc-udp"],
        &["b3-parts", "--frames", "1"],
    ] {
        assert_eq!(bench(bad).status.code(), Some(2), "{bad:?}");
    }
}
