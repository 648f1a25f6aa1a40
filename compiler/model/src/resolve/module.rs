//! Module instances: the type, the instance-sized ports, and where parameter values come from.

use super::Resolver;
use crate::checks::p106_config_entry_missing;
use crate::checks::*;
use crate::ir::*;
use crate::library::module_type::{ModuleKind, ModuleType, PortType};
use crate::library::{LibraryId, PortDecl, PortDir, PortRole};
use crate::load::Confined;
use ferroc_diagnostics::diagnostic::{did_you_mean, Diagnostic};
use ferroc_diagnostics::source::Span;
use ferroc_syntax::Element;
use ferroc_values::types::{Meta, Type};

impl<'r, 'l, 't> Resolver<'r, 'l, 't> {
    pub(super) fn module(
        &mut self,
        scope: ElementId,
        e: &'t Element,
        visible: &'t [LibraryId],
        inst: Option<Span>,
    ) {
        let Some(type_attr) = e.attr("type") else {
            self.broken(scope, e); // M104 said so
            return;
        };
        let type_span = type_attr.value_span;
        let Some((library, type_index)) =
            self.find_module_type(type_attr.value, type_span, visible)
        else {
            self.broken(scope, e);
            return;
        };
        let mt = &self.libs.get(library).module_types[type_index];
        // Vectors of exactly the room they need: `collect` from a filtered iterator
        // reserves at least four entries, and at 100,000 modules of one or two
        // parameters each that slack was ~35 MiB of the checker's peak memory (B1).
        let mut params = Vec::with_capacity(e.children_named("param").count());
        params.extend(
            e.children_named("param")
                .filter_map(|p| self.param_value(p)),
        );
        let extras = self.module_extras(scope, e, mt);
        let mut instance = ModuleInstance {
            library,
            type_index,
            type_span,
            extra_ports: Vec::new(),
            flexible_types: Vec::new(),
            params,
            extras,
        };
        self.flexible_ports(e, mt, &mut instance, visible);
        if mt.is_behaviour() {
            behaviour_ports(mt, &mut instance);
        }
        instance.extra_ports = exact(instance.extra_ports);
        instance.flexible_types = exact(instance.flexible_types);
        self.add_element(scope, e, ElementKind::Module(instance), inst);
    }

    /// What an instance writes besides its type and parameters (`<bind>`s,
    /// `characteristic=`, `budget=`, `ib2c-violations=`); boxed, and only when written.
    fn module_extras(
        &mut self,
        scope: ElementId,
        e: &'t Element,
        mt: &ModuleType,
    ) -> Option<Box<ModuleExtras>> {
        let extras = ModuleExtras {
            binds: exact(
                e.children_named("bind")
                    .filter_map(|b| {
                        Some((
                            b.value("lock")?.to_string(),
                            b.value("resource")?.to_string(),
                            b.value_span("resource"),
                        ))
                    })
                    .collect(),
            ),
            characteristic: self.characteristic(scope, e, mt),
            budget: crate::library::steps::duration_attr(e, "budget", self.loader.diags),
            ib2c_violations: e.value("ib2c-violations").map(str::to_string),
            port_units: Vec::new(),
        };
        let written = !extras.binds.is_empty()
            || extras.characteristic.is_some()
            || extras.budget.is_some()
            || extras.ib2c_violations.is_some();
        written.then(|| Box::new(extras))
    }

    /// `characteristic="true"`: valid on a behaviour (or fusion) inside a group.
    fn characteristic(
        &mut self,
        scope: ElementId,
        e: &Element,
        mt: &crate::library::ModuleType,
    ) -> Option<Span> {
        let attr = e.attr("characteristic")?;
        if attr.value != "true" {
            return None;
        }
        let why = if !mt.is_behaviour() {
            Some((
                format!(
                    "`{}` is not a behaviour, so it cannot characterise a group",
                    mt.qualified
                ),
                "a group's characteristic module is a kind=\"behaviour\" or kind=\"fusion\" module; remove the attribute",
            ))
        } else {
            // The nearest group above, skipping thread containers.
            let mut cur = Some(scope);
            let mut in_group = false;
            while let Some(c) = cur {
                match self.app.element(c).kind {
                    ElementKind::Group => {
                        in_group = true;
                        break;
                    }
                    ElementKind::Thread { .. } => cur = self.app.element(c).parent,
                    _ => break,
                }
            }
            (!in_group).then(|| {
                (
                    "a characteristic behaviour outside any group characterises nothing".to_string(),
                    "move the behaviour into the <group> it should characterise, or remove the attribute",
                )
            })
        };
        match why {
            None => Some(attr.value_span),
            Some((message, help)) => {
                self.loader.diags.push(
                    Diagnostic::new(
                        &m108_invalid_attribute_value::CHECK,
                        attr.value_span,
                        message,
                    )
                    .label("characteristic=\"true\" here")
                    .help(help),
                );
                None
            }
        }
    }

    fn find_module_type(
        &mut self,
        name: &str,
        span: Span,
        visible: &[LibraryId],
    ) -> Option<(LibraryId, usize)> {
        let libs = self.libs;
        let Some((lib, short)) = name.split_once('.') else {
            self.loader.diags.push(
                Diagnostic::new(
                    &m111_unknown_type::CHECK,
                    span,
                    format!("`{name}` is not a qualified module type"),
                )
                .label("missing library prefix")
                .help("module types are written `library.Type`, e.g. `ferroc_std.Constant`"),
            );
            return None;
        };
        let Some(&id) = libs.by_name.get(lib) else {
            if libs.failed.contains(lib) {
                return None; // its manifest's failure is already reported
            }
            let names = libs.by_name.keys().map(String::as_str);
            let d = Diagnostic::new(
                &crate::checks::l101_unknown_library::CHECK,
                span,
                format!("library `{lib}` is not loaded"),
            )
            .label("unknown library");
            self.loader.diags.push(match did_you_mean(lib, names) {
                Some(s) => d.help(format!("did you mean `{s}.{short}`?")),
                None if self.loader.options.builtins.iter().any(|b| b.name == lib) => {
                    d.help(format!("add <use library=\"{lib}\"/>"))
                }
                None => d.help(format!("add <use library=\"{lib}\" manifest=\"…\"/>")),
            });
            return None;
        };
        let library = libs.get(id);
        let Some(&index) = library.module_index.get(short) else {
            let names = library.module_types.iter().map(|m| m.name.as_str());
            let d = Diagnostic::new(
                &m111_unknown_type::CHECK,
                span,
                format!("library `{lib}` has no module type `{short}`"),
            )
            .label("unknown module type");
            self.loader.diags.push(match did_you_mean(short, names) {
                Some(s) => d.help(format!("did you mean `{lib}.{s}`?")),
                None => d.help(format!(
                    "see the module types in {}",
                    self.loader.sources.get(library.file).name
                )),
            });
            return None;
        };
        if !visible.contains(&id) {
            self.not_used(lib, span);
        }
        Some((id, index))
    }

    fn param_value(&mut self, p: &Element) -> Option<ParamValue> {
        let name = p.value("name")?.to_string();
        let name_span = p.value_span("name");
        let cmdline = p
            .attr("cmdline")
            .map(|a| (a.value.to_string(), a.value_span));
        if let Some(config) = p.attr("config") {
            let entry = self.config_entry(config.value, config.value_span);
            // A config file outside the model's folder is reported as such (M113) and
            // not again as a missing entry.
            let entry = match entry {
                Err(None) => Err(String::new()),
                Err(Some(reason)) => {
                    self.report_missing_entry(config.value, config.value_span, &reason);
                    Err(reason)
                }
                Ok(found) => Ok(found),
            };
            let (text, span) = match &entry {
                Ok((t, s)) => (t.clone(), *s),
                Err(_) => (String::new(), config.value_span),
            };
            return Some(ParamValue {
                name,
                name_span,
                text,
                span,
                source: ParamSource::Config(entry),
                source_span: config.value_span,
                cmdline,
            });
        }
        let has_text = !p.text().trim().is_empty();
        if !has_text {
            if let Some(cmd) = p.attr("cmdline") {
                return Some(ParamValue {
                    name,
                    name_span,
                    text: String::new(),
                    span: cmd.value_span,
                    source: ParamSource::Cmdline,
                    source_span: cmd.value_span,
                    cmdline,
                });
            }
        }
        Some(ParamValue {
            name,
            name_span,
            text: p.text().to_string(),
            span: p.text_span(),
            source: ParamSource::Inline,
            source_span: p.text_span(),
            cmdline,
        })
    }

    fn report_missing_entry(&mut self, reference: &str, span: Span, reason: &str) {
        self.loader.diags.push(
            Diagnostic::new(&p106_config_entry_missing::CHECK, span, format!("config entry `{reference}` not found: {reason}"))
                .label("named here")
                .help("write `file.xml#/node/value`; the file is relative to this model, in FINROC's <root>/<node>/<value> format"),
        );
    }

    /// Reads `file.xml#/a/b` from a FINROC-style config file, which must lie in the
    /// model's folder as includes must. `Err(None)`: refused and reported already.
    fn config_entry(
        &mut self,
        reference: &str,
        span: Span,
    ) -> Result<(String, Span), Option<String>> {
        let (file, pointer) = reference
            .split_once('#')
            .ok_or_else(|| "no `#/entry` pointer in the reference".to_string())?;
        let path = match self.loader.confine(span.file, file) {
            Ok(path) => path,
            Err(Confined::Outside) => {
                self.loader.report_outside(span, file, "config files");
                return Err(None);
            }
            Err(Confined::Unreadable(_)) => return Err(Some(format!("cannot read `{file}`"))),
        };
        let (_, root) = self.loader.read_plain(&path)?;
        let root = root.ok_or_else(|| format!("`{file}` is not well-formed XML"))?;
        let mut node = &root;
        let segments: Vec<&str> = pointer.trim_start_matches('/').split('/').collect();
        for (i, seg) in segments.iter().enumerate() {
            let last = i + 1 == segments.len();
            let tag = if last { "value" } else { "node" };
            node = node
                .children
                .iter()
                .find(|c| c.name == tag && c.value("name") == Some(seg))
                .ok_or_else(|| {
                    format!(
                        "`{file}` has no <{tag} name=\"{seg}\"> at `/{}`",
                        segments[..i].join("/")
                    )
                })?;
        }
        Ok((node.text().trim().to_string(), node.text_span()))
    }
}

/// `v` without room to spare (a no-op when it has none). The instance's vectors are
/// grown by pushing, which leaves room for up to four entries for one.
fn exact<T>(mut v: Vec<T>) -> Vec<T> {
    v.shrink_to_fit();
    v
}

/// The meta ports of a behaviour instance: its `inhibitions` inhibition inputs and,
/// for a fusion, activity and target rating inputs and the channel ports per channel.
fn behaviour_ports(mt: &ModuleType, instance: &mut ModuleInstance) {
    let count = |name: &str, default: u32| {
        instance
            .params
            .iter()
            .find(|p| p.name == name)
            .and_then(|p| p.text.trim().parse::<u32>().ok())
            .unwrap_or(default)
            .min(1024)
    };
    let (inhibitions, channels) = (count("inhibitions", 1), count("channels", 2));
    let meta = |name: String, dir, m| PortDecl {
        name,
        dir,
        role: PortRole::Meta,
        ty: PortType::Fixed(Type::Meta(m)),
        unit: None,
        required: false,
        blocking_read: false,
        read_timeout: None,
        merge: false,
        span: mt.span,
    };
    for k in 0..inhibitions {
        instance.extra_ports.push(meta(
            format!("inhibition/{k}"),
            PortDir::In,
            Meta::Inhibition,
        ));
    }
    if mt.kind == ModuleKind::Fusion {
        for k in 0..channels {
            instance.extra_ports.push(meta(
                format!("in/{k}/activity"),
                PortDir::In,
                Meta::Activity,
            ));
            instance.extra_ports.push(meta(
                format!("in/{k}/target_rating"),
                PortDir::In,
                Meta::TargetRating,
            ));
            for c in &mt.channel_in {
                let mut p = c.clone();
                p.name = format!("in/{k}/{}", c.name);
                instance.extra_ports.push(p);
            }
        }
    }
}
