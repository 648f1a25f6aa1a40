//! Every file `ferroc new` writes is XML every tool reads: well-formed (no `--` inside a
//! comment, which libxml2 and editors reject while a lenient reader passes it) and valid
//! against the schemas in `schemas/`, checked with `xmllint`, a reader we did not write.

mod common;
use common::{ferroc, tempdir};
use std::path::{Path, PathBuf};
use std::process::Command;

/// `xmllint --noout [--schema XSD] FILE`: (passed, what it said).
fn xmllint(xmllint: &Path, schema: Option<&str>, file: &Path) -> (bool, String) {
    let mut cmd = Command::new(xmllint);
    cmd.arg("--noout");
    if let Some(xsd) = schema {
        cmd.arg("--schema").arg(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("schemas")
                .join(xsd),
        );
    }
    let out = cmd.arg(file).output().expect("xmllint runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn xml_files(dir: &Path, found: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            xml_files(&path, found);
        } else if path.extension().is_some_and(|e| e == "xml") {
            found.push(path);
        }
    }
}

#[test]
fn every_file_ferroc_new_writes_validates_with_xmllint() {
    let Some(lint) = ferroc_testkit::command("xmllint") else {
        return;
    };
    let dir = tempdir("new_files");
    let lib = dir.join("my_robot");
    let (code, _, err) = ferroc(&["new", "library", "my_robot", "--dir", lib.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let manifest = lib.join("my_robot.lib.xml");
    for (file, library) in [("plain.xml", None), ("mine.xml", Some(&manifest))] {
        let mut args = vec!["new", "model"];
        let path = dir.join(file);
        args.push(path.to_str().unwrap());
        if let Some(m) = library {
            args.extend(["--library", m.to_str().unwrap()]);
        }
        let (code, _, err) = ferroc(&args);
        assert_eq!(code, 0, "{err}");
    }
    let mut files = Vec::new();
    xml_files(&dir, &mut files);
    files.sort();
    assert_eq!(files.len(), 4, "{files:?}");
    for file in &files {
        let schema = if file.to_string_lossy().ends_with(".lib.xml") {
            "library.xsd"
        } else {
            "application.xsd"
        };
        let (ok, said) = xmllint(&lint, None, file);
        assert!(ok, "{} is not well-formed XML:\n{said}", file.display());
        let (ok, said) = xmllint(&lint, Some(schema), file);
        assert!(
            ok,
            "{} does not validate against {schema}:\n{said}",
            file.display()
        );
        // And ferroc reads each as the same language.
        let (code, out, err) = ferroc(&["check", file.to_str().unwrap(), "--format", "short"]);
        if !file.to_string_lossy().ends_with(".lib.xml") {
            assert_eq!(code, 0, "{}: {out}{err}", file.display());
        }
    }
}
