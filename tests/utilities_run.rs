//! The flexible utilities together, as a model run by `ferroc run --lockstep`: three
//! distances (Const, metres) into one millimetre vector (Filter: scaled and cast), an
//! offset added element by element (Add), a FlexiSelect between the sum and the raw
//! vector, printed through Dump.

mod common;
use common::{ferroc, tempdir};

const MODEL: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<application name="utilities" version="1">
  <use library="ferroc_std"/>
  <part name="robot" host="localhost">
    <thread name="main" period="100ms">
      <module name="ranges" type="ferroc_std.Const">
        <port name="out" dir="out" type="f64" unit="m" count="3"/>
        <param name="values">[0.2994, 1.5, -2.0]</param>
      </module>
      <module name="to_mm" type="ferroc_std.Filter">
        <port name="in" dir="in" type="f64" unit="m" count="3"/>
        <port name="out" dir="out" type="i32[3]" unit="mm"/>
        <param name="map">in/0 -> out[0] * 1000 as i32; in/1 -> out[1] * 1000 as i32; in/2 -> out[2] * 1000 as i32</param>
      </module>
      <module name="offset" type="ferroc_std.Const">
        <port name="out" dir="out" type="i32[3]" unit="mm" count="1"/>
        <param name="values">[[10, 20, 30]]</param>
        <param name="publish">once</param>
      </module>
      <module name="add" type="ferroc_std.Add">
        <port name="in" dir="in" type="i32[3]" unit="mm" count="2"/>
      </module>
      <module name="pick" type="ferroc_std.FlexiSelect">
        <port name="in" dir="in" type="i32[3]" unit="mm" count="2"/>
      </module>
      <module name="show" type="ferroc_std.Dump">
        <port name="in" dir="in" type="i32[3]" unit="mm" count="1"/>
        <param name="label">mm</param>
      </module>
      <connect from="ranges/out/0" to="to_mm/in/0"/>
      <connect from="ranges/out/1" to="to_mm/in/1"/>
      <connect from="ranges/out/2" to="to_mm/in/2"/>
      <connect from="to_mm/out" to="add/in/0"/>
      <connect from="offset/out/0" to="add/in/1"/>
      <connect from="add/out" to="pick/in/0"/>
      <connect from="to_mm/out" to="pick/in/1"/>
      <connect from="pick/out" to="show/in/0"/>
    </thread>
  </part>
</application>
"#;

#[test]
fn filter_const_add_and_select_print_the_expected_values() {
    let dir = tempdir("utilities_run");
    let model = dir.join("utilities.xml");
    std::fs::write(&model, MODEL).unwrap();
    let (code, out, err) = ferroc(&[
        "run",
        model.to_str().unwrap(),
        "--lockstep",
        "--cycles",
        "3",
        "-q",
    ]);
    assert_eq!(code, 0, "{out}\n{err}");
    // 0.2994 m → 299.4 mm → 299 (rounded), + 10; 1500 + 20; -2000 + 30. The offset is
    // published once and kept (latest value), so every cycle prints the same sum.
    let lines: Vec<&str> = out.lines().filter(|l| l.starts_with("mm:")).collect();
    assert_eq!(lines, ["mm: in/0 = [309, 1520, -1970]"; 3], "{out}");
}

#[test]
fn a_filter_map_that_does_not_fit_stops_the_check() {
    let dir = tempdir("utilities_bad_map");
    let model = dir.join("utilities.xml");
    std::fs::write(
        &model,
        MODEL.replace("out[2] * 1000 as i32", "out[3] * 1000 as i32"),
    )
    .unwrap();
    let (code, _, err) = ferroc(&["check", model.to_str().unwrap(), "--format", "short"]);
    assert_eq!(code, 1, "{err}");
    let (_, out, _) = ferroc(&["check", model.to_str().unwrap(), "--format", "short"]);
    let all = format!("{out}{err}");
    assert!(
        all.contains("error[P108]: index 3 is out of range: `out` (`i32[3]`) has 3 elements"),
        "{all}"
    );
}
