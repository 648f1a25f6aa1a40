//! Connections, parameter links and calls into the parts: inside one part, or as a
//! link between two (each end's program writes or reads it).

use ferroc_compiler::plan::{PlannedCall, PlannedConnection, PlannedParamLink};
use ferroc_compiler::source::Span;
use ferroc_compiler::types::Type;

use super::super::text;
use super::Split;

impl<'p> Split<'_, 'p> {
    /// Every connection into the part of its modules, or as a link out of the writer's
    /// part and into the reader's; the field accessors its conversion needs go to the
    /// part that converts (the writer's).
    pub(super) fn place_connections(&mut self, connections: &'p [PlannedConnection]) {
        for c in connections {
            self.check_port_names(c);
            let Some(link) = &c.link else {
                let what = format!(
                    "connection `{}/{}` → `{}/{}`",
                    c.from.0, c.from.1, c.to.0, c.to.1
                );
                if let Some(p) = self.one_part((&c.from.0, &c.to.0), &what, c.span) {
                    self.add_fields(p, c);
                    self.parts[p].connections.push(c);
                }
                continue;
            };
            let ends = (
                self.module_part.get(c.from.0.as_str()),
                self.module_part.get(c.to.0.as_str()),
            );
            let (Some(&writer), Some(&reader)) = ends else {
                continue; // an endpoint outside every part was reported above
            };
            if let Some(rust) = link.rust.as_deref().filter(|r| !text::is_rust_path(r)) {
                self.problem(
                    c.span,
                    format!(
                        "the type `{}` of this connection names the Rust type `{}`, which is not a Rust path (`crate_name::Type`)",
                        link.ty,
                        text::comment(rust)
                    ),
                );
            }
            // The writer's program converts, so it needs the field accessors.
            self.add_fields(writer, c);
            if let Some(name) = &link.library {
                self.parts[writer].use_library(name);
                self.parts[reader].use_library(name);
            }
            self.parts[writer].links_out.push(c);
            self.parts[reader].links_in.push(c);
        }
    }

    /// Instance ports are paths of names and indices: `in/0`, `in/2/activity`.
    fn check_port_names(&mut self, c: &PlannedConnection) {
        for port in [&c.from.1, &c.to.1] {
            let segment_ok = |s: &str| {
                text::is_name(s)
                    || (!s.is_empty() && s.len() <= 10 && s.bytes().all(|b| b.is_ascii_digit()))
            };
            if !port.split('/').all(segment_ok) {
                self.problem(
                    c.span,
                    format!("`{}` is not a valid port name", text::comment(port)),
                );
            }
        }
    }

    /// The field accessors `c` needs, into part `p`'s sorted list, each once.
    fn add_fields(&mut self, p: usize, c: &PlannedConnection) {
        let part = &mut self.parts[p];
        for f in super::super::fields::accessors(c, &part.modules, self.libs) {
            if let Err(at) = part.fields.binary_search(&f) {
                part.fields.insert(at, f);
            }
        }
    }

    /// Every output → parameter connection into its part, or as a link between two.
    pub(super) fn place_param_links(&mut self, links: &'p [PlannedParamLink]) {
        for link in links {
            if link.link.is_some() {
                let ends = (
                    self.module_part.get(link.from.0.as_str()),
                    self.module_part.get(link.to.0.as_str()),
                );
                if let (Some(&writer), Some(&reader)) = ends {
                    self.parts[writer].param_links_out.push(link);
                    self.parts[reader].param_links_in.push(link);
                }
                continue;
            }
            let what = format!(
                "parameter link `{}/{}` → `{}/param/{}`",
                link.from.0, link.from.1, link.to.0, link.to.1
            );
            if let Some(p) = self.one_part((&link.from.0, &link.to.0), &what, link.span) {
                self.parts[p].param_links.push(link);
            }
        }
    }

    /// Every client → service call into its part, or as a call between two, whose
    /// request and response types both programs then name.
    pub(super) fn place_calls(&mut self, calls: &'p [PlannedCall]) {
        for call in calls {
            if call.link.is_some() {
                self.place_call_between_parts(call);
                continue;
            }
            let what = format!(
                "call `{}/{}` → `{}/{}`",
                call.client.0, call.client.1, call.service.0, call.service.1
            );
            let ends = (&call.client.0, &call.service.0);
            if let Some(p) = self.one_part(ends, &what, call.span) {
                self.parts[p].calls.push(call);
            }
        }
    }

    fn place_call_between_parts(&mut self, call: &'p PlannedCall) {
        let Some(link) = &call.link else {
            return;
        };
        let ends = (
            self.module_part.get(call.client.0.as_str()),
            self.module_part.get(call.service.0.as_str()),
        );
        let (Some(&client), Some(&server)) = ends else {
            return; // an endpoint outside every part was reported above
        };
        let libs = self.libs;
        let rust = |t: &Type| super::super::fields::rust_type(libs, t).map(|(r, _)| r);
        let types = link
            .response
            .as_ref()
            .and_then(|resp| Some((rust(&link.request)?, rust(resp)?)));
        let Some((request, response)) = types else {
            self.problem(
                call.span,
                format!(
                    "the call `{}/{}` → `{}/{}` crosses between parts, but its client declares no response type the generated code can name: add response=\"TYPE\" to the <client> in its manifest",
                    call.client.0, call.client.1, call.service.0, call.service.1
                ),
            );
            return;
        };
        for rust_path in [&request, &response] {
            if !text::is_rust_type(rust_path) {
                self.problem(
                    call.span,
                    format!(
                        "the call's type `{}` is not a Rust type",
                        text::comment(rust_path)
                    ),
                );
            }
        }
        for t in [Some(&link.request), link.response.as_ref()]
            .into_iter()
            .flatten()
        {
            if let Type::Named(id, _) = t {
                let name = &libs.get(libs.named_type(*id).library).name;
                for p in [client, server] {
                    self.parts[p].use_library(name);
                }
            }
        }
        for p in [client, server] {
            let pair = (request.clone(), response.clone());
            if !self.parts[p].call_types.contains(&pair) {
                self.parts[p].call_types.push(pair);
            }
        }
        self.parts[client].calls_out.push(call);
        self.parts[server].calls_in.push(call);
    }

    /// The part both modules of a connection are in, if they must share one; a problem
    /// otherwise (every kind of link between parts is carried now: this is a guard).
    fn one_part(&mut self, (a, b): (&String, &String), what: &str, span: Span) -> Option<usize> {
        match (
            self.module_part.get(a.as_str()),
            self.module_part.get(b.as_str()),
        ) {
            (Some(&a), Some(&b)) if a == b => Some(a),
            (Some(&a), Some(&b)) => {
                let what = format!(
                    "the {what} joins the parts `{}` and `{}`: only data connections and calls cross between parts so far; move both ends into one part",
                    self.parts[a].name, self.parts[b].name
                );
                self.problem(span, what);
                None
            }
            _ => None, // an endpoint outside every part was reported above
        }
    }
}
