//! The plan marks connections whose writer and reader run in one thread container:
//! the runtime keeps their values in a cell only that container's thread touches.
//! Connections across containers, across parts, and through group ports into another
//! container stay unmarked.

use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::plan::plan;

const MODEL: &str = r#"<application name="l" version="1">
  <use library="ferroc_std"/>
  <part name="p">
    <thread name="fast" period="10ms">
      <module name="c" type="ferroc_std.Constant"/>
      <module name="s" type="ferroc_std.Scale"/>
      <connect from="c/value" to="s/input"/>
    </thread>
    <thread name="slow" period="100ms">
      <module name="s2" type="ferroc_std.Scale"/>
    </thread>
    <connect from="fast/s/output" to="slow/s2/input"/>
  </part>
  <part name="q">
    <thread name="t" period="10ms">
      <module name="s3" type="ferroc_std.Scale"/>
    </thread>
  </part>
  <connect from="p/fast/c/value" to="q/t/s3/input"/>
</application>
"#;

#[test]
fn only_connections_inside_one_container_are_marked_local() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("plan_local");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("model.xml");
    std::fs::write(&path, MODEL).unwrap();
    let options = Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    };
    let result = ferroc_compiler::check_model(&path, &options, &Default::default()).unwrap();
    let app = result.app.as_ref().expect("an application");
    let (plan, unsupported) = plan(app, &result.libraries, &[]);
    assert!(unsupported.is_empty());
    let mut marks: Vec<(String, String, bool)> = (plan.connections.iter())
        .map(|c| (c.from.0.clone(), c.to.0.clone(), c.local))
        .collect();
    marks.sort();
    assert_eq!(
        marks,
        [
            ("p/fast/c".into(), "p/fast/s".into(), true),
            ("p/fast/c".into(), "q/t/s3".into(), false),
            ("p/fast/s".into(), "p/slow/s2".into(), false),
        ]
    );
}
