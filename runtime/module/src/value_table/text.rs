//! How the value table reads registered values as numbers and writes them as text:
//! one [`ValueText`] per family of types (numbers, text, library types via `Debug`).

use super::super::Timestamp;
use std::fmt::{Debug, Write};

/// How a registered value type's values are read as numbers and written as text. Each
/// built-in family has one; library types use [`DebugText`] (their `Debug` output).
pub trait ValueText<T>: 'static {
    /// For people (`ferroc_std.Dump`): `1.5`, `true`, `hello`, `Pose2D { x: 1.0, .. }`.
    fn human(value: &T, out: &mut String);
    /// As one JSON value (for text logs): a JSON number, `true`, a
    /// quoted string, `null` for a non-finite float.
    fn json(value: &T, out: &mut String);
    /// The value as a number, if the type is a number.
    fn to_f64(_value: &T) -> Option<f64> {
        None
    }
    /// A number as a value of the type (saturating), if the type is a number.
    fn from_f64(_x: f64) -> Option<T> {
        None
    }
    /// Whether values are numbers or arrays of numbers, read and written element by
    /// element as `f64` (`Sum`, `Filter`, `Const`): the methods below then work.
    const ELEMENTS: bool = false;
    /// How many elements every value has (1 for a number, N for `f64[N]`, 16 for
    /// `f64[4][4]`); `None` for vectors, whose length varies.
    const FIXED_LEN: Option<usize> = None;
    /// Appends the elements of `value` as `f64` (row by row for nested arrays).
    fn elements(_value: &T, _out: &mut Vec<f64>) {}
    /// Overwrites `into` with `xs` (saturating `as` conversions); `xs` has
    /// [`FIXED_LEN`](Self::FIXED_LEN) elements if that is given.
    fn set_elements(_xs: &[f64], _into: &mut T) {}
}

/// Library types: `Debug` for people, the `Debug` text as a JSON string for logs.
pub struct DebugText;
/// Built-in numbers: `Display`, JSON numbers, and conversions to and from `f64`.
pub struct NumberText;
/// `bool`, `string`, `timestamp`: their `Display`, quoted in JSON where needed.
pub struct PlainText;

impl<T: Debug> ValueText<T> for DebugText {
    fn human(value: &T, out: &mut String) {
        let _ = write!(out, "{value:?}");
    }
    fn json(value: &T, out: &mut String) {
        let start = out.len();
        let _ = write!(out, "{value:?}");
        quote_tail(out, start);
    }
}

/// A built-in number type (what [`NumberText`] can convert).
pub trait Number: Copy + std::fmt::Display {
    /// `self as f64`.
    fn to_f64(self) -> f64;
    /// `x as Self` (saturating; NaN gives 0 for integers).
    fn from_f64(x: f64) -> Self;
    /// Whether the value has a JSON spelling (integers always; finite floats).
    fn is_finite(self) -> bool;
}

macro_rules! number {
    ($($ty:ty: $finite:expr),*) => {$(
        impl Number for $ty {
            fn to_f64(self) -> f64 {
                self as f64
            }
            fn from_f64(x: f64) -> Self {
                x as $ty
            }
            fn is_finite(self) -> bool {
                let check: fn($ty) -> bool = $finite;
                check(self)
            }
        }
    )*};
}
number!(f64: f64::is_finite, f32: f32::is_finite, i8: |_| true, i16: |_| true,
    i32: |_| true, i64: |_| true, u8: |_| true, u16: |_| true, u32: |_| true,
    u64: |_| true);

impl<T: Number> ValueText<T> for NumberText {
    fn human(value: &T, out: &mut String) {
        let _ = write!(out, "{value}");
    }
    fn json(value: &T, out: &mut String) {
        if value.is_finite() {
            let _ = write!(out, "{value}");
        } else {
            out.push_str("null");
        }
    }
    fn to_f64(value: &T) -> Option<f64> {
        Some(value.to_f64())
    }
    fn from_f64(x: f64) -> Option<T> {
        Some(T::from_f64(x))
    }
    const ELEMENTS: bool = true;
    const FIXED_LEN: Option<usize> = Some(1);
    fn elements(value: &T, out: &mut Vec<f64>) {
        out.push(value.to_f64())
    }
    fn set_elements(xs: &[f64], into: &mut T) {
        if let Some(x) = xs.first() {
            *into = T::from_f64(*x);
        }
    }
}

impl ValueText<bool> for PlainText {
    fn human(value: &bool, out: &mut String) {
        out.push_str(if *value { "true" } else { "false" });
    }
    fn json(value: &bool, out: &mut String) {
        Self::human(value, out)
    }
}

impl ValueText<String> for PlainText {
    fn human(value: &String, out: &mut String) {
        out.push_str(value);
    }
    fn json(value: &String, out: &mut String) {
        let start = out.len();
        out.push_str(value);
        quote_tail(out, start);
    }
}

/// `1.5s` for people (`Debug`), seconds as a JSON number.
impl ValueText<std::time::Duration> for PlainText {
    fn human(value: &std::time::Duration, out: &mut String) {
        let _ = write!(out, "{value:?}");
    }
    fn json(value: &std::time::Duration, out: &mut String) {
        let _ = write!(out, "{}", value.as_secs_f64());
    }
}

impl ValueText<Timestamp> for PlainText {
    fn human(value: &Timestamp, out: &mut String) {
        let _ = write!(out, "{value}");
    }
    fn json(value: &Timestamp, out: &mut String) {
        let _ = write!(out, "\"{value}\"");
    }
}

/// Turns `out[start..]` into a JSON string literal in place, without allocating once
/// `out` has the capacity: the escaped text is appended behind the raw text, which is
/// then drained away.
pub(crate) fn quote_tail(out: &mut String, start: usize) {
    let raw_end = out.len();
    out.push('"');
    let mut i = start;
    while let Some(c) = out.get(i..raw_end).and_then(|rest| rest.chars().next()) {
        i += c.len_utf8();
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if c < ' ' => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out.drain(start..raw_end);
}
