//! Conversions on connections: unit scales and numeric type changes.
//!
//! The checker decides what a connection needs (`rad/s` → `deg/s` is a scale of
//! 57.29…, `u32` → `u64` a widening); the runtime realises it with a small converter
//! that the builder schedules right after the writing module's steps, so the reader
//! sees the converted value in the same cycle, exactly as with a direct connection.

use crate::container::Step;
use crate::port::{CopyInputPort, CopyOutputPort, InputHandle, NoUninit, OutputHandle};

/// What a connection does to each value on the way: `to = from · scale + offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conversion {
    /// Multiplier (unit scale, `<convert scale>`).
    pub scale: f64,
    /// Added after scaling (`<convert offset>`).
    pub offset: f64,
}

impl Default for Conversion {
    fn default() -> Self {
        Conversion {
            scale: 1.0,
            offset: 0.0,
        }
    }
}

impl Conversion {
    /// Whether values pass unchanged.
    pub fn is_identity(&self) -> bool {
        self.scale == 1.0 && self.offset == 0.0
    }
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
