//! Vectors and fixed arrays of built-in numbers in the value table: their text and
//! their element-wise access (what `Sum`, `Filter` and `Const` compute with).

use super::{Number, ValueText};
use std::fmt::{Debug, Write};

/// Vectors and fixed arrays of built-in numbers: `Debug` text for people, JSON arrays
/// (non-finite floats as `null`), and element-wise access.
pub struct ArrayText;

/// A vector or array of numbers, nested at most once (`f64[4][4]`).
pub trait NumberArray: 'static {
    /// The element count of every value, if fixed.
    const LEN: Option<usize>;
    /// Visits every element, in order.
    fn each(&self, f: &mut dyn FnMut(f64));
    /// Sets the elements from `xs` (which has [`LEN`](Self::LEN) elements if fixed).
    fn set(&mut self, xs: &[f64]);
}

impl<T: Number + 'static> NumberArray for Vec<T> {
    const LEN: Option<usize> = None;
    fn each(&self, f: &mut dyn FnMut(f64)) {
        self.iter().for_each(|x| f(x.to_f64()))
    }
    fn set(&mut self, xs: &[f64]) {
        self.clear();
        self.extend(xs.iter().map(|x| T::from_f64(*x)));
    }
}

impl<T: Number + 'static, const N: usize> NumberArray for [T; N] {
    const LEN: Option<usize> = Some(N);
    fn each(&self, f: &mut dyn FnMut(f64)) {
        self.iter().for_each(|x| f(x.to_f64()))
    }
    fn set(&mut self, xs: &[f64]) {
        for (slot, x) in self.iter_mut().zip(xs) {
            *slot = T::from_f64(*x);
        }
    }
}

impl<T: Number + 'static, const N: usize, const M: usize> NumberArray for [[T; N]; M] {
    const LEN: Option<usize> = Some(N * M);
    fn each(&self, f: &mut dyn FnMut(f64)) {
        self.iter().flatten().for_each(|x| f(x.to_f64()))
    }
    fn set(&mut self, xs: &[f64]) {
        for (slot, x) in self.iter_mut().flatten().zip(xs) {
            *slot = T::from_f64(*x);
        }
    }
}

impl<A: NumberArray + Debug> ValueText<A> for ArrayText {
    fn human(value: &A, out: &mut String) {
        let _ = write!(out, "{value:?}");
    }
    fn json(value: &A, out: &mut String) {
        out.push('[');
        let mut first = true;
        value.each(&mut |x| {
            if !std::mem::take(&mut first) {
                out.push(',');
            }
            if x.is_finite() {
                let _ = write!(out, "{x}");
            } else {
                out.push_str("null");
            }
        });
        out.push(']');
    }
    const ELEMENTS: bool = true;
    const FIXED_LEN: Option<usize> = A::LEN;
    fn elements(value: &A, out: &mut Vec<f64>) {
        value.each(&mut |x| out.push(x))
    }
    fn set_elements(xs: &[f64], into: &mut A) {
        into.set(xs)
    }
}
