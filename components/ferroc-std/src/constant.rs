//! `ferroc_std.Const` (FlexiConst): constant outputs of any declared type.
//!
//! The instance declares the outputs (`<port name="out" dir="out" type="f64[3]"
//! count="2"/>`) and gives their values in `values`, a JSON array with one value per
//! output in the type's serde form: `[1.5, [1, 2, 3]]`, `["hello"]`, `[{"x": 1.0,
//! "y": 2.0, "theta": 0.0}]` for a library struct. The values are parsed when the
//! instance is created (a value that does not fit its output's type refuses the
//! instance, naming the output); `publish` says when they go out: `once` (the first
//! step), `period` (every `period` of model time) or `always` (every step).

use ferroc_runtime::module::{DynOut, Module, ModuleType, Parameter, Setup, Wire};
use std::time::Duration;

/// `ferroc_std.Const`: see the [module docs](self).
pub struct Const {
    outputs: Vec<(DynOut, Wire, Vec<u8>)>,
    when: When,
    period: Parameter<Duration>,
    /// Log time (ns) when the values are due next; `None`: at the next step.
    next: Option<u64>,
    done: bool,
}

#[derive(Clone, Copy, PartialEq)]
enum When {
    Once,
    Period,
    Always,
}

impl ModuleType for Const {
    const NAME: &'static str = "ferroc_std.Const";
    const DOC: &'static str = "Publishes constant values of any declared type";
    fn create(m: &mut Setup<'_>) -> Self {
        let outputs = m.flexible_outputs("out").min_count(1).build_dyn_outputs();
        let mut values: Parameter<String> = m
            .param("values")
            .doc("a JSON array: one value per output, in its type's serde form")
            .build();
        let mut publish: Parameter<String> = m
            .param("publish")
            .default("always".to_owned())
            .choices(&["once", "period", "always"])
            .doc("the first step only, every period, or every step")
            .build();
        let period = m
            .param("period")
            .default(Duration::from_secs(1))
            .range(0.001, 3600.0)
            .doc("how often `publish=period` publishes")
            .build();
        let when = match publish.value().as_str() {
            "once" => When::Once,
            "period" => When::Period,
            _ => When::Always,
        };
        let mut c = Const {
            outputs: Vec::new(),
            when,
            period,
            next: None,
            done: false,
        };
        if m.path().is_empty() {
            return c;
        }
        match parse(m, outputs, values.value()) {
            Ok(outputs) => c.outputs = outputs,
            Err(why) => m.problem(format!("parameter `values`: {why}")),
        }
        c
    }
}

type Parsed = Vec<(DynOut, Wire, Vec<u8>)>;

fn parse(m: &Setup<'_>, outputs: Vec<DynOut>, text: &str) -> Result<Parsed, String> {
    let values: Vec<serde_json::Value> = serde_json::from_str(text).map_err(|e| {
        format!("write a JSON array with one value per output, e.g. [1.5, [1, 2]] ({e})")
    })?;
    if values.len() != outputs.len() {
        return Err(format!(
            "{} value(s) for {} output(s)",
            values.len(),
            outputs.len()
        ));
    }
    let mut parsed = Vec::with_capacity(outputs.len());
    for (out, value) in outputs.into_iter().zip(values) {
        let ty = m
            .port_groups()
            .iter()
            .find(|g| g.port_names().iter().any(|n| n == out.name()))
            .map_or("", |g| g.model_type);
        let wire = m
            .value_type_of(ty)
            .and_then(|v| v.wire())
            .copied()
            .ok_or_else(|| {
                format!(
                    "output `{}`: `{ty}` has no serde form (its library registers it without serde)",
                    out.name()
                )
            })?;
        let bytes = serde_json::to_vec(&value).map_err(|e| e.to_string())?;
        wire.from_json(None, &bytes)
            .map_err(|e| format!("output `{}`: {value} is {e}", out.name()))?;
        parsed.push((out, wire, bytes));
    }
    Ok(parsed)
}

impl Module for Const {
    fn update(&mut self) {
        if self.done {
            return;
        }
        match self.when {
            When::Once => self.done = true,
            When::Always => {}
            When::Period => {
                let now = crate::logger::log_time();
                let period = u64::try_from(self.period.get().as_nanos()).unwrap_or(u64::MAX);
                // A quarter period early counts as due (containers start a little early
                // or late); deadlines advance by whole periods.
                if self
                    .next
                    .is_some_and(|n| now.saturating_add(period / 4) < n)
                {
                    return;
                }
                self.next = Some(match self.next {
                    Some(n) if now < n.saturating_add(period) => n.saturating_add(period),
                    _ => now.saturating_add(period),
                });
            }
        }
        for (out, wire, bytes) in &self.outputs {
            // Checked at creation: parsing the same text again cannot fail.
            let _ = wire.from_json(Some(out), bytes);
        }
    }
}
