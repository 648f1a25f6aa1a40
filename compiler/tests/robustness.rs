//! No input panics the checker: arbitrary bytes, mutated real models, deep nesting, odd
//! Unicode. Each case runs the whole pipeline (parse, libraries, resolve, every pass).

use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::{check_model, Policy};
use proptest::prelude::*;
use std::path::{Path, PathBuf};

fn options() -> Options {
    Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    }
}

const MODELS: &[&str] = &[
    include_str!("../../models/crash_course.xml"),
    include_str!("../../models/rescue_robot.xml"),
    include_str!("../../models/warehouse_fleet.xml"),
];

/// Writes the case next to the real models so relative manifests and includes resolve.
fn check_bytes(bytes: &[u8], name: &str) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let path: PathBuf = dir.join(format!(".robustness-{name}-{}.xml", std::process::id()));
    std::fs::write(&path, bytes).unwrap();
    let result = check_model(&path, &options(), &Policy::default());
    let _ = std::fs::remove_file(&path);
    if let Ok(r) = result {
        for d in &r.diagnostics {
            // Every finding points somewhere real.
            let file = r.sources.get(d.primary.span.file);
            assert!(d.primary.span.start as usize <= file.text.len());
            assert!(!d.message.is_empty());
        }
    }
}

/// Small edits that keep most of a model intact, so the checker gets past the parser.
fn mutate(model: &str, edits: &[(usize, u8, u8)]) -> Vec<u8> {
    const SNIPPETS: &[&str] = &[
        "<",
        ">",
        "/>",
        "\"",
        "&",
        "&amp;",
        "<module name=\"x\" type=\"ferroc_std.Scale\"/>",
        "<connect from=\"a/b\" to=\"../c\"/>",
        "<group name=\"g\" type=\"local.G\"/>",
        "<include href=\"../../x.xml\"/>",
        "ü",
        "\u{202e}",
        "\0",
        "[9999]",
        "/param/",
        " queue=\"0\"",
        "<thread name=\"t\" period=\"0s\">",
        "</thread>",
        "<port name=\"in\" dir=\"in\" type=\"f64[0]\" count=\"99999\"/>",
    ];
    let mut bytes = model.as_bytes().to_vec();
    for &(pos, kind, pick) in edits {
        if bytes.is_empty() {
            break;
        }
        let at = pos % bytes.len();
        match kind % 3 {
            0 => {
                let end = (at + 1 + pick as usize % 40).min(bytes.len());
                bytes.drain(at..end);
            }
            1 => {
                let s = SNIPPETS[pick as usize % SNIPPETS.len()].as_bytes();
                bytes.splice(at..at, s.iter().copied());
            }
            _ => bytes[at] = pick,
        }
    }
    bytes
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, .. ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
        check_bytes(&bytes, "bytes");
    }

    #[test]
    fn mutated_models_never_panic(
        which in 0..MODELS.len(),
        edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..6),
    ) {
        check_bytes(&mutate(MODELS[which], &edits), "mutated");
    }
}

#[test]
fn deep_nesting_and_huge_counts_are_bounded() {
    let deep = format!(
        "<application name=\"a\" version=\"1\">{}{}</application>",
        "<group name=\"g\">".repeat(10_000),
        "</group>".repeat(10_000)
    );
    check_bytes(deep.as_bytes(), "deep");
    let recursive = "<application name=\"a\" version=\"1\"><group-type name=\"G\"><group name=\"g\" type=\"local.G\"/></group-type>\
<part name=\"p\"><thread name=\"t\" period=\"1s\"><group name=\"g\" type=\"local.G\"/></thread></part></application>";
    check_bytes(recursive.as_bytes(), "recursive");
}
