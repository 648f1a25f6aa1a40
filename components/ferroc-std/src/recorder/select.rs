//! Which outputs `--record` records and which recorder records each: shared by
//! `ferroc run` (which adds the recorders to its plan) and generated programs (which
//! add them to their builder), so both record the same channels.

use ferroc_runtime::module::ValueTable;

/// The model name of the recorder type (registered only for recording runs).
pub const RECORDER_TYPE: &str = "ferroc_std.Recorder";

/// What `--record` may record: an output of a module, or an input subscribed from a
/// ROS 2 topic (its values are what the node receives).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Candidate<'a> {
    /// The module's path and the port (`out/0` for numbered ports).
    pub module: &'a str,
    pub port: &'a str,
    /// The port's model type; empty when it is unknown.
    pub model_type: &'a str,
    /// The thread container running the module.
    pub thread: &'a str,
    /// For an input subscribed from a ROS 2 topic: the end's number (`Ros2Topic::id`),
    /// whose receiving end feeds the input and the recorder.
    pub subscribed: Option<u32>,
}

impl<'a> From<(&'a str, &'a str, &'a str, &'a str)> for Candidate<'a> {
    /// An output: `(module, port, model type, thread)`.
    fn from((module, port, model_type, thread): (&'a str, &'a str, &'a str, &'a str)) -> Self {
        Candidate {
            module,
            port,
            model_type,
            thread,
            subscribed: None,
        }
    }
}

/// One port a recorder records.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RecordedPort {
    /// What the recorder's input is connected to: the writing module's path and its
    /// output port (`in/0` for numbered ports), or for a subscribed input the
    /// receiving end of its topic (`ferroc_runtime::link::ros2::subscriber_end`) and
    /// `out`.
    pub module: String,
    pub port: String,
    /// The recorded port's path (`module/port`): the channel's topic and the
    /// recorder's input.
    pub topic: String,
    /// The output's model type.
    pub model_type: String,
}

/// The recorder at the end of one thread container.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RecorderPlan {
    /// Its module path: `ferroc-record/` and the container's path.
    pub path: String,
    /// The thread container it runs in, last.
    pub thread: String,
    pub ports: Vec<RecordedPort>,
}

/// The recorders for `outputs` — every output that feeds a connection or is published
/// as a ROS 2 topic, and every input subscribed from one ([`Candidate`]) —
/// keeping those matching one of `filters` (all when there is none), each port once.
/// Ports whose type has no encoding in `values` are left out and named on stderr.
/// An error when nothing is left to record.
pub fn select<'a, C: Into<Candidate<'a>>>(
    values: &ValueTable,
    outputs: impl IntoIterator<Item = C>,
    filters: &[String],
) -> Result<Vec<RecorderPlan>, String> {
    let mut recorders: Vec<RecorderPlan> = Vec::new();
    let mut skipped = Vec::new();
    for candidate in outputs {
        let Candidate {
            module,
            port,
            model_type,
            thread,
            subscribed,
        } = candidate.into();
        let topic = format!("{module}/{port}");
        if !filters.is_empty() && !filters.iter().any(|f| glob(f, &topic)) {
            continue;
        }
        let seen = |r: &RecorderPlan| r.ports.iter().any(|p| p.topic == topic);
        if recorders.iter().any(seen) || skipped.iter().any(|s: &String| s.starts_with(&topic)) {
            continue;
        }
        if model_type.is_empty() {
            skipped.push(format!("{topic} (type unknown)"));
            continue;
        }
        if values.get(model_type).and_then(|v| v.wire()).is_none() {
            skipped.push(format!("{topic} ({model_type} has no serde)"));
            continue;
        }
        let (module, port) = match subscribed {
            Some(id) => (ferroc_runtime::link::ros2::subscriber_end(id), "out"),
            None => (module.to_owned(), port),
        };
        let port = RecordedPort {
            module,
            port: port.to_owned(),
            topic,
            model_type: model_type.to_owned(),
        };
        match recorders.iter_mut().find(|r| r.thread == thread) {
            Some(r) => r.ports.push(port),
            None => recorders.push(RecorderPlan {
                path: format!("ferroc-record/{thread}"),
                thread: thread.to_owned(),
                ports: vec![port],
            }),
        }
    }
    if !skipped.is_empty() {
        eprintln!(
            "note: --record leaves out {} output(s) whose values cannot be encoded: {}",
            skipped.len(),
            skipped.join(", ")
        );
    }
    if recorders.is_empty() {
        return Err(format!(
            "no connection between modules{} can be recorded",
            if filters.is_empty() {
                ""
            } else {
                " matches --record-filter"
            }
        ));
    }
    Ok(recorders)
}

/// Whether `text` matches `pattern`, where `*` stands for any characters.
pub fn glob(pattern: &str, text: &str) -> bool {
    let mut parts = pattern.split('*');
    let first = parts.next().unwrap_or("");
    let Some(mut rest) = text.strip_prefix(first) else {
        return false;
    };
    let parts: Vec<&str> = parts.collect();
    let Some((last, middle)) = parts.split_last() else {
        return rest.is_empty();
    };
    for part in middle {
        match rest.find(part) {
            Some(at) => rest = &rest[at + part.len()..],
            None => return false,
        }
    }
    rest.len() >= last.len() && rest.ends_with(last)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn globs_match_whole_topics() {
        assert!(glob("robot/*", "robot/laser/scan"));
        assert!(glob("*scan", "robot/laser/scan"));
        assert!(glob("robot/*/scan", "robot/laser/scan"));
        assert!(glob("robot/laser/scan", "robot/laser/scan"));
        assert!(!glob("robot/laser", "robot/laser/scan"));
        assert!(!glob("*/pose", "robot/laser/scan"));
        assert!(!glob("a*a", "a"), "the two `a`s may not overlap");
    }

    #[test]
    fn one_recorder_per_container_each_output_once_encodable_only() {
        let values = ValueTable::default();
        let outputs = [
            ("r/a", "out/0", "f64", "r/main"),
            ("r/a", "out/0", "f64", "r/main"), // a second connection from it
            ("r/b", "pose", "lib.Pose", "r/main"),
            ("r/c", "x", "", "r/slow"),
            ("r/d", "y", "i32", "r/slow"),
        ];
        let plans = select(&values, outputs, &[]).unwrap();
        assert_eq!(plans.len(), 2);
        assert_eq!(plans[0].path, "ferroc-record/r/main");
        let topics = |p: &RecorderPlan| p.ports.iter().map(|p| p.topic.clone()).collect::<Vec<_>>();
        assert_eq!(topics(&plans[0]), ["r/a/out/0"]);
        assert_eq!(
            (
                plans[0].ports[0].module.as_str(),
                plans[0].ports[0].port.as_str()
            ),
            ("r/a", "out/0"),
            "a numbered output keeps its module apart from its port"
        );
        assert_eq!(topics(&plans[1]), ["r/d/y"]);
        let filtered = select(&values, outputs, &["*/y".into()]).unwrap();
        assert_eq!(filtered.len(), 1);
        let none = select(&values, outputs, &["nothing*".into()]).unwrap_err();
        assert!(none.contains("matches --record-filter"), "{none}");
    }

    #[test]
    fn a_subscribed_input_is_recorded_from_its_topic_s_receiving_end_under_its_own_path() {
        let values = ValueTable::default();
        let enable = Candidate {
            subscribed: Some(3),
            ..Candidate::from(("r/control", "enable", "bool", "r/main"))
        };
        let outputs = [enable, Candidate::from(("r/a", "out", "f64", "r/main"))];
        let plans = select(&values, outputs, &["r/control/*".into()]).unwrap();
        let port = &plans[0].ports[..];
        assert_eq!(port.len(), 1, "the filter matches the input's path");
        assert_eq!(
            (port[0].module.as_str(), port[0].port.as_str()),
            (
                ferroc_runtime::link::ros2::subscriber_end(3).as_str(),
                "out"
            )
        );
        assert_eq!(port[0].topic, "r/control/enable");
        assert_eq!(plans[0].thread, "r/main");
        // An output is connected to itself.
        let plans = select(&values, outputs, &["r/a/*".into()]).unwrap();
        assert_eq!(plans[0].ports[0].module, "r/a");
    }
}
