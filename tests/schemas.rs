//! Our files against the schemas, checked by validators we did not write: every model,
//! fragment, library manifest and silent check fixture in the repository validates with
//! `xmllint` against schemas/*.xsd (so the XSDs accept what the parser accepts), and
//! `ferroc check --format sarif` validates against the OASIS SARIF 2.1.0 schema with
//! Python's `jsonschema`. `scripts/test` installs both; without them the tests skip
//! visibly (ferroc-testkit).

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The `.xml` files directly in `dir`.
fn xml_in(dir: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join(dir))
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "xml"))
        .collect();
    files.sort();
    files
}

/// Every `silent*.xml` fixture under `dir` whose root element is `<application>`.
fn silent_models(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            silent_models(&path, out);
        } else if path
            .file_name()
            .and_then(|n| n.to_str())
            .is_some_and(|n| n.starts_with("silent") && n.ends_with(".xml"))
        {
            let text = std::fs::read(&path).unwrap();
            let head = String::from_utf8_lossy(&text[..text.len().min(4096)]);
            if head.contains("<application") {
                out.push(path);
            }
        }
    }
}

/// Runs xmllint on `files` against `schema`; every file must validate.
fn validate(xmllint: &Path, schema: &str, files: &[PathBuf]) {
    assert!(!files.is_empty(), "no files for {schema}");
    let out = Command::new(xmllint)
        .args(["--noout", "--schema"])
        .arg(root().join(schema))
        .args(files)
        .output()
        .expect("xmllint runs");
    assert!(
        out.status.success(),
        "{} file(s) against {schema}:\n{}",
        files.len(),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn every_model_manifest_and_silent_fixture_validates_with_xmllint() {
    let Some(xmllint) = ferroc_testkit::command("xmllint") else {
        return;
    };
    let mut models = xml_in("models");
    models.extend(xml_in("models/fragments"));
    validate(&xmllint, "schemas/application.xsd", &models);
    let manifests: Vec<PathBuf> = xml_in("components")
        .into_iter()
        .filter(|p| p.to_string_lossy().ends_with(".lib.xml"))
        .collect();
    validate(&xmllint, "schemas/library.xsd", &manifests);
    let mut fixtures = Vec::new();
    silent_models(&root().join("compiler"), &mut fixtures);
    assert!(
        fixtures.len() > 50,
        "only {} silent fixtures",
        fixtures.len()
    );
    validate(&xmllint, "schemas/application.xsd", &fixtures);
}

/// The check-fixture folders of every crate that defines checks.
const CHECK_DIRS: [&str; 5] = [
    "compiler/checks/src",
    "compiler/syntax/src/checks",
    "compiler/model/src/checks",
    "compiler/finroc/src/checks",
    "compiler/src/checks",
];

#[test]
fn sarif_output_of_every_fixture_validates_against_the_oasis_schema() {
    let Some(python) = ferroc_testkit::python(&["jsonschema"]) else {
        return;
    };
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .arg("check")
        .args(CHECK_DIRS)
        .args(["--format", "sarif"])
        .current_dir(root())
        .output()
        .expect("ferroc runs");
    // The fixtures that fire make the check fail; the report is what is validated.
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let sarif = std::env::temp_dir().join(format!("ferroc-sarif-{}.json", std::process::id()));
    std::fs::write(&sarif, &out.stdout).unwrap();
    let script = "import json, sys, jsonschema\n\
        schema = json.load(open(sys.argv[1])); doc = json.load(open(sys.argv[2]))\n\
        jsonschema.validate(doc, schema)\n\
        print(len(doc['runs'][0]['results']))\n";
    let check = Command::new(python)
        .args(["-c", script])
        .arg(root().join("schemas/external/sarif-schema-2.1.0.json"))
        .arg(&sarif)
        .output()
        .expect("python runs");
    let _ = std::fs::remove_file(&sarif);
    let stdout = String::from_utf8_lossy(&check.stdout);
    assert!(
        check.status.success(),
        "{}",
        String::from_utf8_lossy(&check.stderr)
    );
    let results: usize = stdout.trim().parse().expect("a count");
    assert!(results > 100, "only {results} results: {stdout}");
}
