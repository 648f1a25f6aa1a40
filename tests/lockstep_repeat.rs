//! The promise of lockstep (issue 34): every example model in `models/` run twice in
//! lockstep with the same seed prints the same output and writes byte-identical
//! recordings (`--record` and the models' own loggers); run with another seed, a model
//! whose noise takes the run's random source differs. And what would break the
//! promise is said: X106 before the run for a module that seeds from the clock.
//!
//! Short runs (`--for 2s` of model time); the runners of the libraries are built once
//! and shared with the other tests.

mod common;

use common::tempdir;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One lockstep run's output: standard output, then every file it wrote (by name
/// relative to its folder) with its bytes.
struct Run {
    stdout: String,
    files: BTreeMap<String, Vec<u8>>,
}

/// `ferroc run MODEL --lockstep --for 2s --seed SEED --record DIR/record.mcap` with
/// the log folder `DIR` (a fresh one; `inputs` are copied into `DIR/logs` first: the
/// recording a replay model reads).
fn run(model: &Path, dir: &str, seed: &str, inputs: &[(&str, &[u8])]) -> Run {
    let dir = tempdir(dir);
    let logs = dir.join("logs");
    for (name, bytes) in inputs {
        let file = logs.join(name);
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        std::fs::write(file, bytes).unwrap();
    }
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .arg("run")
        .arg(model)
        .args([
            "--lockstep",
            "--for",
            "2s",
            "-q",
            "--seed",
            seed,
            "--record",
        ])
        .arg(dir.join("record.mcap"))
        .env("FERROC_LOG_DIR", &dir)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("ferroc runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "{}: exit {:?}\n{stderr}",
        model.display(),
        out.status.code()
    );
    let mut files = BTreeMap::new();
    collect(&dir, &dir, &mut files);
    for (name, _) in inputs {
        files.remove(&format!("logs/{name}"));
    }
    Run {
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        files,
    }
}

fn collect(root: &Path, dir: &Path, files: &mut BTreeMap<String, Vec<u8>>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            collect(root, &path, files);
        } else {
            let name = path.strip_prefix(root).unwrap().display().to_string();
            files.insert(name, std::fs::read(&path).unwrap());
        }
    }
}

fn models() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    let mut models: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "xml"))
        .collect();
    models.sort();
    models
}

/// `name (N bytes)` for each file: what a failure shows.
fn sizes(run: &Run) -> Vec<String> {
    (run.files.iter())
        .map(|(n, b)| format!("{n} ({} bytes)", b.len()))
        .collect()
}

#[test]
fn every_example_model_runs_the_same_twice_with_one_seed() {
    let models = models();
    assert!(models.len() >= 6, "{models:?}");
    // The replay model reads what the logged one recorded.
    let logged = models
        .iter()
        .find(|m| m.ends_with("crash_course_logged.xml"))
        .expect("models/crash_course_logged.xml");
    let recorded = run(logged, "repeat_logged_input", "7", &[]);
    let recording = recorded.files["logs/crash_course.mcap"].clone();
    for model in &models {
        let name = model.file_stem().unwrap().to_string_lossy().into_owned();
        let inputs: &[(&str, &[u8])] = if name == "crash_course_replay" {
            &[("crash_course.mcap", &recording)]
        } else {
            &[]
        };
        let first = run(model, &format!("repeat_{name}_1"), "7", inputs);
        let second = run(model, &format!("repeat_{name}_2"), "7", inputs);
        assert_eq!(first.stdout, second.stdout, "{name}: the output differs");
        assert_eq!(
            sizes(&first),
            sizes(&second),
            "{name}: other files or sizes"
        );
        for (file, bytes) in &first.files {
            assert!(
                &second.files[file] == bytes,
                "{name}: {file} differs between two runs with --seed 7"
            );
        }
        assert!(
            first.files.contains_key("record.mcap"),
            "{name}: {:?}",
            sizes(&first)
        );
        let seed = "ferroc.run";
        let record = &first.files["record.mcap"];
        assert!(
            record.windows(seed.len()).any(|w| w == seed.as_bytes()),
            "{name}: the recording holds no `ferroc.run` metadata"
        );
    }
}

/// crash_course_logged.xml without its fixed seeds (the model's run seed and the
/// rear noise's own), in a folder of its own with the config file it reads: all of its
/// noise is the run seed's, and the run seed is `--seed`'s or chosen.
fn unseeded_crash_course(dir: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempdir(dir);
    std::fs::create_dir_all(dir.join("etc")).unwrap();
    std::fs::copy(
        root.join("models/etc/crash_course.xml"),
        dir.join("etc/crash_course.xml"),
    )
    .unwrap();
    let manifest = root.join("components/crash_course.lib.xml");
    let text = std::fs::read_to_string(root.join("models/crash_course_logged.xml")).unwrap();
    let text: String = text
        .lines()
        .filter(|l| !l.contains("<param name=\"seed\">"))
        .map(|l| {
            l.replace(
                "../components/crash_course.lib.xml",
                manifest.to_str().unwrap(),
            )
            .replace(" seed=\"1\"", "")
        })
        .map(|l| l + "\n")
        .collect();
    let model = dir.join("unseeded.xml");
    std::fs::write(&model, text).unwrap();
    model
}

#[test]
fn the_run_seed_decides_the_noise_of_a_model_without_fixed_seeds() {
    let model = unseeded_crash_course("repeat_unseeded_model");
    let a = run(&model, "repeat_unseeded_7a", "7", &[]);
    let b = run(&model, "repeat_unseeded_7b", "7", &[]);
    let c = run(&model, "repeat_unseeded_8", "8", &[]);
    let log = "logs/crash_course.mcap";
    assert_eq!(a.files[log], b.files[log], "same seed, same recording");
    assert_eq!(a.files["record.mcap"], b.files["record.mcap"]);
    assert_ne!(a.files[log], c.files[log], "another seed, other noise");
    assert_ne!(a.stdout, "", "the demo prints its poses");
}

#[test]
fn without_a_seed_one_is_chosen_and_printed_and_runs_differ() {
    let model = unseeded_crash_course("repeat_unseeded_model_random");
    let runs: Vec<(String, Vec<u8>)> = (0..2)
        .map(|i| {
            let dir = tempdir(&format!("repeat_unseeded_random_{i}"));
            let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
                .arg("run")
                .arg(&model)
                .args(["--lockstep", "--for", "1s", "-q"])
                .env("FERROC_LOG_DIR", &dir)
                .output()
                .unwrap();
            assert!(out.status.success());
            let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
            let log = std::fs::read(dir.join("logs/crash_course.mcap")).unwrap();
            (stderr, log)
        })
        .collect();
    let seed_of = |stderr: &str| -> String {
        let line = stderr
            .lines()
            .find(|l| l.starts_with("seed: "))
            .unwrap_or_else(|| panic!("no `seed:` line in\n{stderr}"));
        line["seed: ".len()..].split(' ').next().unwrap().to_owned()
    };
    let (first, second) = (seed_of(&runs[0].0), seed_of(&runs[1].0));
    assert_ne!(first, second, "two seeds from the OS");
    assert!(
        runs[0].0.contains(&format!("--seed {first}")),
        "{}",
        runs[0].0
    );
    assert_ne!(runs[0].1, runs[1].1, "other seeds, other noise");
    // Repeating with the printed seed gives the same recording.
    let dir = tempdir("repeat_unseeded_random_again");
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .arg("run")
        .arg(&model)
        .args(["--lockstep", "--for", "1s", "-q", "--seed", &first])
        .env("FERROC_LOG_DIR", &dir)
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(!String::from_utf8_lossy(&out.stderr).contains("seed: "));
    assert_eq!(
        std::fs::read(dir.join("logs/crash_course.mcap")).unwrap(),
        runs[0].1
    );
}

/// What would make a lockstep run differ is said before it runs: `ferroc check
/// --lockstep` reports X106 for a module seeded from the clock and a type marked
/// nondeterministic; without `--lockstep` nothing (a free run differs anyway).
#[test]
fn check_lockstep_reports_modules_that_seed_from_the_clock() {
    let fixture = "compiler/checks/src/deployment/x106_nondeterministic_in_lockstep/fires.xml";
    let (_, out, _) = common::ferroc(&["check", "--lockstep", "--format", "short", fixture]);
    assert_eq!(out.matches("warning[X106]").count(), 3, "{out}");
    assert!(
        out.contains("`robot/main/noise`: `seed` is left at 0"),
        "{out}"
    );
    let (_, free, _) = common::ferroc(&["check", "--format", "short", fixture]);
    assert!(!free.contains("X106"), "{free}");
}
