//! The FINROC front end on real files (tests/finroc_files, copied from FINROC's public
//! sources, see ORIGIN.md): the writer gives back FINROC's bytes, the readers keep
//! spans, and no mutation of a real file makes them panic.

use ferroc_compiler::diagnostic::Diagnostics;
use ferroc_compiler::finroc::{config, read, write};
use ferroc_compiler::source::FileId;
use ferroc_compiler::syntax::xml;
use proptest::prelude::*;
use std::path::Path;

fn file(name: &str) -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/finroc_files")
            .join(name),
    )
    .unwrap()
}

fn round_trip(text: &str) -> (String, Diagnostics) {
    let root = xml::parse(FileId(0), text, 256).expect("well-formed");
    let mut diags = Diagnostics::default();
    let doc = read::read(FileId(0), &root, &mut diags);
    (write::write(&doc), diags)
}

#[test]
fn finrocs_own_round_trip_file_comes_back_byte_identical() {
    for name in [
        "type_conversion.finroc",
        "type_conversion_group.xml",
        "crash_course/CrashCourse.finroc",
    ] {
        let text = file(name);
        let (written, diags) = round_trip(&text);
        assert!(
            diags.items.is_empty(),
            "{name}: {:?}",
            diags.items.iter().map(|d| &d.message).collect::<Vec<_>>()
        );
        assert_eq!(
            written, text,
            "{name} changed on the way through reader and writer"
        );
    }
}

/// Text as libxml2 (FINROC's writer) escapes it: `>` an entity in content, `'` and `"`
/// raw there, newlines in attributes as references. Such a file also comes back byte
/// for byte.
#[test]
fn escaped_text_comes_back_as_finroc_wrote_it() {
    let text = file("type_conversion.finroc").replace(
        "<parameter name=\"Manages Parameter Configuration\">false</parameter>",
        "<parameter name=\"Manages &quot;Parameter&quot;&#10;Configuration\">a -&gt; b &lt; c &amp; 'd' \"e\"</parameter>",
    );
    assert!(text.contains("-&gt; b"), "the fixture line moved");
    let (written, _) = round_trip(&text);
    assert_eq!(written, text);
}

#[test]
fn reader_decodes_paths_and_keeps_their_places() {
    let text = file("type_conversion.finroc");
    let root = xml::parse(FileId(0), &text, 256).unwrap();
    let mut diags = Diagnostics::default();
    let doc = read::read(FileId(0), &root, &mut diags);
    assert_eq!(doc.version, Some(1703));
    assert_eq!(doc.dependencies.len(), 2);
    assert_eq!(
        &text[doc.dependencies[1].span.start as usize..doc.dependencies[1].span.end as usize],
        "finroc_plugins_structure"
    );
    let first = &doc.edges[0];
    assert_eq!(first.src.segments, ["Group 1", "Output", "Array<uint8, 8>"]);
    assert_eq!(
        first.conversion.as_ref().unwrap().operations(),
        ["ToVector", "Wrap"]
    );
    let optional = doc.edges.iter().find(|e| !e.flags.is_empty()).unwrap();
    assert_eq!(
        optional.flags,
        [ferroc_compiler::finroc::finstructable::Flag::Optional]
    );
    let group = &doc.elements[0];
    assert_eq!(
        group.xml_file().unwrap().value.text,
        "plugins/runtime_construction/tests/type_conversion_group.xml"
    );
    // A legacy file: paths literal, links legacy.
    let cc = file("crash_course/CrashCourse.finroc");
    let root = xml::parse(FileId(0), &cc, 256).unwrap();
    let doc = read::read(FileId(0), &root, &mut diags);
    assert_eq!(doc.version, None);
    assert_eq!(doc.links.len(), 3);
    assert_eq!(doc.links[1].cmdline.as_ref().unwrap().text, "front-noise");
    assert_eq!(
        doc.links[0].path.last().unwrap(),
        "Destructive Collision Speed"
    );
}

#[test]
fn config_reader_finds_nested_values_and_tables() {
    let text = "<root>\n  <value name=\"noiselevel\">15 cm</value>\n  <node name=\"a b\">\n    <value name=\"c\">0.1</value>\n  </node>\n  <value name=\"T\"><element><key>1</key><value>2</value></element></value>\n</root>\n";
    let root = xml::parse(FileId(0), text, 256).unwrap();
    let mut diags = Diagnostics::default();
    let cfg = config::read(FileId(0), &root, &mut diags);
    assert!(cfg.entry("/noiselevel").is_some());
    assert!(cfg.entry("/a b/c").is_some());
    assert!(cfg.entry("a b/c").is_some());
    assert!(
        matches!(cfg.entry("/T").unwrap().value, config::ConfigValue::Table(ref r) if r.len() == 1)
    );
    assert!(cfg.entry("/c").is_none());
}

/// One mutation of a real file: cut, duplicate or replace a byte range.
fn mutate(text: &str, at: usize, len: usize, how: u8, junk: &str) -> String {
    let b = text.as_bytes();
    let at = at % (b.len() + 1);
    let end = (at + len).min(b.len());
    let mut out = b[..at].to_vec();
    match how % 4 {
        0 => {}                                            // cut
        1 => out.extend_from_slice(&b[at..end].repeat(2)), // duplicate
        2 => out.extend_from_slice(junk.as_bytes()),       // replace with junk
        _ => out.push(b'%'),                               // an odd escape
    }
    out.extend_from_slice(&b[end..]);
    String::from_utf8_lossy(&out).into_owned()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// Mutated real FINROC files never panic the readers or the writer, and whatever
    /// reads back writes a file that reads again.
    #[test]
    fn mutated_finroc_files_never_panic(
        which in 0usize..3, at in 0usize..4000, len in 0usize..60, how in 0u8..8,
        junk in "[<>/%&\"a-z =]{0,12}",
    ) {
        let name = ["type_conversion.finroc", "type_conversion_group.xml", "crash_course/CrashCourse.finroc"][which];
        let text = mutate(&file(name), at, len, how, &junk);
        if let Ok(root) = xml::parse(FileId(0), &text, 256) {
            let mut diags = Diagnostics::default();
            let doc = read::read(FileId(0), &root, &mut diags);
            let written = write::write(&doc);
            prop_assert!(xml::parse(FileId(0), &written, 256).is_ok(), "written file is not XML:\n{written}");
            let _ = config::read(FileId(0), &root, &mut diags);
        }
    }
}

/// A checkout holding the crash course's files, one of them mutated, checked as a user
/// runs `ferroc check`: findings or a read error, never a panic.
fn check_mutated(which: usize, at: usize, len: usize, how: u8, junk: &str) -> Result<(), String> {
    use ferroc_compiler::{check_model, load::Options, Policy};
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/finroc_files/crash_course");
    let files = [
        "CrashCourse.finroc",
        "gSimulation.h.xml",
        "control/gControl.h.xml",
        "etc/fragile_bot.xml",
        "make.xml",
    ];
    let dir = std::env::temp_dir().join(format!("ferroc-finroc-mut-{}", std::process::id()));
    for f in files {
        let to = dir.join(f);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(src.join(f), &to).unwrap();
    }
    let target = dir.join(files[which % files.len()]);
    let text = std::fs::read_to_string(&target).unwrap();
    std::fs::write(&target, mutate(&text, at, len, how, junk)).unwrap();
    let mut result = Ok(());
    for f in files {
        if let Err(e) = check_model(&dir.join(f), &Options::default(), &Policy::default()) {
            result = Err(e);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    result
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// Mutations of any file of a checkout reach every check (resolution across files,
    /// catalogue, config links) without a panic.
    #[test]
    fn mutated_checkouts_check_without_panic(
        which in 0usize..5, at in 0usize..1500, len in 0usize..40, how in 0u8..8,
        junk in "[<>/%&\"a-zA-Z ,.=]{0,12}",
    ) {
        prop_assert!(check_mutated(which, at, len, how, &junk).is_ok());
    }
}
