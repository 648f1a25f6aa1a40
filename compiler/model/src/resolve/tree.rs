//! The element tree: parts, thread containers (their `period`, `trigger`, `wait`),
//! groups and modules in document order, each element registered under its parent's
//! name scope; `<connect>`s are set aside until the tree is complete.

use super::{Context, PendingConnect, Resolver};
use crate::checks::*;
use crate::ir::*;
use crate::library::LibraryId;
use ferroc_diagnostics::diagnostic::Diagnostic;
use ferroc_diagnostics::source::Span;
use ferroc_syntax::Element;
use ferroc_values::values::parse_duration;

impl<'r, 'l, 't> Resolver<'r, 'l, 't> {
    pub(super) fn add_element(
        &mut self,
        parent: ElementId,
        element: &Element,
        kind: ElementKind,
        instantiated_at: Option<Span>,
    ) -> Option<ElementId> {
        let name = element.value("name")?.to_string();
        let id = ElementId(self.app.elements.len() as u32);
        let name_span = element.value_span("name");
        if let Some(existing) = self.app.child(parent, &name).as_ref() {
            let first = self.app.element(*existing).name_span;
            self.duplicate(name_span, first, &format!("`{name}`"));
            return None;
        }
        let p = self.app.element(parent);
        let (mut thread, mut part) = (p.thread, p.part);
        match kind {
            ElementKind::Thread { .. } => thread = Some(id),
            ElementKind::Part { .. } => part = Some(id),
            _ => {}
        }
        self.app.elements.push(ElementNode {
            kind,
            name,
            parent: Some(parent),
            name_span,
            span: element.span,
            instantiated_at,
            group_ports: Vec::new(),
            thread,
            part,
        });
        self.app.children.insert(&self.app.elements, id);
        Some(id)
    }

    pub(super) fn walk(
        &mut self,
        scope: ElementId,
        element: &'t Element,
        visible: &'t [LibraryId],
        inst: Option<Span>,
        depth: usize,
    ) {
        for child in &element.children {
            match child.name.as_str() {
                "part" => {
                    let host = child
                        .attr("host")
                        .map(|a| (a.value.to_string(), a.value_span));
                    if let Some(id) =
                        self.add_element(scope, child, ElementKind::Part { host }, inst)
                    {
                        self.part_timing(id, child);
                        self.part_shared_memory(id, child);
                        self.walk(id, child, visible, inst, depth);
                        self.part_ros2(id, child);
                    }
                }
                "thread" => {
                    let period = self.thread_period(child);
                    let kind = ElementKind::Thread {
                        period,
                        pool: child
                            .value("pool")
                            .and_then(|p| p.parse().ok())
                            .filter(|n: &u32| *n >= 2),
                        data_trigger: child.value("trigger") == Some("data"),
                        continuous: child.value("trigger") == Some("continuous"),
                        wait: self.thread_wait(child),
                    };
                    if let Some(id) = self.add_element(scope, child, kind, inst) {
                        self.thread_timing(id, child);
                        self.walk(id, child, visible, inst, depth);
                    }
                }
                "group" => self.group(scope, child, visible, inst, depth),
                "module" => self.module(scope, child, visible, inst),
                "connect" => {
                    let context = Context {
                        instantiated_at: inst,
                        visible,
                    };
                    if !self.contexts.last().is_some_and(|c| c.same(&context)) {
                        self.contexts.push(context);
                    }
                    self.pending.push(PendingConnect {
                        element: child,
                        scope,
                        context: (self.contexts.len() - 1) as u32,
                    });
                }
                _ => {}
            }
        }
    }

    /// `wait=`: only a data-triggered container waits for data; on any other the
    /// attribute would silently do nothing, so it is a finding (M108).
    fn thread_wait(&mut self, thread: &Element) -> crate::ir::Wait {
        let Some(wait) = thread.attr("wait") else {
            return crate::ir::Wait::default();
        };
        if thread.value("trigger") != Some("data") {
            self.loader.diags.push(
                Diagnostic::new(
                    &m108_invalid_attribute_value::CHECK,
                    wait.name_span,
                    format!(
                        "`wait` applies only to data-triggered containers, and `{}` is not one",
                        thread.value("name").unwrap_or("")
                    ),
                )
                .label("has no effect here")
                .help("remove `wait`, or add trigger=\"data\" if the container should run when data arrives"),
            );
        }
        crate::ir::Wait::parse(wait.value).unwrap_or_default()
    }

    fn thread_period(&mut self, thread: &Element) -> Option<f64> {
        let period = thread.attr("period");
        let trigger = thread.attr("trigger");
        let bad = |msg: String, span: Span, help: &str| {
            Diagnostic::new(&m108_invalid_attribute_value::CHECK, span, msg)
                .label("here")
                .help(help.to_string())
        };
        match (period, trigger) {
            (Some(_), Some(t)) => {
                self.loader.diags.push(bad(
                    "a thread container is either periodic or triggered, not both".into(),
                    t.name_span,
                    "remove `trigger` or `period`",
                ));
                None
            }
            (None, None) => {
                self.loader.diags.push(bad(
                    format!("thread container `{}` has neither `period` nor `trigger`", thread.value("name").unwrap_or("")),
                    thread.name_span,
                    "add period=\"10ms\" (periodic), trigger=\"data\" (runs when inputs receive data) or trigger=\"continuous\" (cycles back to back)",
                ));
                None
            }
            (Some(p), None) => match parse_duration(p.value) {
                Ok(s) if s > 0.0 && s <= 60.0 => Some(s),
                Ok(_) => {
                    self.loader.diags.push(bad(
                        format!("period `{}` is outside 0 < period <= 60 s", p.value),
                        p.value_span,
                        "use a period such as `10ms` or `1s`",
                    ));
                    None
                }
                Err(_) => {
                    self.loader.diags.push(bad(
                        format!("`{}` is not a duration", p.value),
                        p.value_span,
                        "write e.g. `10ms`, `1.5s`, `250us` or `PT0.04S`",
                    ));
                    None
                }
            },
            (None, Some(_)) => None,
        }
    }
}
