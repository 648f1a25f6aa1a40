//! Conversions on connections: parts of values, unit scales, numeric type changes.
//!
//! The checker decides what a connection needs (`<convert field="linear">` takes one
//! field of a struct, `rad/s` → `deg/s` is a scale of 57.29…, `u32` → `u64` a
//! widening); the runtime realises it with small converters that the builder
//! schedules right after the writing module's steps, so the reader sees the converted
//! value in the same cycle, exactly as with a direct connection.
//!
//! Taking a field apart needs code that knows the struct, so library crates register
//! one accessor per field ([`Registry::register_field`](super::Registry::register_field));
//! elements of `Vec`s of numbers are built in.

use ferroc_exec::Step;
use ferroc_module::{PortKind, PortValue};
use ferroc_ports::port::{CopyInputPort, CopyOutputPort, InputHandle, NoUninit, OutputHandle};
use std::borrow::Borrow;

/// What a connection does to each value on the way: first the parts in `select` are
/// taken, in order, then `to = part · scale + offset`.
#[derive(Clone, Debug, PartialEq)]
pub struct Conversion {
    /// Multiplier (unit scale, `<convert scale>`).
    pub scale: f64,
    /// Added after scaling (`<convert offset>`).
    pub offset: f64,
    /// Fields and elements to take, outermost first (`<convert field|index>`).
    pub select: Vec<Select>,
}

/// One step into a value: a struct field or a list element.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Select {
    /// `<convert field="linear">`.
    Field(String),
    /// `<convert index="2">` (a missing element reads as the default value).
    Index(usize),
}

impl Default for Conversion {
    fn default() -> Self {
        Conversion::linear(1.0, 0.0)
    }
}

impl Conversion {
    /// `to = from · scale + offset`, nothing selected.
    pub fn linear(scale: f64, offset: f64) -> Self {
        Conversion {
            scale,
            offset,
            select: Vec::new(),
        }
    }

    /// This conversion, taking `field` of the value first (after earlier selections).
    pub fn field(mut self, field: &str) -> Self {
        self.select.push(Select::Field(field.to_owned()));
        self
    }

    /// This conversion, taking element `index` of the value first (after earlier
    /// selections).
    pub fn index(mut self, index: usize) -> Self {
        self.select.push(Select::Index(index));
        self
    }

    /// Whether values pass unchanged.
    pub fn is_identity(&self) -> bool {
        self.scale == 1.0 && self.offset == 0.0 && self.select.is_empty()
    }

    /// Whether the numeric part (`scale`, `offset`) changes values.
    pub(crate) fn scales(&self) -> bool {
        self.scale != 1.0 || self.offset != 0.0
    }
}

/// Makes the converter for one [`Select`] step: from its name and the index (0 for a
/// field).
pub(crate) type Extract = std::sync::Arc<dyn Fn(String, usize) -> Converter + Send + Sync>;

/// A converter that reads an `S` and publishes `get(value, index)`.
pub(crate) fn extractor<S: PortValue, F: PortValue>(
    get: impl Fn(&S, usize) -> F + Copy + Send + Sync + 'static,
) -> Extract {
    std::sync::Arc::new(move |name: String, index: usize| {
        let (input, input_handle) = S::Kind::input(&format!("{name}/in"), None);
        let (output, output_handle) = F::Kind::output(&format!("{name}/out"));
        let step = Step::new(name, move || {
            if S::Kind::take_changed(&input) {
                let value = S::Kind::get(&input);
                F::Kind::publish(&output, get(value.borrow(), index));
            }
        });
        Converter {
            input: input_handle,
            output: output_handle,
            step,
        }
    })
}

/// Element `index` of a list, or the default value when the list is shorter.
pub(crate) fn element<T: Copy + Default>(list: &[T], index: usize) -> T {
    list.get(index).copied().unwrap_or_default()
}

/// A numeric type a converter can read and write.
trait Number: NoUninit + Default + Send + Sync + 'static {
    fn to_f64(self) -> f64;
    fn from_f64(x: f64) -> Self;
}

macro_rules! number {
    ($($ty:ty),*) => {$(
        impl Number for $ty {
            fn to_f64(self) -> f64 {
                self as f64
            }
            // `as` saturates at the type's bounds (and maps NaN to 0 for integers).
            fn from_f64(x: f64) -> Self {
                x as $ty
            }
        }
    )*};
}
number!(f64, f32, i8, i16, i32, i64, u8, u16, u32, u64);

/// A converter: an input to connect the source to, an output to connect to the
/// target, and the step that moves (converted) values from one to the other.
pub(crate) struct Converter {
    pub input: InputHandle,
    pub output: OutputHandle,
    pub step: Step,
}

fn make<A: Number, B: Number>(name: String, conversion: Conversion) -> Converter {
    let input = CopyInputPort::<A>::new(format!("{name}/in"));
    let output = CopyOutputPort::<B>::new(format!("{name}/out"));
    let (input_handle, output_handle) = (input.handle(), output.handle());
    let step = Step::new(name, move || {
        if input.take_changed() {
            let x = input.get().to_f64() * conversion.scale + conversion.offset;
            output.publish(B::from_f64(x));
        }
    });
    Converter {
        input: input_handle,
        output: output_handle,
        step,
    }
}

macro_rules! dispatch_to {
    ($from:ty, $to:expr, $name:expr, $conv:expr) => {
        match $to {
            "f64" => Some(make::<$from, f64>($name, $conv)),
            "f32" => Some(make::<$from, f32>($name, $conv)),
            "i8" => Some(make::<$from, i8>($name, $conv)),
            "i16" => Some(make::<$from, i16>($name, $conv)),
            "i32" => Some(make::<$from, i32>($name, $conv)),
            "i64" => Some(make::<$from, i64>($name, $conv)),
            "u8" => Some(make::<$from, u8>($name, $conv)),
            "u16" => Some(make::<$from, u16>($name, $conv)),
            "u32" => Some(make::<$from, u32>($name, $conv)),
            "u64" => Some(make::<$from, u64>($name, $conv)),
            _ => None,
        }
    };
}

/// A converter between two numeric value types (by Rust type name), or `None` when
/// either side is not a number.
pub(crate) fn numeric(
    from: &str,
    to: &str,
    name: String,
    conversion: Conversion,
) -> Option<Converter> {
    match from {
        "f64" => dispatch_to!(f64, to, name, conversion),
        "f32" => dispatch_to!(f32, to, name, conversion),
        "i8" => dispatch_to!(i8, to, name, conversion),
        "i16" => dispatch_to!(i16, to, name, conversion),
        "i32" => dispatch_to!(i32, to, name, conversion),
        "i64" => dispatch_to!(i64, to, name, conversion),
        "u8" => dispatch_to!(u8, to, name, conversion),
        "u16" => dispatch_to!(u16, to, name, conversion),
        "u32" => dispatch_to!(u32, to, name, conversion),
        "u64" => dispatch_to!(u64, to, name, conversion),
        _ => None,
    }
}
