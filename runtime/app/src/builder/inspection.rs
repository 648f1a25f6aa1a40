//! Handing what an inspector needs over before the application starts: the ports,
//! parameters and thread placement of every module (see [`crate::inspect`]).

use super::Builder;
use crate::inspect::{Catalogue, ModuleEntry};
use ferroc_ports::port::OutputHandle;
use std::sync::Arc;

impl Builder<'_> {
    /// What [`Inspector`](crate::inspect::Inspector) serves, taken from the wired
    /// application. Call it after every connection is made, right before
    /// [`start`](Self::start_with): it takes the modules' output handles (later
    /// [`Builder::output`] and connections from these outputs fail). Nothing of it runs
    /// on the cycle path: the inspector connects a probe to an output only while a
    /// value is asked for.
    pub fn inspection(&mut self) -> Catalogue {
        let thread_names: Vec<String> = self.threads.iter().map(|t| t.path.clone()).collect();
        let inspected = &mut self.inspected;
        let modules = self
            .modules
            .iter_mut()
            .filter(|m| !m.link_end)
            .map(|m| {
                let outputs: Vec<(String, Arc<OutputHandle>)> = std::mem::take(&mut m.outputs)
                    .into_iter()
                    .map(|(name, handle)| (name, Arc::new(handle)))
                    .collect();
                inspected.insert(m.path.clone(), outputs.clone());
                (m, outputs)
            })
            .map(|(m, outputs)| ModuleEntry {
                path: m.path.clone(),
                interface: m.interface.clone(),
                thread: m.thread.and_then(|t| thread_names.get(t).cloned()),
                outputs,
                inputs: m
                    .inputs
                    .iter()
                    .map(|(name, handle)| (name.clone(), handle.source()))
                    .collect(),
                params: m.params.clone(),
            })
            .collect();
        let threads = self
            .threads
            .iter()
            .map(|t| {
                let mut paths: Vec<String> = Vec::new();
                for (path, _) in &t.steps {
                    if !paths.contains(path) {
                        paths.push(path.clone());
                    }
                }
                (t.path.clone(), paths)
            })
            .collect();
        Catalogue {
            modules,
            threads,
            ros2: self.remote.ros2.clone(),
            hub: Some(Arc::clone(&self.hub)),
        }
    }
}
