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
