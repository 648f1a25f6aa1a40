//! `ferroc lsp` with clients we did not write: pytest-lsp (tests/lsp/test_ferroc_lsp.py)
//! and Neovim's built-in LSP client (tests/lsp/nvim_diagnostics.lua). A missing client
//! is a visible SKIPPED line (ferroc-testkit; `scripts/test` installs both).

mod common;

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn pytest_lsp_end_to_end() {
    let Some(python) = ferroc_testkit::python(&["pytest_lsp"]) else {
        return; // skipped visibly by the testkit
    };
    let scratch = common::tempdir("lsp-pytest");
    let out = Command::new(python)
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider", "-c"])
        .arg(root().join("tests/lsp/pytest.ini"))
        .arg(root().join("tests/lsp/test_ferroc_lsp.py"))
        .env("FERROC", env!("CARGO_BIN_EXE_ferroc"))
        .env("FERROC_ROOT", root())
        .env("FERROC_SCRATCH", &scratch)
        .current_dir(&scratch)
        .output()
        .expect("python runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    println!("{text}");
    assert!(out.status.success(), "pytest-lsp failed:\n{text}");
    assert!(text.contains("15 passed"), "{text}");
}

/// `CODE LINE:COL SEVERITY` of `ferroc check --format json`'s findings in the model.
fn cli_lines(model: &Path) -> Vec<String> {
    let (_, stdout, _) = common::ferroc(&["check", "--format", "json", model.to_str().unwrap()]);
    let doc: Value = serde_json::from_str(&stdout).unwrap();
    let name = model.file_name().unwrap().to_string_lossy().into_owned();
    let severity = |s: &str| match s {
        "error" => 1,
        "warning" => 2,
        _ => 3,
    };
    (doc["models"][0]["diagnostics"].as_array().unwrap().iter())
        .filter(|d| {
            d["primary"]["location"]["file"]
                .as_str()
                .unwrap()
                .ends_with(&name)
        })
        .map(|d| {
            let l = &d["primary"]["location"];
            format!(
                "{} {}:{} {}",
                d["code"].as_str().unwrap(),
                l["line"],
                l["column"],
                severity(d["severity"].as_str().unwrap())
            )
        })
        .collect()
}

#[test]
fn neovim_shows_what_ferroc_check_finds() {
    let Some(nvim) = ferroc_testkit::command("nvim") else {
        return; // skipped visibly by the testkit
    };
    let dir = common::tempdir("lsp-nvim");
    let fixture =
        root().join("compiler/checks/src/connections/t103_unit_dimension_mismatch/fires.xml");
    let model = dir.join("broken.xml");
    let manifest = root().join("compiler/checks/src/fixtures.lib.xml");
    let text = std::fs::read_to_string(&fixture).unwrap().replace(
        "manifest=\"../../fixtures.lib.xml\"",
        &format!("manifest=\"{}\"", manifest.display()),
    );
    std::fs::write(&model, text).unwrap();
    let want = cli_lines(&model);
    assert!(!want.is_empty(), "the fixture has findings");
    let out_file = dir.join("diagnostics.txt");
    let status = Command::new(nvim)
        .args(["--headless", "-n", "-i", "NONE", "-u", "NONE", "-c"])
        .arg(format!(
            "luafile {}",
            root().join("tests/lsp/nvim_diagnostics.lua").display()
        ))
        .env("FERROC", env!("CARGO_BIN_EXE_ferroc"))
        .env("FERROC_MODEL", &model)
        .env("FERROC_OUT", &out_file)
        .current_dir(&dir)
        .status()
        .expect("nvim runs");
    assert!(status.success());
    let got: Vec<String> = std::fs::read_to_string(&out_file)
        .expect("nvim wrote the diagnostics")
        .lines()
        .map(str::to_string)
        .collect();
    let (mut got_sorted, mut want_sorted) = (got.clone(), want.clone());
    got_sorted.sort();
    want_sorted.sort();
    assert_eq!(
        got_sorted, want_sorted,
        "nvim received {got:?}, ferroc check found {want:?}"
    );
}
