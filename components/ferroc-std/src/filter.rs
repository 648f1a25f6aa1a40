//! `ferroc_std.Filter` (FlexiFilter): instance-declared numeric inputs and outputs and
//! a pin map between their elements (`ferroc_pinmap`: `in/0 -> out[0] * 1000 as i32`),
//! each entry scaled, offset and cast. The map is checked by `ferroc check` (P108) and
//! again when the instance is created, with the same rules.
//!
//! Each step in which an input received a value, every output fed by it is published:
//! elements whose source delivered take `input · scale + offset` (rounded to the
//! nearest integer for integer outputs, then saturated); the others (no new value
//! this step, or not mapped at all) keep their last value (`unmapped=keep`, starting
//! at `reset`) or are set to `reset` (`unmapped=reset`).

use ferroc_pinmap::{Dir, Entry};
use ferroc_runtime::module::{DynIn, DynOut, Module, ModuleType, Parameter, Setup};

/// `ferroc_std.Filter`: see the [module docs](self).
pub struct Filter {
    inputs: Vec<DynIn>,
    latest: Vec<Vec<f64>>,
    outputs: Vec<Output>,
    mappings: Vec<Mapping>,
    reset_unmapped: bool,
    reset: f64,
    path: String,
    warned: bool,
}

struct Output {
    port: DynOut,
    values: Vec<f64>,
    integer: bool,
}

/// One element-to-element copy (a whole-array entry becomes one per element).
struct Mapping {
    from: (usize, usize),
    to: (usize, usize),
    scale: f64,
    offset: f64,
}

impl ModuleType for Filter {
    const NAME: &'static str = "ferroc_std.Filter";
    const DOC: &'static str = "Maps, scales and casts input elements onto output elements";
    fn create(m: &mut Setup<'_>) -> Self {
        let inputs = m.flexible_inputs("in").min_count(1).build_dyn();
        let outputs = m.flexible_outputs("out").min_count(1).build_dyn_outputs();
        let mut map: Parameter<String> = m
            .param("map")
            .doc("input elements onto output elements: `in/0 -> out[1] * 1000 as i32; …`")
            .build();
        let mut unmapped: Parameter<String> = m
            .param("unmapped")
            .default("keep".to_owned())
            .choices(&["keep", "reset"])
            .doc("output elements without a new value keep their last value, or are reset")
            .build();
        let mut reset: Parameter<f64> = m
            .param("reset")
            .default(0.0)
            .doc("the value of elements without one (at the start; every step with reset)")
            .build();
        let types: Vec<(String, Dir, String)> = m
            .port_groups()
            .iter()
            .flat_map(|g| {
                let dir = match g.dir {
                    ferroc_runtime::module::Direction::In => Dir::In,
                    ferroc_runtime::module::Direction::Out => Dir::Out,
                };
                g.port_names()
                    .into_iter()
                    .map(move |n| (n, dir, g.model_type.to_owned()))
            })
            .collect();
        let reset = reset.get();
        let mut filter = Filter {
            latest: vec![Vec::new(); inputs.len()],
            outputs: Vec::new(),
            mappings: Vec::new(),
            reset_unmapped: unmapped.value() == "reset",
            reset,
            path: m.path().to_owned(),
            warned: false,
            inputs,
        };
        if m.path().is_empty() {
            return filter;
        }
        let text = map.value().clone();
        let entries = match ferroc_pinmap::parse(&text) {
            Ok(e) => e,
            Err(e) => {
                m.problem(format!(
                    "parameter `map`: {} (at `{}`)",
                    e.what, &text[e.span]
                ));
                return filter;
            }
        };
        let port = |name: &str| {
            types
                .iter()
                .find(|(n, _, _)| n == name)
                .map(|(_, d, t)| (*d, t.as_str()))
        };
        let misfits = ferroc_pinmap::validate(&entries, port);
        if let Some(first) = misfits.first() {
            m.problem(format!(
                "parameter `map`: {} (at `{}`; help: {})",
                first.what,
                &text[first.span.clone()],
                first.help
            ));
            return filter;
        }
        filter.outputs = outputs
            .into_iter()
            .map(|port| {
                let shape = types
                    .iter()
                    .find(|(n, _, _)| n == port.name())
                    .and_then(|(_, _, t)| ferroc_pinmap::shape(t));
                let len = shape.and_then(|s| s.len).unwrap_or(0);
                Output {
                    port,
                    values: vec![reset; len],
                    integer: shape.is_some_and(|s| !s.element.starts_with('f')),
                }
            })
            .collect();
        filter.mappings = mappings(&entries, &filter.inputs, &mut filter.outputs, &types, reset);
        filter
    }
}

/// The element copies of `entries` (validated), growing vector outputs to the highest
/// index written.
fn mappings(
    entries: &[Entry<'_>],
    inputs: &[DynIn],
    outputs: &mut [Output],
    types: &[(String, Dir, String)],
    reset: f64,
) -> Vec<Mapping> {
    let mut out = Vec::new();
    let len_of = |name: &str| {
        types
            .iter()
            .find(|(n, _, _)| n == name)
            .and_then(|(_, _, t)| ferroc_pinmap::shape(t))
            .and_then(|s| s.len)
            .unwrap_or(1)
    };
    for e in entries {
        let (Some(i), Some(o)) = (
            inputs.iter().position(|p| p.name() == e.from.port),
            outputs.iter().position(|p| p.port.name() == e.to.port),
        ) else {
            continue;
        };
        let pairs: Vec<(usize, usize)> = match (e.from.index, e.to.index) {
            (None, None) => (0..len_of(e.from.port)).map(|k| (k, k)).collect(),
            (a, b) => vec![(a.unwrap_or(0), b.unwrap_or(0))],
        };
        for (a, b) in pairs {
            let o_ = &mut outputs[o];
            if o_.values.len() <= b {
                o_.values.resize(b + 1, reset);
            }
            out.push(Mapping {
                from: (i, a),
                to: (o, b),
                scale: e.scale,
                offset: e.offset,
            });
        }
    }
    out
}

impl Module for Filter {
    fn update(&mut self) {
        let mut any = false;
        let mut fresh = vec![false; self.inputs.len()];
        for (k, input) in self.inputs.iter().enumerate() {
            if input.changed() {
                self.latest[k].clear();
                input.get_elements(&mut self.latest[k]);
                fresh[k] = true;
                any = true;
            }
        }
        if !any {
            return;
        }
        let mut due = vec![false; self.outputs.len()];
        for m in &self.mappings {
            due[m.to.0] |= fresh[m.from.0];
        }
        for (o, out) in self.outputs.iter_mut().enumerate() {
            if !due[o] {
                continue;
            }
            if self.reset_unmapped {
                out.values.iter_mut().for_each(|v| *v = self.reset);
            }
            for m in self
                .mappings
                .iter()
                .filter(|m| m.to.0 == o && fresh[m.from.0])
            {
                if let Some(x) = self.latest[m.from.0].get(m.from.1) {
                    let y = x * m.scale + m.offset;
                    out.values[m.to.1] = if out.integer { y.round() } else { y };
                }
            }
            if let Err(e) = out.port.publish_elements(&out.values) {
                if !std::mem::replace(&mut self.warned, true) {
                    eprintln!("warning: {}: {e} (reported once)", self.path);
                }
            }
        }
    }
}
