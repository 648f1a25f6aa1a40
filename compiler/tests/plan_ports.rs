//! The plan carries each flexible instance's `<port>` declarations: group, direction,
//! model type, count, unit and (for library types) the library and Rust path.

use ferroc_compiler::library::PortDir;
use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::plan::{plan, PlannedPortGroup};

const MODEL: &str = r#"<application name="a" version="1">
  <use library="ferroc_std"/>
  <use library="crash_course" manifest="MANIFEST"/>
  <part name="p">
    <thread name="t" period="10ms">
      <module name="sum" type="ferroc_std.Sum">
        <port name="in" dir="in" type="u32" count="3"/>
      </module>
      <module name="one" type="ferroc_std.Dump">
        <port name="in" dir="in" type="f64" unit="mm/s"/>
      </module>
      <module name="poses" type="ferroc_std.Dump">
        <port name="in" dir="in" type="crash_course.Pose2D" count="2"/>
      </module>
      <module name="c" type="ferroc_std.Constant"/>
    </thread>
  </part>
</application>
"#;

fn group(name: &str, ty: &str, count: Option<u32>) -> PlannedPortGroup {
    PlannedPortGroup {
        name: name.into(),
        dir: PortDir::In,
        ty: ty.into(),
        count,
        unit: None,
        library: None,
        rust: None,
        serde: false,
    }
}

#[test]
fn flexible_instances_plan_their_port_groups() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("plan_ports");
    std::fs::create_dir_all(&dir).unwrap();
    let manifest = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../components/crash_course.lib.xml")
        .canonicalize()
        .unwrap();
    let model = dir.join("m.xml");
    std::fs::write(
        &model,
        MODEL.replace("MANIFEST", manifest.to_str().unwrap()),
    )
    .unwrap();
    let options = Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    };
    let result =
        ferroc_compiler::check_model(&model, &options, &Default::default()).expect("checks");
    let app = result.app.as_ref().expect("an application");
    let (plan, unsupported) = plan(app, &result.libraries, &[]);
    assert!(unsupported.is_empty());
    let ports = |path: &str| {
        plan.modules
            .iter()
            .find(|m| m.path == path)
            .map(|m| m.ports.clone())
            .unwrap()
    };
    assert_eq!(ports("p/t/sum"), [group("in", "u32", Some(3))]);
    assert_eq!(
        ports("p/t/one"),
        [PlannedPortGroup {
            unit: Some("mm/s".into()),
            ..group("in", "f64", None)
        }]
    );
    assert_eq!(
        ports("p/t/poses"),
        [PlannedPortGroup {
            library: Some("crash_course".into()),
            rust: Some("crash_course::Pose2D".into()),
            serde: true, // declared serde="true": a bundle registers it with serde
            ..group("in", "crash_course.Pose2D", Some(2))
        }]
    );
    assert!(ports("p/t/c").is_empty());
}
