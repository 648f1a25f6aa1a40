//! `ferroc lsp` under bad input: half-typed XML, files deleted while open, a 50 MB
//! paste, a model that includes itself, requests out of order and malformed JSON-RPC.
//! No panic, no hang: the server keeps answering and says what it could not do.

mod common;

use common::lsp_client::{uri, Client};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

const MODEL: &str = r#"<application name="tiny" version="1">
  <use library="ferroc_std"/>
  <include href="parts.xml"/>
  <part name="robot">
    <thread name="main" period="10ms">
      <module name="k" type="ferroc_std.Constant"/>
      <module name="s" type="ferroc_std.Scale"/>
      <connect from="k/value" to="s/input"/>
    </thread>
  </part>
</application>
"#;
const FRAGMENT: &str = r#"<fragment>
</fragment>
"#;

fn scratch(name: &str) -> (PathBuf, PathBuf) {
    let dir = common::tempdir(name).canonicalize().unwrap();
    let model = dir.join("tiny.xml");
    std::fs::write(&model, MODEL).unwrap();
    std::fs::write(dir.join("parts.xml"), FRAGMENT).unwrap();
    (dir, model)
}

/// The server answers a request at all (a document symbol request needs no check).
fn answers(client: &mut Client, path: &Path) {
    let r = client.request(
        "textDocument/documentSymbol",
        json!({ "textDocument": { "uri": uri(path) } }),
    );
    assert!(r.get("result").is_some(), "{r}");
}

#[test]
fn half_typed_xml_is_a_finding_and_the_server_goes_on() {
    let (dir, model) = scratch("lsp-half-typed");
    let mut c = Client::start(&dir, &dir);
    c.open(&model, MODEL);
    c.settle(&model);
    let clean = c.codes(&model);
    // Every prefix of a connection being typed, as keystrokes.
    let at = MODEL.find("    </thread>").unwrap();
    let typed = "      <connect from=\"k/value\" to=\"s/";
    for (v, end) in (1..=typed.len()).step_by(3).enumerate() {
        let text = format!("{}{}{}", &MODEL[..at], &typed[..end], &MODEL[at..]);
        c.change(&model, v as i32 + 2, &text);
    }
    c.settle(&model);
    assert_eq!(
        c.codes(&model),
        ["M101"],
        "malformed XML is reported as `ferroc check` does"
    );
    c.change(&model, 100, MODEL);
    c.settle(&model);
    assert_eq!(c.codes(&model), clean);
    answers(&mut c, &model);
    c.shutdown();
}

#[test]
fn files_deleted_while_open_are_reported_not_fatal() {
    let (dir, model) = scratch("lsp-deleted");
    let mut c = Client::start(&dir, &dir);
    c.open(&model, MODEL);
    c.settle(&model);
    let clean = c.codes(&model);
    assert!(!clean.contains(&"M115".to_string()));
    // The included fragment goes: the model's check says it cannot read it.
    let fragment = dir.join("parts.xml");
    let fragment_uri = uri(&fragment);
    std::fs::remove_file(&fragment).unwrap();
    c.notify(
        "workspace/didChangeWatchedFiles",
        json!({ "changes": [{ "uri": fragment_uri, "type": 3 }] }),
    );
    c.settle(&model);
    assert!(
        c.codes(&model).contains(&"M115".to_string()),
        "{:?}",
        c.published()
    );
    // The open model itself goes: its text in the editor is still checked.
    std::fs::remove_file(&model).unwrap();
    c.change(
        &model,
        2,
        &MODEL.replace("<include href=\"parts.xml\"/>", ""),
    );
    c.settle(&model);
    assert_eq!(c.codes(&model), clean, "{:?}", c.published());
    answers(&mut c, &model);
    c.close(&model);
    answers(&mut c, &model);
    c.shutdown();
}

#[test]
fn a_50_mb_paste_is_checked_within_the_limits() {
    let (dir, model) = scratch("lsp-paste");
    let mut c = Client::start(&dir, &dir);
    c.open(&model, MODEL);
    c.settle(&model);
    let clean = c.codes(&model);
    let at = MODEL.find("</application>").unwrap();
    let paste = "<!-- pasted -->\n".repeat(50 * 1024 * 1024 / 16);
    let text = format!("{}{paste}{}", &MODEL[..at], &MODEL[at..]);
    assert!(text.len() >= 50 << 20);
    c.change(&model, 2, &text);
    c.settle(&model);
    assert_eq!(c.codes(&model), clean, "comments change nothing");
    // The same paste in the middle of a tag: a finding, not a hang.
    let broken = format!("{}<part {paste}{}", &MODEL[..at], &MODEL[at..]);
    c.change(&model, 3, &broken);
    c.settle(&model);
    assert_eq!(c.codes(&model), ["M101"]);
    c.change(&model, 4, MODEL);
    c.settle(&model);
    answers(&mut c, &model);
    c.shutdown();
}

#[test]
fn a_model_that_includes_itself_is_m114_as_in_ferroc_check() {
    let (dir, model) = scratch("lsp-self-include");
    let text = MODEL.replace("parts.xml", "tiny.xml");
    std::fs::write(&model, &text).unwrap();
    let (_, json_out, _) = common::ferroc(&["check", "--format", "json", model.to_str().unwrap()]);
    let doc: Value = serde_json::from_str(&json_out).unwrap();
    let cli: Vec<String> = (doc["models"][0]["diagnostics"].as_array().unwrap().iter())
        .map(|d| d["code"].as_str().unwrap().to_string())
        .collect();
    let mut c = Client::start(&dir, &dir);
    c.open(&model, &text);
    c.settle(&model);
    assert_eq!(c.codes(&model), cli);
    assert!(
        cli.iter().any(|code| code == "M114" || code == "M119"),
        "{cli:?}"
    );
    answers(&mut c, &model);
    c.shutdown();
}

#[test]
fn malformed_json_rpc_and_requests_out_of_order_get_answers() {
    let (dir, model) = scratch("lsp-malformed");
    let mut c = Client::spawn(&dir);
    // Before `initialize`: refused with ServerNotInitialized, not ignored.
    let early = c.request("textDocument/hover", json!({}));
    assert_eq!(early["error"]["code"], -32002, "{early}");
    c.initialize(&dir);
    let twice = c.request("initialize", json!({ "capabilities": {} }));
    assert!(twice.get("error").is_some(), "{twice}");
    // Not JSON, JSON that is no message, a header without a length, a huge length.
    c.send_raw(b"{ this is not json");
    c.send_raw(br#"{"hello": "world"}"#);
    c.send_raw(b"");
    c.send_raw(b"\r\nX-Nothing: 1\r\n\r\n");
    let logged = c.wait_for(|m| {
        m["method"] == "window/logMessage"
            && m["params"]["message"]
                .as_str()
                .is_some_and(|s| s.contains("could not read a message"))
    });
    assert!(logged.is_some(), "the server says what it could not read");
    // Parameters of the wrong shape, unknown methods, documents never opened.
    let bad = c.request("textDocument/definition", json!({ "textDocument": 5 }));
    assert_eq!(bad["error"]["code"], -32602, "{bad}");
    let unknown = c.request("ferroc/nothing", json!({}));
    assert_eq!(unknown["error"]["code"], -32601, "{unknown}");
    let never = json!({ "textDocument": { "uri": uri(&model) }, "position": { "line": 0, "character": 0 } });
    assert!(c.request("textDocument/definition", never.clone())["result"].is_null());
    c.notify("textDocument/didChange", json!({ "textDocument": { "uri": uri(&model), "version": 2 }, "contentChanges": [{ "text": "x" }] }));
    c.notify("textDocument/didChange", json!({ "textDocument": 7 }));
    // A change with a range past the end of the text is clamped, not a panic.
    c.open(&model, MODEL);
    c.notify(
        "textDocument/didChange",
        json!({ "textDocument": { "uri": uri(&model), "version": 2 },
                "contentChanges": [{ "range": { "start": { "line": 900, "character": 3 }, "end": { "line": 2, "character": 999 } }, "text": "" }] }),
    );
    c.settle(&model);
    answers(&mut c, &model);
    c.shutdown();
}
