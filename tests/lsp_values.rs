//! `ferroc lsp` on the units inside parameter values (completion of a unit after the
//! number, hover with the quantity read, a wrong unit's finding on the unit's text)
//! and on FINROC files whose neighbour files are open in the editor unsaved.

mod common;

use common::lsp_client::{uri, Client};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A model of the check fixtures' `fx.Supervisor` (parameters of every kind).
fn model() -> String {
    let manifest = root().join("compiler/checks/src/fixtures.lib.xml");
    format!(
        r#"<application name="values" version="1">
  <use library="fx" manifest="{}"/>
  <part name="robot" host="robot-pc">
    <thread name="main" period="10ms">
      <module name="sup" type="fx.Supervisor">
        <param name="device">/dev/watchdog0</param>
        <param name="max_speed">3.6 km/h</param>
        <param name="safety_distance">30 cm</param>
        <param name="watchdog">50 ms</param>
        <param name="gain">2</param>
      </module>
    </thread>
  </part>
</application>
"#,
        manifest.display()
    )
}

/// The 0-based position of the first character of `needle` + `skip` in `text`.
fn at(text: &str, needle: &str, skip: usize) -> Value {
    let i = text.find(needle).unwrap() + skip;
    let line = text[..i].matches('\n').count();
    let col = i - text[..i].rfind('\n').map_or(0, |n| n + 1);
    json!({ "line": line, "character": col })
}

fn position(path: &Path, pos: Value) -> Value {
    json!({ "textDocument": { "uri": uri(path) }, "position": pos })
}

fn labels(client: &mut Client, path: &Path, pos: Value) -> Vec<String> {
    let r = client.request("textDocument/completion", position(path, pos));
    (r["result"]["items"]
        .as_array()
        .cloned()
        .unwrap_or_default()
        .iter())
    .map(|i| i["label"].as_str().unwrap_or_default().to_string())
    .collect()
}

fn setup(name: &str) -> (PathBuf, String, Client) {
    let dir = common::tempdir(name).canonicalize().unwrap();
    let path = dir.join("values.xml");
    let text = model();
    std::fs::write(&path, &text).unwrap();
    let mut client = Client::start(&dir, &dir);
    client.open(&path, &text);
    client.settle(&path);
    (path, text, client)
}

#[test]
fn a_unit_after_the_number_of_a_value_is_completed_in_the_parameters_dimension() {
    let (path, text, mut c) = setup("lsp-value-units");
    // `3.6 km|` in a speed: speeds only, those starting with `km`.
    let got = labels(&mut c, &path, at(&text, "3.6 km/h", "3.6 km".len()));
    assert_eq!(got, ["km/h"], "speeds that start with `km`");
    // Right after the number and a blank: every speed, no length or time.
    let got = labels(&mut c, &path, at(&text, "3.6 km/h", "3.6 ".len()));
    assert!(
        got.contains(&"m/s".to_string()) && got.contains(&"km/h".to_string()),
        "{got:?}"
    );
    assert!(
        !got.contains(&"m".to_string()) && !got.contains(&"s".to_string()),
        "{got:?}"
    );
    // A duration takes times; a length lengths.
    let got = labels(&mut c, &path, at(&text, "50 ms", "50 ".len()));
    assert!(
        got.contains(&"ms".to_string()) && !got.contains(&"m".to_string()),
        "{got:?}"
    );
    let got = labels(&mut c, &path, at(&text, "30 cm", "30 c".len()));
    assert_eq!(got, ["cm"]);
    // Not a unit place: a parameter without a unit, the text before a number, a
    // device name.
    assert!(labels(&mut c, &path, at(&text, ">2<", 2)).is_empty());
    assert!(labels(&mut c, &path, at(&text, "3.6 km/h", 0)).is_empty());
    assert!(labels(&mut c, &path, at(&text, "/dev/watchdog0", 5)).is_empty());
    c.shutdown();
}

#[test]
fn a_unit_completion_replaces_the_unit_typed_so_far() {
    let (path, text, mut c) = setup("lsp-value-unit-edit");
    let pos = at(&text, "3.6 km/h", "3.6 km".len());
    let r = c.request("textDocument/completion", position(&path, pos.clone()));
    let edit = &r["result"]["items"][0]["textEdit"];
    assert_eq!(edit["newText"], "km/h");
    let start = at(&text, "3.6 km/h", "3.6 ".len());
    assert_eq!(edit["range"]["start"], start, "{edit}");
    assert_eq!(edit["range"]["end"], pos, "{edit}");
    c.shutdown();
}

fn hover(c: &mut Client, path: &Path, pos: Value) -> String {
    let r = c.request("textDocument/hover", position(path, pos));
    r["result"]["contents"]["value"]
        .as_str()
        .unwrap_or_default()
        .to_string()
}

#[test]
fn hover_on_a_value_shows_the_quantity_in_the_parameters_unit() {
    let (path, text, mut c) = setup("lsp-value-hover");
    let h = hover(&mut c, &path, at(&text, "3.6 km/h", 1));
    assert!(h.contains("quantity: `3.6` `km/h` = `1 m/s`"), "{h}");
    let h = hover(&mut c, &path, at(&text, "50 ms", 1));
    assert!(h.contains("`50` `ms` = `0.05 s`"), "{h}");
    let h = hover(&mut c, &path, at(&text, ">2<", 1));
    assert!(h.contains("`2` (the parameter has no unit)"), "{h}");
    // Text, not a number: no quantity.
    let h = hover(&mut c, &path, at(&text, "/dev/watchdog0", 2));
    assert!(h.contains("parameter") && !h.contains("quantity"), "{h}");
    c.shutdown();
}

#[test]
fn a_wrong_unit_is_reported_on_the_units_text_and_hover_says_why() {
    let (path, text, mut c) = setup("lsp-value-wrong-unit");
    let broken = text.replace("30 cm", "0.3 s");
    c.change(&path, 2, &broken);
    c.settle(&path);
    let diags = c.published().remove(&uri(&path)).unwrap_or_default();
    let p105: Vec<&Value> = diags.iter().filter(|d| d["code"] == "P105").collect();
    assert_eq!(p105.len(), 1, "{diags:?}");
    let s = at(&broken, "0.3 s", "0.3 ".len());
    let e = at(&broken, "0.3 s", "0.3 s".len());
    assert_eq!(
        p105[0]["range"],
        json!({ "start": s, "end": e }),
        "the unit `s` only"
    );
    let h = hover(&mut c, &path, at(&broken, "0.3 s", 1));
    assert!(h.contains("quantity: cannot be read"), "{h}");
    // The CLI reports the same column.
    std::fs::write(&path, &broken).unwrap();
    let (_, out, _) = common::ferroc(&["check", path.to_str().unwrap()]);
    let line = s["line"].as_u64().unwrap() + 1;
    let col = s["character"].as_u64().unwrap() + 1;
    assert!(
        out.contains("error[P105]") && out.contains(&format!("values.xml:{line}:{col}]")),
        "{out}"
    );
    c.shutdown();
}

/// A FINROC file's parameter link names a config entry; the config file is open in
/// the editor and edited there without saving.
#[test]
fn a_finroc_files_findings_follow_the_unsaved_text_of_its_config_file() {
    let fixtures = root().join("compiler/finroc/src/checks/f108_config_link_missing");
    let dir = common::tempdir("lsp-finroc-neighbour")
        .canonicalize()
        .unwrap();
    let app = dir.join("links.finroc");
    let config = dir.join("config.xml");
    let app_text = std::fs::read_to_string(fixtures.join("fires.xml")).unwrap();
    let config_text = std::fs::read_to_string(fixtures.join("config.xml")).unwrap();
    std::fs::write(&app, &app_text).unwrap();
    std::fs::write(&config, &config_text).unwrap();
    let mut c = Client::start(&dir, &dir);
    c.open(&app, &app_text);
    c.settle(&app);
    assert!(
        c.codes(&app).contains(&"F108".to_string()),
        "{:?}",
        c.codes(&app)
    );
    // The entry the link names, typed into the open config file (not saved).
    c.open(&config, &config_text);
    let fixed = config_text.replace("name=\"noiselevel\"", "name=\"noise_level\"");
    c.change(&config, 2, &fixed);
    c.settle(&config);
    c.settle(&app);
    assert!(
        !c.codes(&app).contains(&"F108".to_string()),
        "{:?}",
        c.codes(&app)
    );
    assert_eq!(
        std::fs::read_to_string(&config).unwrap(),
        config_text,
        "not saved"
    );
    // Undone in the editor: the finding is back.
    c.change(&config, 3, &config_text);
    c.settle(&config);
    c.settle(&app);
    assert!(
        c.codes(&app).contains(&"F108".to_string()),
        "{:?}",
        c.codes(&app)
    );
    c.shutdown();
}
