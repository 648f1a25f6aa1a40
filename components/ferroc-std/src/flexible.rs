//! The flexible modules of `ferroc_std` (`Sum`, `FlexiSelect`, `Dump`) and `Clock`.
//!
//! The instance declares the ports of a flexible type in the model (`<port name="in"
//! dir="in" type="u32" count="3"/>`); the code receives them type-erased from
//! [`Setup::flexible_inputs`] and works with them through the runtime's value-type
//! table: numbers as `f64` (`Sum`), values forwarded unchanged (`FlexiSelect`), values
//! as text (`Dump`, and `Logger` in `logger.rs`).

use ferroc_runtime::console;
use ferroc_runtime::module::{
    DynIn, DynOut, In, Module, ModuleType, Out, Parameter, Setup, Timestamp, Wire,
};

/// `ferroc_std.Clock`: the wall-clock time and a cycle counter.
pub struct Clock {
    time: Out<Timestamp>,
    tick: Out<u64>,
    ticks: u64,
}

impl ModuleType for Clock {
    const NAME: &'static str = "ferroc_std.Clock";
    const DOC: &'static str =
        "Publishes the current time and a monotonically increasing tick count";
    fn create(m: &mut Setup<'_>) -> Self {
        Clock {
            time: m
                .output("time")
                .doc("time at the start of the cycle")
                .build(),
            tick: m
                .output("tick")
                .doc("number of cycles executed so far")
                .build(),
            ticks: 0,
        }
    }
}

impl Module for Clock {
    /// Publishes the time when its step runs (Clock is cheap: put it first in its
    /// thread container to get the start of the cycle) and the number of cycles
    /// including this one (1 in the first cycle).
    fn update(&mut self) {
        self.ticks = self.ticks.saturating_add(1);
        self.time.publish(Timestamp::now());
        self.tick.publish(self.ticks);
    }
}

/// `ferroc_std.Sum`: `out = in/0 + in/1 + …`, in the inputs' (one) type: numbers,
/// or vectors and fixed arrays of numbers added element by element (FlexiAdd).
///
/// Added as `f64` and converted back with `as` (saturating): exact for every number
/// up to 2^53, which covers counters and sensor values; larger `i64`/`u64` sums round.
/// Fixed arrays have one length by their type (the model's type check sees to that);
/// vectors of different lengths are a run-time error: reported once, with the
/// lengths, and nothing is published in such a cycle.
pub struct Sum {
    inputs: Vec<DynIn>,
    out: DynOut,
    path: String,
    elementwise: bool,
    sum: Vec<f64>,
    scratch: Vec<f64>,
    warned: bool,
}

impl ModuleType for Sum {
    const NAME: &'static str = "ferroc_std.Sum";
    const DOC: &'static str = "Adds all of its (instance-declared) inputs";
    fn create(m: &mut Setup<'_>) -> Self {
        Sum::new(m)
    }
}

/// `ferroc_std.Add` (FlexiAdd): [`Sum`] under the name of the flexible utility
/// components, for models that say what they mean with vectors and arrays.
pub struct Add(Sum);

impl ModuleType for Add {
    const NAME: &'static str = "ferroc_std.Add";
    const DOC: &'static str = "Adds its inputs: numbers, or vectors and arrays element by element";
    fn create(m: &mut Setup<'_>) -> Self {
        Add(Sum::new(m))
    }
}

impl Module for Add {
    fn update(&mut self) {
        self.0.update()
    }
}

impl Sum {
    fn new(m: &mut Setup<'_>) -> Self {
        let inputs = m.flexible_inputs("in").same_type().min_count(1).build_dyn();
        let mut elementwise = false;
        if let Some(ty) = m.flexible_type("in") {
            match m.value_type_of(ty) {
                Some(v) if v.is_number() => {}
                Some(v) if v.has_elements() => elementwise = true,
                Some(_) => m.problem(format!(
                    "Sum adds numbers, vectors or arrays of numbers; its inputs have type \
                     `{ty}` (use f64, u32, [f64], f64[3], …)"
                )),
                None => {}
            }
        }
        Sum {
            inputs,
            out: m.output_like("out", "in"),
            path: m.path().to_owned(),
            elementwise,
            sum: Vec::new(),
            scratch: Vec::new(),
            warned: false,
        }
    }
}

impl Module for Sum {
    fn update(&mut self) {
        if !self.elementwise {
            let sum: f64 = self.inputs.iter().filter_map(DynIn::get_f64).sum();
            self.out.publish_f64(sum);
            return;
        }
        if let Err(e) = self.add_elements() {
            if !std::mem::replace(&mut self.warned, true) {
                eprintln!(
                    "warning: {}: {e}; nothing is published while they differ (reported once)",
                    self.path
                );
            }
        }
    }
}

impl Sum {
    /// The element-wise sum, published; an error if the lengths differ.
    fn add_elements(&mut self) -> Result<(), String> {
        self.sum.clear();
        for (k, input) in self.inputs.iter().enumerate() {
            self.scratch.clear();
            input.get_elements(&mut self.scratch);
            if k == 0 {
                self.sum.extend_from_slice(&self.scratch);
            } else if self.scratch.len() != self.sum.len() {
                return Err(format!(
                    "`{}` has {} element(s), `{}` {}: element-wise sums need equal lengths",
                    self.inputs[0].name(),
                    self.sum.len(),
                    input.name(),
                    self.scratch.len()
                ));
            } else {
                self.sum
                    .iter_mut()
                    .zip(&self.scratch)
                    .for_each(|(s, x)| *s += x);
            }
        }
        self.out.publish_elements(&self.sum)
    }
}

/// `ferroc_std.FlexiSelect`: forwards input `select` (clamped to the last input) to
/// `out` and reports on `index` which one it forwarded.
pub struct FlexiSelect {
    inputs: Vec<DynIn>,
    select: In<u32>,
    out: DynOut,
    index: Out<u32>,
}

impl ModuleType for FlexiSelect {
    const NAME: &'static str = "ferroc_std.FlexiSelect";
    const DOC: &'static str = "Forwards one of several inputs of the same type";
    fn create(m: &mut Setup<'_>) -> Self {
        let inputs = m.flexible_inputs("in").same_type().min_count(1).build_dyn();
        FlexiSelect {
            inputs,
            select: m
                .input("select")
                .doc("index of the input to forward (default 0)")
                .build(),
            out: m.output_like("out", "in"),
            index: m
                .output("index")
                .doc("index of the input actually forwarded")
                .build(),
        }
    }
}

impl Module for FlexiSelect {
    /// Forwards every cycle (latest-value semantics, like `Scale`): a pooled value is
    /// cloned into a recycled buffer, a copy value copied.
    fn update(&mut self) {
        let Some(last) = self.inputs.len().checked_sub(1) else {
            return;
        };
        let k = (self.select.get() as usize).min(last);
        self.out.forward(&self.inputs[k]);
        self.index.publish(k as u32);
    }
}

/// `ferroc_std.Dump`: prints every input that received new data, one line each:
/// `label: in/0 = 1.5`. Library types print in their serde form (JSON:
/// `{"x":1.0,"y":2.0}`; NaN shows as `null` there), or by their `Debug` text if their
/// library registers them without serde.
pub struct Dump {
    inputs: Vec<DynIn>,
    /// The serde form of each input of a library type (`None`: built-in or no serde).
    serde: Vec<Option<Wire>>,
    bytes: Vec<u8>,
    label: Parameter<String>,
    line: String,
    print: fn(&str),
}

impl ModuleType for Dump {
    const NAME: &'static str = "ferroc_std.Dump";
    const DOC: &'static str = "Prints its inputs to the console (debugging aid)";
    fn create(m: &mut Setup<'_>) -> Self {
        let inputs = m.flexible_inputs("in").min_count(1).build_dyn();
        let serde = inputs
            .iter()
            .map(|input| {
                let ty = m
                    .port_groups()
                    .iter()
                    .find(|g| g.port_names().iter().any(|n| n == input.name()))?
                    .model_type;
                // Library types are qualified (`rescue.Pose2D`); built-ins keep their text.
                ty.contains('.')
                    .then(|| m.value_type_of(ty)?.wire().copied())
                    .flatten()
            })
            .collect();
        Dump {
            inputs,
            serde,
            bytes: Vec::new(),
            label: m
                .param("label")
                .default("dump".to_owned())
                .doc("prefix of every printed line")
                .build(),
            line: String::new(),
            print: console::line,
        }
    }
}

impl Dump {
    /// The lines of this cycle, each handed to `emit` (the line buffer is reused:
    /// no allocation once it is long enough).
    fn dump(&mut self, mut emit: impl FnMut(&str)) {
        let label = self.label.value();
        for (input, serde) in self.inputs.iter().zip(&self.serde) {
            if input.changed() {
                self.line.clear();
                self.line.push_str(label);
                self.line.push_str(": ");
                self.line.push_str(input.name());
                self.line.push_str(" = ");
                match serde.map(|w| w.json(input, &mut self.bytes)) {
                    Some(Ok(())) => self.line.push_str(&String::from_utf8_lossy(&self.bytes)),
                    _ => input.write_human(&mut self.line),
                }
                emit(&self.line);
            }
        }
    }
}

impl Module for Dump {
    fn update(&mut self) {
        let print = self.print;
        self.dump(print);
    }
}

#[cfg(test)]
mod tests;
