//! L106 `make-target-cycle`: Targets of a FINROC make.xml depend on each other in a cycle.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "L106",
    name: "make-target-cycle",
    severity: Severity::Error,
    summary: "Targets of a FINROC make.xml depend on each other in a cycle.",
    explanation: "FINROC's build (make_builder) refuses cyclic dependencies between targets: it
stops with \"Detected cyclic dependency\" and no target of the repository builds. ferroc
finds the cycle in the make.xml itself, before a build: a `libs` or `optionallibs`
entry is a dependency on a target of the same file when it is that target's name as
FINROC forms it — `rrlib_x`, `finroc_plugins_x_name`, `PREFIX_test_name`, … from the
file's place in a FINROC checkout or repository folder, or from `name` alone for the
older tags (`<rrlib name=\"x\">` is `rrlib_x`); other entries are external libraries.
The cycle is reported once per strongly connected component, as its shortest cycle,
each hop pointing at the `libs` entry that creates it. A target that lists itself is
a cycle of one hop.

Bad:
    <rrlib name=\"geometry\" libs=\"rrlib_math\">…</rrlib>
    <rrlib name=\"math\" libs=\"rrlib_geometry\">…</rrlib>

Fix: move what both need into a third target both depend on, or drop the entry that
points back.",
    fixtures: "compiler/finroc/src/checks/l106_make_cycle",
};

use crate::make_xml::MakeFile;
use ferroc_diagnostics::cycles::{
    report_dependency_cycles, CycleReport, Dependency, DependencyGraph,
};
use ferroc_diagnostics::diagnostic::Diagnostics;

/// Reports every dependency cycle among the targets of one make.xml.
pub fn check(make: &MakeFile, out: &mut Diagnostics) {
    let mut graph = TargetGraph {
        names: make
            .targets
            .iter()
            .map(|t| t.display_name().to_string())
            .collect(),
        edges: vec![Vec::new(); make.targets.len()],
    };
    let mut named_by_entry = vec![false; make.targets.len()];
    for (from, target) in make.targets.iter().enumerate() {
        for lib in &target.libs {
            let Some(to) = make.resolve(&lib.name) else {
                continue;
            };
            // Name a target the way the file refers to it.
            if !named_by_entry[to] {
                named_by_entry[to] = true;
                graph.names[to] = lib.name.clone();
            }
            graph.edges[from].push(Dependency {
                to,
                span: lib.span,
                verb: if lib.optional {
                    "optionally depends on"
                } else {
                    "depends on"
                },
            });
        }
    }
    report_dependency_cycles(
        &graph,
        &CycleReport {
            check: &CHECK,
            what: "make-target cycle",
            help: "FINROC refuses to build cyclic dependencies: remove the entry that points back, or move what these targets share into a target that depends on none of them",
        },
        out,
    );
}

struct TargetGraph {
    names: Vec<String>,
    edges: Vec<Vec<Dependency>>,
}

impl DependencyGraph for TargetGraph {
    fn node_count(&self) -> usize {
        self.names.len()
    }

    fn name(&self, node: usize) -> &str {
        &self.names[node]
    }

    fn dependencies(&self, node: usize) -> Vec<Dependency> {
        self.edges[node].clone()
    }
}
