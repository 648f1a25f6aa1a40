//! Where the cursor is, read from the text before it (no parse: the text being typed
//! is rarely well formed): after `<`, between attributes, inside a value, in a
//! `<param>`'s text; and which elements are open around it.

/// Where the cursor is, read from the text before it.
#[derive(Debug, PartialEq)]
pub(super) enum Place {
    /// After `<`: an element name (`partial` typed so far).
    Tag {
        parents: Vec<(String, Option<String>)>,
        partial: String,
    },
    /// Inside a start tag, between attributes.
    Attr {
        parents: Vec<(String, Option<String>)>,
        tag: String,
    },
    /// In the text of `<param name="param">`, `typed` so far.
    ParamValue {
        parents: Vec<(String, Option<String>)>,
        param: String,
        typed: String,
    },
    /// Inside an attribute's value (`typed` so far); `other`: for `from=`/`to=`, the
    /// other end's value when written before.
    Value {
        parents: Vec<(String, Option<String>)>,
        tag: String,
        attr: String,
        typed: String,
        other: Option<String>,
    },
}

pub(super) fn context(before: &str) -> Option<Place> {
    let lt = before.rfind('<')?;
    if let Some(gt) = before[lt..].find('>') {
        return param_value(before, lt, lt + gt);
    }
    let parents = open_elements(&before[..lt]);
    let inside = &before[lt + 1..];
    if inside.starts_with(['/', '!', '?']) {
        return None;
    }
    let name_end = inside.find(char::is_whitespace);
    let Some(name_end) = name_end else {
        return Some(Place::Tag {
            parents,
            partial: inside.to_string(),
        });
    };
    let tag = inside[..name_end].to_string();
    let rest = &inside[name_end..];
    if rest.matches('"').count() % 2 == 1 {
        let quote = rest.rfind('"')?;
        let attr = rest[..quote].trim_end().trim_end_matches('=').trim_end();
        let attr = attr
            .rsplit(char::is_whitespace)
            .next()
            .unwrap_or("")
            .to_string();
        let typed = rest[quote + 1..].to_string();
        let other_name = match attr.as_str() {
            "from" => Some("to"),
            "to" => Some("from"),
            _ => None,
        };
        let other = other_name.and_then(|n| attr_value(rest, n));
        return Some(Place::Value {
            parents,
            tag,
            attr,
            typed,
            other,
        });
    }
    Some(Place::Attr { parents, tag })
}

/// The cursor in the text of a `<param>` whose start tag is `before[lt..=gt]`.
fn param_value(before: &str, lt: usize, gt: usize) -> Option<Place> {
    let tag = &before[lt + 1..gt];
    let is_param = tag
        .strip_prefix("param")
        .is_some_and(|r| r.starts_with(char::is_whitespace));
    if !is_param || tag.ends_with('/') {
        return None;
    }
    Some(Place::ParamValue {
        parents: open_elements(&before[..lt]),
        param: attr_value(tag, "name")?,
        typed: before[gt + 1..].to_string(),
    })
}

/// `name="value"` in a start tag's text.
fn attr_value(tag_text: &str, name: &str) -> Option<String> {
    let pat = format!("{name}=\"");
    let mut from = 0;
    while let Some(i) = tag_text[from..].find(&pat) {
        let start = from + i;
        let ok = start == 0 || tag_text[..start].ends_with(char::is_whitespace);
        let value_start = start + pat.len();
        if ok {
            let end = tag_text[value_start..].find('"')?;
            return Some(tag_text[value_start..value_start + end].to_string());
        }
        from = value_start;
    }
    None
}

/// The elements open at the end of `text`: tag and `name=`, outermost first.
fn open_elements(text: &str) -> Vec<(String, Option<String>)> {
    let mut stack: Vec<(String, Option<String>)> = Vec::new();
    let mut rest = text;
    while let Some(lt) = rest.find('<') {
        rest = &rest[lt..];
        if let Some(after) = rest.strip_prefix("<!--") {
            rest = after.find("-->").map_or("", |e| &after[e + 3..]);
            continue;
        }
        let end = rest.find('>').map_or(rest.len(), |e| e + 1);
        let tag = &rest[1..end.saturating_sub(1).max(1)];
        if let Some(closing) = tag.strip_prefix('/') {
            let name = closing.trim();
            if let Some(pos) = stack.iter().rposition(|(t, _)| t == name) {
                stack.truncate(pos);
            }
        } else if !tag.starts_with(['?', '!'])
            && !tag.ends_with('/')
            && end <= rest.len()
            && rest[..end].ends_with('>')
        {
            let name = tag
                .split(char::is_whitespace)
                .next()
                .unwrap_or("")
                .to_string();
            stack.push((name, attr_value(tag, "name")));
        }
        rest = &rest[end..];
    }
    stack
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_where_the_cursor_is() {
        let text = "<application name=\"a\" version=\"1\">\n <part name=\"robot\">\n  <thread name=\"main\" period=\"10ms\">\n   <connect from=\"a/out\" to=\"b/";
        match context(text) {
            Some(Place::Value {
                parents,
                tag,
                attr,
                typed,
                other,
            }) => {
                assert_eq!(tag, "connect");
                assert_eq!(attr, "to");
                assert_eq!(typed, "b/");
                assert_eq!(other.as_deref(), Some("a/out"));
                assert_eq!(parents.len(), 3);
                assert_eq!(parents[2].1.as_deref(), Some("main"));
            }
            other => panic!("{other:?}"),
        }
        assert!(
            matches!(context("<application name=\"a\">\n<th"), Some(Place::Tag { partial, .. }) if partial == "th")
        );
        assert!(
            matches!(context("<application name=\"a\">\n<thread "), Some(Place::Attr { tag, .. }) if tag == "thread")
        );
        // After the number of a `<param>` value: the unit typed so far.
        let text =
            "<application>\n<part name=\"p\">\n<module name=\"m\">\n<param name=\"speed\">1.5 km";
        match context(text) {
            Some(Place::ParamValue {
                param,
                typed,
                parents,
            }) => {
                assert_eq!((param.as_str(), typed.as_str()), ("speed", "1.5 km"));
                assert_eq!(parents.last().map(|p| p.0.as_str()), Some("module"));
            }
            other => panic!("{other:?}"),
        }
        assert!(
            context("<param name=\"x\"/>1").is_none(),
            "no text in an empty element"
        );
    }
}
