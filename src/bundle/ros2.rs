//! The lines of a part's `main.rs` that open its ROS 2 node (issue 29, docs/ros2.md):
//! the node as `ferroc run` builds it, written out as a `Ros2Node` literal (the type the
//! plan, the run plan and the runtime share) handed to `Builder::ros2_node`. Laid out as
//! rustfmt lays it out (`tests/bundle.rs` checks generated code with `rustfmt --check`).

use super::code::Code;
use super::literals::call;
use super::text::rust_str;
use ferroc_compiler::plan::{Ros2Interface, Ros2Node, Ros2Service, Ros2Topic};

/// The `builder.ros2_node(…)` block of `node`, after a line break; empty without one.
pub(super) fn node_block(node: Option<&Ros2Node>) -> String {
    let Some(node) = node else {
        return String::new();
    };
    let mut code = Code::default();
    code.blank();
    code.line(
        1,
        &format!(
            "// The part as the ROS 2 node `{}` (domain {}).",
            super::text::comment(&qualified(node)),
            node.domain
        ),
    );
    code.line(1, "builder.ros2_node(Ros2Node {");
    code.line(2, &format!("part: {}.into(),", rust_str(&node.part)));
    code.line(2, &format!("domain: {},", node.domain));
    code.line(
        2,
        &format!("namespace: {}.into(),", rust_str(&node.namespace)),
    );
    code.line(2, &format!("name: {}.into(),", rust_str(&node.name)));
    if node.topics.is_empty() {
        code.line(2, "topics: vec![],");
    } else {
        code.line(2, "topics: vec![");
        node.topics.iter().for_each(|t| topic(&mut code, t));
        code.line(2, "],");
    }
    for (list, ends) in [("services", &node.services), ("clients", &node.clients)] {
        if ends.is_empty() {
            code.line(2, &format!("{list}: vec![],"));
        } else {
            code.line(2, &format!("{list}: vec!["));
            ends.iter().for_each(|s| service(&mut code, s));
            code.line(2, "],");
        }
    }
    if node.interfaces.is_empty() {
        code.line(2, "interfaces: vec![],");
    } else {
        code.line(2, "interfaces: vec![");
        node.interfaces.iter().for_each(|i| interface(&mut code, i));
        code.line(2, "],");
    }
    code.line(1, "})?;");
    code.text.trim_end_matches('\n').to_string()
}

/// The types the node's block names, for its `use` line (none without a node).
pub(super) fn type_names(node: Option<&Ros2Node>) -> Vec<&'static str> {
    let Some(node) = node else {
        return Vec::new();
    };
    let mut names = vec!["Ros2Node"];
    if !node.topics.is_empty() {
        names.extend(["Ros2Qos", "Ros2Topic"]);
    }
    if !(node.services.is_empty() && node.clients.is_empty()) {
        names.push("Ros2Service");
    }
    if !node.interfaces.is_empty() {
        names.push("Ros2Interface");
    }
    // In rustfmt's order.
    names.sort_unstable();
    names
}

/// The node's fully qualified name (`/robot1/base`), for the comment.
fn qualified(node: &Ros2Node) -> String {
    match node.namespace.as_str() {
        "/" => format!("/{}", node.name),
        ns => format!("{ns}/{}", node.name),
    }
}

/// `Some("x".into())` or `None`.
fn option(text: Option<&String>) -> String {
    text.map_or_else(
        || "None".into(),
        |t| format!("Some({}.into())", rust_str(t)),
    )
}

/// `(module.into(), port.into())`, laid out as rustfmt lays out a tuple.
fn pair(port: &(String, String)) -> String {
    call(
        "",
        &[
            format!("{}.into()", rust_str(&port.0)),
            format!("{}.into()", rust_str(&port.1)),
        ],
    )
}

/// One `Ros2Service { … },` at indentation 3.
fn service(code: &mut Code, s: &Ros2Service) {
    code.line(3, "Ros2Service {");
    code.line(4, &format!("id: {},", s.id));
    code.line(4, &format!("port: {},", pair(&s.port)));
    code.line(4, &format!("name: {}.into(),", rust_str(&s.name)));
    code.line(4, &format!("service: {}.into(),", rust_str(&s.service)));
    code.line(
        4,
        &format!("request_field: {},", option(s.request_field.as_ref())),
    );
    code.line(
        4,
        &format!("response_field: {},", option(s.response_field.as_ref())),
    );
    code.line(3, "},");
}

/// One `Ros2Topic { … },` at indentation 3.
fn topic(code: &mut Code, t: &Ros2Topic) {
    code.line(3, "Ros2Topic {");
    code.line(4, &format!("id: {},", t.id));
    code.line(4, &format!("publish: {},", t.publish));
    code.line(4, &format!("port: {},", pair(&t.port)));
    code.line(
        4,
        &format!("model_type: {}.into(),", rust_str(&t.model_type)),
    );
    code.line(4, &format!("topic: {}.into(),", rust_str(&t.topic)));
    code.line(4, &format!("message: {}.into(),", rust_str(&t.message)));
    code.line(4, &format!("field: {},", option(t.field.as_ref())));
    code.line(4, "qos: Ros2Qos {");
    code.line(5, &format!("reliable: {},", t.qos.reliable));
    code.line(5, &format!("transient_local: {},", t.qos.transient_local));
    code.line(5, &format!("depth: {},", t.qos.depth));
    code.line(4, "},");
    code.line(4, &format!("frame_id: {}.into(),", rust_str(&t.frame_id)));
    code.line(3, "},");
}

/// One `Ros2Interface { … },` (a team's definition file, its text as a literal) at
/// indentation 3.
fn interface(code: &mut Code, i: &Ros2Interface) {
    code.line(3, "Ros2Interface {");
    code.line(4, &format!("package: {}.into(),", rust_str(&i.package)));
    code.line(4, &format!("kind: {}.into(),", rust_str(&i.kind)));
    code.line(4, &format!("name: {}.into(),", rust_str(&i.name)));
    code.line(4, &format!("text: {}.into(),", rust_str(&i.text)));
    code.line(3, "},");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_team_s_definitions_are_written_into_the_node_and_named_in_its_use_line() {
        let mut node = Ros2Node {
            part: "robot".into(),
            name: "base".into(),
            namespace: "/".into(),
            ..Ros2Node::default()
        };
        assert!(node_block(Some(&node)).contains("        interfaces: vec![],\n"));
        assert!(!type_names(Some(&node)).contains(&"Ros2Interface"));
        node.interfaces.push(Ros2Interface {
            package: "robot_msgs".into(),
            kind: "msg".into(),
            name: "Wheel".into(),
            text: "float64 speed # \"rad/s\"\n".into(),
        });
        let block = node_block(Some(&node));
        let expected = "        interfaces: vec![
            Ros2Interface {
                package: \"robot_msgs\".into(),
                kind: \"msg\".into(),
                name: \"Wheel\".into(),
                text: \"float64 speed # \\\"rad/s\\\"\\n\".into(),
            },
        ],
";
        assert!(block.contains(expected), "{block}");
        assert!(type_names(Some(&node)).contains(&"Ros2Interface"));
    }
}
