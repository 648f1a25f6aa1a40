//! Deadlock witnesses in `--format json`: each D finding with a witness lists, per
//! blocked thread container, the ordered steps with their locations (the same content
//! as SARIF's `codeFlows`, see sarif_witness.rs); other findings have an empty list.

use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::report::{json, ModelReport};
use ferroc_compiler::{check_model, Policy};
use serde_json::Value;
use std::path::Path;

fn json_of(rel: &str) -> Value {
    let options = Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    let result = check_model(&path, &options, &Policy::default()).expect("readable");
    let report = ModelReport {
        sources: &result.sources,
        diagnostics: &result.diagnostics,
    };
    let doc = json::document(vec![json::model(rel, &report)], Vec::new());
    // Through text, as a consumer would read it.
    serde_json::from_str(&serde_json::to_string(&doc).unwrap()).unwrap()
}

fn diagnostics(doc: &Value) -> &Vec<Value> {
    doc["models"][0]["diagnostics"].as_array().unwrap()
}

/// (file name, line, column, message) of each step of one thread's witness.
fn steps(thread: &Value) -> Vec<(String, u64, u64, String)> {
    thread["steps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            let loc = &s["location"];
            let file = loc["file"].as_str().unwrap();
            (
                file.rsplit('/').next().unwrap().to_string(),
                loc["line"].as_u64().unwrap(),
                loc["column"].as_u64().unwrap(),
                s["message"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

#[test]
fn lock_inversion_lists_each_threads_steps_in_order() {
    let doc = json_of("tests/deadlock_examples/E21_lock_inversion.xml");
    assert_eq!(doc["format_version"], 1);
    let d103: Vec<&Value> = diagnostics(&doc)
        .iter()
        .filter(|d| d["code"] == "D103")
        .collect();
    assert_eq!(d103.len(), 1, "{d103:#?}");
    let threads = d103[0]["witness"].as_array().expect("witness");
    let ids: Vec<&str> = threads
        .iter()
        .map(|t| t["thread"].as_str().unwrap())
        .collect();
    assert_eq!(ids, ["r/T1", "r/T2"]);
    for t in threads {
        assert!(t["message"].as_str().unwrap().contains("host `pc1`"));
    }
    // Each thread: where it took the lock it holds, then where it blocks on the other
    // one; both at its module in the model (M1 on line 9, M2 on line 12).
    let expected = [
        (
            9,
            "1. takes lock `a` (holds it from here)",
            "1. in `r/T1/M1` update: step 2: lock `b`; blocks waiting for lock `b`, held by `r/T2`",
        ),
        (
            12,
            "2. takes lock `b` (holds it from here)",
            "2. in `r/T2/M2` update: step 2: lock `a`; blocks waiting for lock `a`, held by `r/T1`",
        ),
    ];
    for (t, (line, took, blocks)) in threads.iter().zip(expected) {
        let s = steps(t);
        assert_eq!(s.len(), 2, "{s:#?}");
        for step in &s {
            assert_eq!(
                (step.0.as_str(), step.1, step.2),
                ("E21_lock_inversion.xml", line, 21)
            );
        }
        assert_eq!(s[0].3, took);
        assert!(s[1].3.starts_with(blocks), "{s:#?}");
    }
}

#[test]
fn findings_without_witness_have_an_empty_list() {
    let doc = json_of("checks/src/scheduling/s102_period_overrun/fires.xml");
    assert!(!diagnostics(&doc).is_empty());
    for d in diagnostics(&doc) {
        assert_eq!(d["witness"], Value::Array(Vec::new()), "{d:#?}");
    }
}
