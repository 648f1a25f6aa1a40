//! What a runner and a bundle's part program link (issue 26): no compiler crate, no
//! Zenoh, no HTTP stack unless the run or the bundle asks for inspection. Read from the
//! generated packages with `cargo tree --offline` (nothing is built: the runner's build
//! is left to a `cargo` that refuses, after the package is written). That a built
//! runner refuses a plan of another version: tests/runner.rs.

mod cargo_features;
mod common;

use cargo_features::{differences, parse, resolve, Side};
use common::{ferroc, tempdir};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Crates no plain runner and no bundle part without inspection may link.
const NEVER: &[&str] = &[
    "ferroc-compiler",
    "ferroc-model",
    "ferroc-checks",
    "ferroc-syntax",
    "ferroc-host",
    "zenoh",
    "axum",
    "hyper",
];

/// The crates `manifest` links (normal dependencies, every package of its workspace).
fn crates_of(manifest: &Path) -> BTreeSet<String> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let out = Command::new(cargo)
        .args(["tree", "--offline", "-e", "normal", "--prefix", "none"])
        .args(["--workspace", "--format", "{p}", "--manifest-path"])
        .arg(manifest)
        .output()
        .expect("cargo runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "cargo tree failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    text.lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_string)
        .collect()
}

/// `ferroc ARGS` with runners written into `target` and a `cargo` that builds nothing:
/// the runner's package is written, its build fails.
fn write_runner(target: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("CARGO_TARGET_DIR", target)
        .env("CARGO", "false")
        .output()
        .expect("ferroc runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_ne!(out.status.code(), Some(0), "{err}");
    assert!(err.contains("building the runner"), "{err}");
}

/// The Cargo.toml of the one runner package under `target` that depends on `krate`.
fn runner_package(target: &Path, krate: &str) -> PathBuf {
    let found: Vec<PathBuf> = std::fs::read_dir(target.join("ferroc-runner"))
        .unwrap()
        .map(|e| e.unwrap().path().join("Cargo.toml"))
        .filter(|t| {
            std::fs::read_to_string(t)
                .unwrap_or_default()
                .contains(&format!("\n{krate} = {{ path = "))
        })
        .collect();
    assert_eq!(found.len(), 1, "{found:?}");
    found[0].clone()
}

fn assert_lean(crates: &BTreeSet<String>, what: &str) {
    for never in NEVER {
        assert!(!crates.contains(*never), "{what} links {never}: {crates:?}");
    }
    assert!(crates.contains("ferroc-runtime"), "{what}: {crates:?}");
}

#[test]
fn a_plain_runner_links_no_compiler_and_no_zenoh_and_the_inspecting_one_does() {
    let target = tempdir("runner_crates");
    let model = "models/crash_course.xml";
    write_runner(&target, &["run", model, "--cycles", "1", "-q"]);
    let plain = crates_of(&runner_package(&target, "ferroc-runner"));
    assert_lean(&plain, "the plain runner");
    assert!(plain.contains("crash-course"), "{plain:?}");

    write_runner(&target, &["run", model, "--inspect", "--cycles", "1", "-q"]);
    let inspect = crates_of(&runner_package(&target, "ferroc-host"));
    assert!(inspect.contains("zenoh"), "{inspect:?}");
    assert!(inspect.contains("ferroc-compiler"), "{inspect:?}");
    // The web page is the CLI's: an inspecting runner serves Zenoh only.
    assert!(!inspect.contains("axum"), "{inspect:?}");
}

#[test]
fn the_runner_of_a_model_with_ros2_nodes_links_zenoh_but_no_compiler() {
    let target = tempdir("runner_crates_ros2");
    let model = "models/ros2_crash_course.xml";
    write_runner(&target, &["run", model, "--cycles", "1", "-q"]);
    let ros2 = crates_of(&runner_package(&target, "ferroc-zenoh"));
    assert!(ros2.contains("zenoh"), "{ros2:?}");
    assert!(ros2.contains("crash-course"), "{ros2:?}");
    for never in NEVER.iter().filter(|c| **c != "zenoh") {
        assert!(
            !ros2.contains(*never),
            "the ROS 2 runner links {never}: {ros2:?}"
        );
    }
    // Inspected: the inspecting runner, with ferroc-zenoh opening the nodes; still no
    // web page.
    let target = tempdir("runner_crates_ros2_inspect");
    write_runner(&target, &["run", model, "--inspect", "--cycles", "1", "-q"]);
    let inspect = crates_of(&runner_package(&target, "ferroc-zenoh"));
    for linked in ["ferroc-host", "ferroc-compiler", "zenoh", "crash-course"] {
        assert!(inspect.contains(linked), "{linked}: {inspect:?}");
    }
    assert!(!inspect.contains("axum"), "{inspect:?}");
}

#[test]
fn a_bundle_part_links_no_compiler_and_no_http_stack() {
    let out = tempdir("runner_crates_bundle");
    let (code, _, err) = ferroc(&[
        "bundle",
        "models/rescue_robot.xml",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let crates = crates_of(&out.join("Cargo.toml"));
    for never in [
        "ferroc-compiler",
        "ferroc-model",
        "ferroc-checks",
        "axum",
        "hyper",
    ] {
        assert!(
            !crates.contains(never),
            "the bundle links {never}: {crates:?}"
        );
    }
}

/// A part that talks to no other links no Zenoh (its program's crates are then about
/// 60, not about 260): inspection, served on Zenoh, is compiled into it only with
/// `ferroc bundle --inspect`. A linked part serves inspection anyway (Zenoh is there).
#[test]
fn a_bundle_part_talking_to_no_other_links_zenoh_only_when_bundled_with_inspect() {
    let dir = tempdir("runner_crates_bundle_alone");
    let bundle = |out: &str, extra: &[&str]| {
        let out = dir.join(out);
        let mut args = vec![
            "bundle",
            "models/crash_course.xml",
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        let (code, _, err) = ferroc(&args);
        assert_eq!(code, 0, "{err}");
        crates_of(&out.join("Cargo.toml"))
    };
    let alone = bundle("plain", &[]);
    assert_lean(&alone, "the part of the crash course");
    assert!(!alone.contains("ferroc-inspect"), "{alone:?}");
    assert!(alone.len() < 100, "{} crates: {alone:?}", alone.len());

    let inspected = bundle("inspected", &["--inspect"]);
    assert!(inspected.contains("ferroc-inspect"), "{inspected:?}");
    assert!(inspected.contains("zenoh"), "{inspected:?}");
    assert!(!inspected.contains("axum"), "{inspected:?}");

    let out = dir.join("rescue");
    let (code, _, err) = ferroc(&[
        "bundle",
        "models/rescue_robot.xml",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let manifest = std::fs::read_to_string(out.join("parts/robot/Cargo.toml")).unwrap();
    assert!(
        manifest.contains("ferroc-inspect.workspace = true"),
        "{manifest}"
    );
}

/// ferroc's profile tables for single crates (`[profile.release.package.NAME]`) are
/// for crates of Zenoh's graph: runners copy them whole (cargo's warning about one a
/// runner does not link is hidden), and a bundle keeps them only when a program links
/// Zenoh (src/bundle/files.rs), so that building a bundle warns about nothing.
#[test]
fn profile_tables_of_single_crates_are_zenoh_s_and_bundles_keep_them_only_with_zenoh() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let manifest = std::fs::read_to_string(root.join("Cargo.toml")).unwrap();
    let tables: Vec<&str> = (manifest.lines())
        .filter_map(|l| l.strip_prefix("[profile.release.package."))
        .map(|rest| rest.trim_end_matches(']').trim_matches('"'))
        .filter(|name| *name != "*")
        .collect();
    assert!(!tables.is_empty(), "no table read from Cargo.toml");
    let zenoh = resolve(&root.join("Cargo.toml"), Some("ferroc-inspect"));
    for name in &tables {
        assert!(
            zenoh.keys().any(|(_, n, _)| n == name),
            "[profile.release.package.{name}] names no crate of Zenoh's graph: bundles without Zenoh would get it (src/bundle/files.rs, bundle_profiles)"
        );
    }
    let dir = tempdir("runner_crates_profiles");
    for (model, with_zenoh) in [
        ("models/crash_course.xml", false),
        ("models/rescue_robot.xml", true),
    ] {
        let out = dir.join(if with_zenoh { "rescue" } else { "alone" });
        let (code, _, err) = ferroc(&["bundle", model, "-o", out.to_str().unwrap()]);
        assert_eq!(code, 0, "{err}");
        let bundle = std::fs::read_to_string(out.join("Cargo.toml")).unwrap();
        assert!(
            bundle.contains("[profile.release]\ndebug = false\n"),
            "{bundle}"
        );
        for name in &tables {
            let table = format!("[profile.release.package.{name}]");
            assert_eq!(
                bundle.contains(&table),
                with_zenoh,
                "{model}: {table}\n{bundle}"
            );
        }
    }
}

/// The install compiles no ICU4X (about 25 crates, ~20 s of CPU in release): the
/// language server's `url` takes IDNA from unicode-rs (`idna_adapter` 1.1, chosen in
/// Cargo.lock as that crate documents) and miette's `textwrap` breaks lines with
/// `unicode-linebreak` (0.16.2; 0.16.3 and later use ICU4X). A `cargo update` that
/// brings them back fails here with the command that pins them again.
#[test]
fn the_install_compiles_no_icu4x() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let install = resolve(&root.join("Cargo.toml"), Some("ferroc"));
    let icu: BTreeSet<&str> = (install.keys())
        .filter(|(_, name, _)| name.starts_with("icu_") || name.starts_with("zerovec"))
        .map(|(_, name, _)| name.as_str())
        .collect();
    assert!(
        icu.is_empty(),
        "the install compiles ICU4X again: {icu:?}\n  help: cargo update -p idna_adapter --precise 1.1.0 && cargo update -p textwrap --precise 0.16.2 (or find which crate asks for it: cargo tree -p ferroc -i icu_provider)"
    );
    for (name, version) in [("idna_adapter", "1.1.0"), ("textwrap", "0.16.2")] {
        assert!(
            install
                .keys()
                .any(|(_, n, v)| n == name && *v == format!("v{version}")),
            "{name} is not {version} (Cargo.lock): {:?}",
            install
                .keys()
                .filter(|(_, n, _)| n == name)
                .collect::<Vec<_>>()
        );
    }
}

/// The first `ferroc run` after `cargo install --locked --path .` compiles only the
/// workspace's crates and the runner (issue 26): every registry crate of a runner (plain
/// and inspecting) is resolved with the features the install compiled it with, on the
/// same side (program, or build scripts and proc-macros), so cargo finds it compiled.
/// Where ferroc's other crates switch on more features than a runner's tree asks for,
/// the manifest of the crate the runner links (runner/ or host/Cargo.toml) asks for
/// them too; this fails when they drift (a dependency added or updated) and prints the
/// lines to write there.
#[test]
fn runners_compile_their_registry_crates_as_the_install_did() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let install = resolve(&root.join("Cargo.toml"), Some("ferroc"));
    let target = tempdir("runner_crates_features");
    let model = "models/crash_course.xml";
    let mut problems = Vec::new();
    for (inspect, krate, pins) in [
        (false, "ferroc-runner", "runner/Cargo.toml"),
        (true, "ferroc-host", "host/Cargo.toml"),
    ] {
        let mut args = vec!["run", model, "--cycles", "1", "-q"];
        args.extend(inspect.then_some("--inspect"));
        write_runner(&target, &args);
        let runner = resolve(&runner_package(&target, krate), None);
        assert!(
            runner
                .keys()
                .any(|(side, name, _)| *side == Side::Host && name == "syn"),
            "the proc-macros of the runner linking {krate} were not read: {runner:?}"
        );
        problems.extend(differences(&install, &runner, pins));
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The comparison sees each side apart: a crate the install compiles with other
/// features for its proc-macros than for the program matches a runner with the same
/// two sets (silent), and a crate listed after a build-dependency is on the program
/// side again; one feature less on either side is found.
#[test]
fn features_are_compared_per_side() {
    let install = parse(
        "ferroc v0.1.0 (/src/ferroc)\n\
         |-- serde v1.0.1 default,derive,std\n\
         |   `-- serde_derive v1.0.1 (proc-macro)\n\
         |       `-- syn v2.0.1 default,full,visit\n\
         |           `-- memchr v2.7.0 alloc\n\
         |-- ferroc-std v0.1.0 (/src/ferroc/std) mcap\n\
         |-- regex v1.1.0 default\n\
         |   |-- memchr v2.7.0 alloc,default,std\n\
         |   [build-dependencies]\n\
         |   `-- cc v1.0.0\n\
         |       `-- syn v2.0.1 default,full,visit (*)\n\
         `-- itoa v1.0.0\n",
    );
    let memchr = |side| install.get(&(side, "memchr".into(), "v2.7.0".into()));
    assert_eq!(memchr(Side::Host).unwrap().iter().next().unwrap(), "alloc");
    assert_eq!(
        memchr(Side::Target).unwrap().iter().next().unwrap(),
        "alloc,default,std"
    );
    assert!(install.contains_key(&(Side::Host, "cc".into(), "v1.0.0".into())));
    assert!(install.contains_key(&(Side::Target, "itoa".into(), "v1.0.0".into())));
    assert!(
        !install.keys().any(|(_, name, _)| name == "ferroc-std"),
        "path crates are left out"
    );

    let same = parse(
        "ferroc-runner-k v0.0.0 (/cache/k)\n\
         |-- memchr v2.7.0 alloc,default,std\n\
         `-- serde v1.0.1 default,derive,std\n\
         \x20   `-- serde_derive v1.0.1 (proc-macro)\n\
         \x20       `-- syn v2.0.1 default,full,visit\n\
         \x20           `-- memchr v2.7.0 alloc\n",
    );
    assert_eq!(differences(&install, &same, "m"), Vec::<String>::new());

    let fewer = parse(
        "ferroc-runner-k v0.0.0 (/cache/k)\n\
         |-- memchr v2.7.0 alloc,std\n\
         `-- serde_derive v1.0.1 (proc-macro)\n\
         \x20   `-- syn v2.0.1 default,full\n\
         \x20       `-- unicode-ident v1.0.0\n",
    );
    let found = differences(&install, &fewer, "runner/Cargo.toml");
    assert_eq!(found.len(), 3, "{found:#?}");
    assert!(
        found[0].contains("`memchr v2.7.0` (in the program)"),
        "{}",
        found[0]
    );
    assert!(
        found[0].ends_with(
            "[dependencies]: memchr = { version = \"2\", features = [\"alloc\", \"std\"] }"
        ),
        "{}",
        found[0]
    );
    assert!(
        found[1].ends_with(
            "[build-dependencies]: syn = { version = \"2\", features = [\"full\", \"visit\"] }"
        ),
        "{}",
        found[1]
    );
    assert!(found[2].contains("`unicode-ident v1.0.0` (for build scripts and proc-macros) is compiled for the runner but the install does not"), "{}", found[2]);
}

/// Zenoh's shared memory (ferroc-zenoh's feature `shared-memory`: zenoh-shm and 20
/// more crates) is compiled into a bundle only where two parts speaking Zenoh share a
/// host and not both turned it off: the rescue robot's parts run on `robot-pc` and
/// `base-pc`, so its bundle goes without; on one host it has it, unless both parts say
/// `shared-memory="off"`.
#[test]
fn a_bundle_compiles_shared_memory_in_only_where_two_linked_parts_share_a_host() {
    let dir = tempdir("runner_crates_shm");
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR")).join("components/rescue.lib.xml");
    let original = std::fs::read_to_string("models/rescue_robot.xml").unwrap();
    let original = original.replace(
        r#"manifest="../components/rescue.lib.xml""#,
        &format!(r#"manifest="{}""#, manifest.display()),
    );
    let bundle = |name: &str, edits: &[(&str, &str)]| {
        let mut model = original.clone();
        for (from, to) in edits {
            assert!(model.contains(from), "{from}");
            model = model.replace(from, to);
        }
        let file = dir.join(format!("{name}.xml"));
        std::fs::write(&file, model).unwrap();
        let out = dir.join(name);
        let (code, _, err) = ferroc(&[
            "bundle",
            file.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        let workspace = std::fs::read_to_string(out.join("Cargo.toml")).unwrap();
        (crates_of(&out.join("Cargo.toml")), workspace)
    };
    let (apart, workspace) = bundle("apart", &[]);
    assert!(apart.contains("zenoh"), "{apart:?}");
    assert!(!apart.contains("zenoh-shm"), "{apart:?}");
    assert!(
        workspace.contains("zenoh-link\", default-features = false }"),
        "{workspace}"
    );

    let one_host = [(r#"host="base-pc""#, r#"host="robot-pc""#)];
    let (together, workspace) = bundle("together", &one_host);
    assert!(together.contains("zenoh-shm"), "{together:?}");
    assert!(
        !together.contains("zenoh-ext"),
        "no ROS 2 node: {together:?}"
    );
    assert!(
        workspace.contains("default-features = false, features = [\"shared-memory\"] }"),
        "{workspace}"
    );
    // What shared memory brings, and nothing else changes.
    let added: Vec<&String> = together.difference(&apart).collect();
    assert!(added.len() > 10, "{added:?}");
    assert!(apart.is_subset(&together), "{apart:?}");

    let off = [
        one_host[0],
        (
            r#"<part name="robot" host="robot-pc">"#,
            r#"<part name="robot" host="robot-pc" shared-memory="off">"#,
        ),
        (
            r#"<part name="station" host="robot-pc">"#,
            r#"<part name="station" host="robot-pc" shared-memory="off">"#,
        ),
    ];
    let (off, _) = bundle("off", &off);
    assert!(!off.contains("zenoh-shm"), "{off:?}");

    // A ROS 2 node's part keeps it: its peers on the same computer may share memory.
    let out = dir.join("ros2");
    let (code, _, err) = ferroc(&[
        "bundle",
        "models/ros2_crash_course.xml",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let workspace = std::fs::read_to_string(out.join("Cargo.toml")).unwrap();
    // …and a ROS 2 node gets transient-local topics (zenoh-ext), which no other does.
    assert!(crates_of(&out.join("Cargo.toml")).contains("zenoh-ext"));
    assert!(
        workspace.contains(
            "default-features = false, features = [\"shared-memory\", \"ros2-durability\"] }"
        ),
        "{workspace}"
    );
}
