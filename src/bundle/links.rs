//! The parts of a generated `main.rs` that concern other parts: where every part
//! listens, the periods that keep lockstep programs in step, and the two ends of each
//! connection between parts (`Builder::link_out` in the writer's program,
//! `Builder::link_in` in the reader's), each link a named constant.

use super::code::{Code, LIST_WIDTH, MAX_WIDTH};
use super::layout::Part;
use super::literals::{call, duration, float};
use super::text::{comment, rust_str};
use ferroc_compiler::ir::SharedMemory;
use ferroc_compiler::plan::{Part as ValuePart, PlannedCall, PlannedConnection, PlannedLink};
use ferroc_runtime::link::Sharing;
use std::time::Duration;

/// `Conversion::default()` or the one-line chain of a connection's conversion.
pub fn conversion(c: &PlannedConnection) -> String {
    if c.scale == 1.0 && c.offset == 0.0 && c.select.is_empty() {
        return "Conversion::default()".into();
    }
    // One line, as rustfmt leaves a short method chain.
    let mut line = format!(
        "Conversion::linear({}, {})",
        float(c.scale),
        float(c.offset)
    );
    for part in &c.select {
        match part {
            ValuePart::Field(f) => line.push_str(&format!(".field({})", rust_str(f))),
            ValuePart::Index(i) => line.push_str(&format!(".index({i})")),
        }
    }
    line
}

/// `PARTS` (when the part is linked to others) and `PERIODS`, the constants `main`
/// gives the runtime.
pub fn constants(out: &mut Code, parts: &[(String, String)], periods: &[Duration], linked: bool) {
    if linked {
        out.blank();
        out.line(
            0,
            "/// Every part of the application and where it listens (`--peer PART=HOST:PORT`",
        );
        out.line(
            0,
            "/// says otherwise, `--local` puts every part on this computer).",
        );
        let entries: Vec<String> = parts
            .iter()
            .map(|(name, address)| format!("({}, {})", rust_str(name), rust_str(address)))
            .collect();
        out.list(0, "const PARTS: &[(&str, &str)] = &[", &entries, "];");
    }
    out.blank();
    out.line(
        0,
        "/// The periods of all periodic thread containers of the application: lockstep",
    );
    out.line(
        0,
        "/// programs step through the same instants of model time.",
    );
    let periods: Vec<String> = periods.iter().map(|p| duration(*p)).collect();
    out.list(0, "const PERIODS: &[Duration] = &[", &periods, "];");
}

/// `SHARED_MEMORY`: the part's `<part shared-memory…>` settings, which `main` gives
/// its Zenoh network (a `--zenoh-config` file that sets the same key wins).
pub fn shared_memory(out: &mut Code, settings: &SharedMemory) {
    let option = |v: Option<String>| v.map_or_else(|| "None".to_string(), |v| format!("Some({v})"));
    out.blank();
    out.line(
        0,
        "/// `<part shared-memory…>` of the model (docs/zenoh.md); `--zenoh-config` wins.",
    );
    out.line(0, "const SHARED_MEMORY: ModelShm = ModelShm {");
    let fields = [
        ("enabled", settings.enabled.map(|b| b.to_string())),
        ("threshold", settings.threshold.map(|b| b.to_string())),
        ("pool", settings.pool.map(|b| b.to_string())),
    ];
    for (name, value) in fields {
        out.line(1, &format!("{name}: {},", option(value)));
    }
    out.line(0, "};");
}

fn constant_name(link: &PlannedLink) -> String {
    format!("LINK_{}", link.id)
}

/// One `const LINK_n: LinkSpec` for every link of the part, in link order.
pub fn specs(out: &mut Code, part: &Part<'_>) {
    // (link, from, to) of every link with an end here, data and parameter links.
    let mut links: Vec<(&PlannedLink, String, String)> = Vec::new();
    for c in part.links_out.iter().chain(&part.links_in) {
        if let Some(link) = &c.link {
            links.push((
                link,
                format!("{}/{}", c.from.0, c.from.1),
                format!("{}/{}", c.to.0, c.to.1),
            ));
        }
    }
    for p in part.param_links_out.iter().chain(&part.param_links_in) {
        if let Some(link) = &p.link {
            links.push((
                link,
                format!("{}/{}", p.from.0, p.from.1),
                format!("{}/param/{}", p.to.0, p.to.1),
            ));
        }
    }
    links.sort_by_key(|(link, ..)| link.id);
    for (link, from, to) in links {
        out.blank();
        out.line(0, &format!("/// `{}` → `{}`", comment(&from), comment(&to)));
        out.line(
            0,
            &format!("const {}: LinkSpec = LinkSpec {{", constant_name(link)),
        );
        // The same spec `ferroc run` gives the runtime, written out.
        let wire = crate::from_plan::link(link);
        let spec = ferroc_runner::from_plan::link_spec(&wire);
        out.line(1, &format!("id: {},", spec.id));
        out.line(1, &format!("from_part: {},", rust_str(spec.from_part)));
        out.line(1, &format!("to_part: {},", rust_str(spec.to_part)));
        out.line(1, &format!("model_type: {},", rust_str(spec.model_type)));
        match spec.sharing {
            Sharing::OnChange { min_interval } => {
                out.line(1, "sharing: Sharing::OnChange {");
                out.line(2, &format!("min_interval: {},", duration(min_interval)));
                out.line(1, "},");
            }
            Sharing::Periodic(period) => {
                out.line(
                    1,
                    &format!("sharing: Sharing::Periodic({}),", duration(period)),
                );
            }
        }
        out.line(1, &format!("reliable: {},", spec.reliable));
        match spec.deadline {
            Some(d) => out.line(1, &format!("deadline: Some({}),", duration(d))),
            None => out.line(1, "deadline: None,"),
        }
        out.line(0, "};");
    }
}

/// One `const CALL_n: CallSpec` for every service call crossing to or from the part.
pub fn call_specs(out: &mut Code, part: &Part<'_>) {
    let mut calls: Vec<&PlannedCall> = part
        .calls_out
        .iter()
        .chain(&part.calls_in)
        .copied()
        .collect();
    calls.sort_by_key(|c| c.link.as_ref().map(|l| l.id));
    for c in calls {
        let Some(link) = &c.link else { continue };
        out.blank();
        out.line(
            0,
            &format!(
                "/// `{}/{}` calls `{}/{}`",
                comment(&c.client.0),
                comment(&c.client.1),
                comment(&c.service.0),
                comment(&c.service.1)
            ),
        );
        out.line(
            0,
            &format!("const CALL_{}: CallSpec = CallSpec {{", link.id),
        );
        out.line(1, &format!("id: {},", link.id));
        out.line(1, &format!("client_part: {},", rust_str(&link.client_part)));
        out.line(1, &format!("server_part: {},", rust_str(&link.server_part)));
        let service = format!("{}/{}", c.service.0, c.service.1);
        out.line(1, &format!("service: {},", rust_str(&service)));
        out.line(0, "};");
    }
}

/// The `link_out` / `link_in` calls of `build`.
pub fn calls(
    body: &mut Code,
    part: &Part<'_>,
    at: &dyn Fn(ferroc_compiler::source::Span) -> String,
    name_of: &dyn Fn(&str) -> String,
) {
    let end = |(module, port): &(String, String)| call("", &[name_of(module), rust_str(port)]);
    for c in &part.links_out {
        let Some(link) = &c.link else { continue };
        let what = format!("to the part `{}`, {}", link.to_part, comment(&at(c.span)));
        let args = [
            format!("&{}", constant_name(link)),
            end(&c.from),
            conversion(c),
        ];
        commented_call(body, &what, "builder.link_out", &args);
    }
    for p in &part.param_links_out {
        let Some(link) = &p.link else { continue };
        let what = format!(
            "to a parameter in the part `{}`, {}",
            link.to_part,
            comment(&at(p.span))
        );
        let args = [
            format!("&{}", constant_name(link)),
            end(&p.from),
            format!("Conversion::linear({}, 0.0)", float(p.scale)),
        ];
        commented_call(body, &what, "builder.link_out", &args);
    }
    for p in &part.param_links_in {
        let Some(link) = &p.link else { continue };
        let what = format!(
            "set from the part `{}`, {}",
            link.from_part,
            comment(&at(p.span))
        );
        let args = [format!("&{}", constant_name(link)), end(&p.to)];
        commented_call(body, &what, "builder.link_in_param", &args);
    }
    for c in &part.calls_out {
        let Some(link) = &c.link else { continue };
        let what = format!(
            "calls the part `{}`, {}",
            link.server_part,
            comment(&at(c.span))
        );
        let args = [format!("&CALL_{}", link.id), end(&c.client)];
        commented_call(body, &what, "builder.call_out", &args);
    }
    for c in &part.calls_in {
        let Some(link) = &c.link else { continue };
        let what = format!(
            "called from the part `{}`, {}",
            link.client_part,
            comment(&at(c.span))
        );
        let args = [format!("&CALL_{}", link.id), end(&c.service)];
        commented_call(body, &what, "builder.call_in", &args);
    }
    for c in &part.links_in {
        let Some(link) = &c.link else { continue };
        let what = format!(
            "from the part `{}`, {}",
            link.from_part,
            comment(&at(c.span))
        );
        let args = [
            format!("&{}", constant_name(link)),
            end(&c.to),
            "ConnectOptions::default()".into(),
        ];
        commented_call(body, &what, "builder.link_in", &args);
    }
}

/// After a blank line, `// what` and `head(args)?;` in `build`.
fn commented_call(body: &mut Code, what: &str, head: &str, args: &[String]) {
    body.blank();
    body.line(1, &format!("// {what}"));
    method_call(body, head, args);
}

/// `head(args)?;` in `build` (indent 1): on one line when the arguments fit rustfmt's
/// `fn_call_width` and the line its width, else one argument a line.
fn method_call(body: &mut Code, head: &str, args: &[String]) {
    let joined = args.join(", ");
    let line = format!("{head}({joined})?;");
    if joined.len() <= LIST_WIDTH && !joined.contains('\n') && 4 + line.len() <= MAX_WIDTH {
        body.line(1, &line);
        return;
    }
    body.line(1, &format!("{head}("));
    for a in args {
        body.line(2, &format!("{a},"));
    }
    body.line(1, ")?;");
}
