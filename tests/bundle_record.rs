//! `--record` in a bundle's program: the same recording `ferroc run --record` makes
//! (lockstep: the same channels, log times and bytes), read by the Python `mcap` package
//! too; `--record-filter`; bad arguments are refused with exit code 2.

mod common;
use common::{build_bundle, bundle_ok, ferroc, python, tempdir};
use ferroc_std::recording::Recording;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

/// Every exact channel's (log time, bytes) messages, by topic.
fn exact(file: &Path) -> BTreeMap<String, Vec<(u64, Vec<u8>)>> {
    let rec = Recording::read(file).unwrap();
    let mut out = BTreeMap::new();
    for c in rec
        .channels
        .values()
        .filter(|c| c.message_encoding == "postcard")
    {
        let messages = (rec.messages.iter())
            .filter(|m| m.channel == c.id)
            .map(|m| (m.log_time, m.data.clone()))
            .collect();
        out.insert(c.topic.clone(), messages);
    }
    out
}

#[test]
fn a_bundled_program_records_what_ferroc_run_records() {
    let dir = tempdir("bundle_record");
    let out = dir.join("b");
    bundle_ok(Path::new("models/crash_course.xml"), &out);
    let program = build_bundle(&out).join("debug/crash_course-fragile_bot");
    let run = |args: &[&str]| {
        let o = Command::new(&program)
            .args(["--cycles", "50", "--lockstep", "-q"])
            .args(args)
            .current_dir(&dir)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        (o.status.code(), err)
    };
    // A relative path: below the program's working directory.
    let (code, bundle_err) = run(&["--record", "bundle.mcap"]);
    assert_eq!(code, Some(0), "{bundle_err}");
    let bundled = exact(&dir.join("bundle.mcap"));
    let file = dir.join("run.mcap");
    let (code, _, err) = ferroc(&[
        "run",
        "models/crash_course.xml",
        "--cycles",
        "50",
        "--lockstep",
        "-q",
        "--record",
        file.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let ran = exact(&file);
    assert!(ran.contains_key("fragile_bot/main/control/controller/velocity"));
    for (topic, messages) in &bundled {
        assert_eq!(messages.len(), 50, "{topic}");
        assert_eq!(ran.get(topic), Some(messages), "{topic}");
    }
    // The same channels, the pose's too: the bundle registers the recorded library
    // types declared serde="true" (crash_course.Pose2D) with their serde form, as the
    // crash-course crate's `register` does for `ferroc run`. Before, the bundle left the
    // pose out ("crash_course.Pose2D has no serde"). (The last collision pose is
    // published at a collision only: in 50 cycles neither file has its channel.)
    let only_run: Vec<&String> = ran.keys().filter(|t| !bundled.contains_key(*t)).collect();
    assert!(only_run.is_empty(), "{only_run:?}\n{bundle_err}");
    assert_eq!(bundled.len(), ran.len());
    assert!(
        bundled.contains_key("fragile_bot/main/simulation/main_simulation/pose"),
        "{bundle_err}"
    );
    assert!(!bundle_err.contains("--record leaves out"), "{bundle_err}");

    // Only what matches the filter.
    let (code, err) = run(&["--record", "some.mcap", "--record-filter", "*/velocity"]);
    assert_eq!(code, Some(0), "{err}");
    let some = exact(&dir.join("some.mcap"));
    assert_eq!(
        some.keys().collect::<Vec<_>>(),
        ["fragile_bot/main/control/controller/velocity"]
    );

    // Bad arguments: exit 2 with a message, nothing run.
    let (code, err) = run(&["--record-filter", "*"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("--record-filter needs --record FILE"), "{err}");
    let (code, err) = run(&["--record", "x.mcap", "--record-filter", "nothing/*"]);
    assert_eq!(code, Some(2));
    assert!(
        err.contains("no connection between modules matches --record-filter"),
        "{err}"
    );
    let (code, err) = run(&["--record", "../up.mcap"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("climbs out of a folder"), "{err}");

    let Some(python) = python() else { return };
    let script = r#"
import json, sys
from mcap.reader import make_reader
with open(sys.argv[1], "rb") as f:
    summary = make_reader(f).get_summary()
    out = {}
    for c in summary.channels.values():
        s = summary.schemas[c.schema_id]
        out[c.topic + " " + c.message_encoding] = [s.name, c.metadata["ferroc.part"],
            c.metadata["ferroc.unit"], summary.statistics.channel_message_counts[c.id]]
print(json.dumps(out))
"#;
    let o = Command::new(&python)
        .args(["-c", script])
        .arg(dir.join("bundle.mcap"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let channels = v.as_object().unwrap();
    assert_eq!(channels.len(), 2 * bundled.len(), "{v}");
    let velocity = "fragile_bot/main/control/controller/velocity";
    for encoding in ["postcard", "json"] {
        assert_eq!(
            v[format!("{velocity} {encoding}")],
            serde_json::json!(["f64", "fragile_bot", "m/s", 50]),
            "{v}"
        );
    }
}
