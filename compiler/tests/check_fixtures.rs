//! Every registered check has fixtures next to its file (see `ferroc_checks`' docs):
//! `fires*.xml` must raise the check at each `<!-- expect: CODE at LINE:COL -->`, and
//! `silent*.xml` must not raise it at all. `<!-- check-options: lockstep -->` in a
//! fixture checks it as `ferroc check --lockstep` does. The rendered findings of each fixture are
//! snapshot-tested against `NAME.out`; `FERROC_BLESS=1 cargo test` rewrites snapshots.

use ferroc_compiler::checks::REGISTRY;
use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::report::{self, ModelReport};
use ferroc_compiler::{check_model, Policy};
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

/// A finding as the harness compares it: code, file (as displayed), line, column.
type Finding = (String, String, usize, usize);

/// `<!-- expect: T102 at 12:7 -->` markers (in the fixture itself), or
/// `<!-- expect: L102 at ../x.lib.xml:3:5 -->` for a finding in another file, named
/// relative to the fixture's folder.
fn expectations(fixture: &Path, text: &str) -> Vec<Finding> {
    text.match_indices("<!-- expect:")
        .filter_map(|(i, _)| {
            let rest = &text[i + 12..];
            let body = rest[..rest.find("-->")?].trim();
            let (code, at) = body.split_once(" at ")?;
            let mut parts = at.trim().rsplitn(3, ':');
            let col = parts.next()?.parse().ok()?;
            let line = parts.next()?.parse().ok()?;
            let file = match parts.next() {
                Some(rel) => display(&fixture.parent()?.join(rel)),
                None => display(fixture),
            };
            Some((code.trim().to_string(), file, line, col))
        })
        .collect()
}

/// A path the way diagnostics show it: relative to the working directory.
fn display(path: &Path) -> String {
    let cwd = std::env::current_dir().unwrap();
    let full = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
    full.strip_prefix(cwd.canonicalize().unwrap_or(cwd))
        .unwrap_or(&full)
        .display()
        .to_string()
}

/// The options a fixture is checked with: `<!-- check-options: lockstep -->` judges it
/// as run in lockstep (`ferroc check --lockstep`).
fn options_for(path: &Path) -> Options {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    Options {
        lockstep: text.contains("<!-- check-options: lockstep -->"),
        ..options()
    }
}

fn render(path: &Path) -> (Vec<Finding>, String) {
    let result =
        check_model(path, &options_for(path), &Policy::default()).expect("fixture readable");
    let report = ModelReport {
        sources: &result.sources,
        diagnostics: &result.diagnostics,
    };
    let mut out = String::new();
    report::short(&report, &mut out);
    out.push('\n');
    report::human::render(&report, false, &mut out);
    let found = result
        .diagnostics
        .iter()
        .map(|d| {
            let (file, l, c) = result.sources.location(d.primary.span);
            (d.code().to_string(), file.to_string(), l, c)
        })
        .collect();
    (found, out)
}

fn fixtures(dir: &Path, prefix: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| rd.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    v.retain(|p| {
        let name = p.file_name().unwrap().to_string_lossy();
        name.starts_with(prefix) && name.ends_with(".xml")
    });
    v.sort();
    v
}

#[test]
fn every_check_fires_and_stays_silent_where_it_should() {
    let bless = std::env::var_os("FERROC_BLESS").is_some();
    // Paths in rendered output are relative to the compiler's folder (every crate that
    // raises checks lives below it), so snapshots do not depend on where the checkout
    // lives.
    std::env::set_current_dir(env!("CARGO_MANIFEST_DIR")).unwrap();
    let mut failures = Vec::new();
    for check in REGISTRY {
        let Some(dir) = check.fixtures.strip_prefix("compiler/").map(Path::new) else {
            failures.push(format!(
                "{}: fixtures outside compiler/: {}",
                check.code, check.fixtures
            ));
            continue;
        };
        let fires = fixtures(dir, "fires");
        let silent = fixtures(dir, "silent");
        if fires.is_empty() || silent.is_empty() {
            failures.push(format!(
                "{}: needs fires*.xml and silent*.xml in {}",
                check.code,
                dir.display()
            ));
            continue;
        }
        for f in &fires {
            let text = std::fs::read_to_string(f).unwrap();
            let expected = expectations(f, &text);
            if !expected.iter().any(|(c, _, _, _)| c == check.code) {
                failures.push(format!(
                    "{}: {} has no `<!-- expect: {} at L:C -->`",
                    check.code,
                    f.display(),
                    check.code
                ));
            }
            let (found, rendered) = render(f);
            for e in &expected {
                if !found.contains(e) {
                    failures.push(format!(
                        "{}: expected {} at {}:{}:{} not found (checking {}); found {:?}",
                        check.code,
                        e.0,
                        e.1,
                        e.2,
                        e.3,
                        f.display(),
                        found
                    ));
                }
            }
            snapshot(f, &rendered, bless, &mut failures);
        }
        for s in &silent {
            let (found, rendered) = render(s);
            if found.iter().any(|(c, _, _, _)| c == check.code) {
                failures.push(format!(
                    "{}: must stay silent on {}, but:\n{rendered}",
                    check.code,
                    s.display()
                ));
            }
            snapshot(s, &rendered, bless, &mut failures);
        }
    }
    assert!(
        failures.is_empty(),
        "{} fixture failure(s):\n{}",
        failures.len(),
        failures.join("\n")
    );
}

fn snapshot(fixture: &Path, rendered: &str, bless: bool, failures: &mut Vec<String>) {
    let out = fixture.with_extension("out");
    if bless {
        std::fs::write(&out, rendered).unwrap();
        return;
    }
    match std::fs::read_to_string(&out) {
        Ok(expected) if expected == rendered => {}
        Ok(expected) => failures.push(format!("snapshot {} differs (FERROC_BLESS=1 to update):\n--- expected\n{expected}\n--- actual\n{rendered}", out.display())),
        Err(_) => failures.push(format!("snapshot {} missing (run with FERROC_BLESS=1)", out.display())),
    }
}
