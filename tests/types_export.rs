//! `ferroc types`: manifests and the Rust code of built-in module types stay in step.

mod common;

use common::{ferroc, tempdir};
use std::path::Path;

#[test]
fn checked_in_manifests_agree_with_the_code_and_export_to_themselves() {
    let (code, _, err) = ferroc(&["types", "export", "--check", "--lib-path", "components"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("agree with their manifests"), "{err}");
    // One library is one library (before: "in 1 libraries").
    let (code, _, err) = ferroc(&[
        "types",
        "export",
        "--check",
        "--lib-path",
        "components",
        "--library",
        "ferroc_std",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains(" in 1 library agree with their manifests"),
        "{err}"
    );
    // Byte for byte: a manifest that agrees with the code is its own export.
    let out = tempdir("types_same");
    let (code, _, err) = ferroc(&[
        "types",
        "export",
        "--lib-path",
        "components",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let mut compared = 0;
    for entry in std::fs::read_dir(&out).unwrap() {
        let written = entry.unwrap().path();
        let name = written.file_name().unwrap();
        let original = Path::new("components").join(name);
        assert_eq!(
            std::fs::read_to_string(&written).unwrap(),
            std::fs::read_to_string(&original).unwrap(),
            "{} differs from its export",
            original.display()
        );
        compared += 1;
    }
    assert!(compared >= 1);
    assert!(err.contains("wrote "), "{err}");
    // Exported again into the same folder: nothing changes, and it says so.
    let (code, _, err) = ferroc(&[
        "types",
        "export",
        "--lib-path",
        "components",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("wrote "), "{err}");
    assert_eq!(err.matches("unchanged ").count(), compared, "{err}");
}

#[test]
fn a_drifted_manifest_fails_the_check_and_export_repairs_only_that_type() {
    let components = tempdir("types_drift");
    for entry in std::fs::read_dir("components").unwrap() {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "xml") {
            std::fs::copy(&p, components.join(p.file_name().unwrap())).unwrap();
        }
    }
    let manifest = components.join("crash_course.lib.xml");
    let original = std::fs::read_to_string(&manifest).unwrap();
    let drifted = original
        .replace(
            r#"unit="m" min="0" max="1" default="0""#,
            r#"unit="m" min="0" max="2" default="0""#,
        )
        .replace(
            r#"<out name="output" type="f64" unit="m"/>"#,
            r#"<out name="output" type="f64" unit="cm"/>"#,
        );
    assert_ne!(drifted, original);
    std::fs::write(&manifest, &drifted).unwrap();
    let lib_path = components.to_str().unwrap();

    let (code, _, err) = ferroc(&["types", "export", "--check", "--lib-path", lib_path]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(
            "crash_course.lib.xml:82:22: error: the manifest of `crash_course.AddNoise` differs"
        ),
        "{err}"
    );
    assert!(
        err.contains(
            "parameter `standard_deviation`: the manifest says range `0..2`, the code `0..1`"
        ),
        "{err}"
    );
    assert!(
        err.contains("port `output`: the manifest says unit `cm`, the code `m`"),
        "{err}"
    );
    assert!(!err.contains("MainSimulation"), "{err}");

    let repaired = tempdir("types_repaired");
    let (code, _, err) = ferroc(&[
        "types",
        "export",
        "--lib-path",
        lib_path,
        "-o",
        repaired.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("(1 module type generated from code)"), "{err}");
    // Only libraries with built-in module types are written; a written manifest's
    // `<depends manifest="rescue.lib.xml">` still needs that file next to it.
    for entry in std::fs::read_dir(&components).unwrap() {
        let p = entry.unwrap().path();
        let name = p.file_name().unwrap();
        if !repaired.join(name).exists() {
            std::fs::copy(&p, repaired.join(name)).unwrap();
        }
    }
    let text = std::fs::read_to_string(repaired.join("crash_course.lib.xml")).unwrap();
    // Everything outside AddNoise is kept as written, comments included.
    let outside = |s: &str| {
        let a = s.find(r#"<module-type name="AddNoise""#).unwrap();
        let b = a + s[a..].find("</module-type>").unwrap();
        (s[..a].to_string(), s[b..].to_string())
    };
    assert_eq!(outside(&text), outside(&drifted));
    assert!(
        text.contains(r#"max="1""#) && text.contains(r#"budget="20us""#),
        "{text}"
    );
    // The repaired manifest agrees with the code again.
    let (code, _, err) = ferroc(&[
        "types",
        "export",
        "--check",
        "--lib-path",
        repaired.to_str().unwrap(),
        "--lib-path",
        lib_path,
    ]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn a_type_the_manifest_lacks_is_reported_and_exported_and_bad_arguments() {
    // The crate registers crash_course.AddNoise; this copy of the manifest lacks it.
    let dir = tempdir("types_lacking");
    let original = std::fs::read_to_string("components/crash_course.lib.xml").unwrap();
    let a = original.find(r#"<module-type name="AddNoise""#).unwrap();
    let b = a + original[a..].find("</module-type>").unwrap() + "</module-type>".len();
    let lacking = format!("{}{}", &original[..a], &original[b..]);
    std::fs::write(dir.join("crash_course.lib.xml"), &lacking).unwrap();
    let lib_path = dir.to_str().unwrap();
    let (code, _, err) = ferroc(&["types", "export", "--check", "--lib-path", lib_path]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(
            "crash_course.lib.xml: error: `crash_course.AddNoise` is registered by its crate but its manifest does not declare it"
        ),
        "{err}"
    );
    let (code, out, err) = ferroc(&[
        "types",
        "export",
        "--library",
        "crash_course",
        "--lib-path",
        lib_path,
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("<module-type name=\"AddNoise\""), "{out}");
    assert!(
        out.contains("<module-type name=\"MainSimulation\""),
        "{out}"
    );

    let (code, _, err) = ferroc(&["types", "export", "--library", "nope"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("--library nope: no module type of this library"),
        "{err}"
    );
    assert!(err.contains("ferroc_std"), "{err}");
    // Without a lib path: the standard library, built in.
    let (code, out, _) = ferroc(&["types", "list"]);
    assert_eq!(code, 0);
    assert!(out.contains("ferroc_std.Constant"), "{out}");
    assert!(!out.contains("crash_course"), "{out}");
    let (code, out, _) = ferroc(&["types", "list", "--lib-path", "components"]);
    assert_eq!(code, 0);
    assert!(out.contains("crash_course.MainSimulation"), "{out}");
    assert!(out.contains("sense-control"), "{out}");
    // Counts agree with their nouns.
    assert!(
        out.contains("ferroc_std::basic::Constant (1 port, 1 parameter)"),
        "{out}"
    );
    assert!(out.contains("(2 ports, "), "{out}");
    assert!(
        !out.contains(" 1 ports") && !out.contains(" 1 parameters"),
        "{out}"
    );
}
