//! `ferroc run` with the flexible `ferroc_std` modules: ports the instance declares
//! (`<port name="in" dir="in" type="u32" count="2"/>`) are created from the model's
//! type, and a type the binary cannot make ports of is a clear build error.

mod common;

use common::{build_bundle, ferroc, tempdir};

const MODEL: &str = "tests/fixtures/flexible_ports.xml";

#[test]
fn sum_flexiselect_and_dump_over_f64_and_u32_instance_ports() {
    let (code, out, err) = ferroc(&["check", MODEL, "--format", "short"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(!out.contains("error["), "{out}");
    let (code, out, err) = ferroc(&["run", MODEL, "--cycles", "4", "-q"]);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    // Every cycle delivers new values, so every cycle prints each input once.
    for expected in ["count: in/0 = 42", "picked: in/0 = 40", "picked: in/1 = 1"] {
        let n = lines.iter().filter(|l| **l == expected).count();
        assert_eq!(n, 4, "`{expected}` {n} times in:\n{out}");
    }
    assert_eq!(lines.len(), 12, "{out}");
    assert!(err.contains("bench/main: 4 cycles"), "{err}");
}

#[test]
fn a_dump_of_an_unregistered_type_is_a_build_error_naming_module_port_and_type() {
    let dir = tempdir("flexible_unregistered");
    std::fs::write(
        dir.join("tiny.lib.xml"),
        r#"<library name="tiny" version="0.1.0" rust-crate="tiny">
  <type name="Blob" rust="tiny::Blob" serde="true"/>
</library>
"#,
    )
    .unwrap();
    let model = dir.join("m.xml");
    std::fs::write(
        &model,
        r#"<application name="a" version="1">
  <use library="ferroc_std"/>
  <use library="tiny" manifest="tiny.lib.xml"/>
  <part name="p">
    <thread name="t" period="10ms">
      <module name="show" type="ferroc_std.Dump">
        <port name="in" dir="in" type="tiny.Blob" count="1"/>
      </module>
    </thread>
  </part>
</application>
"#,
    )
    .unwrap();
    let m = model.to_str().unwrap();
    let (code, out, err) = ferroc(&["check", m, "--format", "short"]);
    assert_eq!(code, 0, "the model itself is fine: {out}{err}");
    let (code, out, err) = ferroc(&["run", m, "--cycles", "1", "-q"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(
        err.contains(
            "error: `p/t/show` could not be created: port `in/0`: the value type `tiny.Blob` \
             is not registered in this binary"
        ),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

/// The bundle of the same model: the instance's port groups and the library value type
/// are written out, the code is formatted and deterministic, builds without warnings
/// and prints what `ferroc run` prints.
#[test]
fn the_bundle_declares_the_port_groups_and_behaves_like_ferroc_run() {
    let dir = tempdir("flexible_bundle");
    let out = dir.join("b");
    let bundle = |to: &std::path::Path| {
        let (code, _, err) = ferroc(&["bundle", MODEL, "-o", to.to_str().unwrap()]);
        assert_eq!(code, 0, "{err}");
        std::fs::read_to_string(to.join("parts/bench/src/main.rs")).unwrap()
    };
    let main = bundle(&out);
    assert_eq!(main, bundle(&dir.join("again")), "not deterministic");
    for expected in [
        "use ferroc_runtime::module::{Direction, PortGroup, Value};",
        "ports: &[PortGroup::new(\"in\", Direction::In, \"u32\", Some(2))],",
        "ports: &[PortGroup::new(\"in\", Direction::In, \"f64\", Some(2))],",
        "registry.register::<ferroc_std::FlexiSelect>();",
        "registry.register_serde::<crash_course::Pose2D>();", // serde="true": Dump prints its serde form
        "ports: &[],",
    ] {
        assert!(main.contains(expected), "`{expected}` missing in:\n{main}");
    }
    // The resolved model keeps the instances' <port> declarations: it checks clean.
    let resolved = out.join("model/flexible_ports.xml");
    let (code, text, err) = ferroc(&["check", resolved.to_str().unwrap(), "--format", "short"]);
    assert_eq!(code, 0, "{text}{err}");
    assert!(!text.contains("error["), "{text}");
    let cargo_toml = std::fs::read_to_string(out.join("parts/bench/Cargo.toml")).unwrap();
    assert!(cargo_toml.contains("crash-course"), "{cargo_toml}");
    if let Ok(o) = std::process::Command::new("rustfmt")
        .args(["--edition", "2021", "--check"])
        .arg(out.join("parts/bench/src/main.rs"))
        .output()
    {
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
    }
    // Build it into this test's target folder (the crates are built already).
    let target = build_bundle(&out);
    let bundled = std::process::Command::new(target.join("debug/flexible_ports-bench"))
        .args(["--cycles", "3", "-q"])
        .output()
        .unwrap();
    assert!(
        bundled.status.success(),
        "{}",
        String::from_utf8_lossy(&bundled.stderr)
    );
    let (code, run_out, run_err) = ferroc(&["run", MODEL, "--cycles", "3", "-q"]);
    assert_eq!(code, 0, "{run_err}");
    assert_eq!(String::from_utf8_lossy(&bundled.stdout), run_out);
    assert!(run_out.contains("count: in/0 = 42"), "{run_out}");
}

/// The `<flexible>` groups and `$in` types of a manifest are compared with the code.
#[test]
fn a_drifted_flexible_declaration_fails_the_types_check() {
    let dir = tempdir("flexible_drift");
    for entry in std::fs::read_dir("components").unwrap() {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "xml") {
            std::fs::copy(&p, dir.join(p.file_name().unwrap())).unwrap();
        }
    }
    let manifest = dir.join("ferroc_std.lib.xml");
    let original = std::fs::read_to_string(&manifest).unwrap();
    let sum = r#"    <flexible port="in" dir="in" same-type="true" min-count="1"/>
    <out name="out" type="$in"/>
  </module-type>"#;
    assert!(original.contains(sum));
    let drifted = original.replacen(
        sum,
        r#"    <flexible port="in" dir="in" same-type="false" min-count="2"/>
    <out name="out" type="f64"/>
  </module-type>"#,
        1,
    );
    std::fs::write(&manifest, drifted).unwrap();
    let (code, _, err) = ferroc(&[
        "types",
        "export",
        "--check",
        "--lib-path",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    for expected in [
        "the manifest of `ferroc_std.Sum` differs",
        "port `out`: the manifest says type `f64`, the code `$in`",
        "flexible group `in`: the manifest says same-type `false`, the code `true`",
        "flexible group `in`: the manifest says min-count `2`, the code `1`",
    ] {
        assert!(err.contains(expected), "`{expected}` missing in:\n{err}");
    }
    // Export repairs the type from the code: the group and the `$in` type come back.
    let (code, _, err) = ferroc(&[
        "types",
        "export",
        "--lib-path",
        dir.to_str().unwrap(),
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let repaired = std::fs::read_to_string(&manifest).unwrap();
    assert!(
        repaired.contains(
            "    <flexible port=\"in\" dir=\"in\" same-type=\"true\" min-count=\"1\"/>\n    <out name=\"out\" type=\"$in\"/>"
        ),
        "{repaired}"
    );
    let (code, _, err) = ferroc(&[
        "types",
        "export",
        "--check",
        "--lib-path",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
}

/// A `ferroc_std.Constant` given its unit by the instance (`<port name="value" …
/// unit="cm"/>`, as a flexible port's `<port>` gives one) checks without T105 and runs
/// with the unit's scale on its connection: 40 cm arrive as 0.4 m. Before, the instance
/// could not give the unit, and T105's help asked to edit the standard library.
#[test]
fn a_constant_given_its_unit_by_the_instance_is_scaled_into_the_input() {
    let dir = tempdir("constant_unit");
    let model = dir.join("setpoint.xml");
    std::fs::write(
        &model,
        r#"<application name="setpoint" version="1">
  <use library="ferroc_std"/>
  <part name="p" host="localhost">
    <thread name="main" period="10ms">
      <module name="setpoint" type="ferroc_std.Constant">
        <port name="value" dir="out" type="f64" unit="cm"/>
        <param name="value">40</param>
      </module>
      <module name="show" type="ferroc_std.Dump">
        <port name="in" dir="in" type="f64" unit="m" count="1"/>
        <param name="label">metres</param>
      </module>
      <connect from="setpoint/value" to="show/in/0"/>
    </thread>
  </part>
</application>
"#,
    )
    .unwrap();
    let model = model.to_str().unwrap();
    let (code, out, err) = ferroc(&["check", model, "--format", "short"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(!out.contains("T105"), "{out}");
    assert!(
        out.contains("note[T104]: values are scaled by 0.01 from `cm` to `m`"),
        "{out}"
    );
    let (code, out, err) = ferroc(&["run", model, "--lockstep", "--cycles", "2", "-q"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "metres: in/0 = 0.4\nmetres: in/0 = 0.4\n");
    // Another type than the port's is refused: the instance gives a unit, not a type.
    let text = std::fs::read_to_string(model).unwrap();
    std::fs::write(
        model,
        text.replace(r#"type="f64" unit="cm""#, r#"type="f32" unit="cm""#),
    )
    .unwrap();
    let (code, out, _) = ferroc(&["check", model, "--format", "short"]);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.contains("error[M108]: `value` of `ferroc_std.Constant` has type `f64`, not `f32`"),
        "{out}"
    );
}
