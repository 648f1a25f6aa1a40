//! The run plan carries each part's ROS 2 node (issue 29, docs/ros2.md): the ports
//! behind its topics, the topic names expanded as ROS 2 expands them against the node's
//! namespace, the QoS, one number per topic end, the modules' services it offers
//! and the ROS 2 services its clients call. What the runtime cannot open (ends on group
//! ports, ports that do not resolve) is a problem at the element, not a silent omission.

use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::plan::{self, Ros2Topic};
use ferroc_compiler::{check_model_text, Policy};
use std::path::Path;

/// The plan of the ROS 2 crash course with `edit` applied to its text, and the texts
/// of the problems found.
fn plan_of(edit: impl Fn(String) -> String) -> (plan::Plan, Vec<String>) {
    let options = Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/ros2_crash_course.xml");
    let text = edit(std::fs::read_to_string(&path).unwrap());
    let result = check_model_text(
        &path,
        "ros2_crash_course.xml",
        &text,
        &options,
        &Policy::default(),
    )
    .unwrap();
    let app = result.app.as_ref().expect("the model resolves");
    let (plan, problems) = plan::plan(app, &result.libraries, &[]);
    (plan, problems.into_iter().map(|p| p.what).collect())
}

fn topic<'p>(plan: &'p plan::Plan, name: &str) -> &'p Ros2Topic {
    let node = &plan.ros2[0];
    (node.topics.iter())
        .find(|t| t.topic == name)
        .unwrap_or_else(|| panic!("no topic {name} in {:?}", node.topics))
}

#[test]
fn the_demo_s_node_is_planned_with_its_ports_names_and_qos() {
    let (plan, problems) = plan_of(|t| t);
    assert!(problems.is_empty(), "{problems:?}");
    assert_eq!(plan.ros2.len(), 1, "the external teleop node is not run");
    let node = &plan.ros2[0];
    assert_eq!(
        (
            node.part.as_str(),
            node.name.as_str(),
            node.namespace.as_str(),
            node.domain
        ),
        ("fragile_bot", "fragile_bot", "/", 0)
    );
    let cmd_vel = topic(&plan, "/cmd_vel");
    assert_eq!(cmd_vel.id, 0);
    assert!(cmd_vel.publish && cmd_vel.qos.reliable && !cmd_vel.qos.transient_local);
    assert_eq!(
        cmd_vel.port,
        ("fragile_bot/main/control/twist_out".into(), "twist".into())
    );
    assert_eq!(cmd_vel.model_type, "crash_course.Twist");
    assert_eq!(cmd_vel.message, "geometry_msgs/msg/Twist");
    assert_eq!(cmd_vel.qos.depth, 10);
    assert_eq!(cmd_vel.field, None, "the whole Twist");
    // A single value fills the one field of a wrapper message.
    let ir = topic(&plan, "/ir_front");
    assert_eq!(
        (ir.id, ir.model_type.as_str(), ir.qos.reliable),
        (1, "f64", false)
    );
    assert_eq!(ir.field.as_deref(), Some("data"));
    let enable = topic(&plan, "/enable");
    assert_eq!((enable.id, enable.publish), (2, false));
    assert_eq!(enable.field.as_deref(), Some("data"));
    assert_eq!(
        enable.port,
        (
            "fragile_bot/main/control/controller".into(),
            "enable".into()
        )
    );
}

#[test]
fn relative_and_private_names_expand_against_the_node_s_namespace() {
    let (plan, problems) = plan_of(|t| {
        t.replace(
            r#"<ros2 node="fragile_bot" domain="0">"#,
            r#"<ros2 node="fragile_bot" namespace="/robot1" domain="7">"#,
        )
        .replace(r#"topic="ir_front""#, r#"topic="~/ir" depth="3""#)
    });
    assert!(problems.is_empty(), "{problems:?}");
    assert_eq!(plan.ros2[0].domain, 7);
    assert_eq!(topic(&plan, "/robot1/cmd_vel").id, 0);
    assert_eq!(topic(&plan, "/robot1/fragile_bot/ir").qos.depth, 3);
    // Absolute names stay.
    assert_eq!(topic(&plan, "/enable").id, 2);
}

#[test]
fn a_module_s_service_is_planned_as_a_ros2_service_with_its_expanded_name() {
    let (plan, problems) = plan_of(|t| {
        t.replace(
            r#"<subscribe port="main/control/controller/enable""#,
            r#"<service port="main/scaler/scale" name="~/scale" type="std_srvs/srv/SetBool"/>
      <subscribe port="main/control/controller/enable""#,
        )
        .replace(
            r#"<thread name="main" period="40ms" priority="50" warn-overrun="true">"#,
            r#"<thread name="main" period="40ms" priority="50" warn-overrun="true">
      <module name="scaler" type="ferroc_std.ScaleService"/>"#,
        )
    });
    assert!(problems.is_empty(), "{problems:?}");
    let services = &plan.ros2[0].services;
    assert_eq!(services.len(), 1, "{services:?}");
    let s = &services[0];
    assert_eq!(s.id, 0);
    assert_eq!(s.port, ("fragile_bot/main/scaler".into(), "scale".into()));
    assert_eq!(s.name, "/fragile_bot/scale");
    assert_eq!(s.service, "std_srvs/srv/SetBool");
    // A single value fills SetBool's one request field; the response has two.
    assert_eq!(s.request_field.as_deref(), Some("data"));
    assert_eq!(s.response_field, None);
}

#[test]
fn a_module_s_client_is_planned_as_a_ros2_client_numbered_with_the_services() {
    let (plan, problems) = plan_of(|t| {
        t.replace(
            r#"<subscribe port="main/control/controller/enable""#,
            r#"<service port="main/scaler/scale" name="~/scale" type="std_srvs/srv/SetBool"/>
      <client port="main/asker/ask" name="/other/scale" type="std_srvs/srv/SetBool"/>
      <subscribe port="main/control/controller/enable""#,
        )
        .replace(
            r#"<thread name="main" period="40ms" priority="50" warn-overrun="true">"#,
            r#"<thread name="main" period="40ms" priority="50" warn-overrun="true">
      <module name="scaler" type="ferroc_std.ScaleService"/>
      <module name="asker" type="ferroc_std.Ask"/>"#,
        )
    });
    assert!(problems.is_empty(), "{problems:?}");
    let node = &plan.ros2[0];
    assert_eq!(node.services.len(), 1, "{node:?}");
    let c = &node.clients[0];
    assert_eq!(
        c.id, 1,
        "one numbering for services and clients, in model order"
    );
    assert_eq!(c.port, ("fragile_bot/main/asker".into(), "ask".into()));
    assert_eq!(c.name, "/other/scale");
    assert_eq!(c.request_field.as_deref(), Some("data"));
}

#[test]
fn a_ros2_end_whose_port_does_not_resolve_is_a_problem_not_left_out() {
    let (plan, problems) = plan_of(|t| {
        t.replace(
            r#"<subscribe port="main/control/controller/enable""#,
            r#"<client port="main/control/controller/reset" name="~/reset" type="std_srvs/srv/Trigger"/>
      <subscribe port="main/control/controller/enable""#,
        )
    });
    assert!(
        problems.iter().any(|p| p.contains("does not resolve")),
        "{problems:?}"
    );
    assert_eq!(plan.ros2[0].topics.len(), 3, "the topics are planned still");
}

#[test]
fn every_node_carries_the_model_s_own_message_packages_and_none_without() {
    let (plain, _) = plan_of(|t| t);
    assert!(plain.ros2[0].interfaces.is_empty());

    // R109's silent fixture: the team package robot_msgs, used by a subscription.
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("checks/src/ros2/r109_invalid_ros2_interfaces/silent.xml");
    let options = Options::default();
    let result = ferroc_compiler::check_model(&path, &options, &Policy::default()).unwrap();
    let app = result.app.as_ref().expect("the model resolves");
    let (plan, _) = plan::plan(app, &result.libraries, &[]);
    let carried: Vec<(&str, &str, &str)> = (plan.ros2[0].interfaces.iter())
        .map(|i| (i.package.as_str(), i.kind.as_str(), i.name.as_str()))
        .collect();
    assert_eq!(
        carried,
        [
            ("robot_msgs", "msg", "Drive"),
            ("robot_msgs", "msg", "Wheel"),
            ("robot_msgs", "srv", "SetMode"),
        ]
    );
    let wheel = &plan.ros2[0].interfaces[1];
    assert!(wheel.text.contains("float64 torque"), "{}", wheel.text);
}
