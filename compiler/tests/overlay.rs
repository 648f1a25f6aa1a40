//! `Options::overlay`: texts that stand in for files (an editor's unsaved buffers,
//! `ferroc lsp`) are what the model, its fragments and its manifests are checked as.

use ferroc_compiler::load::Options;
use ferroc_compiler::{check_model, Policy};
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

fn scratch() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("overlay");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let dir = dir.canonicalize().unwrap();
    std::fs::write(
        dir.join("m.xml"),
        r#"<application name="m" version="1">
  <use library="lib" manifest="lib.lib.xml"/>
  <include href="f.xml"/>
  <part name="p"><thread name="t" period="10ms"><module name="a" type="lib.A"/></thread></part>
</application>
"#,
    )
    .unwrap();
    std::fs::write(dir.join("f.xml"), "<fragment>\n</fragment>\n").unwrap();
    std::fs::write(
        dir.join("lib.lib.xml"),
        r#"<library name="lib" version="1" rust-crate="lib">
  <module-type name="A" rust="lib::A"/>
</library>
"#,
    )
    .unwrap();
    dir
}

fn codes(options: &Options, model: &std::path::Path) -> Vec<(String, String)> {
    let r = check_model(model, options, &Policy::default()).unwrap();
    (r.diagnostics.iter())
        .map(|d| {
            let file = &r.sources.get(d.primary.span.file).path;
            let name = file.file_name().unwrap().to_string_lossy().into_owned();
            (d.code().to_string(), name)
        })
        .collect()
}

#[test]
fn unsaved_texts_are_checked_instead_of_the_files() {
    let dir = scratch();
    let model = dir.join("m.xml");
    let on_disk = codes(&Options::default(), &model);
    assert!(
        on_disk.iter().all(|(code, _)| !code.starts_with('M')),
        "{on_disk:?}"
    );
    let overlay: HashMap<PathBuf, Arc<str>> = HashMap::from([
        (dir.join("f.xml"), Arc::from("<fragment>\n  <part name=\"q\">\n</fragment>\n")),
        (
            dir.join("lib.lib.xml"),
            Arc::from("<library name=\"lib\" version=\"1\" rust-crate=\"lib\">\n  <module-type name=\"B\" rust=\"lib::B\"/>\n</library>\n"),
        ),
    ]);
    let options = Options {
        overlay: Arc::new(overlay),
        ..Options::default()
    };
    let edited = codes(&options, &model);
    assert!(
        edited.contains(&("M101".into(), "f.xml".into())),
        "the fragment's unsaved text: {edited:?}"
    );
    assert!(
        edited
            .iter()
            .any(|(code, file)| file == "m.xml" && code != "M101"),
        "lib.A is gone from the manifest's unsaved text: {edited:?}"
    );
    // The files on disk did not change.
    assert_eq!(
        std::fs::read_to_string(dir.join("f.xml")).unwrap(),
        "<fragment>\n</fragment>\n"
    );
}
