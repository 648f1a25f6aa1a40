//! Interoperability with a Zenoh client we did not write: Python's `eclipse-zenoh`
//! (installed by `scripts/test` in a venv) connects to a running part's endpoint, receives
//! its samples on the documented keys (docs/zenoh.md) and sees its liveliness token.
//!
//! The interpreter is `$FERROC_PYTHON`, else the venv `scripts/test` makes
//! (`target/ci-venv`); without one that has `zenoh` the test skips visibly, and fails
//! under FERROC_REQUIRE_ALL=1 (ferroc-testkit).

mod support;

use std::path::Path;
use std::process::Command;
use support::*;

/// postcard's u32: a LEB128 varint.
fn varint(bytes: &[u8]) -> Option<u64> {
    let mut value = 0u64;
    for (i, b) in bytes.iter().enumerate() {
        value |= u64::from(b & 0x7f) << (7 * i);
        if b & 0x80 == 0 {
            return (i + 1 == bytes.len()).then_some(value);
        }
    }
    None
}

fn hex(text: &str) -> Vec<u8> {
    (0..text.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&text[i..i + 2], 16).unwrap())
        .collect()
}

#[test]
fn a_python_zenoh_client_sees_the_documented_keys_and_tokens() {
    let Some(python) = ferroc_testkit::python(&["zenoh"]) else {
        return;
    };
    let registry = registry();
    let peers = two_peers();
    // Part `a` alone, running freely: its link to `b` publishes on the documented key.
    let a = echoes(&registry, &["a"], 201.0)
        .start_with(over_zenoh(free(1_000_000), "interop", "a", &peers))
        .unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/subscribe.py");
    let endpoint = format!("tcp/{}", peers["a"]);
    let out = Command::new(&python)
        .arg(&script)
        .args([endpoint.as_str(), "interop", "20"])
        .output()
        .unwrap();
    a.stop();
    drop(a);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let text = String::from_utf8_lossy(&out.stdout);
    let report: serde_json::Value = serde_json::from_str(text.trim()).expect("one JSON object");
    let tokens = report["tokens"].as_array().unwrap();
    assert_eq!(
        tokens,
        &[serde_json::json!("ferroc/interop/alive/a")],
        "{text}"
    );
    let samples = report["samples"].as_array().unwrap();
    assert!(samples.len() >= 5, "{text}");
    let mut last = 0;
    for s in samples {
        assert_eq!(s["key"], "ferroc/interop/data/a/echo/out", "{s}");
        assert_eq!(s["encoding"], "application/postcard;u32", "{s}");
        assert_eq!(s["attachment"], "00000000", "link 0, little-endian: {s}");
        // `a` publishes n · 1 + 0 (nothing comes back from `b`): 1, 2, 3, …
        let value = varint(&hex(s["payload"].as_str().unwrap())).expect("a postcard u32");
        assert!(value > last, "values count up: {s}");
        last = value;
    }
}
