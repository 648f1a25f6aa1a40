//! ROS 2's names: which node names, namespaces and topic names ROS 2 accepts, and how a
//! relative or private topic name expands against a node's namespace, following
//! <http://design.ros2.org/articles/topic_and_service_names.html> and the rules rcl and
//! rmw enforce (`rcl_validate_topic_name`, `rmw_validate_node_name`,
//! `rmw_validate_namespace`, `rmw_validate_full_topic_name`). A model that passes these
//! never has a name refused when the node starts.

/// The longest fully qualified topic name (`RMW_TOPIC_MAX_NAME_LENGTH`: 255 less 8
/// reserved for DDS prefixes).
pub const MAX_TOPIC_LEN: usize = 255 - 8;
/// The longest namespace (`RMW_NAMESPACE_MAX_LENGTH`).
pub const MAX_NAMESPACE_LEN: usize = MAX_TOPIC_LEN - 2;
/// The longest node name (`RMW_NODE_NAME_MAX_NAME_LENGTH`).
pub const MAX_NODE_NAME_LEN: usize = 255;

/// Why ROS 2 refuses a name, in plain words.
pub type Refusal = String;

fn token_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// A node name: letters, digits and `_`, not starting with a digit.
pub fn validate_node_name(name: &str) -> Result<(), Refusal> {
    if name.is_empty() {
        return Err("a node name must not be empty".into());
    }
    if let Some(c) = name.chars().find(|c| !token_char(*c)) {
        return Err(format!(
            "`{}` is not allowed in a node name (letters, digits and `_` only)",
            c.escape_default()
        ));
    }
    if name.starts_with(|c: char| c.is_ascii_digit()) {
        return Err("a node name must not start with a digit".into());
    }
    if name.len() > MAX_NODE_NAME_LEN {
        return Err(format!(
            "a node name has at most {MAX_NODE_NAME_LEN} characters"
        ));
    }
    Ok(())
}

/// Checks the `/`-separated tokens of an absolute name (namespace or full topic name).
fn validate_tokens(name: &str, what: &str) -> Result<(), Refusal> {
    if name.contains("//") {
        return Err(format!("a {what} must not contain `//`"));
    }
    if let Some(c) = name.chars().find(|c| !(token_char(*c) || *c == '/')) {
        return Err(format!(
            "`{}` is not allowed in a {what} (letters, digits, `_` and `/` only)",
            c.escape_default()
        ));
    }
    if name
        .split('/')
        .any(|t| t.starts_with(|c: char| c.is_ascii_digit()))
    {
        return Err(format!(
            "no `/`-separated part of a {what} may start with a digit"
        ));
    }
    Ok(())
}

/// A node's namespace: absolute (`/` or `/a/b`), no trailing `/`.
pub fn validate_namespace(ns: &str) -> Result<(), Refusal> {
    if !ns.starts_with('/') {
        return Err("a namespace must start with `/`".into());
    }
    if ns.len() > 1 && ns.ends_with('/') {
        return Err("a namespace must not end with `/`".into());
    }
    validate_tokens(ns, "namespace")?;
    if ns.len() > MAX_NAMESPACE_LEN {
        return Err(format!(
            "a namespace has at most {MAX_NAMESPACE_LEN} characters"
        ));
    }
    Ok(())
}

/// A topic or service name as written (absolute `/a/b`, relative `a/b`, private `~/a`,
/// with the substitutions `{node}`, `{ns}` and `{namespace}`), before expansion.
pub fn validate_topic_name(name: &str) -> Result<(), Refusal> {
    if name.is_empty() {
        return Err("a topic name must not be empty".into());
    }
    if name.ends_with('/') {
        return Err("a topic name must not end with `/`".into());
    }
    if let Some(rest) = name.strip_prefix('~') {
        if !(rest.is_empty() || rest.starts_with('/')) {
            return Err("`~` must be followed by `/` (`~/name`)".into());
        }
    }
    let mut rest = name.strip_prefix('~').unwrap_or(name);
    let mut plain = String::new();
    while let Some(open) = rest.find('{') {
        plain.push_str(&rest[..open]);
        let Some(close) = rest[open..].find('}') else {
            return Err("a `{` substitution is not closed".into());
        };
        let sub = &rest[open + 1..open + close];
        if !matches!(sub, "node" | "ns" | "namespace") {
            return Err(format!(
                "`{{{sub}}}` is not a substitution ROS 2 knows (`{{node}}`, `{{ns}}`, `{{namespace}}`)"
            ));
        }
        plain.push_str("sub");
        rest = &rest[open + close + 1..];
    }
    plain.push_str(rest);
    if plain.contains('}') {
        return Err("`}` without `{`".into());
    }
    if plain.contains('~') {
        return Err("`~` may only start a topic name".into());
    }
    validate_tokens(&plain, "topic name")
}

/// The fully qualified name of `topic` for a node `node` in namespace `ns`, as rcl expands
/// it: absolute names stay, `~` is the node's own namespace (`/ns/node`), relative names
/// go below the namespace. Validates the name as written and the result.
pub fn expand_topic_name(topic: &str, node: &str, ns: &str) -> Result<String, Refusal> {
    validate_topic_name(topic)?;
    let node_fqn = if ns == "/" {
        format!("/{node}")
    } else {
        format!("{ns}/{node}")
    };
    let mut out = if let Some(rest) = topic.strip_prefix('~') {
        format!("{node_fqn}{rest}")
    } else if topic.starts_with('/') {
        topic.to_string()
    } else if topic.starts_with('{') && ns != "/" {
        format!("{ns}/{topic}")
    } else if ns == "/" {
        format!("/{topic}")
    } else {
        format!("{ns}/{topic}")
    };
    out = out
        .replace("{node}", node)
        .replace("{namespace}", ns.trim_start_matches('/'))
        .replace("{ns}", ns.trim_start_matches('/'));
    let out = out.replace("//", "/");
    validate_tokens(&out, "topic name")?;
    if out.len() > MAX_TOPIC_LEN {
        return Err(format!(
            "the full topic name `{out}` is longer than {MAX_TOPIC_LEN} characters"
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_names() {
        for good in ["talker", "_x", "node_2"] {
            assert!(validate_node_name(good).is_ok(), "{good}");
        }
        for bad in ["", "2d", "my-node", "a/b", "ü"] {
            assert!(validate_node_name(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn namespaces() {
        for good in ["/", "/robot1", "/a/b_c"] {
            assert!(validate_namespace(good).is_ok(), "{good}");
        }
        for bad in ["", "robot", "/robot/", "/a//b", "/1robot", "/a-b"] {
            assert!(validate_namespace(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn topic_names_as_rcl_checks_them() {
        for good in [
            "cmd_vel", "/cmd_vel", "~/status", "~", "a/b", "{node}/x", "/ns/{ns}",
        ] {
            assert!(validate_topic_name(good).is_ok(), "{good}");
        }
        for bad in [
            "", "cmd vel", "cmd-vel", "/a//b", "a/", "1scan", "/a/2b", "~a", "a~b", "{x}", "{node",
        ] {
            assert!(validate_topic_name(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn expansion_follows_ros2s_rules() {
        let e = |t, n, ns| expand_topic_name(t, n, ns).unwrap();
        assert_eq!(e("cmd_vel", "drive", "/"), "/cmd_vel");
        assert_eq!(e("cmd_vel", "drive", "/robot1"), "/robot1/cmd_vel");
        assert_eq!(e("/odom", "drive", "/robot1"), "/odom");
        assert_eq!(e("~/status", "drive", "/robot1"), "/robot1/drive/status");
        assert_eq!(e("~/status", "drive", "/"), "/drive/status");
        assert_eq!(e("{node}/x", "drive", "/r"), "/r/drive/x");
        let long = format!("/{}", "a".repeat(MAX_TOPIC_LEN));
        assert!(expand_topic_name(&long, "n", "/").is_err());
    }
}
