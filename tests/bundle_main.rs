//! What a bundle part's generated `main.rs` holds: constants that never clash with
//! the model's names, and Zenoh's runtime threads chosen before anything else runs.

mod common;
use common::bundle;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A scratch folder of this file's own (below `bundle_main/`).
fn tempdir(name: &str) -> PathBuf {
    common::tempdir(&format!("bundle_main/{name}"))
}

/// Modules named like the other constants of `main.rs` (`parts`, `periods`, `link_0`)
/// get other constant names: each constant is defined once, or the bundle would not
/// compile.
#[test]
fn module_names_that_match_generated_constants_get_other_constant_names() {
    let model = std::fs::read_to_string("models/rescue_robot.xml").unwrap();
    let renamed = model
        .replace("mapper", "link_0")
        .replace("name=\"clock\"", "name=\"periods\"")
        .replace("\"clock/tick\"", "\"periods/tick\"")
        .replace("name=\"heartbeat\"", "name=\"parts\"")
        .replace("\"heartbeat/in/0\"", "\"parts/in/0\"");
    // Next to the real model, so that its includes and manifests resolve.
    let path = format!("models/.bundle-names-{}.xml", std::process::id());
    std::fs::write(&path, renamed).unwrap();
    let out = tempdir("constant_names");
    let (code, err) = bundle(Path::new(&path), &out, &[]);
    let _ = std::fs::remove_file(&path);
    assert_eq!(code, 0, "{err}");
    let mut seen_link = false;
    for part in ["robot", "station"] {
        let main = std::fs::read_to_string(out.join(format!("parts/{part}/src/main.rs"))).unwrap();
        let mut names: Vec<&str> = main
            .lines()
            .filter_map(|l| l.strip_prefix("const ")?.split(':').next())
            .collect();
        let count = names.len();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), count, "a constant defined twice:\n{main}");
        assert!(names.contains(&"PARTS") && names.contains(&"PERIODS"));
        seen_link |= main.contains("const LINK_0: LinkSpec");
        if part == "robot" {
            assert!(
                main.contains("const MAPPING_LINK_0: &str = \"robot/mapping/link_0\";"),
                "{main}"
            );
        } else {
            assert!(
                main.contains("const LOGGING_PERIODS: &str = \"station/logging/periods\";"),
                "{main}"
            );
            assert!(
                main.contains("const LOGGING_PARTS: &str = \"station/logging/parts\";"),
                "{main}"
            );
        }
    }
    assert!(seen_link, "the model has a link numbered 0");
}

/// A part that talks to others over Zenoh sets Zenoh's runtime threads (ferroc's,
/// unless `ZENOH_RUNTIME` is set) first in `main`, before any thread or session
/// (docs/zenoh.md "Zenoh's threads"); a part that talks to nobody does not link Zenoh at all.
#[test]
fn linked_parts_choose_zenohs_runtime_threads_first_and_a_lone_part_does_not() {
    let call = "ferroc_zenoh::config::runtime::use_default();";
    let out = tempdir("zenoh_runtime");
    let (code, err) = bundle(Path::new("models/rescue_robot.xml"), &out, &[]);
    assert_eq!(code, 0, "{err}");
    for part in ["robot", "station"] {
        let file = out.join(format!("parts/{part}/src/main.rs"));
        let main = std::fs::read_to_string(&file).unwrap();
        let at = main
            .find(call)
            .unwrap_or_else(|| panic!("no `{call}` in:\n{main}"));
        for later in ["Args::from_env", "ctrlc::set_handler", "Zenoh::with_model"] {
            let then = main.find(later).unwrap_or_else(|| panic!("no `{later}`"));
            assert!(at < then, "`{call}` after `{later}`:\n{main}");
        }
        if let Ok(fmt) = Command::new("rustfmt")
            .args(["--edition", "2021", "--check"])
            .arg(&file)
            .output()
        {
            let diff = String::from_utf8_lossy(&fmt.stdout);
            assert!(fmt.status.success(), "{diff}");
        }
    }
    let lone = tempdir("zenoh_runtime_lone");
    let (code, err) = bundle(Path::new("models/crash_course.xml"), &lone, &[]);
    assert_eq!(code, 0, "{err}");
    let main = std::fs::read_to_string(lone.join("parts/fragile_bot/src/main.rs")).unwrap();
    assert!(!main.contains("ferroc_zenoh"), "{main}");
}
