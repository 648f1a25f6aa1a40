//! Timing attributes: thread priority and pinning, host cores, the utilisation warning
//! threshold and `<flow>` requirements (read by the S checks, `checks/scheduling/`).

use super::Resolver;
use crate::checks::{m108_invalid_attribute_value, m110_unresolved_path};
use crate::ir::*;
use ferroc_diagnostics::diagnostic::Diagnostic;
use ferroc_diagnostics::source::Span;
use ferroc_syntax::Element;
use ferroc_values::values::parse_duration;

impl Resolver<'_, '_, '_> {
    /// `priority` and `cpu` of a thread container.
    pub(super) fn thread_timing(&mut self, id: ElementId, e: &Element) {
        if let Some(p) = count(e, "priority") {
            self.app.timing.priority.insert(id, p);
        }
        if let Some(c) = count(e, "cpu") {
            self.app.timing.cpu.insert(id, c);
        }
    }

    /// `cores` of a part.
    pub(super) fn part_timing(&mut self, id: ElementId, e: &Element) {
        if let Some(c) = count(e, "cores") {
            if c.0 == 0 {
                self.invalid(
                    c.1,
                    "a host has at least one core",
                    "write cores=\"1\" or more",
                );
            } else {
                self.app.timing.cores.insert(id, c);
            }
        }
    }

    /// `utilisation-warning` and the `<flow>`s of the application element.
    pub(super) fn application_timing(&mut self, root: &Element) {
        if let Some(a) = root.attr("utilisation-warning") {
            match percent(a.value) {
                Some(f) => self.app.timing.warning = Some((f, a.value_span)),
                None => self.invalid(
                    a.value_span,
                    &format!("`{}` is not a utilisation threshold", a.value),
                    "write a percentage between 1% and 100%, e.g. utilisation-warning=\"80%\"",
                ),
            }
        }
        for f in root.children_named("flow") {
            self.flow(f);
        }
    }

    fn flow(&mut self, f: &Element) {
        let (Some(name), Some(from), Some(to), Some(max)) = (
            f.value("name"),
            f.attr("from"),
            f.attr("to"),
            f.attr("max-latency"),
        ) else {
            return; // M104 reported the missing attribute
        };
        let max_latency = match parse_duration(max.value) {
            Ok(s) if s > 0.0 => (s, max.value_span),
            _ => {
                self.invalid(
                    max.value_span,
                    &format!("`{}` is not a positive duration", max.value),
                    "write e.g. max-latency=\"50ms\"",
                );
                return;
            }
        };
        let from_m = self.flow_end(from.value, from.value_span);
        let to_m = self.flow_end(to.value, to.value_span);
        if let (Some(from_m), Some(to_m)) = (from_m, to_m) {
            self.app.timing.flows.push(Flow {
                name: name.to_string(),
                span: f.name_span,
                from: from_m,
                from_span: from.value_span,
                to: to_m,
                to_span: to.value_span,
                max_latency,
            });
        }
    }

    /// A flow end: a module, or a port of a module (which stands for its module).
    fn flow_end(&mut self, path: &str, span: Span) -> Option<ElementId> {
        let mut cur = ElementId(0);
        for seg in path.split('/') {
            match self.app.child(cur, seg) {
                Some(c) => cur = c,
                None => break,
            }
        }
        if cur != ElementId(0) && self.app.path(cur) == path {
            if let ElementKind::Module(_) = self.app.element(cur).kind {
                return Some(cur);
            }
        }
        match self.resolve_path(ElementId(0), path, span)?.0 {
            Endpoint::Port { element, .. } | Endpoint::Param { element, .. } => Some(element),
            Endpoint::GroupPort { .. } => {
                self.loader.diags.push(
                    Diagnostic::new(
                        &m110_unresolved_path::CHECK,
                        span,
                        format!("`{path}` is a group port; a flow starts and ends at a module"),
                    )
                    .label("group port")
                    .help("name the module (or a module's port) inside the group"),
                );
                None
            }
        }
    }

    pub(super) fn invalid(&mut self, span: Span, msg: &str, help: &str) {
        self.loader.diags.push(
            Diagnostic::new(&m108_invalid_attribute_value::CHECK, span, msg.to_string())
                .label("invalid value")
                .help(help.to_string()),
        );
    }
}

/// A non-negative integer attribute (the validator reported malformed ones).
fn count(e: &Element, name: &str) -> Option<(u32, Span)> {
    let a = e.attr(name)?;
    Some((a.value.trim().parse().ok()?, a.value_span))
}

/// `80%` or `0.8` as a fraction in (0, 1].
fn percent(text: &str) -> Option<f64> {
    let t = text.trim();
    let f = match t.strip_suffix('%') {
        Some(p) => p.trim().parse::<f64>().ok()? / 100.0,
        None => t.parse::<f64>().ok()?,
    };
    (f > 0.0 && f <= 1.0).then_some(f)
}

#[cfg(test)]
mod tests {
    #[test]
    fn percentages() {
        assert_eq!(super::percent("80%"), Some(0.8));
        assert_eq!(super::percent("0.5"), Some(0.5));
        assert_eq!(super::percent("100 %"), Some(1.0));
        assert_eq!(super::percent("0%"), None);
        assert_eq!(super::percent("120%"), None);
        assert_eq!(super::percent("high"), None);
    }
}
