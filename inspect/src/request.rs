//! The inspection keys (docs/inspect.md), built by the client and read by the server.
//!
//! `ferroc/APP/inspect/PART/WHAT`, where `WHAT` is one of `tree`, `containers`,
//! `links`, `activities`, `transport`, `value/MODULE/PATH/PORT`,
//! `param/MODULE/PATH/NAME`, `edit` or `model`. `APP`
//! and `PART` may be `*` (every application, every part); `WHAT` is always literal.

use serde::{Deserialize, Serialize};

/// What a query asks for.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum What {
    /// The element tree of the part.
    Tree,
    /// The thread containers' figures.
    Containers,
    /// The state of inputs fed by links from other parts.
    Links,
    /// The iB2C behaviours' activities and target ratings.
    Activities,
    /// How the values of the links the part sends travel (shared memory or network),
    /// and its shared-memory pool.
    Transport,
    /// A port's latest value (`MODULE/PATH/PORT`).
    Value(String),
    /// A parameter (`MODULE/PATH/NAME`); with a [`SetRequest`] payload, a change.
    Param(String),
    /// A structural edit of the model ([`EditRequest`] payload), checked by the
    /// compiler before it is applied.
    Edit,
    /// The model as it runs now (edits and parameter changes written in).
    Model,
}

impl What {
    /// The key's tail for this request.
    pub fn tail(&self) -> String {
        match self {
            What::Tree => "tree".into(),
            What::Containers => "containers".into(),
            What::Links => "links".into(),
            What::Activities => "activities".into(),
            What::Transport => "transport".into(),
            What::Value(p) => format!("value/{p}"),
            What::Param(p) => format!("param/{p}"),
            What::Edit => "edit".into(),
            What::Model => "model".into(),
        }
    }
}

/// The key of `what` for the part `part` of `app` (either may be `*`).
pub fn key(app: &str, part: &str, what: &What) -> String {
    format!("ferroc/{app}/inspect/{part}/{}", what.tail())
}

/// A query's key, read: the application and part it names (either may be `*`) and
/// what it asks, or why that is malformed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Parsed {
    /// The application, or `*`.
    pub app: String,
    /// The part, or `*`.
    pub part: String,
    /// What is asked, or why the request is malformed.
    pub what: Result<What, String>,
}

/// Reads a query's key; `None` for a key that is not `ferroc/APP/inspect/PART/…` (some
/// other query that happened to match: the server stays silent).
pub fn parse(key: &str) -> Option<Parsed> {
    let mut chunks = key.splitn(5, '/');
    let (Some("ferroc"), Some(app), Some("inspect"), Some(part)) =
        (chunks.next(), chunks.next(), chunks.next(), chunks.next())
    else {
        return None;
    };
    let tail = chunks.next().unwrap_or("");
    Some(Parsed {
        app: app.to_owned(),
        part: part.to_owned(),
        what: what(key, tail),
    })
}

fn what(key: &str, tail: &str) -> Result<What, String> {
    if tail.split('/').any(|c| c.contains(['*', '$', '?', '#'])) {
        return Err(format!(
            "`{key}`: write the request without wildcards after the part (tree, containers, links, activities, value/MODULE/PORT, param/MODULE/NAME)"
        ));
    }
    Ok(match tail.split_once('/') {
        None => match tail {
            "tree" => What::Tree,
            "containers" => What::Containers,
            "links" => What::Links,
            "activities" => What::Activities,
            "transport" => What::Transport,
            "edit" => What::Edit,
            "model" => What::Model,
            other => return Err(unknown(other)),
        },
        Some(("value", path)) if !path.is_empty() => What::Value(path.to_owned()),
        Some(("param", path)) if !path.is_empty() => What::Param(path.to_owned()),
        Some((other, _)) => return Err(unknown(other)),
    })
}

fn unknown(what: &str) -> String {
    format!(
        "`{what}` is not an inspection request; ask for tree, containers, links, activities, transport, value/MODULE/PORT, param/MODULE/NAME, edit or model"
    )
}

/// The payload of a parameter change.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SetRequest {
    /// The new value as a model writes it, with a unit if the parameter has one
    /// (`0.3 m/s`, `45 cm`, `right`, `2s`).
    pub set: String,
    /// The token the program printed at start.
    pub token: String,
}

/// The payload of a structural edit (docs/inspect.md, "Structural edits").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EditRequest {
    /// The token the program printed at start.
    pub token: String,
    /// The operations, a JSON list (`[{"op": "add", …}, …]`).
    pub ops: serde_json::Value,
}

/// The payload of an error answer.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ErrorReply {
    /// What went wrong, in plain words.
    pub error: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_round_trip() {
        for what in [
            What::Tree,
            What::Containers,
            What::Links,
            What::Activities,
            What::Transport,
            What::Value("robot/control/avoid/activity".into()),
            What::Param("robot/control/avoid/min_activity".into()),
            What::Edit,
            What::Model,
        ] {
            let k = key("nav", "robot", &what);
            let r = parse(&k).unwrap();
            assert_eq!(
                (r.app.as_str(), r.part.as_str(), r.what),
                ("nav", "robot", Ok(what))
            );
        }
        let r = parse("ferroc/*/inspect/*/tree").unwrap();
        assert_eq!((r.app.as_str(), r.part.as_str()), ("*", "*"));
    }

    #[test]
    fn other_keys_are_ignored_and_malformed_requests_are_errors() {
        assert_eq!(parse("ferroc/nav/data/robot/x"), None);
        assert_eq!(parse("something/else"), None);
        assert_eq!(parse(""), None);
        for bad in [
            "ferroc/nav/inspect/robot/",
            "ferroc/nav/inspect/robot",
            "ferroc/nav/inspect/robot/trees",
            "ferroc/nav/inspect/robot/**",
            "ferroc/nav/inspect/robot/value/robot/*/x",
            "ferroc/nav/inspect/robot/reboot/now",
            "ferroc/nav/inspect/robot/value/",
        ] {
            let e = parse(bad).unwrap().what.unwrap_err();
            assert!(e.contains("tree, containers"), "{bad}: {e}");
        }
    }

    #[test]
    fn a_set_request_has_exactly_its_fields() {
        let ok: SetRequest = serde_json::from_str(r#"{"set":"1 m","token":"t"}"#).unwrap();
        assert_eq!(ok.set, "1 m");
        assert!(serde_json::from_str::<SetRequest>(r#"{"set":"1"}"#).is_err());
        assert!(serde_json::from_str::<SetRequest>(r#"{"set":"1","token":"t","x":1}"#).is_err());
    }

    proptest::proptest! {
        /// Any key parses or is refused with a message; an inspection key's request
        /// either round-trips or is an error naming the requests there are.
        #[test]
        fn no_key_panics(tail in "[a-z/*$?#]{0,40}", other in "\\PC{0,60}") {
            let _ = parse(&other);
            if let Some(p) = parse(&format!("ferroc/app/inspect/robot/{tail}")) {
                match p.what {
                    Ok(w) => proptest::prop_assert_eq!(w.tail(), tail),
                    Err(e) => proptest::prop_assert!(e.contains("tree, containers"), "{}", e),
                }
            }
        }
    }
}
