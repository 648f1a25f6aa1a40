//! Hostile team packages (`<ros2-interfaces>`, check R109): a definition file that is a
//! link out of the package's folder is not read, a huge one is refused, a path out of
//! the model's folder is refused (M113) — each a finding, nothing read that should not
//! be, no panic. Built in a temporary folder (links cannot live in the fixtures).

use ferroc_compiler::load::Options;
use ferroc_compiler::{check_model, Policy};
use std::path::PathBuf;

fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "ferroc-ros2-interfaces-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("model/team/robot_msgs/msg")).unwrap();
    dir
}

/// The findings of checking `model` (its text) in `dir/model/`, as `CODE message`.
fn findings(dir: &std::path::Path, model: &str) -> Vec<String> {
    let path = dir.join("model/app.xml");
    std::fs::write(&path, model).unwrap();
    let result = check_model(&path, &Options::default(), &Policy::default()).unwrap();
    result
        .diagnostics
        .iter()
        .map(|d| format!("{} {}", d.code(), d.message))
        .collect()
}

const MODEL: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<application name="hostile" version="1">
  <ros2-interfaces package="robot_msgs" path="team/robot_msgs"/>
</application>
"#;

#[cfg(unix)]
#[test]
fn a_link_out_of_the_package_and_a_huge_file_are_refused_not_read() {
    let dir = folder("link");
    let msg = dir.join("model/team/robot_msgs/msg");
    std::fs::write(dir.join("secret.txt"), "do not show me\n").unwrap();
    std::os::unix::fs::symlink(dir.join("secret.txt"), msg.join("Secret.msg")).unwrap();
    std::fs::write(msg.join("Huge.msg"), "#".repeat((1 << 20) + 1)).unwrap();
    std::fs::write(msg.join("Fine.msg"), "float64 x\n").unwrap();
    let found = findings(&dir, MODEL);
    let r109: Vec<&String> = found.iter().filter(|f| f.starts_with("R109")).collect();
    assert_eq!(r109.len(), 1, "one finding for both: {found:#?}");
    assert!(
        r109[0].contains("msg/Huge.msg: 1048577 bytes, more than"),
        "{found:#?}"
    );
    assert!(
        r109[0].contains("msg/Secret.msg: it leads outside"),
        "{found:#?}"
    );
    assert!(
        !found.iter().any(|f| f.contains("do not show me")),
        "{found:#?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_package_path_out_of_the_model_s_folder_is_refused() {
    let dir = folder("outside");
    std::fs::create_dir_all(dir.join("elsewhere/msg")).unwrap();
    std::fs::write(dir.join("elsewhere/msg/X.msg"), "float64 x\n").unwrap();
    let found = findings(&dir, &MODEL.replace("team/robot_msgs", "../elsewhere"));
    assert!(found.iter().any(|f| f.starts_with("M113")), "{found:#?}");
    assert!(!found.iter().any(|f| f.starts_with("R109")), "{found:#?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_good_package_checks_clean() {
    let dir = folder("good");
    let msg = dir.join("model/team/robot_msgs/msg");
    std::fs::write(msg.join("Wheel.msg"), "float64 speed\nfloat64 torque\n").unwrap();
    std::fs::write(
        msg.join("Drive.msg"),
        "Wheel[<=4] wheels\ngeometry_msgs/Vector3 d\n",
    )
    .unwrap();
    let found = findings(&dir, MODEL);
    assert!(!found.iter().any(|f| f.starts_with("R109")), "{found:#?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
