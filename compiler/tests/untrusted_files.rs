//! Files a model names are read as untrusted input: nothing that could block (a FIFO)
//! or never end (`/dev/zero`, a growing file) is read past the size limit, `config=`
//! and `manifest=` stay in the model's folder as includes do, and a file that is not
//! XML is shown by the line of its error, never whole.

use ferroc_compiler::load::{read_text, BuiltinLibrary, Limits, Options};
use ferroc_compiler::{check_model, CheckResult, Policy};
use std::path::{Path, PathBuf};
use std::time::Duration;

fn options(allow_outside: bool) -> Options {
    Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        allow_outside_includes: allow_outside,
        ..Options::default()
    }
}

/// A scratch folder with `model/` (the model's folder) and a sibling `outside/`.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("untrusted")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("model")).unwrap();
    std::fs::create_dir_all(dir.join("outside")).unwrap();
    dir
}

/// A model whose one module takes its value from `config` and whose extra library
/// `extra` has the manifest `manifest` (both optional), plus `more` inside <application>.
fn model(config: Option<&str>, manifest: Option<&str>, more: &str) -> String {
    let param = config.map_or(String::new(), |c| {
        format!(r#"<param name="value" config="{c}"/>"#)
    });
    let library = manifest.map_or(String::new(), |m| {
        format!(r#"<use library="extra" manifest="{m}"/>"#)
    });
    format!(
        r#"<application name="m" version="1">
  <use library="ferroc_std"/>
  {library}{more}
  <part name="p"><thread name="t" period="10ms">
    <module name="c" type="ferroc_std.Constant">{param}</module>
  </thread></part>
  <allow code="T110" reason="a single constant"/>
</application>
"#
    )
}

/// Checks on another thread, so that a regression that blocks fails instead of hanging.
fn check(path: &Path, allow_outside: bool) -> Result<CheckResult, String> {
    let path = path.to_path_buf();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(check_model(
            &path,
            &options(allow_outside),
            &Policy::default(),
        ));
    });
    rx.recv_timeout(Duration::from_secs(120))
        .expect("the check blocked")
}

/// "CODE message" of every finding.
fn findings(r: &CheckResult) -> Vec<String> {
    r.diagnostics
        .iter()
        .map(|d| format!("{} {}", d.check.code, d.message))
        .collect()
}

fn fifo(path: &Path) {
    let made = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .unwrap();
    assert!(made.success());
}

#[test]
fn a_fifo_as_model_or_include_is_refused_without_blocking() {
    let dir = scratch("fifo");
    let pipe = dir.join("model/pipe.xml");
    fifo(&pipe);
    let err = check(&pipe, false).err().expect("a FIFO model is not read");
    assert!(err.contains("FIFO"), "{err}");
    let path = dir.join("model/m.xml");
    std::fs::write(&path, model(None, None, r#"<include href="pipe.xml"/>"#)).unwrap();
    let r = check(&path, false).unwrap();
    let f = findings(&r);
    assert!(
        f.len() == 1 && f[0].starts_with("M115") && f[0].contains("FIFO"),
        "{f:?}"
    );
    // The same FIFO as a config file and as a manifest (trusted: inside the folder).
    std::fs::write(&path, model(Some("pipe.xml#/v"), Some("pipe.xml"), "")).unwrap();
    let f = findings(&check(&path, false).unwrap());
    assert!(
        f.iter()
            .any(|m| m.starts_with("P106") && m.contains("FIFO")),
        "{f:?}"
    );
    assert!(
        f.iter()
            .any(|m| m.starts_with("L102") && m.contains("FIFO")),
        "{f:?}"
    );
}

#[test]
fn dev_zero_is_never_read_even_when_outside_files_are_allowed() {
    let dir = scratch("zero");
    let path = dir.join("model/m.xml");
    std::fs::write(&path, model(Some("/dev/zero#/v"), Some("/dev/zero"), "")).unwrap();
    let f = findings(&check(&path, false).unwrap());
    assert_eq!(
        f.iter().filter(|m| m.starts_with("M113")).count(),
        2,
        "config and manifest are outside the model's folder: {f:?}"
    );
    let f = findings(&check(&path, true).unwrap());
    assert!(
        f.iter()
            .any(|m| m.starts_with("P106") && m.contains("device")),
        "{f:?}"
    );
    assert!(
        f.iter()
            .any(|m| m.starts_with("L102") && m.contains("device")),
        "{f:?}"
    );
}

#[test]
fn the_size_limit_counts_the_bytes_read_not_the_size_reported() {
    // /proc files report a size of 0 and hold more.
    let limits = Limits {
        max_file_bytes: 16,
        ..Limits::default()
    };
    let err = read_text(Path::new("/proc/self/status"), &limits).unwrap_err();
    assert!(err.contains("over the limit"), "{err}");
    assert!(read_text(Path::new("/proc/self/status"), &Limits::default()).is_ok());
}

#[test]
fn config_files_are_confined_to_the_models_folder_like_includes() {
    let dir = scratch("config");
    let entry = r#"<root><value name="v">2.5</value></root>"#;
    std::fs::write(dir.join("outside/secret.xml"), entry).unwrap();
    std::fs::write(dir.join("model/inside.xml"), entry).unwrap();
    let path = dir.join("model/m.xml");
    for config in [
        "../outside/secret.xml#/v".to_string(),
        format!("{}#/v", dir.join("outside/secret.xml").display()),
    ] {
        std::fs::write(&path, model(Some(&config), None, "")).unwrap();
        let f = findings(&check(&path, false).unwrap());
        assert_eq!(f.len(), 1, "one finding, not M113 and P106: {f:?}");
        assert!(f[0].starts_with("M113"), "{f:?}");
        // --allow-outside-includes lets it in, as for includes.
        assert!(findings(&check(&path, true).unwrap()).is_empty());
    }
    // A symlink in the folder that leads out is judged by where it leads.
    std::os::unix::fs::symlink(dir.join("outside/secret.xml"), dir.join("model/link.xml")).unwrap();
    std::fs::write(&path, model(Some("link.xml#/v"), None, "")).unwrap();
    let f = findings(&check(&path, false).unwrap());
    assert!(f.len() == 1 && f[0].starts_with("M113"), "{f:?}");
    // Inside the folder: read as before.
    std::fs::write(&path, model(Some("inside.xml#/v"), None, "")).unwrap();
    assert!(findings(&check(&path, false).unwrap()).is_empty());
}

#[test]
fn manifests_outside_the_models_folder_must_be_named_as_manifests() {
    let dir = scratch("manifest");
    std::fs::write(dir.join("outside/secret.txt"), "root:x:0:0\nsecond line\n").unwrap();
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../components/ring.lib.xml"),
        dir.join("outside/ring.lib.xml"),
    )
    .unwrap();
    let path = dir.join("model/m.xml");
    std::fs::write(&path, model(None, Some("../outside/secret.txt"), "")).unwrap();
    let r = check(&path, false).unwrap();
    let f = findings(&r);
    assert!(f.len() == 1 && f[0].starts_with("M113"), "{f:?}");
    assert!(
        r.sources.files().all(|(_, s)| !s.text.contains("root:x")),
        "the file was not even read"
    );
    // A symlink named like a manifest that leads to another file is judged by its target.
    std::os::unix::fs::symlink(
        dir.join("outside/secret.txt"),
        dir.join("outside/x.lib.xml"),
    )
    .unwrap();
    std::fs::write(&path, model(None, Some("../outside/x.lib.xml"), "")).unwrap();
    let f = findings(&check(&path, false).unwrap());
    assert!(f.len() == 1 && f[0].starts_with("M113"), "{f:?}");
    // The usual layout, libraries next to the models: read.
    let text = model(None, Some("../outside/ring.lib.xml"), "").replace("\"extra\"", "\"ring\"");
    std::fs::write(&path, text).unwrap();
    let f = findings(&check(&path, false).unwrap());
    assert!(
        f.iter()
            .all(|m| !m.starts_with("M113") && !m.starts_with("L102")),
        "{f:?}"
    );
}

#[test]
fn a_file_that_is_not_xml_is_reported_at_one_line() {
    let dir = scratch("not_xml");
    std::fs::write(
        dir.join("model/shadow.txt"),
        "root:x:0:0\nsecond line\nthird line\nfourth line\n",
    )
    .unwrap();
    let path = dir.join("model/m.xml");
    std::fs::write(&path, model(Some("shadow.txt#/v"), None, "")).unwrap();
    let r = check(&path, false).unwrap();
    let m101 = r
        .diagnostics
        .iter()
        .find(|d| d.check.code == "M101")
        .expect("M101 in the text file");
    let span = m101.primary.span;
    let text = &r.sources.get(span.file).text;
    let shown = &text[span.start as usize..span.end as usize];
    assert_eq!(shown, "root:x:0:0", "the span ends with its line");
}
