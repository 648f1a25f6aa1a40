//! Paths and connections: `robot/control/laser/scan`, `planner/param/max_speed`, `vec[2]`.

use super::{PendingConnect, Resolver};
use crate::checks::m110_unresolved_path;
use crate::ir::*;
use ferroc_diagnostics::diagnostic::{did_you_mean, Diagnostic};
use ferroc_diagnostics::source::Span;
use ferroc_syntax::Element;

/// A resolved path: the endpoint and an optional element index.
pub(super) type Resolved = (Endpoint, Option<u32>);

impl<'r, 'l, 't> Resolver<'r, 'l, 't> {
    pub(super) fn resolve_connect(&mut self, p: PendingConnect<'t>) {
        let e = p.element;
        let context = self.contexts[p.context as usize];
        let (Some(from), Some(to)) = (e.attr("from"), e.attr("to")) else {
            return;
        };
        let from_r = self.resolve_path(p.scope, from.value, from.value_span);
        let to_r = self.resolve_path(p.scope, to.value, to.value_span);
        let (Some((from_ep, from_index)), Some((to_ep, to_index))) = (from_r, to_r) else {
            // The end that resolved was meant to be connected: no "not connected" finding
            // for it on top of the one about the other end.
            if let Some((ep, _)) = from_r.or(to_r) {
                self.app.cut_off.insert(ep);
            }
            return;
        };
        let mut converts = Vec::new();
        for c in e.children_named("convert") {
            let number = |name: &str, this: &mut Self| -> Option<(f64, Span)> {
                let a = c.attr(name)?;
                match a.value.trim().parse::<f64>() {
                    Ok(v) if v.is_finite() => Some((v, a.value_span)),
                    _ => {
                        this.loader.diags.push(
                            Diagnostic::new(
                                &ferroc_syntax::checks::m108_invalid_attribute_value::CHECK,
                                a.value_span,
                                format!("`{}` is not a number", a.value),
                            )
                            .label("expected a number")
                            .help(format!("write {name}=\"1000\" or similar")),
                        );
                        None
                    }
                }
            };
            let scale = number("scale", self);
            let offset = number("offset", self);
            let to_type = c.attr("to-type").and_then(|a| {
                self.libs
                    .resolve_type(a.value, a.value_span, context.visible, self.loader.diags)
                    .map(|t| (t, a.value_span))
            });
            converts.push(ConvertStep {
                span: c.name_span,
                index: c
                    .attr("index")
                    .and_then(|a| Some((a.value.parse().ok()?, a.value_span))),
                field: c.attr("field").map(|a| (a.value.to_string(), a.value_span)),
                scale,
                offset,
                to_type,
            });
        }
        let index = self.app.connections.len();
        self.app.connections.push(Connection {
            from: from_ep,
            to: to_ep,
            from_index,
            to_index,
            span: e.name_span,
            from_span: from.value_span,
            to_span: to.value_span,
            // Over the limit is reported (M116) when the file is validated.
            queue: (e.value("queue").and_then(|q| q.parse::<u32>().ok()))
                .map(|q| q.min(ferroc_syntax::vocabulary::MAX_QUEUE)),
            on_full: e.value("on-full").map(str::to_string),
            delay: e.value("delay") == Some("1"),
            initial: e.value("initial").and_then(|q| q.parse().ok()).unwrap_or(0),
            link: link_settings(e),
            converts,
            instantiated_at: context.instantiated_at,
            scope: p.scope,
        });
        let a = self.node(from_ep);
        let b = self.node(to_ep);
        self.app.graph.add_edge(a, b, index);
    }

    fn node(&mut self, ep: Endpoint) -> petgraph::graph::NodeIndex {
        self.app.nodes.get_or_add(&mut self.app.graph, ep)
    }

    fn unresolved(&mut self, span: Span, path: &str, msg: String, help: String) {
        self.loader.diags.push(
            Diagnostic::new(
                &m110_unresolved_path::CHECK,
                span,
                format!("`{path}` does not resolve: {msg}"),
            )
            .label("unresolved path")
            .help(help),
        );
    }

    /// Walks a path from `scope`. Reports and returns `None` when it does not resolve.
    pub(super) fn resolve_path(
        &mut self,
        scope: ElementId,
        path: &str,
        span: Span,
    ) -> Option<Resolved> {
        let segments: Vec<&str> = path.split('/').collect();
        if path.is_empty() || segments.iter().any(|s| s.is_empty()) {
            self.unresolved(
                span,
                path,
                "empty path segment".into(),
                "write names joined by single `/`, without leading or trailing `/`".into(),
            );
            return None;
        }
        let mut current = scope;
        for (i, seg) in segments.iter().enumerate() {
            if self.broken_groups.contains(&current) {
                return None;
            }
            let rest = &segments[i..];
            let (name, index) = split_index(seg);
            if rest.len() == 1 {
                // Bare name: a port of the current group (or of the scope itself).
                if let Some(k) = self
                    .app
                    .element(current)
                    .group_ports
                    .iter()
                    .position(|p| p.name == name)
                {
                    return self.indexed(
                        Endpoint::GroupPort {
                            element: current,
                            port: k as u32,
                        },
                        index,
                        span,
                        path,
                    );
                }
            }
            if let Some(child) = self.app.child(current, seg) {
                current = child;
                if let ElementKind::Module(_) = self.app.element(current).kind {
                    return self.module_endpoint(current, &segments[i + 1..], span, path);
                }
                continue;
            }
            if self.broken.contains(&(current, name.to_string())) {
                return None;
            }
            self.no_such_element(current, name, span, path);
            return None;
        }
        let what = self.app.path(current);
        self.unresolved(
            span,
            path,
            format!("`{what}` is an element, not a port"),
            "name a port of a module, or a group's interface port".into(),
        );
        None
    }

    fn module_endpoint(
        &mut self,
        module: ElementId,
        rest: &[&str],
        span: Span,
        path: &str,
    ) -> Option<Resolved> {
        let libs = self.libs;
        let module_path = self.app.path(module);
        if rest.is_empty() {
            self.unresolved(
                span,
                path,
                format!("`{module_path}` is a module, not a port"),
                "append the port name, e.g. `…/module/port`".into(),
            );
            return None;
        }
        if rest[0] == "param" && rest.len() == 2 {
            return self.param_endpoint(module, rest[1], span, path);
        }
        let joined = rest.join("/");
        let (name, index) = split_index(&joined);
        let found = self
            .app
            .module_ports(libs, module)
            .find(|(_, p)| p.name == name)
            .map(|(k, _)| k);
        match found {
            Some(k) => self.indexed(
                Endpoint::Port {
                    element: module,
                    port: k,
                },
                index,
                span,
                path,
            ),
            None => {
                self.no_such_port(module, name, span, path);
                None
            }
        }
    }

    /// Reports that `current` has no element or port `name`, with the names it has.
    fn no_such_element(&mut self, current: ElementId, name: &str, span: Span, path: &str) {
        let here = self.app.path(current);
        let mut candidates: Vec<String> =
            self.app.child_names(current).map(str::to_string).collect();
        candidates.extend(
            self.app
                .element(current)
                .group_ports
                .iter()
                .map(|p| p.name.clone()),
        );
        candidates.sort();
        let hint = did_you_mean(name, candidates.iter().map(String::as_str));
        let where_ = if here.is_empty() {
            "the top level".to_string()
        } else {
            format!("`{here}`")
        };
        let help = match hint {
            Some(h) => format!("did you mean `{h}`?"),
            None if candidates.is_empty() => format!("{where_} contains nothing of that name"),
            None => format!("{where_} contains: {}", candidates.join(", ")),
        };
        self.unresolved(
            span,
            path,
            format!("{where_} has no element or port `{name}`"),
            help,
        );
    }

    /// `module/param/name`: a parameter of the module's type.
    fn param_endpoint(
        &mut self,
        module: ElementId,
        param: &str,
        span: Span,
        path: &str,
    ) -> Option<Resolved> {
        let mt = self.app.module_type(self.libs, module)?;
        if let Some(k) = mt.params.iter().position(|p| p.name == param) {
            return Some((
                Endpoint::Param {
                    element: module,
                    param: k as u32,
                },
                None,
            ));
        }
        let hint = did_you_mean(param, mt.params.iter().map(|p| p.name.as_str()));
        self.unresolved(
            span,
            path,
            format!(
                "module type `{}` has no parameter `{}`",
                mt.qualified, param
            ),
            hint.map_or(
                "see the module type's parameters in its manifest".into(),
                |h| format!("did you mean `param/{h}`?"),
            ),
        );
        None
    }

    /// Reports that `module` has no port `name`, with the ports it has.
    fn no_such_port(&mut self, module: ElementId, name: &str, span: Span, path: &str) {
        let module_path = self.app.path(module);
        let names: Vec<String> = self
            .app
            .module_ports(self.libs, module)
            .map(|(_, p)| p.name.clone())
            .collect();
        let hint = did_you_mean(name, names.iter().map(String::as_str));
        let type_name = self
            .app
            .module_type(self.libs, module)
            .map_or(String::new(), |m| m.qualified.clone());
        self.unresolved(
            span,
            path,
            format!("module `{module_path}` ({type_name}) has no port `{name}`"),
            match hint {
                Some(h) => format!("did you mean `{h}`?"),
                None => format!("its ports are: {}", names.join(", ")),
            },
        );
    }

    fn indexed(
        &mut self,
        ep: Endpoint,
        index: Option<Result<u32, ()>>,
        span: Span,
        path: &str,
    ) -> Option<Resolved> {
        match index {
            None => Some((ep, None)),
            Some(Ok(i)) => Some((ep, Some(i))),
            Some(Err(())) => {
                self.unresolved(
                    span,
                    path,
                    "the index in `[…]` is not a number".into(),
                    "write `port[2]` to address element 2".into(),
                );
                None
            }
        }
    }
}

/// The link settings of a `<connect>`, `None` when it writes none of them.
fn link_settings(e: &Element) -> Option<Box<LinkSettings>> {
    const NAMES: [&str; 5] = [
        "sharing",
        "min-interval",
        "period",
        "reliability",
        "deadline",
    ];
    if !e.attrs().any(|a| NAMES.contains(&a.name)) {
        return None;
    }
    let attr_span = |name: &str| e.attr(name).map(|a| a.value_span);
    let seconds = |name: &str| {
        e.value(name)
            .and_then(|v| ferroc_values::values::parse_duration(v).ok())
    };
    Some(Box::new(LinkSettings {
        sharing: e
            .attr("sharing")
            .map(|a| (a.value.to_string(), a.value_span)),
        min_interval: attr_span("min-interval"),
        period: attr_span("period"),
        min_interval_seconds: seconds("min-interval"),
        period_seconds: seconds("period"),
        reliability: attr_span("reliability"),
        reliable: e.value("reliability").map(|r| r == "reliable"),
        deadline: attr_span("deadline"),
        deadline_seconds: seconds("deadline"),
    }))
}

/// `vec[2]` → (`vec`, Some(Ok(2))).
fn split_index(seg: &str) -> (&str, Option<Result<u32, ()>>) {
    match seg.strip_suffix(']').and_then(|s| s.split_once('[')) {
        Some((name, idx)) => (name, Some(idx.trim().parse().map_err(|_| ()))),
        None => (seg, None),
    }
}
