//! Deadlock witnesses in SARIF: a D finding carries `codeFlows` with one `threadFlow`
//! per blocked thread container, whose locations are where it took the locks it holds,
//! then where it blocks (`reference/deadlocks.md` §2.8).

use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::report::{sarif, ModelReport};
use ferroc_compiler::{check_model, Policy};
use serde_json::Value;
use std::path::Path;

fn options() -> Options {
    Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    }
}

fn sarif_of(rel: &str) -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    let result = check_model(&path, &options(), &Policy::default()).expect("readable");
    let report = ModelReport {
        sources: &result.sources,
        diagnostics: &result.diagnostics,
    };
    // Through text, as a consumer would read it.
    let text = serde_json::to_string(&sarif::document(&[report])).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn results(doc: &Value) -> &Vec<Value> {
    doc["runs"][0]["results"].as_array().unwrap()
}

/// (uri suffix, line, message) of each location of a thread flow.
fn locations(flow: &Value) -> Vec<(String, u64, String)> {
    flow["locations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| {
            let loc = &l["location"];
            let phys = &loc["physicalLocation"];
            (
                phys["artifactLocation"]["uri"]
                    .as_str()
                    .unwrap()
                    .to_string(),
                phys["region"]["startLine"].as_u64().unwrap(),
                loc["message"]["text"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

#[test]
fn lock_inversion_has_one_thread_flow_per_blocked_thread() {
    let doc = sarif_of("tests/deadlock_examples/E21_lock_inversion.xml");
    let d103: Vec<&Value> = results(&doc)
        .iter()
        .filter(|r| r["ruleId"] == "D103")
        .collect();
    assert_eq!(d103.len(), 1, "{d103:#?}");
    let flows = d103[0]["codeFlows"].as_array().expect("codeFlows");
    assert_eq!(flows.len(), 1);
    let threads = flows[0]["threadFlows"].as_array().unwrap();
    let ids: Vec<&str> = threads.iter().map(|t| t["id"].as_str().unwrap()).collect();
    assert_eq!(ids, ["r/T1", "r/T2"]);
    for (t, (holds, waits)) in threads.iter().zip([("a", "b"), ("b", "a")]) {
        assert!(t["message"]["text"]
            .as_str()
            .unwrap()
            .contains("host `pc1`"));
        let locs = locations(t);
        // First where it took the lock it holds, then where it blocks on the other.
        assert_eq!(locs.len(), 2, "{locs:#?}");
        assert!(
            locs[0].2.contains(&format!("takes lock `{holds}`")),
            "{locs:#?}"
        );
        assert!(locs[1].2.contains(&format!("lock `{waits}`")), "{locs:#?}");
        assert!(locs[1].2.contains("blocks waiting for"), "{locs:#?}");
        // Both in the model (lines 9 and 12: the two modules) or the manifest.
        for (uri, line, _) in &locs {
            assert!(uri.ends_with(".xml"), "{uri}");
            assert!(*line > 0);
        }
    }
}

#[test]
fn call_cycle_flows_name_the_calls_and_findings_without_witness_have_none() {
    let doc = sarif_of("tests/deadlock_examples/E25_cross_part_call_cycle.xml");
    let d101 = results(&doc)
        .iter()
        .find(|r| r["ruleId"] == "D101")
        .expect("D101");
    let threads = d101["codeFlows"][0]["threadFlows"].as_array().unwrap();
    assert_eq!(threads.len(), 2);
    for t in threads {
        let locs = locations(t);
        assert_eq!(locs.len(), 1, "no lock held: only the blocking call");
        assert!(locs[0].2.contains("sync call"), "{locs:#?}");
    }
    // A finding that is not a witness has no codeFlows.
    let doc = sarif_of("checks/src/scheduling/s102_period_overrun/fires.xml");
    for r in results(&doc) {
        assert!(r.get("codeFlows").is_none(), "{r:#?}");
    }
}
