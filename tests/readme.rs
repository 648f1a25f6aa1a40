//! The README's first steps cost one release build: `cargo install` with `--locked`
//! (the lock file the tests ran with; without it the install resolves anew) and then
//! the installed `ferroc`, not a second build through `cargo run --release`.

#[test]
fn the_readme_installs_once_and_uses_the_installed_ferroc() {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    let installs: Vec<&str> = readme
        .lines()
        .filter(|l| l.trim_start().starts_with("cargo install"))
        .collect();
    assert_eq!(installs.len(), 1, "{installs:?}");
    assert!(installs[0].contains("--locked"), "{}", installs[0]);
    let rebuilds: Vec<&str> = readme
        .lines()
        .filter(|l| l.contains("cargo run --release -- "))
        .collect();
    assert!(
        rebuilds.is_empty(),
        "use the installed ferroc: {rebuilds:?}"
    );
    for command in [
        "ferroc run models/crash_course.xml",
        "ferroc check models/crash_course.xml",
    ] {
        assert!(readme.contains(&format!("\n{command}\n")), "{command}");
    }
}

/// The README's test command is the one CI runs, and it names the set-up that the
/// skipped tests point to.
#[test]
fn the_readme_test_command_is_what_ci_runs() {
    let root = env!("CARGO_MANIFEST_DIR");
    let readme = std::fs::read_to_string(format!("{root}/README.md")).unwrap();
    let ci = std::fs::read_to_string(format!("{root}/.ci/run")).unwrap();
    assert!(
        readme.contains("\nscripts/test\n"),
        "the README's test command"
    );
    assert!(
        ci.lines()
            .any(|l| l.trim() == "FERROC_REQUIRE_ALL=1 exec scripts/test"),
        "{ci}"
    );
    assert!(
        readme.contains(ferroc_testkit::SETUP),
        "{}",
        ferroc_testkit::SETUP
    );
    let script = std::fs::read_to_string(format!("{root}/scripts/test")).unwrap();
    assert!(
        script.contains("cargo test --workspace --no-fail-fast\n"),
        "the script runs the suite"
    );
}

/// The first-use times the README states are those bench/README.md's table measured
/// with bench/first_use.sh: a new measurement changes both, or this fails.
#[test]
fn the_readme_states_the_measured_first_use_times() {
    let root = env!("CARGO_MANIFEST_DIR");
    let readme = std::fs::read_to_string(format!("{root}/README.md")).unwrap();
    let bench = std::fs::read_to_string(format!("{root}/bench/README.md")).unwrap();
    for step in ["install", "crash_course", "new_library", "edit"] {
        let row = bench
            .lines()
            .find(|l| l.starts_with(&format!("| `{step}` |")))
            .unwrap_or_else(|| panic!("bench/README.md has no row for `{step}`"));
        let measured = row
            .trim_end()
            .trim_end_matches('|')
            .rsplit('|')
            .next()
            .unwrap();
        let figure = measured.split(',').next().unwrap().trim();
        assert!(
            !figure.is_empty() && figure != "—",
            "bench/README.md: `{step}` not measured"
        );
        assert!(
            readme.contains(&format!(" {figure}")),
            "the README does not state the measured `{step}` time {figure}"
        );
    }
}
