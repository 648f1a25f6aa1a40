//! Does a module type's Rust code declare what its manifest says?
//!
//! A model is checked against library manifests; the binary runs Rust types. If the two
//! disagree (a port renamed in the code, a unit changed in the manifest), the checked
//! model is not the program that would run, so `ferroc run` refuses. Docs and the Rust
//! path are not compared; names, directions, roles, types, units, requirement,
//! parameter ranges, defaults and choices are.

use ferroc_compiler::library::{ModuleKind, ModuleType, PortDir, PortRole, PortType};
use ferroc_compiler::units::{parse_unit, relate, Unit, UnitRelation};
use ferroc_compiler::values::parse_duration;
use ferroc_runtime::module::{Direction, Interface, Kind, PortInfo, Role, ServiceInfo};
use ferroc_runtime::service::Executes;

/// Every difference, one plain sentence each (empty: they agree).
pub fn differences(manifest: &ModuleType, code: &Interface) -> Vec<String> {
    let mut out = Vec::new();
    kind_differences(manifest, code, &mut out);
    port_differences(manifest, code, &mut out);
    flexible_differences(manifest, code, &mut out);
    param_differences(manifest, code, &mut out);
    services(manifest, code, &mut out);
    out
}

/// The module's kind: plain, sense/control, behaviour, fusion.
fn kind_differences(manifest: &ModuleType, code: &Interface, out: &mut Vec<String>) {
    let manifest_kind = match manifest.kind {
        ModuleKind::SenseControl => Kind::SenseControl,
        ModuleKind::Behaviour => Kind::Behaviour,
        ModuleKind::Fusion => Kind::Fusion,
        ModuleKind::Module => Kind::Plain,
    };
    if manifest_kind != code.kind {
        out.push(format!(
            "the manifest says kind `{}`, the code `{}`",
            manifest_kind.as_str(),
            code.kind.as_str()
        ));
    }
}

/// Data and meta ports by name: direction, role, type, unit, requirement; the ports a
/// behaviour has per instance by what its kind implies.
fn port_differences(manifest: &ModuleType, code: &Interface, out: &mut Vec<String>) {
    for port in &manifest.ports {
        let role = match port.role {
            PortRole::Plain => Role::Plain,
            PortRole::Sensor => Role::Sensor,
            PortRole::Controller => Role::Controller,
            PortRole::Meta => Role::Meta,
            // Compared by `services`, with their response types and execution.
            PortRole::Client | PortRole::Service => continue,
        };
        let dir = match port.dir {
            PortDir::In => Direction::In,
            PortDir::Out => Direction::Out,
        };
        let element = role.element(dir);
        let Some(c) = code.port(&port.name) else {
            out.push(format!(
                "the manifest declares <{element} name=\"{}\">, the code has no such port",
                port.name
            ));
            continue;
        };
        if (c.dir, c.role) != (dir, role) {
            out.push(format!(
                "port `{}`: the manifest says <{element}>, the code <{}>",
                port.name,
                c.role.element(c.dir)
            ));
        }
        let manifest_type = match &port.ty {
            PortType::Fixed(ty) => ty.to_string(),
            // `type="$in"`: the type of the instance's flexible group `in`.
            PortType::SameAs(group) => format!("${group}"),
        };
        if !same_type(&manifest_type, &c.model_type) {
            out.push(format!(
                "port `{}`: the manifest says type `{manifest_type}`, the code `{}`",
                port.name, c.model_type
            ));
        }
        if !same_unit(port.unit.as_ref(), c.unit.as_deref()) {
            out.push(format!(
                "port `{}`: the manifest says unit `{}`, the code `{}`",
                port.name,
                port.unit.as_ref().map_or("none".into(), |u| u.text.clone()),
                c.unit.as_deref().unwrap_or("none")
            ));
        }
        if port.required != c.required {
            out.push(format!(
                "port `{}`: required is {} in the manifest, {} in the code",
                port.name, port.required, c.required
            ));
        }
    }
    for c in &code.ports {
        if manifest.port(&c.name).is_none() && !instance_port(manifest, c, out) {
            out.push(format!(
                "the code declares <{} name=\"{}\">, the manifest does not",
                c.role.element(c.dir),
                c.name
            ));
        }
    }
}

/// Parameters by name: type, unit, range, default, choices.
fn param_differences(manifest: &ModuleType, code: &Interface, out: &mut Vec<String>) {
    for param in &manifest.params {
        let Some(c) = code.param(&param.name) else {
            out.push(format!(
                "the manifest declares the parameter `{}`, the code does not",
                param.name
            ));
            continue;
        };
        let what = |field: &str, m: String, k: String| {
            format!(
                "parameter `{}`: the manifest says {field} `{m}`, the code `{k}`",
                param.name
            )
        };
        if !same_type(&param.ty.to_string(), &c.model_type) {
            out.push(what("type", param.ty.to_string(), c.model_type.clone()));
        }
        if !same_unit(param.unit.as_ref(), c.unit.as_deref()) {
            let m = param
                .unit
                .as_ref()
                .map_or("none".into(), |u| u.text.clone());
            out.push(what("unit", m, c.unit.clone().unwrap_or("none".into())));
        }
        if param.min != c.min || param.max != c.max {
            let range = |a: Option<f64>, b: Option<f64>| format!("{}..{}", opt(a), opt(b));
            out.push(what(
                "range",
                range(param.min, param.max),
                range(c.min, c.max),
            ));
        }
        if !same_default(param.default.as_deref(), c.default.as_deref()) {
            let m = param.default.clone().unwrap_or("none".into());
            out.push(what(
                "default",
                m,
                c.default.clone().unwrap_or("none".into()),
            ));
        }
        if param.choices != c.choices {
            out.push(what(
                "choices",
                param.choices.join(" "),
                c.choices.join(" "),
            ));
        }
    }
    for c in &code.params {
        if manifest.param(&c.name).is_none() {
            out.push(format!(
                "the code declares the parameter `{}`, the manifest does not",
                c.name
            ));
        }
    }
}

/// `<flexible port dir same-type min-count max-count>` against the groups the code
/// declares with `Setup::flexible_inputs` / `flexible_outputs`.
fn flexible_differences(manifest: &ModuleType, code: &Interface, out: &mut Vec<String>) {
    for f in &manifest.flexible {
        let Some(c) = code.flexible.iter().find(|c| c.group == f.port) else {
            out.push(format!(
                "the manifest declares <flexible port=\"{}\">, the code has no such group",
                f.port
            ));
            continue;
        };
        let dir = match f.dir {
            PortDir::In => Direction::In,
            PortDir::Out => Direction::Out,
        };
        let what = |field: &str, m: String, k: String| {
            format!(
                "flexible group `{}`: the manifest says {field} `{m}`, the code `{k}`",
                f.port
            )
        };
        if c.dir != dir {
            out.push(what("dir", format!("{dir:?}"), format!("{:?}", c.dir)));
        }
        if c.same_type != f.same_type {
            out.push(what(
                "same-type",
                f.same_type.to_string(),
                c.same_type.to_string(),
            ));
        }
        if c.min_count != f.min_count {
            out.push(what(
                "min-count",
                f.min_count.to_string(),
                c.min_count.to_string(),
            ));
        }
        if c.max_count != f.max_count {
            let text = |m: Option<u32>| m.map_or("none".into(), |m| m.to_string());
            out.push(what("max-count", text(f.max_count), text(c.max_count)));
        }
    }
    for c in &code.flexible {
        if !manifest.flexible.iter().any(|f| f.port == c.group) {
            out.push(format!(
                "the code declares the flexible group `{}`, the manifest does not",
                c.group
            ));
        }
    }
}

/// A `<client>` or `<service>` of the manifest, as the code's services are described.
struct Declared<'m> {
    name: &'m str,
    client: bool,
    request: String,
    response: Option<String>,
    executes: Executes,
    /// Seconds; only for blocking clients.
    timeout: Option<Option<f64>>,
}

/// `<client>`s and `<service>`s: side, request and response types, who executes a
/// service, a blocking client's timeout (the deadlock analysis relies on the last two).
fn services(manifest: &ModuleType, code: &Interface, out: &mut Vec<String>) {
    for m in declared_services(manifest) {
        let Some(c) = code.service(m.name) else {
            out.push(format!(
                "the manifest declares <{} name=\"{}\">, the code has no such {0}",
                side(m.client),
                m.name
            ));
            continue;
        };
        service_differences(&m, c, out);
    }
    for c in &code.services {
        let known = manifest.clients.iter().any(|d| d.name == c.name)
            || manifest.services.iter().any(|d| d.name == c.name);
        if !known {
            out.push(format!(
                "the code declares <{} name=\"{}\">, the manifest does not",
                side(c.client),
                c.name
            ));
        }
    }
}

/// `client` or `service`.
fn side(client: bool) -> &'static str {
    if client {
        "client"
    } else {
        "service"
    }
}

/// The manifest's clients, then its services.
fn declared_services(manifest: &ModuleType) -> Vec<Declared<'_>> {
    let request = |port: usize| match manifest.ports.get(port).map(|p| &p.ty) {
        Some(PortType::Fixed(ty)) => ty.to_string(),
        _ => String::new(),
    };
    let clients = manifest.clients.iter().map(|c| Declared {
        name: &c.name,
        client: true,
        request: request(c.port),
        response: c.response.as_ref().map(|t| t.to_string()),
        executes: Executes::Server,
        timeout: c.blocking.then_some(c.timeout),
    });
    let services = manifest.services.iter().map(|s| Declared {
        name: &s.name,
        client: false,
        request: request(s.port),
        response: s.response.as_ref().map(|t| t.to_string()),
        executes: if s.inline {
            Executes::Caller
        } else {
            Executes::Server
        },
        timeout: None,
    });
    clients.chain(services).collect()
}

/// One client or service the manifest and the code both have.
fn service_differences(m: &Declared<'_>, c: &ServiceInfo, out: &mut Vec<String>) {
    let what = side(m.client);
    if c.client != m.client {
        out.push(format!(
            "`{}`: the manifest says <{what}>, the code <{}>",
            m.name,
            side(c.client)
        ));
        return;
    }
    if !same_type(&m.request, &c.request) {
        out.push(format!(
            "{what} `{}`: the manifest says request `{}`, the code `{}`",
            m.name, m.request, c.request
        ));
    }
    if let Some(response) = &m.response {
        if !same_type(response, &c.response) {
            out.push(format!(
                "{what} `{}`: the manifest says response `{response}`, the code `{}`",
                m.name, c.response
            ));
        }
    }
    if m.executes != c.executes {
        let name = |e: Executes| match e {
            Executes::Server => "server",
            Executes::Caller => "caller",
        };
        out.push(format!(
            "service `{}`: the manifest says executes=\"{}\", the code `{}`",
            m.name,
            name(m.executes),
            name(c.executes)
        ));
    }
    if let Some(timeout) = m.timeout {
        let code_timeout = c.timeout.map(|d| d.as_secs_f64());
        let same = match (timeout, code_timeout) {
            (Some(a), Some(b)) => (a - b).abs() <= 1e-9 * a.abs().max(1.0),
            (a, b) => a.is_none() && b.is_none(),
        };
        if !same {
            let text = |t: Option<f64>| t.map_or("none".to_string(), |s| format!("{s}s"));
            out.push(format!(
                "client `{}`: the manifest says timeout `{}`, the code `{}`",
                m.name,
                text(timeout),
                text(code_timeout)
            ));
        }
    }
}

/// Ports a behaviour has per instance (`inhibition/k`; a fusion's `in/k/activity`,
/// `in/k/target_rating`, `in/k/<channel-in>`): the manifest declares none of them by
/// name, so the code's are compared with what the kind implies. True if `c` is one
/// (differences pushed to `out`).
fn instance_port(manifest: &ModuleType, c: &PortInfo, out: &mut Vec<String>) -> bool {
    if !manifest.is_behaviour() {
        return false;
    }
    let numbered = |prefix: &str| {
        let rest = c.name.strip_prefix(prefix)?;
        let (k, rest) = rest.split_once('/').unwrap_or((rest, ""));
        k.parse::<u32>().ok().map(|_| rest)
    };
    let ty = if numbered("inhibition/") == Some("") {
        "Inhibition"
    } else if manifest.kind != ModuleKind::Fusion {
        return false;
    } else {
        match numbered("in/") {
            Some("activity") => "Activity",
            Some("target_rating") => "TargetRating",
            Some(data) => match manifest.channel_in.iter().find(|p| p.name == data) {
                Some(decl) => {
                    let PortType::Fixed(ty) = &decl.ty else {
                        return true;
                    };
                    let ty = ty.to_string();
                    if c.dir != Direction::In {
                        out.push(format!("channel port `{}` must be an input", c.name));
                    }
                    if !same_type(&ty, &c.model_type) {
                        out.push(format!(
                            "channel port `{}`: the manifest's <channel-in name=\"{data}\"> says type `{ty}`, the code `{}`",
                            c.name, c.model_type
                        ));
                    }
                    if !same_unit(decl.unit.as_ref(), c.unit.as_deref()) {
                        out.push(format!(
                            "channel port `{}`: the manifest's <channel-in name=\"{data}\"> says unit `{}`, the code `{}`",
                            c.name,
                            decl.unit.as_ref().map_or("none".into(), |u| u.text.clone()),
                            c.unit.as_deref().unwrap_or("none")
                        ));
                    }
                    return true;
                }
                None => return false,
            },
            None => return false,
        }
    };
    if c.dir != Direction::In || c.role != Role::Meta || c.model_type != ty {
        out.push(format!(
            "port `{}`: a behaviour's per-instance port is a meta input of type `{ty}`, the code declares <{}> of type `{}`",
            c.name,
            c.role.element(c.dir),
            c.model_type
        ));
    }
    true
}

fn opt(x: Option<f64>) -> String {
    x.map_or(String::new(), |v| v.to_string())
}

/// `Pose2D` in a manifest means its own library's type: the code says it qualified.
fn same_type(manifest: &str, code: &str) -> bool {
    manifest == code
        || code
            .rsplit_once('.')
            .is_some_and(|(_, bare)| bare == manifest)
}

fn same_unit(manifest: Option<&Unit>, code: Option<&str>) -> bool {
    match (manifest, code.map(parse_unit)) {
        (None, None) => true,
        (Some(m), Some(Ok(c))) => relate(m, &c) == UnitRelation::Same,
        _ => false,
    }
}

/// Defaults compare as numbers where both are numbers (`0.5` = `.5`), as durations
/// where both are durations (a manifest's `200ms` is the `0.2s` a Rust `Duration`
/// default writes), else as text.
fn same_default(manifest: Option<&str>, code: Option<&str>) -> bool {
    match (manifest, code) {
        (Some(m), Some(c)) => match (m.trim().parse::<f64>(), c.trim().parse::<f64>()) {
            (Ok(a), Ok(b)) => a == b,
            _ => match (parse_duration(m), parse_duration(c)) {
                // `200ms` is 200 × 0.001 s: equal up to rounding.
                (Ok(a), Ok(b)) => (a - b).abs() <= 1e-12 * a.abs().max(b.abs()),
                _ => m.trim() == c.trim(),
            },
        },
        (m, c) => m == c,
    }
}

#[cfg(test)]
#[path = "interface_tests.rs"]
mod tests;
