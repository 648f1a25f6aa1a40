//! Ports driving parameters: `<connect from="context/max_speed" to="planner/param/max_speed"/>`.
//!
//! OpenRDK-style properties and FINROC's parameter connections: a module's output sets
//! another module's parameter while the application runs. A step after the writer's
//! steps (like a converter) takes each new value and sets the parameter, which the
//! reading module notices with `changed()`. Numbers only: the value travels as `f64`
//! and becomes the parameter's own type.

use super::{convert, find, BuildError, Builder, Conversion};
use crate::container::Step;
use crate::module::{ParamHandle, Value};
use crate::port::{ConnectOptions, CopyInputPort};
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
        let number = convert::numeric(output.value_type(), "f64", describe.clone(), conversion)
            .ok_or_else(|| {
                BuildError::Connect(format!(
                    "{describe}: the port carries {}, not a number",
                    output.value_type()
                ))
            })?;
        let input = CopyInputPort::<f64>::new(format!("{describe}/param"));
        let fail = |e: crate::port::ConnectError| BuildError::Connect(format!("{describe}: {e}"));
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
