//! An instance's `<port>` elements: the type, count and unit of a flexible module
//! type's ports, and the unit an instance gives a fixed port its type declares without
//! one.

use super::Resolver;
use crate::checks::*;
use crate::ir::*;
use crate::library::module_type::{FlexibleDecl, PortType};
use crate::library::{LibraryId, PortDecl, PortDir, PortRole};
use ferroc_diagnostics::diagnostic::Diagnostic;
use ferroc_syntax::Element;
use ferroc_values::types::Type;
use ferroc_values::units::Unit;

impl<'r, 'l, 't> Resolver<'r, 'l, 't> {
    /// `<port name dir type count>` on an instance of a flexible module type.
    pub(super) fn flexible_ports(
        &mut self,
        e: &Element,
        mt: &crate::library::ModuleType,
        instance: &mut ModuleInstance,
        visible: &[LibraryId],
    ) {
        for p in e.children_named("port") {
            let (Some(name), Some(ty_text)) = (p.value("name"), p.value("type")) else {
                continue;
            };
            if !mt.flexible.iter().any(|f| f.port == name) {
                if let Some(index) = mt.ports.iter().position(|d| d.name == name) {
                    self.port_unit(p, mt, index, instance, visible);
                    continue;
                }
            }
            let Some(flex) = self.flexible_group(p, name, mt) else {
                continue;
            };
            let Some(ty) =
                self.libs
                    .resolve_type(ty_text, p.value_span("type"), visible, self.loader.diags)
            else {
                continue;
            };
            let unit = crate::library::unit_attr(p, self.loader.diags);
            let count: Option<u32> = p.value("count").and_then(|c| c.parse().ok());
            let n = count.unwrap_or(1);
            if n < flex.min_count || flex.max_count.is_some_and(|m| n > m) {
                self.loader.diags.push(
                    Diagnostic::new(
                        &m108_invalid_attribute_value::CHECK,
                        p.value_span("count"),
                        format!(
                            "port group `{name}` needs between {} and {} ports",
                            flex.min_count,
                            flex.max_count
                                .map_or("any number".into(), |m| m.to_string())
                        ),
                    )
                    .label("count out of range")
                    .secondary(flex.span, "constraint declared here"),
                );
            }
            let decl = |port_name: String| PortDecl {
                name: port_name,
                dir: flex.dir,
                role: PortRole::Plain,
                ty: PortType::Fixed(ty.clone()),
                unit: unit.clone(),
                required: false,
                blocking_read: false,
                read_timeout: None,
                merge: false,
                span: p.value_span("name"),
            };
            match count {
                Some(c) => instance.extra_ports.extend(
                    (0..c.min(ferroc_syntax::vocabulary::MAX_GROUP_PORTS))
                        .map(|k| decl(format!("{name}/{k}"))),
                ),
                None => instance.extra_ports.push(decl(name.to_string())),
            }
            self.flexible_type(p, name, flex, instance, ty, unit);
        }
    }

    /// `<port name dir type unit>` naming a fixed port of the type: the instance gives a
    /// port its type declares without a unit one (a `ferroc_std.Constant` publishing
    /// metres), as a flexible port's `<port>` does. Direction and type must be the
    /// type's; a port that has a unit keeps it.
    fn port_unit(
        &mut self,
        p: &Element,
        mt: &crate::library::ModuleType,
        index: usize,
        instance: &mut ModuleInstance,
        visible: &[LibraryId],
    ) {
        let fixed = &mt.ports[index];
        let dir = if p.value("dir") == Some("out") {
            PortDir::Out
        } else {
            PortDir::In
        };
        let ty = self.libs.resolve_type(
            p.value("type").unwrap_or_default(),
            p.value_span("type"),
            visible,
            self.loader.diags,
        );
        let wrong = |what: &str, span, label: &str, help: String| {
            Diagnostic::new(&m108_invalid_attribute_value::CHECK, span, what.to_string())
                .label(label.to_string())
                .secondary(fixed.span, "the port is declared here")
                .help(help)
        };
        let name = &fixed.name;
        let d = match (&fixed.ty, &fixed.unit, p.attr("unit"), ty) {
            _ if dir != fixed.dir => wrong(
                &format!("`{name}` of `{}` is declared with the other direction", mt.qualified),
                p.value_span("dir"),
                "wrong direction",
                format!("use dir=\"{}\"", if fixed.dir == PortDir::In { "in" } else { "out" }),
            ),
            (PortType::Fixed(t), _, _, Some(ty)) if *t != ty => wrong(
                &format!("`{name}` of `{}` has type `{t}`, not `{ty}`", mt.qualified),
                p.value_span("type"),
                "another type",
                format!("write type=\"{t}\": a <port> on an instance can give a port a unit, not another type"),
            ),
            (_, Some(u), _, _) => wrong(
                &format!("`{name}` of `{}` is measured in `{u}` already", mt.qualified),
                p.value_span("name"),
                "has a unit",
                "remove this <port>: only a port declared without a unit takes one from the instance".into(),
            ),
            (PortType::Fixed(t), None, Some(_), _) if !t.is_numeric() => wrong(
                &format!("`{name}` of `{}` carries `{t}`, which has no unit", mt.qualified),
                p.value_span("unit"),
                "not a number",
                "remove this <port>: units belong to numbers".into(),
            ),
            (PortType::Fixed(_), None, Some(_), Some(_)) => {
                if let Some(unit) = crate::library::unit_attr(p, self.loader.diags) {
                    instance
                        .extras
                        .get_or_insert_with(Default::default)
                        .port_units
                        .push((index as u32, unit));
                }
                return;
            }
            (_, None, None, Some(_)) => wrong(
                &format!("`{name}` is a port of `{}`'s own interface", mt.qualified),
                p.value_span("name"),
                "declares nothing new",
                "give it a unit (unit=\"m\") or remove this <port>; only flexible port groups take <port> declarations of new ports".into(),
            ),
            _ => return,
        };
        self.loader.diags.push(d);
    }

    /// The flexible port group a `<port>` declares ports of, and in its direction;
    /// `None`, reported, for a group the module type lacks or the other direction.
    fn flexible_group<'m>(
        &mut self,
        p: &Element,
        name: &str,
        mt: &'m crate::library::ModuleType,
    ) -> Option<&'m FlexibleDecl> {
        let Some(flex) = mt.flexible.iter().find(|f| f.port == name) else {
            let groups: Vec<&str> = mt.flexible.iter().map(|f| f.port.as_str()).collect();
            let d = Diagnostic::new(
                &m105_misplaced_element::CHECK,
                p.value_span("name"),
                format!(
                    "module type `{}` has no flexible port group `{name}`",
                    mt.qualified
                ),
            )
            .label("not declarable here")
            .secondary(mt.span, "module type declared here");
            self.loader.diags.push(if groups.is_empty() {
                d.help("only flexible module types take <port> declarations; this type's interface is fixed")
            } else {
                d.help(format!("its flexible port groups are: {}", groups.join(", ")))
            });
            return None;
        };
        let dir = if p.value("dir") == Some("out") {
            PortDir::Out
        } else {
            PortDir::In
        };
        if dir != flex.dir {
            self.loader.diags.push(
                Diagnostic::new(
                    &m108_invalid_attribute_value::CHECK,
                    p.value_span("dir"),
                    format!("port group `{name}` is declared with the wrong direction"),
                )
                .label("wrong direction")
                .secondary(flex.span, "declared by the module type here")
                .help(format!(
                    "use dir=\"{}\"",
                    if flex.dir == PortDir::In { "in" } else { "out" }
                )),
            );
            return None;
        }
        Some(flex)
    }

    /// Records the type of a flexible port group (for `$group` port types); a group
    /// of one type reports a `<port>` of another.
    fn flexible_type(
        &mut self,
        p: &Element,
        name: &str,
        flex: &FlexibleDecl,
        instance: &mut ModuleInstance,
        ty: Type,
        unit: Option<Unit>,
    ) {
        if flex.same_type {
            if let Some((_, first, _)) = instance.flexible_types.iter().find(|(g, _, _)| g == name)
            {
                if *first != ty {
                    self.loader.diags.push(
                        Diagnostic::new(&crate::checks::t102_incompatible_types::CHECK, p.value_span("type"), format!("all ports of group `{name}` must have one type; `{ty}` differs from `{first}`"))
                            .label("different type")
                            .help(format!("declare every `{name}` port with type `{first}`")),
                    );
                }
                return;
            }
        }
        instance.flexible_types.push((name.to_string(), ty, unit));
    }
}
