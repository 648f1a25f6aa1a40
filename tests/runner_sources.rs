//! Where the runner takes a library's crate and the runtime from: a crate named by
//! version (`rust-crate="PACKAGE@VERSION"`, fetched by cargo; offline here, so the
//! fetch fails and must be reported at the manifest), and a crate depending on another
//! copy of `ferroc-runtime` (refused before cargo, naming both places and the fixes;
//! by `ferroc run` and by `ferroc bundle`).

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

/// A crate `beep-lib` in `dir` whose `ferroc-runtime` dependency is `runtime` (TOML).
fn write_crate(dir: &Path, runtime: &str) {
    std::fs::create_dir_all(dir.join("src")).unwrap();
    std::fs::write(
        dir.join("Cargo.toml"),
        format!(
            "[package]\nname = \"beep-lib\"\nversion = \"0.1.0\"\nedition = \"2021\"\n\n\
             [dependencies]\nferroc-runtime = {runtime}\n\n[workspace]\n"
        ),
    )
    .unwrap();
    std::fs::write(dir.join("src/lib.rs"), "").unwrap();
    write_model(dir, "beep-lib");
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
    assert!(toml.contains("ferroc-runner = { path = "), "{toml}");
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

/// Another "checkout" in `dir/other`: a runtime and a host crate of its own, and the
/// folders a bundle depends on by path (their crates are not built here).
fn other_checkout(dir: &Path) -> PathBuf {
    let other = dir.join("other");
    std::fs::create_dir_all(other.join("runtime/src")).unwrap();
    for folder in ["host", "inspect", "components/ferroc-std"] {
        std::fs::create_dir_all(other.join(folder)).unwrap();
    }
    std::fs::write(
        other.join("runtime/Cargo.toml"),
        "[package]\nname = \"ferroc-runtime\"\nversion = \"0.1.0\"\nedition = \"2021\"\n",
    )
    .unwrap();
    std::fs::write(other.join("runtime/src/lib.rs"), "").unwrap();
    std::fs::write(
        other.join("host/Cargo.toml"),
        "[package]\nname = \"ferroc-host\"\n",
    )
    .unwrap();
    other
}

/// `ferroc bundle beeper.xml -o bundle` in `dir` (an earlier bundle removed first),
/// with FERROC_SOURCE set to `source` if given.
fn bundle_in(dir: &Path, source: Option<&Path>) -> (i32, String) {
    let _ = std::fs::remove_dir_all(dir.join("bundle"));
    let mut ferroc = Command::new(env!("CARGO_BIN_EXE_ferroc"));
    ferroc
        .args(["bundle", "beeper.xml", "-o", "bundle"])
        .current_dir(dir)
        .env_remove("FERROC_SOURCE");
    if let Some(source) = source {
        ferroc.env("FERROC_SOURCE", source);
    }
    let out = ferroc.output().expect("ferroc runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_bundle_of_a_crate_on_another_runtime_is_refused_before_anything_is_written() {
    let dir = tempdir("bundle_other_runtime");
    let other = other_checkout(&dir);
    // As `ferroc new library` of another checkout writes it: the crate next to its
    // manifest, on that checkout's runtime. Cargo would stop building the bundle with
    // "package collision in the lockfile" (two ferroc-runtime by path).
    let lib = dir.join("lib");
    write_crate(&lib, "{ path = \"../other/runtime\" }");
    let (code, err) = bundle_in(&lib, None);
    assert_eq!(code, 1, "{err}");
    assert_names_both_runtimes(&err, &other, "the bundle's programs link");
    let other = other.canonicalize().unwrap();
    assert!(
        err.contains(&format!(
            "or bundle with the ferroc of that checkout (`cargo install --path {0}`), or make the bundle depend on its sources: FERROC_SOURCE={0} ferroc bundle",
            other.display()
        )),
        "{err}"
    );
    assert!(!lib.join("bundle").exists(), "nothing written");

    // What the help says: with FERROC_SOURCE at that checkout, the bundle depends on
    // its runtime, and the crate is bundled.
    let (code, err) = bundle_in(&lib, Some(&other));
    assert_eq!(code, 0, "{err}");
    let workspace = std::fs::read_to_string(lib.join("bundle/Cargo.toml")).unwrap();
    assert!(
        workspace.contains("ferroc-runtime = { path = \"../../other/runtime\" }"),
        "{workspace}"
    );

    // The silent case: a crate on this ferroc's runtime, next to its manifest, is bundled.
    write_crate(&lib, &format!("{{ path = {:?} }}", our_runtime()));
    let (code, err) = bundle_in(&lib, None);
    assert_eq!(code, 0, "{err}");
    let workspace = std::fs::read_to_string(lib.join("bundle/Cargo.toml")).unwrap();
    assert!(
        workspace.contains("beep-lib = { path = \"..\" }"),
        "{workspace}"
    );
}

#[test]
fn a_crate_on_another_runtime_is_refused_before_cargo_with_both_places_and_the_fixes() {
    let dir = tempdir("runner_other_runtime");
    let other = other_checkout(&dir);
    let lib = dir.join("lib");
    write_crate(&lib, "{ path = \"../other/runtime\" }");
    let (code, err) = run_in(&lib);
    assert_eq!(code, 1, "{err}");
    assert_names_both_runtimes(&err, &other, "the runner links");
    assert!(
        err.contains(&format!(
            "FERROC_SOURCE={}",
            other.canonicalize().unwrap().display()
        )),
        "{err}"
    );
    assert!(!err.contains("collision"), "refused before cargo: {err}");

    // From a registry: the same, without a checkout to suggest.
    write_crate(&lib, "\"0.1\"");
    let (code, err) = run_in(&lib);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("depends on ferroc-runtime ^0.1 from the registry"),
        "{err}"
    );
    assert!(!err.contains("FERROC_SOURCE"), "{err}");

    // The silent case: the crate on this ferroc's runtime is not refused (it builds).
    write_crate(&lib, &format!("{{ path = {:?} }}", our_runtime()));
    let (_, err) = run_in(&lib);
    assert!(!err.contains("depends on"), "{err}");
}

/// The refusal of a crate on the runtime of checkout `other`: at the manifest, naming
/// both runtimes and what links ours (`linker`: "the runner links"), and the manifest
/// line that fixes it.
fn assert_names_both_runtimes(err: &str, other: &Path, linker: &str) {
    let ours = our_runtime();
    let theirs = other.join("runtime").canonicalize().unwrap();
    assert!(
        err.contains(&format!(
            "beep.lib.xml:1:16: error: the crate `beep-lib` of library `beep` depends on the ferroc-runtime at {}, but {linker} the ferroc-runtime of this ferroc's sources, {}",
            theirs.display(),
            ours.display()
        )),
        "{err}"
    );
    let fix = format!("ferroc-runtime = {{ path = \"{}\" }}", ours.display());
    assert!(err.contains(&fix), "{err}");
}

/// This checkout's `runtime/` folder, canonical (as the messages name it).
fn our_runtime() -> PathBuf {
    let ours = Path::new(env!("CARGO_MANIFEST_DIR")).join("runtime");
    ours.canonicalize().unwrap()
}
