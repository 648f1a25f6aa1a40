//! Typed parameters with change notification.
//!
//! A module keeps a [`Parameter<T>`] as a struct field and reads it in its step. Whoever
//! holds the matching [`ParamHandle`] (the runtime, a configuration tool) may set a new
//! value at any time; the module sees it at its next read, and [`Parameter::changed`]
//! tells it once that the value changed (to recompute derived state). Reading an
//! unchanged parameter is one atomic load: no lock on the cycle path.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// A parameter value as models give it (after unit conversion into the declared unit).
/// Serde: a run plan carries parameter values (`ferroc_runner::plan`).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Value {
    /// `true` / `false`.
    Bool(bool),
    /// An integer.
    Int(i128),
    /// A number in the parameter's declared unit.
    Float(f64),
    /// A string (also the choices of an enumeration).
    Text(String),
    /// A duration.
    Duration(Duration),
    /// A list of values.
    List(Vec<Value>),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Bool(b) => write!(f, "{b}"),
            Value::Int(i) => write!(f, "{i}"),
            Value::Float(x) => write!(f, "{x}"),
            Value::Text(s) => write!(f, "{s:?}"),
            Value::Duration(d) => write!(f, "{d:?}"),
            Value::List(items) => {
                write!(f, "[")?;
                for (i, item) in items.iter().enumerate() {
                    if i > 0 {
                        write!(f, ", ")?;
                    }
                    write!(f, "{item}")?;
                }
                write!(f, "]")
            }
        }
    }
}

/// A Rust type a parameter can have.
pub trait ParamValue: Clone + Send + Sync + 'static {
    /// The type's name in manifests (`f64`, `u64`, `string`, `bool`, `duration`).
    fn model_type() -> &'static str;
    /// Converts a model value, or says in plain words why it does not fit.
    fn from_value(value: &Value) -> Result<Self, String>;
    /// The value as a manifest writes it (`default="…"`).
    fn to_text(&self) -> String;
}

impl ParamValue for f64 {
    fn model_type() -> &'static str {
        "f64"
    }
    fn from_value(value: &Value) -> Result<Self, String> {
        match value {
            Value::Float(x) => Ok(*x),
            Value::Int(i) => Ok(*i as f64),
            other => Err(format!("expected a number, got {other}")),
        }
    }
    fn to_text(&self) -> String {
        format!("{self}")
    }
}

macro_rules! int_param {
    ($($ty:ty => $name:literal),*) => {$(
        impl ParamValue for $ty {
            fn model_type() -> &'static str {
                $name
            }
            fn from_value(value: &Value) -> Result<Self, String> {
                match value {
                    Value::Int(i) => <$ty>::try_from(*i)
                        .map_err(|_| format!("{i} does not fit in {}", $name)),
                    other => Err(format!("expected an integer, got {other}")),
                }
            }
            fn to_text(&self) -> String {
                format!("{self}")
            }
        }
    )*};
}

int_param!(i32 => "i32", i64 => "i64", u8 => "u8", u16 => "u16", u32 => "u32", u64 => "u64");

impl ParamValue for bool {
    fn model_type() -> &'static str {
        "bool"
    }
    fn from_value(value: &Value) -> Result<Self, String> {
        match value {
            Value::Bool(b) => Ok(*b),
            other => Err(format!("expected true or false, got {other}")),
        }
    }
    fn to_text(&self) -> String {
        format!("{self}")
    }
}

impl ParamValue for String {
    fn model_type() -> &'static str {
        "string"
    }
    fn from_value(value: &Value) -> Result<Self, String> {
        match value {
            Value::Text(s) => Ok(s.clone()),
            other => Err(format!("expected a string, got {other}")),
        }
    }
    fn to_text(&self) -> String {
        self.clone()
    }
}

impl ParamValue for Duration {
    fn model_type() -> &'static str {
        "duration"
    }
    fn from_value(value: &Value) -> Result<Self, String> {
        match value {
            Value::Duration(d) => Ok(*d),
            other => Err(format!("expected a duration, got {other}")),
        }
    }
    fn to_text(&self) -> String {
        format!("{}s", self.as_secs_f64())
    }
}

/// What a parameter and its handles share: the latest value set and its version.
struct ParamCell<T> {
    version: AtomicU64,
    latest: Mutex<T>,
}

/// A parameter field of a module: `pub gain: Parameter<f64>`.
pub struct Parameter<T: ParamValue> {
    cell: Arc<ParamCell<T>>,
    value: T,
    seen: u64,
    changed: bool,
}

impl<T: ParamValue> Parameter<T> {
    /// A parameter holding `value` (the model's value, or the declared default) and
    /// its handle.
    pub(crate) fn new(name: &str, value: T, check: Option<Check>) -> (Self, ParamHandle) {
        let cell = Arc::new(ParamCell {
            version: AtomicU64::new(0),
            latest: Mutex::new(value.clone()),
        });
        let handle = ParamHandle {
            name: name.to_owned(),
            setter: Box::new(Setter {
                cell: cell.clone(),
                check,
            }),
        };
        let parameter = Parameter {
            cell,
            value,
            seen: 0,
            changed: false,
        };
        (parameter, handle)
    }

    /// A parameter holding `value` that nothing can set: for unit tests that build a
    /// module by hand instead of through a [`Setup`](super::Setup).
    pub fn fixed(value: T) -> Self {
        Self::new("", value, None).0
    }

    /// One load and a compare when nothing was set (every cycle of every module that
    /// reads a parameter goes through here); the copy is out of line.
    #[inline(always)]
    fn refresh(&mut self) {
        // Relaxed: the value itself is taken under the mutex, which orders it.
        let version = self.cell.version.load(Ordering::Relaxed);
        if version != self.seen {
            self.take_latest(version);
        }
    }

    #[cold]
    #[inline(never)]
    fn take_latest(&mut self, version: u64) {
        let latest = self
            .cell
            .latest
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        self.value = latest.clone();
        self.seen = version;
        self.changed = true;
    }

    /// The current value, borrowed: no clone, so a `String` parameter costs no
    /// allocation per cycle.
    #[inline]
    pub fn value(&mut self) -> &T {
        self.refresh();
        &self.value
    }

    /// The current value, cloned (convenient for numbers).
    #[inline]
    pub fn get(&mut self) -> T {
        self.value().clone()
    }

    /// True once after each new value was set (the initial value is not a change).
    pub fn changed(&mut self) -> bool {
        self.refresh();
        std::mem::take(&mut self.changed)
    }
}

/// Range and choice constraints a set value must meet (from the declaration).
#[derive(Clone, Debug, Default)]
pub(crate) struct Check {
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub choices: Vec<String>,
}

impl Check {
    pub(crate) fn validate(&self, value: &Value) -> Result<(), String> {
        let number = match value {
            Value::Float(x) => Some(*x),
            Value::Int(i) => Some(*i as f64),
            _ => None,
        };
        if let Some(x) = number {
            if self.min.is_some_and(|min| x < min) || self.max.is_some_and(|max| x > max) {
                return Err(format!(
                    "{x} is outside the allowed range {}..={}",
                    self.min.map_or("".into(), |m| m.to_string()),
                    self.max.map_or("".into(), |m| m.to_string())
                ));
            }
        }
        if let (Value::Text(s), false) = (value, self.choices.is_empty()) {
            if !self.choices.contains(s) {
                return Err(format!(
                    "{s:?} is not one of the choices: {}",
                    self.choices.join(", ")
                ));
            }
        }
        Ok(())
    }
}

trait SetErased: Send + Sync {
    fn set(&self, value: &Value) -> Result<(), String>;
    /// The latest value set, as a manifest writes it (for inspection).
    fn text(&self) -> String;
}

struct Setter<T> {
    cell: Arc<ParamCell<T>>,
    check: Option<Check>,
}

impl<T: ParamValue> SetErased for Setter<T> {
    fn set(&self, value: &Value) -> Result<(), String> {
        let typed = T::from_value(value)?;
        if let Some(check) = &self.check {
            check.validate(value)?;
        }
        let mut latest = self
            .cell
            .latest
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        *latest = typed;
        // Bumped under the lock, so a reader that sees the new version reads this value.
        self.cell.version.fetch_add(1, Ordering::Release);
        Ok(())
    }

    fn text(&self) -> String {
        let latest = self
            .cell
            .latest
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        latest.to_text()
    }
}

/// Sets a module's parameter from outside the module, at any time.
pub struct ParamHandle {
    name: String,
    setter: Box<dyn SetErased>,
}

impl ParamHandle {
    /// The parameter's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Sets a new value; a value of the wrong type or out of range is refused with the
    /// reason, and the module keeps the old one.
    pub fn set(&self, value: &Value) -> Result<(), String> {
        self.setter.set(value)
    }

    /// The latest value set (or the initial one), as a manifest writes it: what an
    /// inspector shows. Takes the parameter's lock briefly; the module's reads do not
    /// wait for it unless a value is being set.
    pub fn current(&self) -> String {
        self.setter.text()
    }
}

impl std::fmt::Debug for ParamHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ParamHandle({})", self.name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_set_value_is_seen_once_as_a_change() {
        let (mut gain, handle) = Parameter::new("gain", 1.0, None);
        assert!(!gain.changed());
        assert_eq!(gain.get(), 1.0);
        handle.set(&Value::Float(2.5)).unwrap();
        assert_eq!(*gain.value(), 2.5);
        assert!(gain.changed());
        assert!(!gain.changed());
    }

    #[test]
    fn bad_values_are_refused_and_the_old_value_stays() {
        let check = Check {
            min: Some(0.0),
            max: Some(1.0),
            choices: vec![],
        };
        let (mut p, handle) = Parameter::new("p", 0.5, Some(check));
        assert_eq!(
            handle.set(&Value::Float(3.0)).unwrap_err(),
            "3 is outside the allowed range 0..=1"
        );
        assert_eq!(
            handle.set(&Value::Text("x".into())).unwrap_err(),
            "expected a number, got \"x\""
        );
        assert_eq!(p.get(), 0.5);
        assert!(!p.changed());
        let (_, handle) = Parameter::new("n", 1u8, None);
        assert_eq!(
            handle.set(&Value::Int(300)).unwrap_err(),
            "300 does not fit in u8"
        );
    }

    #[test]
    fn choices_are_enforced() {
        let check = Check {
            choices: vec!["left".into(), "right".into()],
            ..Check::default()
        };
        let (_, handle) = Parameter::new("turn", String::from("left"), Some(check));
        assert!(handle.set(&Value::Text("right".into())).is_ok());
        assert!(handle.set(&Value::Text("up".into())).is_err());
    }
}
