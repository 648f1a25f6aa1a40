//! The B1 scale-model generator (benchmarks.md, B1).
//!
//! [`generate`] writes a synthetic application model that looks like a large real one,
//! so that `ferroc check` is measured on the shapes it meets in practice rather than on
//! one flat list: modules sit in groups of ten, groups in thread containers (N/100 of
//! them), containers in parts (max(1, N/5000), each on its own host). Where everything
//! goes is computed once in [`layout::Layout`].
//!
//! Data flows through every group (18 connections inside, via the group's interface
//! ports) and from group to group in one ring over all thread containers (2
//! connections per group, written at application level with full paths such as
//! `p0/t3/g7/out`). Connections that cross thread containers are queues (`on-full`
//! drop-oldest, drop-newest or block); the ring closes with `delay="1"` when it stays in
//! one container. Every required input is connected once, every output is read.
//!
//! What can wait, at the density of a real robot (module types in `b1.lib.xml`, which
//! [`write_model`] puts next to the model): containers form blocks of ten, the last of
//! each (the hub, data-triggered, no priority) runs a map server. A quarter of the
//! other groups call it — blocking without a timeout, asynchronously, and with a
//! timeout — and call a calibration service of their own group that runs inline
//! (`executes="caller"`); another quarter take the block's `map` and `pose` locks, in
//! the order the server's body takes them (resources with levels, bound per module).
//! The first group of a container reads the ring's queue blocking, with a timeout.
//! A quarter of the groups are instances of one `<group-type>`, so both the
//! instantiation path and the plain element walk of the resolver are exercised.
//!
//! All of it is deadlock-free by construction: calls go only from periodic containers
//! to their hub, whose service bodies call nobody; every lock is taken map before pose;
//! hubs and the first container of each block do not read blocking, so the blocking
//! reads form no ring; no hub writes into a `block` queue, so no container waits for
//! space behind one that calls it. The model checks without any finding (the tests assert it and
//! that the deadlock analysis sees the waits). iB2C behaviour groups are not generated
//! yet: they would be another [`GroupKind`].

mod body;
mod layout;
#[cfg(test)]
mod tests;

use body::GroupParams;
use layout::{GroupKind, Layout};
use std::fmt::Write;
use std::path::Path;

/// Modules per group (the body written by [`Generator::group_body`]).
pub const GROUP_SIZE: usize = 10;

/// File name of the `b1` manifest the model's `<use>` names, next to the model.
pub const MANIFEST_FILE: &str = "b1.lib.xml";

/// The `b1` manifest: the module types that call, serve, lock and read blocking.
pub const MANIFEST: &str = include_str!("generate/b1.lib.xml");

/// The model for `n_modules` modules (rounded up to a multiple of [`GROUP_SIZE`]).
/// It needs [`MANIFEST`] as [`MANIFEST_FILE`] in its folder; see [`write_model`].
pub fn generate(n_modules: usize) -> String {
    generate_with(n_modules, false)
}

/// Every how many groups the model with findings repeats a connection.
pub const DUPLICATE_EVERY: usize = 3;

/// The model for `n_modules` modules that also has findings: the `level → aux`
/// connection of every [`DUPLICATE_EVERY`]th group is written a second time at the end
/// of the file, one T107 warning each, whose secondary label points at the first
/// connection far above. This is the "many findings" case of B1: rendering thousands
/// of findings must cost what their snippets cost.
pub fn generate_with_findings(n_modules: usize) -> String {
    generate_with(n_modules, true)
}

/// How many findings [`generate_with_findings`] puts in a model of `n_modules`.
pub fn findings_in(n_modules: usize) -> usize {
    Layout::new(n_modules).groups.div_ceil(DUPLICATE_EVERY)
}

fn generate_with(n_modules: usize, findings: bool) -> String {
    let layout = Layout::new(n_modules);
    let mut g = Generator {
        out: String::with_capacity(layout.groups * 2900 + 4096),
        layout,
        findings,
    };
    g.header();
    g.parts();
    g.connections();
    g.out.push_str("</application>\n");
    g.out
}

/// Writes the model to `file` and the manifest next to it; returns the model's size.
pub fn write_model(file: &Path, n_modules: usize) -> std::io::Result<usize> {
    write_text(file, generate(n_modules))
}

/// [`write_model`] for the model with findings ([`generate_with_findings`]).
pub fn write_model_with_findings(file: &Path, n_modules: usize) -> std::io::Result<usize> {
    write_text(file, generate_with_findings(n_modules))
}

fn write_text(file: &Path, text: String) -> std::io::Result<usize> {
    std::fs::write(file, &text)?;
    let dir = file.parent().unwrap_or(Path::new("."));
    std::fs::write(dir.join(MANIFEST_FILE), MANIFEST)?;
    Ok(text.len())
}

struct Generator {
    out: String,
    layout: Layout,
    /// Repeat some connections at the end (see [`generate_with_findings`]).
    findings: bool,
}

impl Generator {
    fn line(&mut self, indent: usize, text: &str) {
        for _ in 0..indent {
            self.out.push_str("  ");
        }
        self.out.push_str(text);
        self.out.push('\n');
    }

    fn header(&mut self) {
        let l = &self.layout;
        let intro = format!(
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
             <!-- Generated by ferroc-bench (B1 scale model): {} modules in {} groups, \
             {} thread containers, {} parts. Do not edit. -->\n\
             <application name=\"b1_scale_{}\" version=\"1\" doc=\"synthetic model for the checker benchmark\">\n\
             \x20 <use library=\"ferroc_std\"/>\n\
             \x20 <use library=\"b1\" manifest=\"{MANIFEST_FILE}\"/>\n",
            l.groups * GROUP_SIZE,
            l.groups,
            l.threads,
            l.parts,
            l.groups * GROUP_SIZE
        );
        self.out.push_str(&intro);
        // Each block's two locks; the level says map is taken before pose (D116).
        for b in 0..self.layout.blocks() {
            self.line(1, &format!("<resource name=\"map{b}\" level=\"2\"/>"));
            self.line(1, &format!("<resource name=\"pose{b}\" level=\"1\"/>"));
        }
        self.line(
            1,
            "<group-type name=\"Filter\" doc=\"a small signal chain with monitoring\">",
        );
        self.group_body(2, &GroupParams::of_type(), GroupKind::Instance);
        self.line(1, "</group-type>");
    }

    fn parts(&mut self) {
        let (groups, threads) = (self.layout.groups, self.layout.threads);
        let mut group = 0;
        for t in 0..threads {
            let p = self.layout.part_of(t);
            if t == 0 || self.layout.part_of(t - 1) != p {
                if t > 0 {
                    self.line(1, "</part>");
                }
                self.line(1, &format!("<part name=\"p{p}\" host=\"host{p}\">"));
            }
            let activation = match self.layout.priority(t) {
                _ if self.layout.data_triggered(t) => "trigger=\"data\"".to_string(),
                Some(prio) => format!("period=\"10ms\" priority=\"{prio}\""),
                None => "period=\"10ms\"".to_string(),
            };
            self.line(2, &format!("<thread name=\"t{t}\" {activation}>"));
            while group < groups && self.layout.thread_of(group) == t {
                self.group(group);
                group += 1;
            }
            self.line(2, "</thread>");
        }
        self.line(1, "</part>");
    }

    fn group(&mut self, group: usize) {
        let local = self.layout.local(group);
        match self.layout.kind(group) {
            GroupKind::Instance => self.line(
                3,
                &format!("<group name=\"g{local}\" type=\"local.Filter\"/>"),
            ),
            kind => {
                let block = self.layout.thread_of(group) / layout::BLOCK;
                self.line(3, &format!("<group name=\"g{local}\">"));
                self.group_body(4, &GroupParams::inline(group, block), kind);
                self.line(3, "</group>");
            }
        }
    }

    /// The ring over all groups (`out → in` and `level → aux` of the next group) and
    /// the calls of each client group to its hub's map server.
    fn connections(&mut self) {
        let l = &self.layout;
        let mut text = String::with_capacity(l.groups * 260);
        let mut repeated = String::new();
        for cur in 0..l.groups {
            let prev = (cur + l.groups - 1) % l.groups;
            let (tp, tc) = (l.thread_of(prev), l.thread_of(cur));
            let (from, to) = (l.path(prev), l.path(cur));
            // A queue decouples thread containers; a ring inside one container is an
            // intended feedback loop.
            let (data, meta) = if tp != tc {
                let sharing = if l.part_of(tp) != l.part_of(tc) {
                    " sharing=\"on-change\""
                } else {
                    ""
                };
                // Every module's default activity writes its outputs, so a writer
                // waits on a full `block` queue until the reader's container drains
                // it. Never from a hub: the reader may be calling that hub (D105).
                let on_full = match tc % 3 {
                    0 if !l.is_hub(tp) => "block",
                    1 => "drop-newest",
                    _ => "drop-oldest",
                };
                (
                    format!(" queue=\"8\" on-full=\"{on_full}\"{sharing}"),
                    sharing.to_string(),
                )
            } else if cur == 0 {
                (" delay=\"1\"".to_string(), " delay=\"1\"".to_string())
            } else {
                (String::new(), String::new())
            };
            let _ = writeln!(
                text,
                "  <connect from=\"{from}/out\" to=\"{to}/in\"{data}/>"
            );
            let level = format!("  <connect from=\"{from}/level\" to=\"{to}/aux\"{meta}/>\n");
            text.push_str(&level);
            if self.findings && cur % DUPLICATE_EVERY == 0 {
                repeated.push_str(&level);
            }
            if l.kind(cur) == GroupKind::Client {
                let server = l.server_of(tc);
                for (client, service) in [
                    ("smooth/map", "get"),
                    ("smooth/notify", "journal"),
                    ("drive/pose", "pose"),
                ] {
                    let _ = writeln!(
                        text,
                        "  <connect from=\"{to}/{client}\" to=\"{server}/{service}\"/>"
                    );
                }
            }
        }
        self.out.push_str(&text);
        self.out.push_str(&repeated);
    }
}
