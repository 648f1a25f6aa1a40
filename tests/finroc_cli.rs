//! `ferroc check`, `import finroc` and `export finroc` on FINROC files: the crash
//! course checkout (compiler/tests/finroc_files, copied from FINROC 17.03, see
//! ORIGIN.md), FINROC's round-trip test file, and broken input.

mod common;

use common::{ferroc, tempdir};
use std::path::Path;

const FILES: &str = "compiler/tests/finroc_files";

#[test]
fn importing_the_crash_course_gives_a_model_that_checks_clean() {
    // As a team would: the model is written into the checkout, so that the config
    // files it names lie below the model's folder (they are confined to it, M113).
    let dir = tempdir("finroc_import").join("cc");
    copy_tree(&Path::new(FILES).join("crash_course"), &dir);
    let model = dir.join("model.xml");
    let (code, _, err) = ferroc(&[
        "import",
        "finroc",
        dir.join("CrashCourse.finroc").to_str().unwrap(),
        "-o",
        model.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("not imported"), "{err}");
    let text = std::fs::read_to_string(&model).unwrap();
    // What the C++ constructor of Simulation builds, what gSimulation.h.xml adds, the edges
    // of CrashCourse.finroc and the parameter links with the config file and option.
    for want in [
        "<module name=\"mainsimulation\" type=\"finroc_projects_crash_course.MainSimulation\" doc=\"FINROC: finroc_projects_crash_course/MainSimulation: MainSimulation\">",
        "<module name=\"addnoise_rear\" type=\"finroc_projects_crash_course.AddNoise\" doc=\"FINROC: finroc_projects_crash_course/AddNoise: AddNoise Rear\">",
        "<connect from=\"addnoise_rear/output\" to=\"ir_distance_rear\"/>",
        "<connect from=\"control/velocity\" to=\"simulation/velocity\"/>",
        "fragile_bot.xml#/noiselevel\" cmdline=\"front-noise\"",
    ] {
        assert!(text.contains(want), "{want} missing in\n{text}");
    }
    assert!(dir.join("finroc_projects_crash_course.lib.xml").is_file());
    let (code, out, err) = ferroc(&["check", model.to_str().unwrap(), "--format", "short"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(
        !out.contains("error[") && !out.contains("warning["),
        "{out}"
    );
}

#[test]
fn exporting_finrocs_round_trip_file_is_byte_identical() {
    let dir = tempdir("finroc_export");
    for name in [
        "type_conversion.finroc",
        "type_conversion_group.xml",
        "crash_course/CrashCourse.finroc",
    ] {
        let input = Path::new(FILES).join(name);
        let output = dir.join("out.finroc");
        let (code, _, err) = ferroc(&[
            "export",
            "finroc",
            input.to_str().unwrap(),
            "-o",
            output.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        assert_eq!(
            std::fs::read(&output).unwrap(),
            std::fs::read(&input).unwrap(),
            "{name}"
        );
    }
}

/// finroc_run makes one top-level thread container per `.finroc` file: a model with
/// two thread containers exports to two files, the first unchanged by the second, a
/// connect across them named as left out.
#[test]
fn exporting_a_model_with_two_thread_containers_writes_one_finroc_file_each() {
    let dir = tempdir("finroc_export_threads").join("cc");
    copy_tree(&Path::new(FILES).join("crash_course"), &dir);
    let model = dir.join("model.xml");
    let (code, _, err) = ferroc(&[
        "import",
        "finroc",
        dir.join("CrashCourse.finroc").to_str().unwrap(),
        "-o",
        model.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(&model).unwrap();
    let attr = |tag: &str| {
        let at = text.find(&format!("<{tag} name=\"")).unwrap() + tag.len() + 8;
        text[at..at + text[at..].find('"').unwrap()].to_string()
    };
    let (part, thread) = (attr("part"), attr("thread"));
    let second = "<thread name=\"noise\" period=\"10ms\">\n\
        <module name=\"extra\" type=\"finroc_projects_crash_course.AddNoise\"/>\n\
        <module name=\"extra2\" type=\"finroc_projects_crash_course.AddNoise\"/>\n\
        <connect from=\"extra/output\" to=\"extra2/input\"/>\n\
        </thread>\n";
    let at = text.find("</thread>").unwrap() + "</thread>".len() + 1;
    let mut changed = format!("{}{second}{}", &text[..at], &text[at..]);
    let across = format!(
        "<connect from=\"{part}/{thread}/simulation/ir_distance_front\" to=\"{part}/noise/extra/input\"/>\n"
    );
    let end = changed.rfind("</application>").unwrap();
    changed.insert_str(end, &across);
    std::fs::write(&model, changed).unwrap();

    let out = dir.join("out.finroc");
    let (code, _, err) = ferroc(&[
        "export",
        "finroc",
        model.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        std::fs::read(&out).unwrap(),
        std::fs::read(dir.join("CrashCourse.finroc")).unwrap(),
        "the first container is the imported application, unchanged"
    );
    let noise = std::fs::read_to_string(dir.join("out.noise.finroc")).unwrap();
    for want in [
        "<Finstructable defaultname=\"noise\" dependencies=\"finroc_projects_crash_course\">",
        "<element name=\"extra\" group=\"finroc_projects_crash_course\" type=\"AddNoise\">",
        "<edge src=\"extra/Output/Output\" dest=\"extra2/Input/Input\"/>",
    ] {
        assert!(noise.contains(want), "{want} missing in\n{noise}");
    }
    assert!(
        !noise.contains("Ir Distance Front"),
        "the connect across containers is in neither file: {noise}"
    );
    assert!(
        err.contains("joins two thread containers") && err.contains("finroc_run"),
        "{err}"
    );
    let (code, _, err) = ferroc(&["export", "finroc", model.to_str().unwrap(), "-o", "-"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("2 thread containers"), "{err}");
}

#[test]
fn checking_a_checkout_resolves_files_and_names_what_it_skipped() {
    let dir = tempdir("finroc_checkout");
    let src = Path::new(FILES).join("crash_course");
    for f in [
        "CrashCourse.finroc",
        "gSimulation.h.xml",
        "control/gControl.h.xml",
        "etc/fragile_bot.xml",
        "make.xml",
    ] {
        let to = dir.join(f);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(src.join(f), &to).unwrap();
    }
    std::fs::write(dir.join("README.txt"), "notes").unwrap();
    std::fs::write(dir.join("etc/crash_course.fingui"), "<fingui/>").unwrap();
    std::fs::write(dir.join("other.xml"), "<launch/>").unwrap();
    std::fs::create_dir_all(dir.join(".git")).unwrap();
    std::fs::write(dir.join(".git/config"), "x").unwrap();
    let (code, out, err) = ferroc(&["check", dir.to_str().unwrap(), "--color", "never"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(
        out.contains("README.txt: not an .xml or .finroc file"),
        "{out}"
    );
    assert!(
        out.contains("crash_course.fingui: not an .xml or .finroc file"),
        "{out}"
    );
    assert!(
        out.contains(
            "other.xml: root element <launch> is neither a ferroc model nor a FINROC file"
        ),
        "{out}"
    );
    assert!(out.contains(".git: hidden (name starts with `.`)"), "{out}");
    assert!(!out.contains(".git/config"), "{out}");
    assert!(out.contains("checked 5 file(s), skipped 4"), "{out}");
    // Resolved against each other: the link to the config file and the group file of Control.
    assert!(
        out.contains("`0.1` has no unit, but `Destructive Collision Speed` is measured in m/s"),
        "{out}"
    );
    assert!(
        out.contains("nothing in group `Control` writes its output(s)"),
        "{out}"
    );
    // The make.xml prefix can be given.
    let (_, out, _) = ferroc(&[
        "check",
        dir.join("make.xml").to_str().unwrap(),
        "--finroc-prefix",
        "finroc_projects_crash_course",
    ]);
    assert!(!out.contains("not checked"), "{out}");
}

#[test]
fn broken_finroc_input_is_reported_at_its_place_never_a_panic() {
    let dir = tempdir("finroc_broken");
    let cases = [
        ("truncated.finroc", "<Finstructable>\n  <edge src=\"A/Output/x\"", "truncated.finroc:2:", 1),
        ("escape.finroc", "<Finstructable version=\"1703\">\n  <edge src=\"A/Output/x%G1\" dest=\"B/Input/y\"/>\n</Finstructable>\n", "escape.finroc:2:24: error[F101]", 1),
        ("cfg.xml", "<root>\n  <value name=\"k\">1,5 m</value>\n</root>\n", "cfg.xml:2:19: error[F106]", 1),
        ("notfinroc.finroc", "<html><body/></html>", "notfinroc.finroc", 0),
    ];
    for (name, text, want, exit) in cases {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        let (code, out, err) = ferroc(&["check", p.to_str().unwrap(), "--format", "short"]);
        assert!(code == exit || code == 1, "{name}: exit {code}\n{out}{err}");
        assert!(code != 101 && !err.contains("panicked"), "{name}: {err}");
        assert!(
            out.contains(want) || err.contains(want),
            "{name}: {out}{err}"
        );
    }
    // A cycle of groups loading each other's files is read without looping.
    std::fs::write(
        dir.join("a.xml"),
        "<Finstructable dependencies=\"finroc_plugins_structure\">\n  <element name=\"B\" group=\"finroc_plugins_structure\" type=\"Group\">\n    <parameters><parameter name=\"XML file\">b.xml</parameter></parameters>\n  </element>\n</Finstructable>\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("b.xml"),
        "<Finstructable dependencies=\"finroc_plugins_structure\">\n  <element name=\"A\" group=\"finroc_plugins_structure\" type=\"Group\">\n    <parameters><parameter name=\"XML file\">a.xml</parameter></parameters>\n  </element>\n  <edge src=\"A/Output/x\" dest=\"A/Input/y\"/>\n</Finstructable>\n",
    )
    .unwrap();
    let (code, out, err) = ferroc(&[
        "check",
        dir.join("b.xml").to_str().unwrap(),
        "--format",
        "short",
    ]);
    assert!(code <= 1, "{out}{err}");
    assert!(out.contains("b.xml:5:14: error[F102]"), "{out}");
}

#[test]
fn a_make_cycle_in_a_folder_finroc_does_not_name_is_found_with_the_prefix_given() {
    let dir = tempdir("finroc_prefix").join("my checkout");
    std::fs::create_dir_all(&dir).unwrap();
    let make = dir.join("make.xml");
    std::fs::write(
        &make,
        "<targets>\n  <library name=\"a\" libs=\"myproj_b\"><sources>a.cpp</sources></library>\n  <library name=\"b\" libs=\"myproj_a\"><sources>b.cpp</sources></library>\n</targets>\n",
    )
    .unwrap();
    let make = make.to_str().unwrap();
    // The folder's name tells no prefix: the names cannot be resolved, and ferroc says so.
    let (code, out, _) = ferroc(&["check", make]);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("tells no FINROC target prefix"), "{out}");
    let (code, out, _) = ferroc(&[
        "check",
        make,
        "--finroc-prefix",
        "myproj",
        "--format",
        "short",
    ]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("make.xml:2:27: error[L106]"), "{out}");
}

/// Copies the folder `from` to `to` (created), files and subfolders.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

/// `ferroc` run in `dir`: (exit code, stdout, stderr).
fn ferroc_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("ferroc runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A FINROC file named without a folder lies in the current one: its checkout is found
/// as with `./NAME`. Before, its folder was the empty path: `CrashCourse.finroc` found no
/// config file (`under ` an empty path) and lost its F106 warning.
#[test]
fn finroc_files_named_without_a_folder_give_the_findings_of_dot_slash() {
    let dir = tempdir("finroc_bare_names").join("cc");
    copy_tree(&Path::new(FILES).join("crash_course"), &dir);
    for (folder, name) in [
        ("", "CrashCourse.finroc"),
        ("", "gSimulation.h.xml"),
        ("", "make.xml"),
        ("etc", "fragile_bot.xml"),
        ("control", "gControl.h.xml"),
    ] {
        let cwd = dir.join(folder);
        let dotted = format!("./{name}");
        for format in ["short", "human"] {
            let bare = ferroc_in(&cwd, &["check", name, "--format", format]);
            let with_dot = ferroc_in(&cwd, &["check", &dotted, "--format", format]);
            assert_eq!(
                bare.0, with_dot.0,
                "{name}: {bare:?}\nwith ./: {with_dot:?}"
            );
            assert_eq!(
                bare.1.replace(&dotted, name),
                with_dot.1.replace(&dotted, name),
                "{name} ({format})"
            );
            assert!(
                !bare.1.contains("under \n") && !bare.1.contains("under ,"),
                "{}",
                bare.1
            );
        }
    }
    let (_, out, _) = ferroc_in(&dir, &["check", "CrashCourse.finroc", "--format", "short"]);
    assert!(out.contains("warning[F106]"), "{out}");
}

/// `import finroc NAME.finroc` inside a checkout imports what `./NAME.finroc` does (the
/// group files beside it), and the `--help` example's pair checks clean.
#[test]
fn importing_a_finroc_file_named_without_a_folder_finds_its_checkout() {
    let dir = tempdir("finroc_import_bare").join("cc");
    copy_tree(&Path::new(FILES).join("crash_course"), &dir);
    let (code, _, err) = ferroc_in(
        &dir,
        &[
            "import",
            "finroc",
            "CrashCourse.finroc",
            "-o",
            "crash_course.xml",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("not in the checkout"), "{err}");
    assert!(!err.contains("warning"), "{err}");
    let text = std::fs::read_to_string(dir.join("crash_course.xml")).unwrap();
    assert_eq!(text.matches("<module ").count(), 5, "{text}");
    assert!(text.contains("config=\"etc/fragile_bot.xml#"), "{text}");
    let (code, out, err) = ferroc_in(&dir, &["check", "crash_course.xml", "--format", "short"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(
        !out.contains("error[") && !out.contains("warning["),
        "{out}"
    );
}

/// Written outside the checkout, the model names config files `check` refuses (M113):
/// the import says so, and where to write it instead. Before, it said nothing and
/// `check` gave three M113 errors.
#[test]
fn importing_outside_the_checkout_says_what_check_will_refuse() {
    let dir = tempdir("finroc_import_outside").join("cc");
    copy_tree(&Path::new(FILES).join("crash_course"), &dir);
    let (code, _, err) = ferroc_in(
        &dir,
        &[
            "import",
            "finroc",
            "CrashCourse.finroc",
            "-o",
            "crash_course/model.xml",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains(
            "warning: the model names config files outside its folder (../etc/fragile_bot.xml)"
        ),
        "{err}"
    );
    assert!(
        err.contains("help: write the model into the checkout (-o ./model.xml)"),
        "{err}"
    );
    // What it warned of is what check finds; the flag it names makes it pass.
    let (code, out, _) = ferroc_in(
        &dir,
        &["check", "crash_course/model.xml", "--format", "short"],
    );
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("error[M113]"), "{out}");
    let (code, out, _) = ferroc_in(
        &dir,
        &[
            "check",
            "crash_course/model.xml",
            "--allow-outside-includes",
            "--format",
            "short",
        ],
    );
    assert_eq!(code, 0, "{out}");
}

/// One finding is printed once per check run: two applications of a folder linking the
/// same config value without its unit reach the same F106 at the same place. Before, the
/// folder check printed it once per application.
#[test]
fn a_finding_two_files_reach_is_printed_once() {
    let dir = tempdir("finroc_once").join("cc");
    copy_tree(&Path::new(FILES).join("crash_course"), &dir);
    std::fs::copy(dir.join("CrashCourse.finroc"), dir.join("Again.finroc")).unwrap();
    let (_, out, err) = ferroc(&["check", dir.to_str().unwrap(), "--format", "short"]);
    let f106 = out.lines().filter(|l| l.contains("warning[F106]")).count();
    assert_eq!(f106, 1, "{out}{err}");
}
