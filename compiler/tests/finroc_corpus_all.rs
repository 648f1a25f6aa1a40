//! Every file of the FINROC corpus (`shared/corpus/finroc`, origin in MANIFEST.tsv, kind
//! in KINDS.tsv) through `check_model`, as a user runs `ferroc check`: none is refused
//! for its format, none panics, FINROC files give no model. Checked twice: as the corpus
//! stores them (flat, all versions side by side) and in checkout layouts rebuilt from
//! MANIFEST.tsv (each repository's newest files at their paths, so applications,
//! group files, config files and make.xml resolve against each other as in a checkout).
//!
//! The findings of both runs are snapshot-tested (`finroc_corpus_all.flat.out`,
//! `finroc_corpus_all.checkouts.out`; `FERROC_BLESS=1` rewrites them), and each kind of
//! real finding is asserted at its line in a real file. Skipped with a message when the
//! corpus is absent.

use ferroc_compiler::load::Options;
use ferroc_compiler::{check_model, Policy};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn corpus() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus/finroc");
    if dir.join("MANIFEST.tsv").is_file() {
        Some(dir)
    } else {
        println!(
            "note: {} is absent; FINROC corpus test skipped",
            dir.display()
        );
        None
    }
}

fn table(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap_or_default()
        .lines()
        .skip(1)
        .map(|l| l.split('\t').map(str::to_string).collect())
        .filter(|r: &Vec<String>| r.len() >= 2)
        .collect()
}

/// Checks `files` (paths shown relative to `base`); returns the findings, one line each.
fn check_all(
    files: &[PathBuf],
    base: &Path,
    options: &Options,
    failures: &mut Vec<String>,
) -> Vec<String> {
    let mut lines = Vec::new();
    for path in files {
        let shown = path
            .strip_prefix(base)
            .unwrap_or(path)
            .display()
            .to_string();
        let result = match check_model(path, options, &Policy::default()) {
            Ok(r) => r,
            Err(e) => {
                failures.push(format!("{shown}: {e}"));
                continue;
            }
        };
        if result.app.is_some() {
            failures.push(format!("{shown}: read as a ferroc model"));
        }
        for d in &result.diagnostics {
            if d.code() == "M119" {
                failures.push(format!("{shown}: refused for its format: {}", d.message));
            }
            let (file, line, col) = result.sources.location(d.primary.span);
            let file = Path::new(&file);
            let file = file
                .strip_prefix(base)
                .unwrap_or(file)
                .display()
                .to_string();
            lines.push(format!(
                "{file}:{line}:{col}: {}[{}]: {}",
                d.severity.as_str(),
                d.code(),
                d.message
            ));
        }
    }
    lines.sort();
    lines.dedup();
    lines
}

fn snapshot(name: &str, lines: &[String], failures: &mut Vec<String>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join(name);
    let text = lines.join("\n") + "\n";
    if std::env::var_os("FERROC_BLESS").is_some() {
        std::fs::write(&path, &text).unwrap();
        return;
    }
    let old = std::fs::read_to_string(&path).unwrap_or_default();
    if old != text {
        failures.push(format!(
            "{name} differs (FERROC_BLESS=1 to accept):\n--- now\n{text}--- was\n{old}"
        ));
    }
}

fn counts(lines: &[String]) -> BTreeMap<String, usize> {
    let mut c = BTreeMap::new();
    for l in lines {
        if let Some(code) = l.split('[').nth(1).and_then(|r| r.split(']').next()) {
            *c.entry(code.to_string()).or_default() += 1;
        }
    }
    c
}

#[test]
fn the_whole_corpus_reads_and_its_real_defects_are_found_at_their_lines() {
    let Some(dir) = corpus() else { return };
    let mut failures = Vec::new();
    let kinds = table(&dir.join("KINDS.tsv"));
    let mut flat: Vec<PathBuf> = kinds.iter().map(|r| dir.join(&r[0])).collect();
    flat.sort();
    let options = Options::default();
    let found = check_all(&flat, &dir, &options, &mut failures);
    println!(
        "flat corpus: {} files, findings per code {:?}",
        flat.len(),
        counts(&found)
    );
    snapshot("finroc_corpus_all.flat.out", &found, &mut failures);

    // Each distinct kind of real finding, at its line (verified against the files and,
    // for FINROC's behaviour, its C++ sources: see the checks' explanations).
    for want in [
        // A comma decimal in the curvature lookup table copied through the Unimog projects.
        "rc_unimog__etc__control_calibration.xml:28:10: error[F106]: `-1,47 1/m` has a comma",
        "Mobile-Roboter__etc__control_calibration.xml:28:10: error[F106]",
        // Edges written twice, and written backwards (re-oriented by FINROC).
        "Robotics__my-finroc-proj__stereo__simulations__ICARUS_physics__gRoboticNavigation.h.xml:14:3: warning[F103]",
        "Robotics__my-finroc-proj__stereo__simulations__ICARUS_physics__gRoboticNavigation.h.xml:7:3: warning[F103]: this edge is an earlier one reversed",
        // Sensor data into a controller port.
        "Robotics__my-finroc-proj__stereo__simulations__ICARUS_physics__gRoboticNavigation.h.xml:3:103: warning[F104]",
        // The older type_conversion.finroc lacks finroc_plugins_structure (added upstream later).
        "finroc_plugins_runtime_construction__tests__type_conversion.8167440.finroc:21:34: warning[F109]",
        // A velocity from the config file without its unit.
        "finroc_projects_crash_course__etc__fragile_bot.xml:5:47: warning[F106]: `0.1` has no unit",
        // A config file wrapped in <targets> (with a program pasted beside): FINROC's
        // tConfigFile looks for <node>/<value> below the root only, so no entry is found.
        "Mobile-Roboter__rc_unimog_control_Unimog_v1__etc__config.xml:3:2: error[F101]",
        // smart_home's config file is not well-formed (kept in the corpus on purpose).
        "finroc_projects_smart_home__etc__config.xml:3:3: error[M101]",
        // rc_unimog's group MainControl (gMainControl.h/.cpp of robprak_2024_2): no
        // `Pose` among its sensor inputs, no `In Pose 3d` in TrackRecognition (nor in
        // any version of the repository's C++): FINROC drops the edge.
        "rc_unimog__gMainControl.h.xml:4:14: error[F102]: `Sensor Input/Pose` does not exist",
        // ICARUS simulation (arasdar/Robotics): gIcarusSimulation.cpp no longer creates
        // StViPr, ProcessedSensorDataToMapping, the map displays, the scanner chains (the
        // code is commented out); edges between them are dropped, edges from what it
        // does create are left pending.
        "Robotics__my-finroc-proj__stereo__simulations__ICARUS__gIcarusSimulation.h.xml:5:14: error[F102]: `StViPr/Sensor Output/Map Grid Stereo` does not exist",
        "Robotics__my-finroc-proj__stereo__simulations__ICARUS__gIcarusSimulation.h.xml:3:49: warning[F102]: `StViPr/Sensor Input/Robot Pose` does not exist",
        // Its so_pose_x/_y/_yaw ports: nothing in the group writes them.
        "Robotics__my-finroc-proj__stereo__simulations__ICARUS__gIcarusSimulation.h.xml:2:2: warning[F105]: nothing in group `IcarusSimulation` writes its output(s) `Sensor Output/Pose X`",
    ] {
        if !found.iter().any(|l| l.starts_with(want)) {
            failures.push(format!("expected finding not found: {want}"));
        }
    }
    // Files FINROC loads cleanly stay free of errors.
    for clean in [
        "finroc_plugins_runtime_construction__tests__type_conversion.finroc",
        "finroc_plugins_runtime_construction__tests__type_conversion_group.xml",
        "finroc_projects_crash_course__CrashCourse.finroc",
        "finroc_projects_crash_course__gSimulation.h.xml",
    ] {
        if let Some(l) = found
            .iter()
            .find(|l| l.starts_with(clean) && l.contains(": error["))
        {
            failures.push(format!("error in a file FINROC loads cleanly: {l}"));
        }
    }

    // Checkout layouts: each repository's newest files at their paths.
    let layout =
        std::env::temp_dir().join(format!("ferroc-finroc-checkouts-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&layout);
    let mut placed = Vec::new();
    for row in table(&dir.join("MANIFEST.tsv")) {
        if row.len() < 3 {
            continue;
        }
        let (saved, repo, path) = (&row[0], &row[1], &row[2]);
        let repo_name = repo.rsplit('/').next().unwrap_or(repo);
        if saved != &format!("{repo_name}__{}", path.replace('/', "__")) {
            continue; // an older version: checked flat only
        }
        let to = layout.join(repo_name).join(path);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(dir.join(saved), &to).unwrap();
        placed.push(to);
    }
    placed.sort();
    let found = check_all(&placed, &layout, &options, &mut failures);
    println!(
        "checkouts: {} files, findings per code {:?}",
        placed.len(),
        counts(&found)
    );
    snapshot("finroc_corpus_all.checkouts.out", &found, &mut failures);
    for want in [
        // Resolved in its checkout: the crash course's Control group writes no output.
        "finroc_projects_crash_course/control/gControl.h.xml:2:2: warning[F105]",
        "finroc_projects_crash_course/etc/fragile_bot.xml:5:47: warning[F106]",
        "rc_unimog/gMainControl.h.xml:4:14: error[F102]",
    ] {
        if !found.iter().any(|l| l.starts_with(want)) {
            failures.push(format!(
                "expected finding not found in the checkouts: {want}"
            ));
        }
    }
    let _ = std::fs::remove_dir_all(&layout);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
