//! L103 `dependency-cycle`: Libraries depend on each other in a cycle.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "L103",
    name: "dependency-cycle",
    severity: Severity::Error,
    summary: "Libraries depend on each other in a cycle.",
    explanation: "Library dependencies go one way (FINROC's rule): a cycle makes build order and
initialisation order undefined. The cycle is reported once per strongly connected
component, as its shortest cycle, each hop pointing at the `<depends>` that creates it.

Bad:
    a.lib.xml: <depends library=\"b\"/>
    b.lib.xml: <depends library=\"a\"/>

Fix: move what both need into a third library both depend on.",
    fixtures: "compiler/model/src/checks/l103_dependency_cycle",
};

use crate::library::LibrarySet;
use ferroc_diagnostics::cycles::{
    report_dependency_cycles, CycleReport, Dependency, DependencyGraph,
};
use ferroc_diagnostics::diagnostic::Diagnostics;

/// Reports each strongly connected component of the dependency graph once, as its
/// shortest cycle, every hop pointing at the `<depends>` that creates it.
pub fn report_cycles(set: &LibrarySet, out: &mut Diagnostics) {
    report_dependency_cycles(
        &LibraryGraph(set),
        &CycleReport {
            check: &CHECK,
            what: "library dependency cycle",
            help: "dependencies must go one way: move what these libraries share into a library that depends on none of them",
        },
        out,
    );
}

struct LibraryGraph<'a>(&'a LibrarySet);

impl DependencyGraph for LibraryGraph<'_> {
    fn node_count(&self) -> usize {
        self.0.libraries.len()
    }

    fn name(&self, node: usize) -> &str {
        &self.0.libraries[node].name
    }

    fn dependencies(&self, node: usize) -> Vec<Dependency> {
        self.0.libraries[node]
            .depends
            .iter()
            .filter_map(|d| {
                Some(Dependency {
                    to: d.target?.0 as usize,
                    span: d.span,
                    verb: "depends on",
                })
            })
            .collect()
    }
}
