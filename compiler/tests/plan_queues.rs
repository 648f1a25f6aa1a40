//! The run executes the queue policy the checks judged: a `queue` without `on-full`
//! is `drop-oldest` (the language's default) to both. Before, the plan made it `block`
//! while the deadlock analysis read it as dropping, so a model the checks passed hung
//! `ferroc run` after one cycle.

use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::plan::plan;

/// A queued input in the container of its writer, read by a module that never pops.
fn model(on_full: &str) -> String {
    format!(
        r#"<application name="q" version="1">
  <use library="ferroc_std"/>
  <part name="p">
    <thread name="t" period="10ms">
      <module name="c" type="ferroc_std.Constant"/>
      <module name="s" type="ferroc_std.Scale"/>
    </thread>
    <connect from="t/c/value" to="t/s/input" queue="1"{on_full}/>
  </part>
</application>
"#
    )
}

/// (codes of the findings, the planned queue of p/t/s).
fn check(name: &str, on_full: &str) -> (Vec<String>, Vec<(String, u32, String)>) {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("plan_queues");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, model(on_full)).unwrap();
    let options = Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    };
    let result = ferroc_compiler::check_model(&path, &options, &Default::default()).unwrap();
    let codes = result
        .diagnostics
        .iter()
        .map(|d| d.check.code.to_string())
        .filter(|c| c.starts_with('D'))
        .collect();
    let app = result.app.as_ref().expect("an application");
    let (plan, _) = plan(app, &result.libraries, &[]);
    let queues = plan
        .modules
        .iter()
        .find(|m| m.path == "p/t/s")
        .unwrap()
        .queues
        .clone();
    (codes, queues)
}

#[test]
fn a_queue_without_on_full_drops_the_oldest_in_the_checks_and_in_the_plan() {
    let (codes, queues) = check("default.xml", "");
    assert!(codes.is_empty(), "no deadlock to report: {codes:?}");
    assert_eq!(
        queues,
        [("input".to_string(), 1, "drop-oldest".to_string())]
    );
}

#[test]
fn an_explicit_block_is_planned_as_block_and_judged_as_blocking() {
    let (codes, queues) = check("block.xml", r#" on-full="block""#);
    assert!(!codes.is_empty(), "the analysis sees the blocking write");
    assert_eq!(queues, [("input".to_string(), 1, "block".to_string())]);
}
