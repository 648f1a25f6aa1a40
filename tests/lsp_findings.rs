//! `ferroc lsp` reports what `ferroc check` reports: for every example model and every
//! check fixture, the diagnostics an LSP client receives (file, range, code, severity,
//! message, related locations) equal `ferroc check --format json`'s findings.

mod common;

use common::lsp_client::{uri, Client};
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One finding as both sides can say it.
type Finding = (String, [u64; 4], String, u64, String, usize);

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A file the editor does not check on its own: `ferroc check` given a manifest or a
/// fragment says M119 (wrong root element); the server checks such a file through the
/// models that use it (tests/lsp_robust.rs and the pytest-lsp tests cover that).
fn checked_alone(path: &Path) -> bool {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let mut rest = text.as_str();
    // The root element: the first tag that is no declaration, comment or instruction.
    while let Some(i) = rest.find('<') {
        rest = &rest[i + 1..];
        if let Some(after) = rest.strip_prefix("!--") {
            rest = after.find("-->").map_or("", |e| &after[e..]);
        } else if !rest.starts_with(['?', '!']) {
            return !(rest.starts_with("library") || rest.starts_with("fragment"));
        }
    }
    true
}

/// The example models and every `fires*`/`silent*` fixture of every check.
fn models() -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(root().join("models"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "xml"))
        .collect();
    fixtures(&root().join("compiler"), &mut out);
    out.retain(|p| checked_alone(p));
    out.sort();
    out
}

fn fixtures(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        let name = e.file_name().to_string_lossy().into_owned();
        if p.is_dir() && name != "target" {
            fixtures(&p, out);
        } else if (name.starts_with("fires") || name.starts_with("silent"))
            && name.ends_with(".xml")
            && p.to_string_lossy().contains("/src/")
        {
            out.push(p);
        }
    }
}

/// Column `col` (1-based, in characters, as the JSON report counts) of 1-based `line`
/// as LSP counts it (0-based, UTF-16 units).
fn utf16(text: &str, line: u64, col: u64) -> u64 {
    let l = text.split('\n').nth(line as usize - 1).unwrap_or("");
    l.chars()
        .take(col as usize - 1)
        .map(|c| c.len_utf16() as u64)
        .sum()
}

fn severity(s: &str) -> u64 {
    match s {
        "error" => 1,
        "warning" => 2,
        _ => 3,
    }
}

/// `ferroc check --format json` of all models at once, by model path.
fn cli_findings(models: &[PathBuf]) -> BTreeMap<String, Vec<Finding>> {
    let mut args = vec!["check".to_string(), "--format".into(), "json".into()];
    args.extend(models.iter().map(|m| m.display().to_string()));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, stdout, stderr) = common::ferroc(&args);
    assert!(
        code == 0 || code == 1,
        "ferroc check failed ({code}): {stderr}"
    );
    let doc: Value = serde_json::from_str(&stdout).unwrap();
    let mut texts: BTreeMap<PathBuf, String> = BTreeMap::new();
    let mut out = BTreeMap::new();
    for m in doc["models"].as_array().unwrap() {
        let mut found = Vec::new();
        for d in m["diagnostics"].as_array().unwrap() {
            let loc = &d["primary"]["location"];
            let file = root().join(loc["file"].as_str().unwrap());
            let Ok(file) = file.canonicalize() else {
                continue;
            }; // the built-in manifest
            let text = texts
                .entry(file.clone())
                .or_insert_with(|| std::fs::read_to_string(&file).unwrap());
            let (l, c) = (
                loc["line"].as_u64().unwrap(),
                loc["column"].as_u64().unwrap(),
            );
            let (el, ec) = (
                loc["end_line"].as_u64().unwrap(),
                loc["end_column"].as_u64().unwrap(),
            );
            // Related locations in files (the built-in standard library's manifest is none).
            let in_file = |l: &Value| {
                root()
                    .join(l["location"]["file"].as_str().unwrap())
                    .exists()
            };
            let related = d["secondary"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|l| in_file(l))
                .count()
                + (d["witness"].as_array().unwrap().iter())
                    .map(|w| {
                        w["steps"]
                            .as_array()
                            .unwrap()
                            .iter()
                            .filter(|l| in_file(l))
                            .count()
                    })
                    .sum::<usize>();
            found.push((
                uri(&file),
                [l - 1, utf16(text, l, c), el - 1, utf16(text, el, ec)],
                d["code"].as_str().unwrap().to_string(),
                severity(d["severity"].as_str().unwrap()),
                d["message"].as_str().unwrap().to_string(),
                related,
            ));
        }
        found.sort();
        let model = root()
            .join(m["model"].as_str().unwrap())
            .canonicalize()
            .unwrap();
        out.insert(model.display().to_string(), found);
    }
    out
}

/// What the LSP client received for one model, opened alone.
fn lsp_findings(client: &mut Client, model: &Path) -> Vec<Finding> {
    client.notes.clear();
    let text = std::fs::read_to_string(model).unwrap();
    client.open(model, &text);
    // A hover waits for the check of the text just opened, so every publication of
    // that check has arrived when its answer does.
    let pos =
        json!({ "textDocument": { "uri": uri(model) }, "position": { "line": 0, "character": 0 } });
    client.request("textDocument/hover", pos);
    let mut found = Vec::new();
    for (file, diags) in client.published() {
        for d in diags {
            let r = &d["range"];
            let n = |v: &Value| v.as_u64().unwrap();
            let message = d["message"].as_str().unwrap();
            found.push((
                file.clone(),
                [
                    n(&r["start"]["line"]),
                    n(&r["start"]["character"]),
                    n(&r["end"]["line"]),
                    n(&r["end"]["character"]),
                ],
                d["code"].as_str().unwrap().to_string(),
                n(&d["severity"]),
                message.lines().next().unwrap_or("").to_string(),
                d["relatedInformation"].as_array().map_or(0, Vec::len),
            ));
        }
    }
    client.close(model);
    found.sort();
    found
}

#[test]
fn lsp_diagnostics_equal_ferroc_check_for_every_example_and_fixture() {
    let models = models();
    assert!(models.len() > 250, "found only {} models", models.len());
    let expected = cli_findings(&models);
    // An empty workspace: no model is searched for behind a file that is not one, so
    // every publication comes from the model opened.
    let mut client = Client::start(&root(), &common::tempdir("lsp-empty-workspace"));
    let mut failures = Vec::new();
    let mut findings = 0;
    for model in &models {
        let key = model.canonicalize().unwrap().display().to_string();
        let want = expected.get(&key).cloned().unwrap_or_default();
        let got = lsp_findings(&mut client, model);
        findings += want.len();
        if got != want {
            failures.push(format!(
                "{}:\n  ferroc check: {want:?}\n  ferroc lsp:   {got:?}",
                model.display()
            ));
        }
    }
    client.shutdown();
    assert!(findings > 200, "only {findings} findings compared");
    assert!(
        failures.is_empty(),
        "{} of {} models differ:\n{}",
        failures.len(),
        models.len(),
        failures.join("\n")
    );
}

/// `(range, code, message)` of each finding, sorted: what both sides say of one text.
type Short = Vec<([u64; 4], String, String)>;

/// `ferroc check --format json` of `file` (ASCII text: columns are characters).
fn cli_short(file: &Path) -> Short {
    let (code, stdout, stderr) =
        common::ferroc(&["check", "--format", "json", &file.display().to_string()]);
    assert!(
        code == 0 || code == 1,
        "ferroc check failed ({code}): {stderr}"
    );
    let doc: Value = serde_json::from_str(&stdout).unwrap();
    let mut out: Short = Vec::new();
    for d in doc["models"][0]["diagnostics"].as_array().unwrap() {
        let loc = &d["primary"]["location"];
        let n = |k: &str| loc[k].as_u64().unwrap() - 1;
        out.push((
            [n("line"), n("column"), n("end_line"), n("end_column")],
            d["code"].as_str().unwrap().to_string(),
            d["message"].as_str().unwrap().to_string(),
        ));
    }
    out.sort();
    out
}

/// What the client last received for `file`.
fn lsp_short(client: &Client, file: &Path) -> Short {
    let diags = client.published().remove(&uri(file)).unwrap_or_default();
    let mut out: Short = diags
        .iter()
        .map(|d| {
            let r = &d["range"];
            let n = |v: &Value| v.as_u64().unwrap();
            (
                [
                    n(&r["start"]["line"]),
                    n(&r["start"]["character"]),
                    n(&r["end"]["line"]),
                    n(&r["end"]["character"]),
                ],
                d["code"].as_str().unwrap().to_string(),
                d["message"]
                    .as_str()
                    .unwrap()
                    .lines()
                    .next()
                    .unwrap_or("")
                    .to_string(),
            )
        })
        .collect();
    out.sort();
    out
}

/// The server keeps each file's syntax tree between checks and parses again only the
/// element an edit lies in (`ParseCache`): after every edit of a sequence — in a start
/// tag, in an element's content, across elements, breaking the XML and mending it —
/// its findings equal `ferroc check`'s of the edited text saved as a file.
#[test]
fn edits_typed_one_after_another_are_checked_as_ferroc_check_checks_the_text() {
    let dir = common::tempdir("lsp-edits").canonicalize().unwrap();
    let model = dir.join("typed.xml");
    let saved = dir.join("saved.xml");
    let start = r#"<application name="typed" version="1">
  <use library="ferroc_std"/>
  <part name="robot">
    <!-- the controller -->
    <thread name="main" period="10ms">
      <module name="k" type="ferroc_std.Constant"/>
      <module name="s" type="ferroc_std.Scale"/>
      <connect from="k/value" to="s/input"/>
    </thread>
  </part>
</application>
"#;
    std::fs::write(&model, start).unwrap();
    let edits: &[(&str, &str)] = &[
        ("name=\"typed\"", "name=\"typed2\""),
        ("to=\"s/input\"", "to=\"s/inptu\""),
        ("period=\"10ms\"", "period=\"10 parsecs\""),
        ("<module name=\"s\"", "<modul name=\"s\""),
        ("<modul name=\"s\"", "<module name=\"s\""),
        ("ferroc_std.Scale", "ferroc_std.Scael"),
        (
            "<!-- the controller -->",
            "<thread name=\"second\" period=\"1ms\"/>",
        ),
        ("</part>", "</part>\n  <part name=\"robot\"/>"),
        ("name=\"k\" ", "name=\"k\" name=\"j\" "),
    ];
    let mut client = Client::start(&root(), &dir);
    client.open(&model, start);
    client.settle(&model);
    let mut text = start.to_string();
    let mut failures = Vec::new();
    for (version, (from, to)) in edits.iter().enumerate() {
        assert!(text.contains(from), "{from}");
        text = text.replacen(from, to, 1);
        client.change(&model, version as i32 + 2, &text);
        client.settle(&model);
        std::fs::write(&saved, &text).unwrap();
        let (want, got) = (cli_short(&saved), lsp_short(&client, &model));
        if want.is_empty() && from.contains("Scale") {
            failures.push(format!("{from} → {to}: no finding at all"));
        }
        if got != want {
            failures.push(format!(
                "{from} → {to}:\n  ferroc check: {want:?}\n  ferroc lsp:   {got:?}"
            ));
        }
    }
    client.shutdown();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
