//! The .msg/.srv parser and the registry: what they read, and their errors at
//! file:line:col in plain words.
use ferroc_ros2::def::{Arity, BaseType, Primitive, TypeName};
use ferroc_ros2::parse::{parse_message, parse_service};
use ferroc_ros2::{DefinitionError, Registry};

fn msg_err(text: &str) -> DefinitionError {
    parse_message(text, "demo_pkg", "Thing", "demo_pkg/msg/Thing.msg").unwrap_err()
}

#[test]
fn reads_every_form_of_field_constant_and_comment() {
    let text = "# File comment, not the first field's.\n\
                \n\
                uint8 MODE_IDLE=0   # a constant\n\
                string NAME_PREFIX=robot_\n\
                # The speed above its field [m/s]\n\
                float64 speed 0.5\n\
                string<=16 label \"hi\"\n\
                int32[] counts\n\
                float32[3] gains [1.0, 2.0, 3.0]\n\
                uint16[<=4] ids [1, 2]\n\
                string<=8[<=2] tags\n\
                Header header\n\
                Point here\n\
                geometry_msgs/Pose pose  # [m]\n\
                geometry_msgs/msg/Twist twist\n";
    let m = parse_message(text, "demo_pkg", "Thing", "Thing.msg").unwrap();
    assert_eq!(m.constants.len(), 2);
    assert_eq!(m.constants[0].name, "MODE_IDLE");
    assert_eq!(m.constants[0].value, "0");
    assert_eq!(m.constants[1].value, "robot_");
    let f = |name: &str| m.fields.iter().find(|f| f.name == name).unwrap();
    assert_eq!(f("speed").ty.base, BaseType::Primitive(Primitive::Float64));
    assert_eq!(f("speed").default.as_deref(), Some("0.5"));
    assert_eq!(f("speed").unit.as_deref(), Some("m/s"));
    assert_eq!(f("speed").place.line, 6);
    assert_eq!(f("label").ty.base, BaseType::String { bound: Some(16) });
    assert_eq!(f("counts").ty.arity, Arity::Unbounded);
    assert_eq!(f("gains").ty.arity, Arity::Fixed(3));
    assert_eq!(f("ids").ty.arity, Arity::Bounded(4));
    assert_eq!(f("tags").ty.base, BaseType::String { bound: Some(8) });
    assert_eq!(f("tags").ty.arity, Arity::Bounded(2));
    let nested = |name: &str| match &f(name).ty.base {
        BaseType::Nested(n) => n.to_string(),
        other => panic!("{other:?}"),
    };
    assert_eq!(nested("header"), "std_msgs/msg/Header");
    assert_eq!(nested("here"), "demo_pkg/msg/Point");
    assert_eq!(nested("pose"), "geometry_msgs/msg/Pose");
    assert_eq!(nested("twist"), "geometry_msgs/msg/Twist");
    assert_eq!(f("pose").unit.as_deref(), Some("m"));
    // The file comment above the first blank line belongs to no field.
    assert!(m.fields.iter().all(|f| !f.comment.contains("File comment")));
}

#[test]
fn a_service_splits_at_its_separator() {
    let s = parse_service(
        "bool data\n---\nbool success\nstring message\n",
        "std_srvs",
        "SetBool",
        "SetBool.srv",
    )
    .unwrap();
    assert_eq!(s.request.name.to_string(), "std_srvs/srv/SetBool_Request");
    assert_eq!(s.response.name.to_string(), "std_srvs/srv/SetBool_Response");
    assert_eq!(s.response.fields[1].place.line, 4);
    let none = parse_service("bool data\n", "demo_pkg", "Ask", "Ask.srv").unwrap_err();
    assert!(none.message.contains("needs a `---` line"), "{none}");
    let two = parse_service(
        "bool a\n---\nbool b\n---\nbool c\n",
        "demo_pkg",
        "Ask",
        "Ask.srv",
    )
    .unwrap_err();
    assert_eq!((two.line, two.col), (4, 1));
}

#[test]
fn a_syntax_error_names_file_line_and_column() {
    let e = msg_err("float64 x\n  float64\n");
    assert_eq!(
        e.to_string().lines().next().unwrap(),
        "demo_pkg/msg/Thing.msg:2:3: `float64` is a type without a name"
    );
    assert!(e.help.contains("TYPE NAME"));
    let e = msg_err("float64 Bad_Name\n");
    assert_eq!((e.line, e.col), (1, 9));
    assert!(e.message.contains("not a valid field name"), "{e}");
    let e = msg_err("float64[3 x\n");
    assert!(e.message.contains("ends with `]`"), "{e}");
    let e = msg_err("string<=0 s\n");
    assert!(e.message.contains("not a size"), "{e}");
    let e = msg_err("float64 x\nfloat64 x\n");
    assert!(e.message.contains("defined twice") && e.line == 2, "{e}");
}

#[test]
fn a_bad_default_or_constant_value_is_refused_at_the_value() {
    let e = msg_err("uint8 level 300\n");
    assert_eq!((e.line, e.col), (1, 13));
    assert!(
        e.message.contains("`300` is not a value of type `uint8`"),
        "{e}"
    );
    let e = msg_err("float32[2] g [1.0]\n");
    assert!(e.message.contains("has 1 values; the array has 2"), "{e}");
    let e = msg_err("string<=3 s \"toolong\"\n");
    assert!(
        e.message.contains("longer than the string's bound of 3"),
        "{e}"
    );
    let e = msg_err("int8 LIMIT=-129\n");
    assert!(e.message.contains("not a value of type `int8`"), "{e}");
    let e = msg_err("int8 lower_case=1\n");
    assert!(e.message.contains("not a valid constant name"), "{e}");
    let e = msg_err("Header h 3\n");
    assert!(e.message.contains("cannot have a default"), "{e}");
}

#[test]
fn an_unknown_type_is_an_error_at_its_field() {
    // Neither primitive nor a message name: the parser says so.
    let e = msg_err("float64 x\nflaot64 y\n");
    assert_eq!((e.line, e.col), (2, 1));
    assert!(e.message.contains("unknown type `flaot64`"), "{e}");
    assert!(e.help.contains("float64"), "{}", e.help);
    let e = msg_err("time stamp\n");
    assert!(
        e.message.contains("ROS 1 type") && e.help.contains("builtin_interfaces/Time"),
        "{e}"
    );
    // A message name no package defines: the registry says so, where it is used.
    let mut r = Registry::shipped();
    r.add_text(
        "demo_pkg",
        "msg",
        "Goal",
        "# target\ngeometry_msgs/Pointt target\n",
        "demo/msg/Goal.msg",
    )
    .unwrap();
    let errors = r.check();
    assert_eq!(errors.len(), 1);
    assert_eq!(
        errors[0].to_string().lines().next().unwrap(),
        "demo/msg/Goal.msg:2:1: unknown type `geometry_msgs/msg/Pointt` (field `target`)"
    );
    // Silent when the type exists.
    let mut ok = Registry::shipped();
    ok.add_text(
        "demo_pkg",
        "msg",
        "Goal",
        "geometry_msgs/Point target\n",
        "Goal.msg",
    )
    .unwrap();
    assert!(ok.check().is_empty());
}

#[test]
fn a_cycle_of_nested_types_is_an_error_naming_the_chain() {
    let mut r = Registry::new();
    r.add_text(
        "demo_pkg",
        "msg",
        "Tree",
        "string name\nBranch[] branches\n",
        "msg/Tree.msg",
    )
    .unwrap();
    r.add_text(
        "demo_pkg",
        "msg",
        "Branch",
        "float64 length\nTree[<=1] subtree\n",
        "msg/Branch.msg",
    )
    .unwrap();
    let errors = r.check();
    assert_eq!(errors.len(), 1, "{errors:?}");
    let e = &errors[0];
    assert_eq!((e.file.as_str(), e.line, e.col), ("msg/Tree.msg", 2, 1));
    assert!(
        e.message
            .contains("demo_pkg/msg/Branch → demo_pkg/msg/Tree → demo_pkg/msg/Branch"),
        "{e}"
    );
    // A message nesting itself directly.
    let mut r = Registry::new();
    r.add_text("demo_pkg", "msg", "Node", "Node next\n", "Node.msg")
        .unwrap();
    assert!(r.check()[0]
        .message
        .contains("demo_pkg/msg/Node → demo_pkg/msg/Node"));
    // A diamond (two paths to one type) is not a cycle.
    let mut r = Registry::new();
    r.add_text("demo_pkg", "msg", "Leaf", "int8 v\n", "Leaf.msg")
        .unwrap();
    r.add_text("demo_pkg", "msg", "Mid", "Leaf a\nLeaf b\n", "Mid.msg")
        .unwrap();
    r.add_text("demo_pkg", "msg", "Top", "Mid m\nLeaf l\n", "Top.msg")
        .unwrap();
    assert!(r.check().is_empty());
}

#[test]
fn a_team_adds_its_own_package_from_its_folder() {
    let root = std::env::temp_dir().join(format!("ferroc-ros2-pkg-{}", std::process::id()));
    let pkg = root.join("rover_msgs");
    std::fs::create_dir_all(pkg.join("msg")).unwrap();
    std::fs::create_dir_all(pkg.join("srv")).unwrap();
    std::fs::write(
        pkg.join("msg/WheelSpeeds.msg"),
        "std_msgs/Header header\nfloat64[4] speeds # [rad/s]\n",
    )
    .unwrap();
    std::fs::write(pkg.join("srv/Dock.srv"), "string station\n---\nbool ok\n").unwrap();
    let mut r = Registry::shipped();
    r.add_package(&pkg).unwrap();
    assert!(r.check().is_empty());
    let ws = r
        .message(&TypeName::parse("rover_msgs/msg/WheelSpeeds").unwrap())
        .unwrap();
    assert_eq!(ws.fields[1].unit.as_deref(), Some("rad/s"));
    assert!(r
        .service(&TypeName::parse("rover_msgs/srv/Dock").unwrap())
        .is_some());
    // A broken file in the folder: every error comes back, with the file's path.
    std::fs::write(pkg.join("msg/Broken.msg"), "float64\n").unwrap();
    let errors = Registry::new().add_package(&pkg).unwrap_err();
    assert_eq!(errors.len(), 1);
    assert!(
        errors[0].file.ends_with("Broken.msg") && errors[0].line == 1,
        "{:?}",
        errors[0]
    );
    // A folder without definitions.
    let empty = root.join("nothing_here");
    std::fs::create_dir_all(&empty).unwrap();
    let errors = Registry::new().add_package(&empty).unwrap_err();
    assert!(
        errors[0].message.contains("no `msg/*.msg`"),
        "{}",
        errors[0]
    );
    std::fs::remove_dir_all(&root).unwrap();
}

#[test]
fn the_shipped_packages_hold_the_types_issue_29_names() {
    let r = Registry::shipped();
    for name in [
        "std_msgs/msg/Header",
        "builtin_interfaces/msg/Time",
        "builtin_interfaces/msg/Duration",
        "geometry_msgs/msg/Twist",
        "geometry_msgs/msg/PoseStamped",
        "sensor_msgs/msg/LaserScan",
        "sensor_msgs/msg/Imu",
        "sensor_msgs/msg/Image",
        "sensor_msgs/msg/JointState",
        "sensor_msgs/msg/PointCloud2",
        "sensor_msgs/msg/NavSatFix",
        "nav_msgs/msg/Odometry",
        "nav_msgs/msg/Path",
        "nav_msgs/msg/OccupancyGrid",
    ] {
        assert!(
            r.message(&TypeName::parse(name).unwrap()).is_some(),
            "{name}"
        );
    }
    for name in [
        "std_srvs/srv/Trigger",
        "std_srvs/srv/Empty",
        "std_srvs/srv/SetBool",
    ] {
        assert!(
            r.service(&TypeName::parse(name).unwrap()).is_some(),
            "{name}"
        );
    }
    let scan = r
        .message(&TypeName::parse("sensor_msgs/msg/LaserScan").unwrap())
        .unwrap();
    let names: Vec<&str> = scan.fields.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "header",
            "angle_min",
            "angle_max",
            "angle_increment",
            "time_increment",
            "scan_time",
            "range_min",
            "range_max",
            "ranges",
            "intensities"
        ]
    );
    assert_eq!(scan.fields[1].unit.as_deref(), Some("rad"));
    // Every msg/ and srv/ file of the seven packages (interfaces/NOTICE.md).
    assert_eq!(Registry::shipped_files().count(), 105);
}
