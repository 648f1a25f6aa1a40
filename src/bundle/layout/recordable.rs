//! `--record` in generated programs: which outputs of a part's modules feed a
//! connection (the ones `ferroc run --record` would record), with their model types
//! from the compiler. `rust/recordable.rs` writes them into `main.rs` as the table
//! `RECORDABLE` that `ferroc_std::Recorders` reads when the program is started with
//! `--record`.
//!
//! The program registers no value type for recording: it records what its registry can
//! encode (built-in types, library types crossing to other parts or on flexible ports
//! declared serde), like `ferroc run`, whose libraries' `register` decide. Registering
//! every recorded library type declared `serde="true"` would break the build of a
//! bundle whose crate does not implement serde for it, for an internal connection.

use super::Part;
use ferroc_compiler::ir::{Application, Endpoint};
use ferroc_compiler::library::{LibrarySet, PortDir};

/// An output of one of the part's modules that feeds a connection.
pub struct RecordedOutput {
    pub module: String,
    pub port: String,
    /// Its model type, as the runtime names it (`f64`, `crash_course.Pose2D`).
    pub model_type: String,
    /// The thread container running the module.
    pub thread: String,
}

/// The outputs `part` records with `--record`: the sources of its connections and of
/// its links to other parts, each once, in connection order.
pub fn outputs(app: &Application, libs: &LibrarySet, part: &Part<'_>) -> Vec<RecordedOutput> {
    let mut out: Vec<RecordedOutput> = Vec::new();
    for c in part.connections.iter().chain(&part.links_out) {
        let (module, port) = (&c.from.0, &c.from.1);
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
            .find(|(_, p)| p.name == *port && p.dir == PortDir::Out)
            .map(|(i, _)| i);
        let endpoint = index.map(|port| Endpoint::Port {
            element: m.element,
            port,
        });
        let Some(view) = endpoint.and_then(|e| app.view(libs, e)) else {
            continue;
        };
        out.push(RecordedOutput {
            module: module.clone(),
            port: port.clone(),
            model_type: view.ty.to_string(),
            thread: thread.path.clone(),
        });
    }
    out
}
