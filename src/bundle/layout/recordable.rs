//! `--record` in generated programs: which outputs of a part's modules feed a
//! connection or are published as ROS 2 topics, and which inputs are subscribed from
//! ROS 2 topics (the ones `ferroc run --record` would record), with their model types
//! from the compiler. `rust/recordable.rs` writes them into `main.rs` as the table
//! `RECORDABLE` that `ferroc_std::Recorders` reads when the program is started with
//! `--record`.
//!
//! A recorded library type declared `serde="true"` in its manifest (the crash course's
//! `Pose2D`) is registered with its serde form (`serde_rust`, `rust.rs`'s
//! `registrations`), as the library's own `register` does for `ferroc run`: both
//! record the same channels. Types without `serde="true"` are left out, named on
//! stderr, by both. The unit of every port the part's modules connect is in `units`
//! (from the plan), written as the table `UNITS` for the channel metadata.

use super::Part;
use ferroc_compiler::ir::{Application, Endpoint};
use ferroc_compiler::library::{LibrarySet, PortDir};
use ferroc_compiler::types::Type;

/// An output of one of the part's modules that feeds a connection.
pub struct RecordedOutput {
    pub module: String,
    pub port: String,
    /// Its model type, as the runtime names it (`f64`, `crash_course.Pose2D`).
    pub model_type: String,
    /// The thread container running the module.
    pub thread: String,
    /// The Rust path of a library type declared `serde="true"`: registered with serde.
    pub serde_rust: Option<String>,
    /// The library that declares that type: the part depends on its crate.
    pub serde_library: Option<String>,
    /// An input subscribed from a ROS 2 topic (not an output): its end's number.
    pub subscribed: Option<u32>,
}

/// The outputs `part` records with `--record`: the sources of its connections and of
/// its links to other parts, each once, in connection order.
pub fn outputs(app: &Application, libs: &LibrarySet, part: &Part<'_>) -> Vec<RecordedOutput> {
    let mut out: Vec<RecordedOutput> = Vec::new();
    // Outputs feeding connections and links, those published as ROS 2 topics, and
    // inputs subscribed from ROS 2 topics.
    let ros2 = (part.ros2.iter()).flat_map(|n| &n.topics);
    let froms = (part.connections.iter().chain(&part.links_out))
        .map(|c| (&c.from.0, &c.from.1, None))
        .chain(ros2.map(|t| (&t.port.0, &t.port.1, (!t.publish).then_some(t.id))));
    for (module, port, subscribed) in froms {
        let dir = match subscribed {
            Some(_) => PortDir::In,
            None => PortDir::Out,
        };
        if out.iter().any(|o| o.module == *module && o.port == *port) {
            continue;
        }
        let Some(thread) = (part.threads.iter()).find(|t| t.steps.iter().any(|(p, _)| p == module))
        else {
            continue;
        };
        let Some(m) = part.modules.iter().find(|m| m.path == *module) else {
            continue;
        };
        let index = app
            .module_ports(libs, m.element)
            .find(|(_, p)| p.name == *port && p.dir == dir)
            .map(|(i, _)| i);
        let endpoint = index.map(|port| Endpoint::Port {
            element: m.element,
            port,
        });
        let Some(view) = endpoint.and_then(|e| app.view(libs, e)) else {
            continue;
        };
        let (serde_rust, serde_library) = match view.ty {
            Type::Named(id, _) if libs.named_type(*id).serde => {
                let named = libs.named_type(*id);
                (
                    Some(named.rust.clone()),
                    Some(libs.get(named.library).name.clone()),
                )
            }
            _ => (None, None),
        };
        out.push(RecordedOutput {
            module: module.clone(),
            port: port.clone(),
            model_type: view.ty.to_string(),
            thread: thread.path.clone(),
            serde_rust,
            serde_library,
            subscribed,
        });
    }
    out
}

/// The units of the ports `part`'s modules connect (`(port path, unit)`, from
/// [`Plan::units`](ferroc_compiler::plan::Plan::units)), sorted by port.
pub fn units(plan_units: &[(String, String)], part: &Part<'_>) -> Vec<(String, String)> {
    let ends: std::collections::BTreeSet<String> = (part.connections.iter())
        .flat_map(|c| [&c.from, &c.to])
        .chain(part.links_out.iter().map(|c| &c.from))
        .chain(part.links_in.iter().map(|c| &c.to))
        .chain(
            part.ros2
                .iter()
                .flat_map(|n| n.topics.iter().map(|t| &t.port)),
        )
        .map(|(module, port)| format!("{module}/{port}"))
        .collect();
    (plan_units.iter())
        .filter(|(port, _)| ends.contains(port))
        .cloned()
        .collect()
}
