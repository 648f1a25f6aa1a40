use ferroc_compiler::diagnostic::Severity;
use ferroc_compiler::edit::*;
use ferroc_compiler::{check_model_text, plan, Policy};

const MODEL: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<!-- a comment that must survive -->
<application name="edited" version="1">
  <use library="ferroc_std"/>
  <part name="robot" host="localhost">
    <thread name="fast" period="5ms">
      <module name="source" type="ferroc_std.Constant">
        <param name="value">4</param>
      </module>
      <module name="scaled" type="ferroc_std.Scale">
        <param name="factor">2</param>
      </module>
      <!-- the data path -->
      <connect from="source/value" to="scaled/input"/>
    </thread>
    <thread name="slow" period="20ms"/>
  </part>
</application>
"#;

fn ops(json: &str) -> Vec<Op> {
    parse_ops(json.as_bytes()).unwrap()
}

fn check(text: &str) -> ferroc_compiler::CheckResult {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("edit_test.xml");
    let options = ferroc_compiler::load::Options {
        builtins: vec![ferroc_compiler::load::BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Default::default()
    };
    check_model_text(
        &path,
        "edit_test.xml (edited)",
        text,
        &options,
        &Policy::default(),
    )
    .unwrap()
}

fn errors(r: &ferroc_compiler::CheckResult) -> Vec<&str> {
    (r.diagnostics.iter())
        .filter(|d| d.severity == Severity::Error)
        .map(|d| d.code())
        .collect()
}

const INSERT_FILTER: &str = r#"[
  {"op": "disconnect", "from": "robot/fast/source/value", "to": "robot/fast/scaled/input"},
  {"op": "add", "module": "robot/fast/filter", "type": "ferroc_std.Filter",
   "ports": [{"name": "in", "dir": "in", "type": "f64", "count": 1},
             {"name": "out", "dir": "out", "type": "f64"}],
   "params": {"map": "in/0 -> out * 3"}},
  {"op": "connect", "from": "robot/fast/source/value", "to": "robot/fast/filter/in/0"},
  {"op": "connect", "from": "robot/fast/filter/out", "to": "robot/fast/scaled/input"}
]"#;

#[test]
fn inserting_a_filter_keeps_comments_and_layout_and_checks_clean() {
    assert!(errors(&check(MODEL)).is_empty());
    let edited = apply(MODEL, &ops(INSERT_FILTER)).unwrap();
    let t = &edited.text;
    assert!(t.contains("<!-- a comment that must survive -->"), "{t}");
    assert!(t.contains("<!-- the data path -->"), "{t}");
    assert!(
        !t.contains(r#"<connect from="source/value" to="scaled/input"/>"#),
        "{t}"
    );
    assert!(
        t.contains("      <module name=\"filter\" type=\"ferroc_std.Filter\">\n        <port name=\"in\" dir=\"in\" type=\"f64\" count=\"1\"/>"),
        "{t}"
    );
    assert!(
        t.contains("        <param name=\"map\">in/0 -> out * 3</param>\n      </module>"),
        "{t}"
    );
    assert!(
        t.contains("      <connect from=\"filter/out\" to=\"scaled/input\"/>"),
        "{t}"
    );
    let r = check(t);
    assert!(errors(&r).is_empty(), "{:?}", r.diagnostics);
    assert_eq!(edited.done.len(), 4);
}

#[test]
fn removing_a_module_removes_its_connections() {
    let edited = apply(
        MODEL,
        &ops(r#"[{"op": "remove", "module": "robot/fast/scaled"}]"#),
    )
    .unwrap();
    assert!(!edited.text.contains("scaled"), "{}", edited.text);
    assert!(edited.done[0].contains("1 connection"), "{:?}", edited.done);
    assert!(edited.text.contains("<!-- the data path -->"));
}

#[test]
fn a_moved_module_takes_its_connections_along() {
    let edited = apply(
        MODEL,
        &ops(r#"[{"op": "move", "module": "robot/fast/scaled", "to": "robot/slow"}]"#),
    )
    .unwrap();
    let t = &edited.text;
    assert_eq!(
        edited.moved,
        [(
            "robot/fast/scaled".to_string(),
            "robot/slow/scaled".to_string()
        )]
    );
    // The self-closing thread is opened; the connection now lies in the part.
    assert!(
        t.contains(concat!(
            "<thread name=\"slow\" period=\"20ms\">\n",
            "      <module name=\"scaled\" type=\"ferroc_std.Scale\">\n",
            "        <param name=\"factor\">2</param>\n",
            "      </module>\n",
            "    </thread>"
        )),
        "{t}"
    );
    assert!(
        t.contains("<connect from=\"fast/source/value\" to=\"slow/scaled/input\"/>"),
        "{t}"
    );
    let r = check(t);
    assert!(errors(&r).is_empty(), "{:?}", r.diagnostics);
}

#[test]
fn set_writes_a_parameter_value_into_the_model() {
    let edited = apply(
        MODEL,
        &ops(
            r#"[{"op": "set", "param": "robot/fast/scaled/factor", "value": "5"},
                 {"op": "set", "param": "robot/fast/source/value", "value": "1 < 2 & 3"}]"#,
        ),
    )
    .unwrap();
    assert!(
        edited.text.contains("<param name=\"factor\">5</param>"),
        "{}",
        edited.text
    );
    assert!(edited.text.contains("1 &lt; 2 &amp; 3"), "{}", edited.text);
    let added = apply(
        MODEL,
        &ops(r#"[{"op": "set", "param": "robot/fast/scaled/nothing", "value": "1"}]"#),
    )
    .unwrap();
    assert!(
        added.text.contains(
            "<param name=\"factor\">2</param>\n        <param name=\"nothing\">1</param>"
        ),
        "{}",
        added.text
    );
}

/// Issue 27 item 15: a port group's `count` over the runtime's limit was capped silently
/// (`count="4000000000"` checked clean, so the edit was applied); it is an error at the
/// attribute that names the limit, and the editor refuses edits with errors.
#[test]
fn an_edit_with_a_port_count_over_the_limit_is_refused() {
    let add = |count: u64| {
        format!(
            r#"[{{"op": "add", "module": "robot/fast/dump", "type": "ferroc_std.Dump",
                 "ports": [{{"name": "in", "dir": "in", "type": "f64", "count": {count}}}]}}]"#
        )
    };
    let edited = apply(MODEL, &ops(&add(4_000_000_000))).unwrap();
    let r = check(&edited.text);
    let m116: Vec<_> = (r.diagnostics.iter())
        .filter(|d| d.code() == "M116")
        .collect();
    assert_eq!(m116.len(), 1, "{:?}", r.diagnostics);
    assert_eq!(m116[0].severity, Severity::Error);
    assert!(
        m116[0].message.contains("4000000000") && m116[0].message.contains("4096"),
        "{}",
        m116[0].message
    );
    assert_eq!(
        r.sources.text(m116[0].primary.span),
        "4000000000",
        "the finding points at the count"
    );
    // The limit itself is accepted.
    let edited = apply(MODEL, &ops(&add(4096))).unwrap();
    let r = check(&edited.text);
    assert!(!errors(&r).contains(&"M116"), "{:?}", r.diagnostics);
}

#[test]
fn operations_that_cannot_apply_say_which_and_why() {
    let cases = [
        (
            r#"[{"op": "remove", "module": "robot/fast/nope"}]"#,
            "operation 1 (remove): there is no element `robot/fast/nope`",
        ),
        (
            r#"[{"op": "disconnect", "from": "robot/fast/source/value", "to": "robot/fast/x/y"}]"#,
            "no <connect>",
        ),
        (
            r#"[{"op": "connect", "from": "robot/fast/source/value", "to": "robot/fast/scaled/input"}]"#,
            "connected already",
        ),
        (
            r#"[{"op": "add", "module": "robot/fast/source", "type": "ferroc_std.Constant"}]"#,
            "exists already",
        ),
        (
            r#"[{"op": "add", "module": "robot", "type": "ferroc_std.Constant"}]"#,
            "PART/THREAD/NAME",
        ),
        (
            r#"[{"op": "move", "module": "robot/fast/source", "to": "robot/fast"}]"#,
            "already",
        ),
        (
            r#"[{"op": "move", "module": "robot/fast/source", "to": "robot/fast/scaled"}]"#,
            "is a <module>",
        ),
    ];
    for (json, want) in cases {
        let e = apply(MODEL, &ops(json)).unwrap_err();
        assert!(e.contains(want), "{json}: {e}");
    }
}

#[test]
fn malformed_edits_are_refused_with_the_shape_of_an_edit() {
    for bad in [
        "",
        "{}",
        "[]",
        "[{\"op\": \"explode\"}]",
        "[{\"op\": \"remove\"}]",
        "[{\"op\": \"remove\", \"module\": \"a\", \"extra\": 1}]",
        "\"remove\"",
    ] {
        let e = parse_ops(bad.as_bytes()).unwrap_err();
        assert!(e.contains("operations"), "{bad}: {e}");
    }
    assert_eq!(
        ops(r#"{"ops": [{"op": "remove", "module": "a/b/c"}]}"#).len(),
        1
    );
}

#[test]
fn the_plan_diff_names_what_changes() {
    let old_r = check(MODEL);
    let (old, _) = plan::plan(old_r.app.as_ref().unwrap(), &old_r.libraries, &[]);
    let edited = apply(MODEL, &ops(INSERT_FILTER)).unwrap();
    let new_r = check(&edited.text);
    let (new, _) = plan::plan(new_r.app.as_ref().unwrap(), &new_r.libraries, &[]);
    let d = diff::diff(&old, &new, &edited.moved);
    assert!(d.unsupported.is_empty(), "{:?}", d.unsupported);
    assert!(d.removed.is_empty() && d.moved.is_empty() && d.params.is_empty());
    assert_eq!(d.added.len(), 1);
    assert_eq!(new.modules[d.added[0]].path, "robot/fast/filter");
    let ends = |cs: &[ferroc_compiler::plan::PlannedConnection]| -> Vec<String> {
        cs.iter()
            .map(|c| format!("{}/{}>{}/{}", c.from.0, c.from.1, c.to.0, c.to.1))
            .collect()
    };
    assert_eq!(
        ends(&d.disconnect),
        ["robot/fast/source/value>robot/fast/scaled/input"]
    );
    let mut made = ends(&d.connect);
    made.sort();
    assert_eq!(
        made,
        [
            "robot/fast/filter/out>robot/fast/scaled/input",
            "robot/fast/source/value>robot/fast/filter/in/0"
        ]
    );
    assert_eq!(
        d.threads
            .iter()
            .map(|&i| new.threads[i].path.as_str())
            .collect::<Vec<_>>(),
        ["robot/fast"]
    );

    // A move: the same instance in another container, connections unchanged.
    let moved = apply(MODEL, &ops(r#"[{"op": "move", "module": "robot/fast/scaled", "to": "robot/slow"},
                                    {"op": "set", "param": "robot/slow/scaled/factor", "value": "3"}]"#)).unwrap();
    let r = check(&moved.text);
    let (new, _) = plan::plan(r.app.as_ref().unwrap(), &r.libraries, &[]);
    let d = diff::diff(&old, &new, &moved.moved);
    assert!(
        d.unsupported.is_empty() && d.added.is_empty() && d.removed.is_empty(),
        "{d:?}"
    );
    // Its connection now joins two containers: made again (no same-container path
    // may outlive the move).
    assert_eq!(
        ends(&d.disconnect),
        ["robot/fast/source/value>robot/fast/scaled/input"]
    );
    assert_eq!(
        ends(&d.connect),
        ["robot/fast/source/value>robot/slow/scaled/input"]
    );
    assert_eq!(
        d.moved,
        [(
            "robot/fast/scaled".to_string(),
            "robot/slow/scaled".to_string()
        )]
    );
    assert_eq!(
        d.params,
        [(
            "robot/slow/scaled".to_string(),
            "factor".to_string(),
            ferroc_values::values::Value::Float(3.0)
        )]
    );
    assert_eq!(d.threads.len(), 2);
    // Nothing edited: nothing changes.
    assert!(diff::diff(&old, &old, &[]).is_empty());
}

proptest::proptest! {
    /// Any bytes are an edit or an error, and any edit is applied or refused; the
    /// original text is never half-edited.
    #[test]
    fn no_edit_panics(json in "\\PC{0,120}", module in "[a-z/]{0,20}", value in "\\PC{0,20}") {
        let _ = parse_ops(json.as_bytes());
        for op in [
            Op::Remove { module: module.clone() },
            Op::Move { module: module.clone(), to: "robot/slow".into() },
            Op::Set { param: module.clone(), value: value.clone() },
            Op::Connect { from: module.clone(), to: value.clone() },
            Op::Add { module: module.clone(), r#type: value.clone(), params: Default::default(), ports: Vec::new() },
        ] {
            if let Ok(e) = apply(MODEL, std::slice::from_ref(&op)) {
                proptest::prop_assert!(ferroc_syntax::xml::parse(ferroc_diagnostics::source::FileId(0), &e.text, 256).is_ok(), "{}", e.text);
            }
        }
    }
}
