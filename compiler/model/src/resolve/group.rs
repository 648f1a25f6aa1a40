//! Groups: plain groups, instances of group types (local ones and those of libraries,
//! with the recursion and depth guards) and the interface ports a group declares.

use super::Resolver;
use crate::checks::*;
use crate::ir::*;
use crate::library::{LibraryId, PortDir};
use ferroc_diagnostics::diagnostic::{did_you_mean, Diagnostic};
use ferroc_diagnostics::source::Span;
use ferroc_syntax::Element;

impl<'r, 'l, 't> Resolver<'r, 'l, 't> {
    pub(super) fn group(
        &mut self,
        scope: ElementId,
        child: &'t Element,
        visible: &'t [LibraryId],
        inst: Option<Span>,
        depth: usize,
    ) {
        let Some(type_attr) = child.attr("type") else {
            if let Some(id) = self.add_element(scope, child, ElementKind::Group, inst) {
                self.walk(id, child, visible, inst, depth);
                self.group_ports(id, child, visible);
            }
            return;
        };
        let Some((def, def_visible)) =
            self.find_group_type(type_attr.value, type_attr.value_span, visible)
        else {
            // Keep the group so that paths to it resolve; paths into it end silently
            // (its content is unknown, which the unknown type already says).
            if let Some(id) = self.add_element(scope, child, ElementKind::Group, inst) {
                self.broken_groups.insert(id);
            }
            return;
        };
        let use_span = type_attr.value_span;
        if let Some(pos) = self
            .instantiating
            .iter()
            .position(|(d, _)| std::ptr::eq(*d, def))
        {
            let mut d = Diagnostic::new(
                &m117_recursive_group_type::CHECK,
                use_span,
                format!(
                    "group type `{}` contains an instance of itself",
                    type_attr.value
                ),
            )
            .label("instantiated again here");
            for (_, span) in &self.instantiating[pos..] {
                d = d.secondary(*span, "instantiated here");
            }
            self.loader
                .diags
                .push(d.help("break the recursion: a group type cannot contain itself"));
            self.broken(scope, child);
            return;
        }
        if depth >= self.loader.options.limits.max_instance_depth {
            self.loader.diags.push(
                Diagnostic::new(
                    &m116_limit_exceeded::CHECK,
                    use_span,
                    format!(
                        "group types nest more than {} deep",
                        self.loader.options.limits.max_instance_depth
                    ),
                )
                .label("one level too many")
                .help("flatten the group structure"),
            );
            self.broken(scope, child);
            return;
        }
        let Some(id) = self.add_element(scope, child, ElementKind::Group, inst) else {
            return;
        };
        self.instantiating.push((def as *const Element, use_span));
        // Elements of the definition point into it and remember this use.
        let inner_inst = Some(inst.unwrap_or(use_span));
        self.walk(id, def, def_visible, inner_inst, depth + 1);
        self.group_ports(id, def, def_visible);
        self.instantiating.pop();
    }

    /// `local.Name` or `lib.Name`: the definition and the libraries its content may use.
    fn find_group_type(
        &mut self,
        name: &str,
        span: Span,
        visible: &'t [LibraryId],
    ) -> Option<(&'t Element, &'t [LibraryId])> {
        let libs = self.libs;
        let (lib, short) = name.split_once('.').unwrap_or(("", name));
        if lib == "local" {
            if let Some((_, def)) = self.local_group_types.get(short) {
                return Some((def, visible));
            }
            let names: Vec<&str> = self.local_group_types.keys().copied().collect();
            self.unknown_group_type(
                name,
                span,
                did_you_mean(short, names).map(|s| format!("local.{s}")),
            );
            return None;
        }
        if let Some(id) = libs.by_name.get(lib) {
            let library = libs.get(*id);
            if let Some(gt) = library.group_types.iter().find(|g| g.name == short) {
                if !visible.contains(id) {
                    self.not_used(lib, span);
                }
                return Some((&gt.element, &library.visible));
            }
            let names = library.group_types.iter().map(|g| g.name.as_str());
            let hint = did_you_mean(short, names).map(|s| format!("{lib}.{s}"));
            self.unknown_group_type(name, span, hint);
            return None;
        }
        self.unknown_group_type(name, span, None);
        None
    }

    fn unknown_group_type(&mut self, name: &str, span: Span, hint: Option<String>) {
        let d = Diagnostic::new(
            &m111_unknown_type::CHECK,
            span,
            format!("unknown group type `{name}`"),
        )
        .label("no such group type");
        self.loader.diags.push(match hint {
            Some(h) => d.help(format!("did you mean `{h}`?")),
            None => d.help(
                "group types are `local.Name` (this file and its includes) or `library.Name`",
            ),
        });
    }

    fn group_ports(&mut self, id: ElementId, def: &'t Element, visible: &'t [LibraryId]) {
        let mut ports = Vec::new();
        for p in def.children_named("port") {
            let (Some(name), Some(ty)) = (p.value("name"), p.value("type")) else {
                continue;
            };
            if let Some(first) = ports.iter().find(|x: &&GroupPort| x.name == name) {
                let first = first.span;
                self.duplicate(p.value_span("name"), first, &format!("port `{name}`"));
                continue;
            }
            let Some(ty) =
                self.libs
                    .resolve_type(ty, p.value_span("type"), visible, self.loader.diags)
            else {
                continue;
            };
            ports.push(GroupPort {
                name: name.to_string(),
                dir: if p.value("dir") == Some("out") {
                    PortDir::Out
                } else {
                    PortDir::In
                },
                ty,
                unit: crate::library::unit_attr(p, self.loader.diags),
                span: p.value_span("name"),
            });
        }
        for port in &ports {
            if let Some(child) = self.app.child(id, &port.name).as_ref() {
                let first = self.app.element(*child).name_span;
                self.duplicate(port.span, first, &format!("`{}`", port.name));
            }
        }
        self.app.elements[id.0 as usize].group_ports = ports;
    }
}
