//! Where the runner takes a library's crate from: a crate named by version
//! (`rust-crate="PACKAGE@VERSION"`, fetched by cargo; offline here, so the fetch fails
//! and must be reported at the manifest).

mod common;

use common::tempdir;
use std::path::{Path, PathBuf};
use std::process::Command;

/// This test run's target folder (runners share it with the checkout's crates).
fn target() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.ancestors().nth(3).unwrap().to_path_buf()
}

/// `ferroc run beeper.xml` in `dir`, offline: no test reaches a registry.
fn run_in(dir: &Path) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(["run", "beeper.xml", "--cycles", "1"])
        .current_dir(dir)
        .env("CARGO_TARGET_DIR", target())
        .env("CARGO_NET_OFFLINE", "true")
        .output()
        .expect("ferroc runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

const MODEL: &str = r#"<application name="beeper" version="1">
  <use library="beep" manifest="beep.lib.xml"/>
  <part name="p"><thread name="t" period="10ms">
    <module name="c" type="beep.Counter"/>
  </thread></part>
</application>
"#;

/// A manifest naming `rust_crate`, and the model.
fn write_model(dir: &Path, rust_crate: &str) {
    std::fs::write(
        dir.join("beep.lib.xml"),
        format!(
            r#"<library name="beep" version="0.1.0" rust-crate="{rust_crate}">
  <module-type name="Counter" rust="beep::Counter" doc="counts">
    <out name="count" type="f64"/>
  </module-type>
</library>
"#
        ),
    )
    .unwrap();
    std::fs::write(dir.join("beeper.xml"), MODEL).unwrap();
}

/// The generated Cargo.toml of the runner package that mentions `text`.
fn runner_toml_with(text: &str) -> Option<String> {
    let generated = target().join("ferroc-runner");
    std::fs::read_dir(generated)
        .ok()?
        .flatten()
        .filter_map(|e| std::fs::read_to_string(e.path().join("Cargo.toml")).ok())
        .find(|toml| toml.contains(text))
}

#[test]
fn a_crate_named_by_version_is_fetched_by_cargo_and_a_failed_fetch_points_at_the_manifest() {
    let dir = tempdir("runner_registry");
    let package = "ferroc-test-crate-that-is-not-published";
    write_model(&dir, &format!("{package}@0.3"));
    let (code, err) = run_in(&dir);
    assert_eq!(code, 1, "{err}");
    // The runner asks for the package by version, not by path.
    let line = format!("library_0 = {{ package = \"{package}\", version = \"0.3\" }}");
    let toml = runner_toml_with(&line).unwrap_or_else(|| panic!("no runner says {line}"));
    assert!(toml.contains("ferroc-host = { path = "), "{toml}");
    // cargo's reason first, then ours at the manifest.
    assert!(
        err.contains(&format!("no matching package named `{package}`")),
        "{err}"
    );
    assert!(
        err.contains(&format!(
            "beep.lib.xml:1:16: error: the crate `{package}` 0.3 of library `beep` could not be fetched from the registry"
        )),
        "{err}"
    );
    assert!(err.contains("CARGO_NET_OFFLINE"), "{err}");
    // A bundle takes the crate by that version too (with the default --deps path).
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(["bundle", "beeper.xml", "-o", "bundle"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let workspace = std::fs::read_to_string(dir.join("bundle/Cargo.toml")).unwrap();
    assert!(
        workspace.contains(&format!("{package} = {{ version = \"0.3\" }}")),
        "{workspace}"
    );

    // Not a version: refused before cargo runs.
    write_model(&dir, &format!("{package}@latest"));
    let (code, err) = run_in(&dir);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("beep.lib.xml:1:16: error: `latest` after the `@`")
            && err.contains("is not a version"),
        "{err}"
    );
    assert!(
        !err.contains("no matching package"),
        "cargo did not run: {err}"
    );
}
