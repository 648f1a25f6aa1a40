//! Editing a model's XML text in place: where an element starts and ends (from the
//! spanned tree of `syntax/xml.rs`), inserting a child with the indentation of its
//! siblings, removing an element with its line. Everything not touched keeps its
//! bytes: comments, layout, attribute order.

use super::splice::{indent_at, insert_child, remove_spans, start_tag_end};
use super::{Edited, Op, PortGroup};
use ferroc_diagnostics::source::FileId;
use ferroc_syntax::escape::{attr, text as content};
use ferroc_syntax::xml::{self, Element};

/// Elements whose `name` is a step of an element path (and may hold `<connect>`s).
const SCOPES: [&str; 3] = ["part", "thread", "group"];

pub(super) fn apply_one(edited: &mut Edited, op: &Op) -> Result<(), String> {
    let text = std::mem::take(&mut edited.text);
    let result = match op {
        Op::Add {
            module,
            r#type,
            params,
            ports,
        } => add(&text, module, r#type, params, ports),
        Op::Remove { module } => remove(&text, module),
        Op::Connect { from, to } => connect(&text, from, to, None),
        Op::Disconnect { from, to } => disconnect(&text, from, to),
        Op::Move { module, to } => move_module(&text, module, to),
        Op::Set { param, value } => set(&text, param, value),
    };
    match result {
        Ok((new, line)) => {
            if let Op::Move { module, to } = op {
                let name = module.rsplit('/').next().unwrap_or(module);
                edited.moved.push((module.clone(), format!("{to}/{name}")));
            }
            edited.text = new;
            edited.done.push(line);
            Ok(())
        }
        Err(e) => {
            edited.text = text;
            Err(e)
        }
    }
}

pub(super) fn parse(text: &str) -> Result<Element, String> {
    xml::parse(FileId(0), text, 256).map_err(|e| format!("the model is not XML: {}", e.message))
}

/// The element chain (application first) to the element at `path`.
fn find<'a>(root: &'a Element, path: &str) -> Result<Vec<&'a Element>, String> {
    let mut chain = vec![root];
    for (i, name) in path.split('/').enumerate() {
        let here = *chain.last().expect("starts with the root");
        if here.name == "group" && here.value("type").is_some() {
            return Err(format!(
                "`{path}` lies inside an instance of the group type `{}`: edit the group type, not one instance",
                here.value("type").unwrap_or_default()
            ));
        }
        let kinds: &[&str] = if i == 0 {
            &["part"]
        } else {
            &["thread", "group", "module"]
        };
        let next = here
            .children
            .iter()
            .find(|c| kinds.contains(&c.name.as_str()) && c.value("name") == Some(name));
        match next {
            Some(el) => chain.push(el),
            None => {
                return Err(format!(
                    "there is no element `{path}` in the model's file (elements of included fragments and group types cannot be edited here)"
                ))
            }
        }
    }
    Ok(chain)
}

fn find_module<'a>(root: &'a Element, path: &str) -> Result<&'a Element, String> {
    let el = *find(root, path)?.last().expect("at least the root");
    if el.name != "module" {
        return Err(format!("`{path}` is a <{}>, not a <module>", el.name));
    }
    Ok(el)
}

/// A `<connect>` of the model's file with its ends made absolute.
struct Connect<'a> {
    el: &'a Element,
    from: String,
    to: String,
}

fn connects(root: &Element) -> Vec<Connect<'_>> {
    fn walk<'a>(el: &'a Element, scope: &str, out: &mut Vec<Connect<'a>>) {
        for c in &el.children {
            if c.name == "connect" {
                let abs = |v: &str| match scope {
                    "" => v.to_owned(),
                    s => format!("{s}/{v}"),
                };
                out.push(Connect {
                    el: c,
                    from: abs(c.value("from").unwrap_or_default()),
                    to: abs(c.value("to").unwrap_or_default()),
                });
            } else if SCOPES.contains(&c.name.as_str()) && c.value("type").is_none() {
                let name = c.value("name").unwrap_or_default();
                let inner = match scope {
                    "" => name.to_owned(),
                    s => format!("{s}/{name}"),
                };
                walk(c, &inner, out);
            }
        }
    }
    let mut out = Vec::new();
    walk(root, "", &mut out);
    out
}

/// Whether the port path `end` (`a/b/port[2]`) belongs to the module `module`.
fn joins(end: &str, module: &str) -> bool {
    end.strip_prefix(module)
        .is_some_and(|rest| rest.starts_with('/'))
}

/// The deepest scope element both port paths lie in, with its path.
fn common_scope<'a>(root: &'a Element, a: &str, b: &str) -> (Vec<&'a Element>, String) {
    let (a, b): (Vec<&str>, Vec<&str>) = (a.split('/').collect(), b.split('/').collect());
    let mut chain = vec![root];
    let mut path = Vec::new();
    // The last step of each is the module and port at least: stop before the port.
    for (i, (x, y)) in a.iter().zip(&b).enumerate() {
        if x != y || i + 2 >= a.len().min(b.len()) {
            break;
        }
        let here = *chain.last().expect("root");
        let kinds: &[&str] = if i == 0 {
            &["part"]
        } else {
            &["thread", "group"]
        };
        match here.children.iter().find(|c| {
            kinds.contains(&c.name.as_str())
                && c.value("name") == Some(x)
                && c.value("type").is_none()
        }) {
            Some(el) => {
                chain.push(el);
                path.push(*x);
            }
            None => break,
        }
    }
    (chain, path.join("/"))
}

fn relative(path: &str, scope: &str) -> String {
    match scope {
        "" => path.to_owned(),
        s => path
            .strip_prefix(s)
            .and_then(|r| r.strip_prefix('/'))
            .unwrap_or(path)
            .to_owned(),
    }
}

fn add(
    text: &str,
    path: &str,
    ty: &str,
    params: &std::collections::BTreeMap<String, String>,
    ports: &[PortGroup],
) -> Result<(String, String), String> {
    let root = parse(text)?;
    let (parent_path, name) = path.rsplit_once('/').ok_or_else(|| {
        format!("`{path}`: a module lies in a part's thread container: write PART/THREAD/NAME")
    })?;
    if find(&root, path).is_ok() {
        return Err(format!("`{path}` exists already"));
    }
    let chain = find(&root, parent_path)?;
    let parent = *chain.last().expect("root");
    if !SCOPES.contains(&parent.name.as_str()) {
        return Err(format!(
            "`{parent_path}` is a <{}>; a module goes into a <thread>, <group> or <part>",
            parent.name
        ));
    }
    let mut lines = vec![format!(
        "<module name=\"{}\" type=\"{}\">",
        attr(name),
        attr(ty)
    )];
    for p in ports {
        let mut line = format!(
            "  <port name=\"{}\" dir=\"{}\" type=\"{}\"",
            attr(&p.name),
            attr(&p.dir),
            attr(&p.r#type)
        );
        if let Some(u) = &p.unit {
            line += &format!(" unit=\"{}\"", attr(u));
        }
        if let Some(n) = p.count {
            line += &format!(" count=\"{n}\"");
        }
        lines.push(line + "/>");
    }
    for (n, v) in params {
        lines.push(format!(
            "  <param name=\"{}\">{}</param>",
            attr(n),
            content(v)
        ));
    }
    let snippet = if lines.len() == 1 {
        lines[0].replace('>', "/>")
    } else {
        lines.push("</module>".into());
        lines.join("\n")
    };
    let new = insert_child(text, parent, &snippet, "module")?;
    Ok((new, format!("added `{path}` of type `{ty}`")))
}

fn remove(text: &str, path: &str) -> Result<(String, String), String> {
    let root = parse(text)?;
    let module = find_module(&root, path)?;
    let mut spans = vec![(module.span.start as usize, module.span.end as usize)];
    let joined: Vec<Connect> = connects(&root)
        .into_iter()
        .filter(|c| joins(&c.from, path) || joins(&c.to, path))
        .collect();
    spans.extend(
        joined
            .iter()
            .map(|c| (c.el.span.start as usize, c.el.span.end as usize)),
    );
    let new = remove_spans(text, spans);
    Ok((
        new,
        format!("removed `{path}` and its {} connection(s)", joined.len()),
    ))
}

/// A `<connect>`'s text and the offsets (in it) of its `from` and `to` values.
type Template<'a> = (&'a str, (usize, usize), (usize, usize));

/// Inserts `<connect from to>` in the deepest scope holding both ends; `template`
/// (a `<connect>`'s text with the offsets of its `from` and `to` values) keeps the
/// other attributes and children of a connection that moves.
fn connect(
    text: &str,
    from: &str,
    to: &str,
    template: Option<Template<'_>>,
) -> Result<(String, String), String> {
    let root = parse(text)?;
    if connects(&root).iter().any(|c| c.from == from && c.to == to) {
        return Err(format!("`{from}` → `{to}` is connected already"));
    }
    let (chain, scope) = common_scope(&root, from, to);
    let (rf, rt) = (relative(from, &scope), relative(to, &scope));
    let snippet = match template {
        None => format!("<connect from=\"{}\" to=\"{}\"/>", attr(&rf), attr(&rt)),
        Some((t, f, o)) => {
            let mut parts = [(f, attr(&rf)), (o, attr(&rt))];
            parts.sort_by_key(|((s, _), _)| std::cmp::Reverse(*s));
            let mut s = t.to_owned();
            for ((a, b), v) in parts {
                s.replace_range(a..b, &v);
            }
            s
        }
    };
    let parent = *chain.last().expect("root");
    let new = insert_child(text, parent, &snippet, "connect")?;
    Ok((new, format!("connected `{from}` → `{to}`")))
}

fn disconnect(text: &str, from: &str, to: &str) -> Result<(String, String), String> {
    let root = parse(text)?;
    let all = connects(&root);
    let Some(c) = all.iter().find(|c| c.from == from && c.to == to) else {
        let near: Vec<String> = (all.iter())
            .filter(|c| c.to == to || c.from == from)
            .map(|c| format!("`{}` → `{}`", c.from, c.to))
            .take(5)
            .collect();
        return Err(format!(
            "no <connect> of the model's file joins `{from}` → `{to}`{}",
            match near.is_empty() {
                true => String::new(),
                false => format!("; near it: {}", near.join(", ")),
            }
        ));
    };
    let new = remove_spans(
        text,
        vec![(c.el.span.start as usize, c.el.span.end as usize)],
    );
    Ok((new, format!("disconnected `{from}` → `{to}`")))
}

fn move_module(text: &str, path: &str, to: &str) -> Result<(String, String), String> {
    let root = parse(text)?;
    let module = find_module(&root, path)?;
    let name = module.value("name").unwrap_or_default().to_owned();
    let target = *find(&root, to)?.last().expect("root");
    if !SCOPES.contains(&target.name.as_str()) {
        return Err(format!(
            "`{to}` is a <{}>; a module moves into a <thread>, <group> or <part>",
            target.name
        ));
    }
    let new_path = format!("{to}/{name}");
    if new_path == path {
        return Err(format!("`{path}` is in `{to}` already"));
    }
    if find(&root, &new_path).is_ok() {
        return Err(format!("`{new_path}` exists already"));
    }
    // Its lines lose their old indentation; the insertion gives them the new one.
    let old_indent = indent_at(text, module.span.start as usize);
    let snippet = (text[module.span.start as usize..module.span.end as usize].split('\n'))
        .enumerate()
        .map(|(i, line)| match i {
            0 => line,
            _ => line.strip_prefix(old_indent.as_str()).unwrap_or(line),
        })
        .collect::<Vec<_>>()
        .join("\n");
    // Its connections, to be written again with the new path.
    let mut moved = Vec::new();
    let mut spans = vec![(module.span.start as usize, module.span.end as usize)];
    for c in connects(&root) {
        if !(joins(&c.from, path) || joins(&c.to, path)) {
            continue;
        }
        let start = c.el.span.start as usize;
        let rel = |name: &str| {
            let a = c.el.attr(name).expect("a connect has from and to");
            (
                a.value_span.start as usize - start,
                a.value_span.end as usize - start,
            )
        };
        let renamed = |end: &str| match joins(end, path) {
            true => format!("{new_path}{}", &end[path.len()..]),
            false => end.to_owned(),
        };
        moved.push((
            text[start..c.el.span.end as usize].to_owned(),
            rel("from"),
            rel("to"),
            renamed(&c.from),
            renamed(&c.to),
        ));
        spans.push((start, c.el.span.end as usize));
    }
    let mut new = remove_spans(text, spans);
    let root = parse(&new)?;
    let target = *find(&root, to)?.last().expect("root");
    new = insert_child(&new, target, &snippet, "module")?;
    for (t, f, o, from, to) in &moved {
        new = connect(&new, from, to, Some((t, *f, *o)))?.0;
    }
    Ok((
        new,
        format!(
            "moved `{path}` to `{new_path}` with {} connection(s)",
            moved.len()
        ),
    ))
}

fn set(text: &str, param: &str, value: &str) -> Result<(String, String), String> {
    let root = parse(text)?;
    let (module_path, name) = param
        .rsplit_once('/')
        .ok_or_else(|| format!("`{param}`: write MODULE/PATH/NAME"))?;
    let module = find_module(&root, module_path)?;
    let line = format!("`{param}` = {value}");
    let existing = module
        .children_named("param")
        .find(|p| p.value("name") == Some(name));
    let Some(p) = existing else {
        let snippet = format!("<param name=\"{}\">{}</param>", attr(name), content(value));
        return Ok((insert_child(text, module, &snippet, "param")?, line));
    };
    if let Some(by) = ["config", "cmdline"]
        .into_iter()
        .find(|a| p.attr(a).is_some())
    {
        return Err(format!(
            "`{param}` takes its value from `{by}=`; the saved model cannot keep a value set at run time there"
        ));
    }
    let (start, end) = (p.span.start as usize, p.span.end as usize);
    let tag = &text[start..start_tag_end(text, p)?];
    let open = match tag.strip_suffix("/>") {
        Some(head) => format!("{}>", head.trim_end()),
        None => tag.to_owned(),
    };
    let replacement = format!("{open}{}</param>", content(value));
    let mut new = text.to_owned();
    new.replace_range(start..end, &replacement);
    Ok((new, line))
}
