//! Tests of the built-in catalogue: FINROC names, types, units and files as the C++
//! sources give them, and manifests that load as ferroc libraries.

use super::*;

#[test]
fn catalogue_holds_the_crash_course_and_structure_types_with_finroc_names() {
    let c = builtin();
    let main = c
        .get("finroc_projects_crash_course", "MainSimulation")
        .unwrap();
    let p = main.port("Sensor Output", "Ir Distance Front").unwrap();
    assert_eq!(
        (p.ty.as_str(), p.unit.as_deref(), p.output),
        ("double", Some("m"), true)
    );
    assert_eq!(
        main.port("Sensor Output", "Pose").unwrap().ty,
        "rrlib.localization.Pose2D"
    );
    assert_eq!(
        main.param("Destructive Collision Speed")
            .unwrap()
            .1
            .as_deref(),
        Some("m/s")
    );
    let sim = c.get("finroc_projects_crash_course", "Simulation").unwrap();
    assert!(sim.composite && !sim.open);
    assert_eq!(sim.xml_file.as_deref(), Some("gSimulation.h.xml"));
    let content = sim.content.as_ref().unwrap();
    assert_eq!(content.elements.len(), 2);
    assert_eq!(content.edges.len(), 5);
    let tc = c
        .get(
            "finroc_plugins_structure",
            "ThreadContainer<SenseControlGroup>",
        )
        .unwrap();
    assert!(tc.port("Profiling", "Execution Duration").is_some());
    assert!(
        c.get("finroc_plugins_runtime_construction", "Default Interface")
            .unwrap()
            .open
    );
    assert_eq!(
        c.ferroc_types["rrlib.localization.Pose2D"],
        "finroc_projects_crash_course.Pose2D"
    );
    assert_eq!(c.ferroc_types["double"], "f64");
    let behaviour = c.get("finroc_plugins_ib2c", "LimitOutput").unwrap();
    assert!(behaviour.interfaces.iter().any(|i| i == "iB2C Input"));
    assert!(behaviour.port("iB2C Output", "Activity").is_some());
}

#[test]
fn port_names_are_finrocs_explicit_or_built_ones() {
    let c = builtin();
    let track = c
        .get("finroc_projects_robprak_2024_2", "TrackRecognition")
        .unwrap();
    let p = track.port("Sensor Input", "ZED Cam Single Image").unwrap();
    assert_eq!(p.member, "zed_camera_solo_image");
    assert_eq!(p.ty, "rrlib.coviroa.Image");
    // No name given in C++: port_name_builder's.
    let movement = c
        .get("finroc_projects_robprak_2024_2", "TrackMovement")
        .unwrap();
    assert_eq!(
        movement
            .port("Controller Output", "Curvature")
            .unwrap()
            .unit
            .as_deref(),
        Some("1/m")
    );
    let main = c
        .get("finroc_projects_robprak_2024_2", "MainControl")
        .unwrap();
    assert_eq!(
        main.xml_file.as_deref(),
        Some("projects/robprak_2024_2/gMainControl.h.xml")
    );
    assert!(main.port("Sensor Input", "Us Front").is_some());
    assert!(main.port("Sensor Input", "Pose").is_none());
    // The kind prefix is dropped only where it names the port's kind.
    let e = |t: &str| xml::parse(FileId(0), t, 8).unwrap();
    assert_eq!(
        finroc_name(&e("<sensor-in name=\"si_us_front\"/>"), "sensor-in"),
        "Us Front"
    );
    assert_eq!(
        finroc_name(&e("<in name=\"si_us_front\"/>"), "in"),
        "Si Us Front"
    );
    assert_eq!(
        finroc_name(&e("<in name=\"x\" doc=\"FINROC: us_front\"/>"), "in"),
        "us_front"
    );
}

/// The manifests are ferroc manifests: they load through the library loader cleanly.
#[test]
fn catalogue_manifests_load_as_ferroc_libraries() {
    let dir = std::env::temp_dir().join(format!("ferroc-catalogue-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut names = Vec::new();
    for (name, text) in FILES.iter().filter(|(n, _)| n.ends_with(".lib.xml")) {
        std::fs::write(dir.join(name), text).unwrap();
        names.push(name.trim_end_matches(".lib.xml").to_string());
    }
    let options = ferroc_model::load::Options {
        lib_path: vec![dir.clone()],
        ..Default::default()
    };
    let loaded = ferroc_model::load_manifests(&names, &options);
    let _ = std::fs::remove_dir_all(&dir);
    let problems: Vec<_> = loaded
        .diagnostics
        .iter()
        .map(|d| format!("{} {}", d.code(), d.message))
        .collect();
    assert!(problems.is_empty(), "{problems:?}");
    assert_eq!(loaded.libraries.libraries.len(), names.len());
}
