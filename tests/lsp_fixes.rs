//! Where `ferroc lsp` must offer no mechanical quick fix although the finding looks
//! like one it fixes (the fixes themselves are applied by pytest-lsp in
//! tests/lsp/test_ferroc_lsp.py): a required input with no output of its type and unit,
//! a connection from an input that swapping would not mend, a queue setting on a
//! connection without a queue (D105 through a call offers no `on-full`; through a
//! blocking queue it does).

mod common;

use common::lsp_client::{uri, Client};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// A library manifest of the checks' fixtures (`fixtures.lib.xml`, `deadlocks/dl.lib.xml`).
fn manifest(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("compiler/checks/src")
        .join(name)
}

/// The code actions offered for each finding of `code` in `text` (saved as `name`),
/// whose `MANIFEST` is the checks' `fixtures.lib.xml`.
fn actions_for(name: &str, text: &str, code: &str) -> Vec<Vec<String>> {
    actions_with(name, text, code, "fixtures.lib.xml")
}

fn actions_with(name: &str, text: &str, code: &str, lib: &str) -> Vec<Vec<String>> {
    let dir = common::tempdir(name).canonicalize().unwrap();
    let path = dir.join("model.xml");
    let text = text.replace("MANIFEST", &manifest(lib).display().to_string());
    std::fs::write(&path, &text).unwrap();
    let mut c = Client::start(&dir, &dir);
    c.open(&path, &text);
    c.settle(&path);
    let diags = c.published().remove(&uri(&path)).unwrap_or_default();
    let found: Vec<&Value> = diags.iter().filter(|d| d["code"] == code).collect();
    assert!(!found.is_empty(), "{code} in {diags:?}");
    let titles = found.iter().map(|d| titles(&mut c, &path, d)).collect();
    c.shutdown();
    titles
}

fn titles(c: &mut Client, path: &Path, d: &Value) -> Vec<String> {
    let r = c.request(
        "textDocument/codeAction",
        json!({ "textDocument": { "uri": uri(path) }, "range": d["range"],
                "context": { "diagnostics": [d] } }),
    );
    (r["result"].as_array().cloned().unwrap_or_default().iter())
        .map(|a| a["title"].as_str().unwrap_or_default().to_string())
        .collect()
}

#[test]
fn no_connection_is_offered_for_an_input_nothing_of_its_unit_can_feed() {
    // The motor needs m/s; the compass gives radians, the bumper a bool.
    let model = r#"<application name="t109" version="1">
  <use library="fx" manifest="MANIFEST"/>
  <part name="robot" host="robot-pc">
    <thread name="main" period="10ms">
      <module name="bumper" type="fx.BumpSwitch"/>
      <module name="compass" type="fx.Compass"/>
      <module name="motor" type="fx.Motor"/>
    </thread>
  </part>
  <connect from="robot/main/bumper/pressed" to="robot/main/motor/enable"/>
</application>
"#;
    assert_eq!(
        actions_for("lsp-fix-t109-none", model, "T109"),
        [Vec::<String>::new()]
    );
}

#[test]
fn a_connection_from_an_input_to_an_input_is_not_swapped() {
    // Both ends are inputs: T101 says "connect from an output port", not "swap".
    let model = r#"<application name="t101" version="1">
  <use library="fx" manifest="MANIFEST"/>
  <part name="robot" host="robot-pc">
    <thread name="main" period="10ms">
      <module name="speedo" type="fx.Speedometer"/>
      <module name="rec" type="fx.Recorder"/>
      <module name="motor" type="fx.Motor"/>
    </thread>
  </part>
  <connect from="robot/main/speedo/speed" to="robot/main/motor/velocity"/>
  <connect from="robot/main/motor/velocity" to="robot/main/rec/velocity"/>
</application>
"#;
    let got = actions_for("lsp-fix-t101-none", model, "T101");
    assert!(got.iter().flatten().all(|t| !t.contains("swap")), "{got:?}");
}

/// D105's help ends "or make the queue drop (on-full=\"drop-oldest\")" for every cycle;
/// the fix is offered only where the cycle runs through a queue.
fn d105_actions(name: &str, connect: &str) -> Vec<Vec<String>> {
    let model = format!(
        r#"<application name="d105" version="1">
  <use library="dl" manifest="MANIFEST"/>
  <resource name="can_bus"/>
  <resource name="l"/>
  <part name="r" host="pc1">
    <thread name="Control" period="10ms">
      <module name="Arm" type="dl.Arm"/>
      <module name="P" type="dl.LockWriter"/>
    </thread>
    <thread name="GripperIO" period="10ms">
      <module name="Gripper" type="dl.Gripper"/>
      <module name="C" type="dl.LockPoller"/>
    </thread>
  </part>
  {connect}
</application>
"#
    );
    actions_with(name, &model, "D105", "deadlocks/dl.lib.xml")
}

#[test]
fn a_lock_held_across_a_call_is_not_offered_a_queue_setting() {
    let got = d105_actions(
        "lsp-fix-d105-call",
        r#"<connect from="r/Control/Arm/query" to="r/GripperIO/Gripper/query"/>"#,
    );
    assert!(
        got.iter().flatten().all(|t| !t.contains("on-full")),
        "{got:?}"
    );
}

#[test]
fn a_lock_held_across_a_blocking_queue_write_is_offered_drop_oldest() {
    let got = d105_actions(
        "lsp-fix-d105-queue",
        r#"<connect from="r/Control/P/o" to="r/GripperIO/C/q" queue="2" on-full="block"/>"#,
    );
    assert_eq!(
        got,
        [["D105: set on-full=\"drop-oldest\" on this <connect>"]]
    );
}
