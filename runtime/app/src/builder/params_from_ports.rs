//! Ports driving parameters: `<connect from="context/max_speed" to="planner/param/max_speed"/>`.
//!
//! OpenRDK-style properties and FINROC's parameter connections: a module's output sets
//! another module's parameter while the application runs. A step after the writer's
//! steps (like a converter) takes each new value and sets the parameter, which the
//! reading module notices with `changed()`. Numbers only: the value travels as `f64`
//! and becomes the parameter's own type.

use super::{convert, find, BuildError, Builder, Conversion};
use ferroc_exec::Step;
use ferroc_module::{ParamHandle, Value};
use ferroc_ports::port::{ConnectOptions, CopyInputPort};
use std::sync::Arc;
use std::time::Duration;

impl Builder<'_> {
    /// Makes the output `from` (module path, port) set the parameter `to` (module
    /// path, parameter name) whenever it publishes a new value, scaled by
    /// `conversion` (units). Values the parameter refuses (out of its range) leave it
    /// unchanged and are reported once.
    pub fn connect_param(
        &mut self,
        from: (&str, &str),
        to: (&str, &str),
        conversion: Conversion,
    ) -> Result<(), BuildError> {
        let (writer, reader) = (self.module(from.0)?, self.module(to.0)?);
        let describe = format!("`{}/{}` → `{}/param/{}`", from.0, from.1, to.0, to.1);
        let output = find(&self.modules[writer].outputs, from, "output")?;
        let (param, make) = self.drivable_param(reader, to, &describe)?;
        let number = convert::numeric(output.value_type(), "f64", describe.clone(), conversion)
            .ok_or_else(|| {
                BuildError::Connect(format!(
                    "{describe}: the port carries {}, not a number",
                    output.value_type()
                ))
            })?;
        let input = CopyInputPort::<f64>::new(format!("{describe}/param"));
        let fail =
            |e: ferroc_ports::port::ConnectError| BuildError::Connect(format!("{describe}: {e}"));
        output
            .connect(&number.input, ConnectOptions::default())
            .map_err(fail)?;
        number
            .output
            .connect(&input.handle(), ConnectOptions::default())
            .map_err(fail)?;
        let set = set_step(describe, input, param, make);
        let steps = &mut self.modules[writer].converters;
        steps.push(number.step);
        steps.push(set);
        Ok(())
    }
}

impl Builder<'_> {
    /// The receiving end of a parameter link from another part (`spec.model_type` is
    /// `f64`; the sending end is an ordinary [`Builder::link_out`] with the unit scale):
    /// each value that arrives sets the parameter `to` (module path, parameter name).
    pub fn link_in_param(
        &mut self,
        spec: &ferroc_link::LinkSpec<'_>,
        to: (&str, &str),
    ) -> Result<(), BuildError> {
        let reader = self.module(to.0)?;
        let describe = format!("part `{}` → `{}/param/{}`", spec.from_part, to.0, to.1);
        let (param, make) = self.drivable_param(reader, to, &describe)?;
        let end = Arc::new(ParamEnd {
            param,
            make,
            describe: describe.clone(),
            warned: std::sync::atomic::AtomicBool::new(false),
        });
        self.direct_end(spec.id, end, &describe)?;
        (self.remote.receiving).insert(spec.id, spec.from_part.to_owned());
        Ok(())
    }

    /// The parameter `to` of module `reader` and how an `f64` becomes its value.
    fn drivable_param(
        &self,
        reader: usize,
        to: (&str, &str),
        describe: &str,
    ) -> Result<(Arc<ParamHandle>, MakeValue), BuildError> {
        let param = self.modules[reader]
            .params
            .iter()
            .find(|(n, _)| n == to.1)
            .map(|(_, h)| Arc::clone(h))
            .ok_or_else(|| BuildError::Create {
                path: to.0.into(),
                problems: vec![format!("the type has no parameter `{}`", to.1)],
            })?;
        let model_type = self.modules[reader]
            .interface
            .param(to.1)
            .map(|p| p.model_type.clone())
            .unwrap_or_default();
        let make = value_maker(&model_type).ok_or_else(|| {
            BuildError::Connect(format!(
                "{describe}: only number, bool and duration parameters can be driven by a port, not `{model_type}`"
            ))
        })?;
        Ok((param, make))
    }
}

/// How an `f64` becomes a parameter's value (see [`value_maker`]).
type MakeValue = fn(f64) -> Value;

/// Sets a parameter from the `f64`s that arrive from another part.
struct ParamEnd {
    param: Arc<ParamHandle>,
    make: MakeValue,
    describe: String,
    warned: std::sync::atomic::AtomicBool,
}

impl ferroc_link::Receive for ParamEnd {
    fn receive(&self, bytes: &[u8]) -> Result<(), String> {
        let x: f64 = postcard::from_bytes(bytes).map_err(|e| format!("{}: {e}", self.describe))?;
        if let Err(why) = self.param.set(&(self.make)(x)) {
            if !self.warned.swap(true, std::sync::atomic::Ordering::Relaxed) {
                eprintln!(
                    "warning: {}: {why}; the parameter keeps its value",
                    self.describe
                );
            }
        }
        Ok(())
    }
}

/// How an `f64` becomes a value of a parameter of this model type.
fn value_maker(model_type: &str) -> Option<fn(f64) -> Value> {
    Some(match model_type {
        "f32" | "f64" | "Activity" | "Stimulation" | "Inhibition" | "TargetRating" => Value::Float,
        "i8" | "i16" | "i32" | "i64" | "u8" | "u16" | "u32" | "u64" => {
            |x: f64| Value::Int(x.round() as i128)
        }
        "bool" => |x: f64| Value::Bool(x != 0.0),
        "duration" => |x: f64| Value::Duration(Duration::from_secs_f64(x.clamp(0.0, 1e9))),
        _ => return None,
    })
}

fn set_step(
    name: String,
    input: CopyInputPort<f64>,
    param: Arc<ParamHandle>,
    make: fn(f64) -> Value,
) -> Step {
    let mut warned = false;
    Step::new(name.clone(), move || {
        if input.take_changed() {
            if let Err(why) = param.set(&make(input.get())) {
                if !std::mem::replace(&mut warned, true) {
                    eprintln!("warning: {name}: {why}; the parameter keeps its value");
                }
            }
        }
    })
}
