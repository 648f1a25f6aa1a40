//! Navigation and hover of `ferroc lsp` on a model written for them: definition from
//! `config="file#/entry"` to the entry, references of a group type (its instances),
//! hover on a parameter (its documentation, the resolved value and where it comes
//! from) and on a thread container (period and load from the budgets).

mod common;

use common::lsp_client::{uri, Client};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

const MODEL: &str = r#"<application name="nav" version="1">
  <use library="ferroc_std"/>
  <group-type name="Pair">
    <module name="k" type="ferroc_std.Constant"/>
  </group-type>
  <part name="robot">
    <thread name="main" period="10ms">
      <group name="a" type="local.Pair"/>
      <group name="b" type="local.Pair"/>
      <module name="c" type="ferroc_std.Constant">
        <param name="value" config="values.xml#/gain" cmdline="gain"/>
      </module>
    </thread>
  </part>
</application>
"#;

const VALUES: &str = "<root>\n  <value name=\"gain\">2.5</value>\n</root>\n";

fn setup(name: &str) -> (PathBuf, Client) {
    let dir = common::tempdir(name).canonicalize().unwrap();
    let model = dir.join("nav.xml");
    std::fs::write(&model, MODEL).unwrap();
    std::fs::write(dir.join("values.xml"), VALUES).unwrap();
    let mut client = Client::start(Path::new(env!("CARGO_MANIFEST_DIR")), &dir);
    client.open(&model, MODEL);
    client.settle(&model);
    (model, client)
}

/// The 0-based line and the column of the first character of `needle` + `skip`.
fn at(needle: &str, skip: usize) -> Value {
    let i = MODEL.find(needle).unwrap() + skip;
    let line = MODEL[..i].matches('\n').count();
    let col = i - MODEL[..i].rfind('\n').map_or(0, |n| n + 1);
    json!({ "line": line, "character": col })
}

fn position(model: &Path, pos: Value) -> Value {
    json!({ "textDocument": { "uri": uri(model) }, "position": pos })
}

fn hover_text(client: &mut Client, model: &Path, pos: Value) -> String {
    let r = client.request("textDocument/hover", position(model, pos));
    r["result"]["contents"]["value"]
        .as_str()
        .unwrap_or_default()
        .to_string()
}

#[test]
fn definition_of_a_config_reference_is_its_entry() {
    let (model, mut client) = setup("lsp-nav-config");
    let r = client.request(
        "textDocument/definition",
        position(&model, at("values.xml#/gain", 12)),
    );
    let found = r["result"].as_array().cloned().unwrap_or_default();
    let values = model.with_file_name("values.xml");
    assert!(
        found
            .iter()
            .any(|l| l["uri"] == uri(&values) && l["range"]["start"]["line"] == 1),
        "{r}"
    );
    // Elsewhere in the same element: no config entry.
    let r = client.request(
        "textDocument/definition",
        position(&model, at("cmdline=\"gain\"", 10)),
    );
    let found = r["result"].as_array().cloned().unwrap_or_default();
    assert!(!found.iter().any(|l| l["uri"] == uri(&values)), "{r}");
    client.shutdown();
}

#[test]
fn references_of_a_group_type_are_its_instances() {
    let (model, mut client) = setup("lsp-nav-group-refs");
    let lines = |r: &Value| -> Vec<u64> {
        let mut v: Vec<u64> = (r["result"].as_array().cloned().unwrap_or_default().iter())
            .map(|l| l["range"]["start"]["line"].as_u64().unwrap())
            .collect();
        v.sort();
        v
    };
    let refs = |client: &mut Client, pos: Value, decl: bool| {
        let mut p = position(&model, pos);
        p["context"] = json!({ "includeDeclaration": decl });
        client.request("textDocument/references", p)
    };
    // From the declaration's name: the two instances.
    let r = refs(&mut client, at("name=\"Pair\"", 7), false);
    assert_eq!(lines(&r), [7, 8], "{r}");
    // From an instance, with the declaration.
    let r = refs(&mut client, at("type=\"local.Pair\"", 8), true);
    assert_eq!(lines(&r), [2, 7, 8], "{r}");
    // A module type's name is not a group type.
    let r = refs(&mut client, at("ferroc_std.Constant\"/>", 3), false);
    assert!(!lines(&r).contains(&7), "{r}");
    client.shutdown();
}

#[test]
fn hover_shows_a_parameters_documentation_and_value_and_a_threads_load() {
    let (model, mut client) = setup("lsp-nav-hover");
    let text = hover_text(&mut client, &model, at("name=\"value\"", 7));
    for want in [
        "the number to publish",
        "`2.5`",
        "config file",
        "--param gain=",
    ] {
        assert!(text.contains(want), "{want} not in: {text}");
    }
    let text = hover_text(&mut client, &model, at("name=\"main\"", 7));
    for want in ["every 10 ms", "3 module(s)", "load: ", "%"] {
        assert!(text.contains(want), "{want} not in: {text}");
    }
    client.shutdown();
}
