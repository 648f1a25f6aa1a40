//! Where `ferroc lsp` must offer no mechanical quick fix although the finding looks
//! like one it fixes (the fixes themselves are applied by pytest-lsp in
//! tests/lsp/test_ferroc_lsp.py): a required input with no output of its type and unit,
//! a connection from an input that swapping would not mend, a queue setting on a
//! connection without a queue.

mod common;

use common::lsp_client::{uri, Client};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn manifest() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("compiler/checks/src/fixtures.lib.xml")
}

/// The code actions offered for each finding of `code` in `text` (saved as `name`).
fn actions_for(name: &str, text: &str, code: &str) -> Vec<Vec<String>> {
    let dir = common::tempdir(name).canonicalize().unwrap();
    let path = dir.join("model.xml");
    let text = text.replace("MANIFEST", &manifest().display().to_string());
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
