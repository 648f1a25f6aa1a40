//! The make-file checks over real FINROC `make.xml` files (`shared/corpus/finroc`, kind
//! `make_xml` in KINDS.tsv, origin in MANIFEST.tsv). Every file must parse and check
//! without a panic; the totals below are what the real files give and pin the name
//! resolution down (a change in them is a change in behaviour: look before updating).
//!
//! Each file is checked twice: through `check_model` as a user would (the corpus stores
//! files flat, so no FINROC prefix is known), and with the prefix its repository and path
//! give, as if it sat in its checkout.

use ferroc_compiler::diagnostic::Diagnostics;
use ferroc_compiler::finroc::{self, make_xml};
use ferroc_compiler::load::Options;
use ferroc_compiler::source::SourceMap;
use ferroc_compiler::syntax::xml;
use ferroc_compiler::{check_model, Policy};
use std::collections::HashMap;
use std::path::Path;

/// What the corpus gives (recorded from the real files).
const FILES: usize = 518;
const TARGETS: usize = 1888;
const LIB_ENTRIES: usize = 654;
/// `libs`/`optionallibs` entries naming a target of the same file: all of them programs
/// and test programs using their own repository's library (e.g. `finroc_core`).
const LOCAL_DEPENDENCIES: usize = 50;
/// Files whose location tells no FINROC prefix (projects outside a FINROC checkout).
const WITHOUT_PREFIX: usize = 48;
/// No real file has a make-target cycle (L106) or a repeated lib (L107).
const FINDINGS: usize = 0;

fn table(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap_or_default()
        .lines()
        .skip(1)
        .map(|l| l.split('\t').map(str::to_string).collect())
        .collect()
}

#[test]
fn real_make_files_parse_and_check() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus/finroc");
    if !dir.join("KINDS.tsv").is_file() {
        println!(
            "note: {} is absent; FINROC corpus test skipped",
            dir.display()
        );
        return;
    }
    let origin: HashMap<String, (String, String)> = table(&dir.join("MANIFEST.tsv"))
        .into_iter()
        .filter(|r| r.len() >= 3)
        .map(|r| (r[0].clone(), (r[1].clone(), r[2].clone())))
        .collect();
    let mut files: Vec<String> = table(&dir.join("KINDS.tsv"))
        .into_iter()
        .filter(|r| r.len() >= 2 && r[1] == "make_xml")
        .map(|r| r[0].clone())
        .collect();
    files.sort();

    let (mut targets, mut entries, mut local, mut without_prefix) = (0, 0, 0, 0);
    let mut findings = Vec::new();
    let mut failures = Vec::new();
    for name in &files {
        let path = dir.join(name);
        // As a user would run it.
        let result = check_model(&path, &Options::default(), &Policy::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        if result.app.is_some() {
            failures.push(format!("{name}: checked as a model, not as a make file"));
        }
        // No prefix known here: only names FINROC forms from `name` alone resolve, a subset
        // of the dependencies below, so with no findings there nothing may show here either.
        // One file KINDS.tsv counts as a make.xml is an etc/config.xml wrapped in <targets>
        // with a program pasted in: its F101 (config entries FINROC never finds) is real
        // and pinned in finroc_corpus_all.rs.
        for d in &result.diagnostics {
            let config_in_targets = name
                == "Mobile-Roboter__rc_unimog_control_Unimog_v1__etc__config.xml"
                && d.code() == "F101";
            if !config_in_targets {
                failures.push(format!("{name}: {} {}", d.code(), d.message));
            }
        }

        // As it sits in its checkout: `repository-name/path/in/repository`.
        let (repo, in_repo) = &origin[name];
        let located = Path::new(repo.rsplit('/').next().unwrap_or(repo)).join(in_repo);
        let prefix = make_xml::target_prefix(&located);
        without_prefix += usize::from(prefix.is_none());
        let mut sources = SourceMap::default();
        let text = std::fs::read_to_string(&path).unwrap();
        let file = sources.add(name.clone(), path.clone(), text);
        let root = match xml::parse(file, &sources.get(file).text, 256) {
            Ok(root) => root,
            Err(e) => {
                failures.push(format!("{name}: does not parse: {}", e.message));
                continue;
            }
        };
        let make = make_xml::read(file, &root, prefix.as_deref());
        targets += make.targets.len();
        for t in &make.targets {
            entries += t.libs.len();
            local += t
                .libs
                .iter()
                .filter(|l| make.resolve(&l.name).is_some())
                .count();
        }
        let mut diags = Diagnostics::default();
        finroc::check_make(&make, &mut diags);
        for d in diags.items {
            let (_, line, col) = sources.location(d.primary.span);
            findings.push(format!("{name}:{line}:{col}: {} {}", d.code(), d.message));
        }
    }
    println!(
        "FINROC corpus: {} make.xml files, {targets} targets, {entries} libs entries, \
         {local} local dependencies, {without_prefix} without prefix, {} findings",
        files.len(),
        findings.len()
    );
    for f in &findings {
        println!("  {f}");
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert_eq!(
        (
            files.len(),
            targets,
            entries,
            local,
            without_prefix,
            findings.len()
        ),
        (
            FILES,
            TARGETS,
            LIB_ENTRIES,
            LOCAL_DEPENDENCIES,
            WITHOUT_PREFIX,
            FINDINGS
        ),
        "(files, targets, libs entries, local dependencies, without prefix, findings)"
    );
}
