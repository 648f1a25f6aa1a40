//! A module output driving another module's parameter (`…/param/NAME`), in `ferroc
//! run` and in bundles.

mod common;
use common::{bundle_ok, ferroc, tempdir};

const MODEL: &str = r#"<application name="driven" version="1">
  <use library="ferroc_std"/>
  <part name="p">
    <thread name="t" period="1ms">
      <module name="input" type="ferroc_std.Constant"><param name="value">3</param></module>
      <module name="gain" type="ferroc_std.Constant"><param name="value">4</param></module>
      <module name="scale" type="ferroc_std.Scale"/>
      <module name="show" type="ferroc_std.Dump">
        <port name="in" dir="in" type="f64" count="1"/>
        <param name="label">scaled</param>
      </module>
    </thread>
    <connect from="t/input/value" to="t/scale/input"/>
    <connect from="t/gain/value" to="t/scale/param/factor"/>
    <connect from="t/scale/output" to="t/show/in/0"/>
  </part>
</application>
"#;

#[test]
fn an_output_sets_a_parameter_while_running() {
    let dir = tempdir("param_links_run");
    let path = dir.join("driven.xml");
    std::fs::write(&path, MODEL).unwrap();
    let (code, stdout, stderr) = ferroc(&["run", path.to_str().unwrap(), "--cycles", "3", "-q"]);
    assert_eq!(code, 0, "{stderr}");
    // factor's default is 1: 3 · 4 shows that the gain module's value reached it.
    assert!(stdout.contains("scaled: in/0 = 12"), "{stdout}{stderr}");
    assert!(!stdout.contains("scaled: in/0 = 3\n"), "{stdout}");
}

#[test]
fn bundles_write_the_same_link() {
    let dir = tempdir("param_links_bundle");
    let path = dir.join("driven.xml");
    std::fs::write(&path, MODEL).unwrap();
    let out = dir.join("bundle");
    bundle_ok(&path, &out);
    let main = std::fs::read_to_string(out.join("parts/p/src/main.rs")).unwrap();
    assert!(main.contains("builder.connect_param("), "{main}");
    assert!(main.contains("Conversion::linear(1.0, 0.0),"), "{main}");
}
