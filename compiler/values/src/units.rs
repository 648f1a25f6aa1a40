//! Physical units: SI symbols with prefixes, plus `deg`, `rpm`, `Hz`, `min`, `h`.
//!
//! A unit is a dimension vector and a scale to the coherent SI unit. Angle is kept as its
//! own dimension (not dimensionless, as strict SI has it) so that `rad` fed into `m`
//! is caught: in robot software that is nearly always a bug.

use std::fmt;

/// Exponents of m, kg, s, A, K, mol, cd, rad.
pub type Dimension = [i8; 8];

const NAMES: [&str; 8] = ["m", "kg", "s", "A", "K", "mol", "cd", "rad"];

#[derive(Clone, Debug, PartialEq)]
pub struct Unit {
    pub dimension: Dimension,
    /// Multiply a value in this unit by `scale` to get coherent SI (`mm` → 0.001).
    pub scale: f64,
    /// The text as written, for messages.
    pub text: String,
}

impl fmt::Display for Unit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

/// Names the dimension the way an engineer reads it: `velocity (m·s^-1)`.
pub fn describe_dimension(d: &Dimension) -> String {
    let symbols = dimension_symbols(d);
    let name = match d {
        [1, 0, 0, 0, 0, 0, 0, 0] => "length",
        [0, 0, 1, 0, 0, 0, 0, 0] => "time",
        [0, 1, 0, 0, 0, 0, 0, 0] => "mass",
        [0, 0, 0, 0, 0, 0, 0, 1] => "angle",
        [1, 0, -1, 0, 0, 0, 0, 0] => "velocity",
        [1, 0, -2, 0, 0, 0, 0, 0] => "acceleration",
        [0, 0, -1, 0, 0, 0, 0, 1] => "angular velocity",
        [0, 0, -1, 0, 0, 0, 0, 0] => "frequency",
        [1, 1, -2, 0, 0, 0, 0, 0] => "force",
        _ => return symbols,
    };
    format!("{name} ({symbols})")
}

fn dimension_symbols(d: &Dimension) -> String {
    let parts: Vec<String> = d
        .iter()
        .zip(NAMES)
        .filter(|(e, _)| **e != 0)
        .map(|(e, n)| {
            if *e == 1 {
                n.to_string()
            } else {
                format!("{n}^{e}")
            }
        })
        .collect();
    if parts.is_empty() {
        "dimensionless".into()
    } else {
        parts.join("·")
    }
}

fn dim(m: i8, kg: i8, s: i8, a: i8, k: i8, rad: i8) -> Dimension {
    [m, kg, s, a, k, 0, 0, rad]
}

/// Units an editor offers as completions (`ferroc lsp`): the symbols [`parse_unit`]
/// reads and the prefixed and compound units robot models use most. Each parses (a
/// test says so); [`parse_unit`] accepts many more.
pub const SUGGESTED: &[&str] = &[
    "m", "mm", "cm", "km", "m/s", "mm/s", "km/h", "m/s^2", "rad", "rad/s", "rad/s^2", "deg",
    "deg/s", "rpm", "s", "ms", "us", "ns", "min", "h", "Hz", "kHz", "kg", "g", "N", "N*m", "Pa",
    "kPa", "bar", "J", "W", "kW", "V", "mV", "A", "mA", "C", "Ohm", "K", "mol", "cd", "L", "%",
];

/// Unprefixed symbols: (symbol, dimension, scale, accepts SI prefixes).
fn symbol(sym: &str) -> Option<(Dimension, f64, bool)> {
    use std::f64::consts::PI;
    Some(match sym {
        "m" => (dim(1, 0, 0, 0, 0, 0), 1.0, true),
        "g" => (dim(0, 1, 0, 0, 0, 0), 1e-3, true),
        "s" => (dim(0, 0, 1, 0, 0, 0), 1.0, true),
        "A" => (dim(0, 0, 0, 1, 0, 0), 1.0, true),
        "K" => (dim(0, 0, 0, 0, 1, 0), 1.0, true),
        "mol" => ([0, 0, 0, 0, 0, 1, 0, 0], 1.0, true),
        "cd" => ([0, 0, 0, 0, 0, 0, 1, 0], 1.0, true),
        "rad" => (dim(0, 0, 0, 0, 0, 1), 1.0, true),
        "deg" | "°" => (dim(0, 0, 0, 0, 0, 1), PI / 180.0, false),
        "rpm" => (dim(0, 0, -1, 0, 0, 1), 2.0 * PI / 60.0, false),
        "Hz" => (dim(0, 0, -1, 0, 0, 0), 1.0, true),
        "N" => (dim(1, 1, -2, 0, 0, 0), 1.0, true),
        "Pa" => (dim(-1, 1, -2, 0, 0, 0), 1.0, true),
        "J" => (dim(2, 1, -2, 0, 0, 0), 1.0, true),
        "W" => (dim(2, 1, -3, 0, 0, 0), 1.0, true),
        "V" => (dim(2, 1, -3, -1, 0, 0), 1.0, true),
        "C" => (dim(0, 0, 1, 1, 0, 0), 1.0, true),
        "Ohm" | "Ω" => (dim(2, 1, -3, -2, 0, 0), 1.0, true),
        "min" => (dim(0, 0, 1, 0, 0, 0), 60.0, false),
        "h" => (dim(0, 0, 1, 0, 0, 0), 3600.0, false),
        "L" | "l" => (dim(3, 0, 0, 0, 0, 0), 1e-3, true),
        "bar" => (dim(-1, 1, -2, 0, 0, 0), 1e5, true),
        "%" => ([0; 8], 0.01, false),
        _ => return None,
    })
}

fn prefix(p: &str) -> Option<f64> {
    Some(match p {
        "G" => 1e9,
        "M" => 1e6,
        "k" => 1e3,
        "h" => 1e2,
        "da" => 1e1,
        "d" => 1e-1,
        "c" => 1e-2,
        "m" => 1e-3,
        "u" | "µ" | "μ" => 1e-6,
        "n" => 1e-9,
        "p" => 1e-12,
        _ => return None,
    })
}

fn atom(text: &str) -> Option<(Dimension, f64)> {
    if let Some((d, s, _)) = symbol(text) {
        return Some((d, s));
    }
    // Longest prefix first: `da` before `d`.
    for split in (1..text.len()).rev() {
        if !text.is_char_boundary(split) {
            continue;
        }
        let (p, rest) = text.split_at(split);
        if let (Some(factor), Some((d, s, true))) = (prefix(p), symbol(rest)) {
            return Some((d, s * factor));
        }
    }
    None
}

/// Parses `m`, `mm/s`, `m/s^2`, `m/s2`, `N*m`, `N.m`, `rad/s`, `km/h`, `1/s`.
pub fn parse_unit(text: &str) -> Result<Unit, String> {
    let t = text.trim();
    if t.is_empty() {
        return Err("empty unit".into());
    }
    let mut dimension = [0i8; 8];
    let mut scale = 1.0;
    let mut sign = 1i8;
    let mut rest = t;
    loop {
        let end = rest.find(['*', '/', '.', '·']).unwrap_or(rest.len());
        let factor = rest[..end].trim();
        let (sym, exp) =
            split_exponent(factor).ok_or_else(|| format!("`{factor}` is not a unit"))?;
        if !(sym == "1" && sign == 1 && exp == 1) {
            let (d, s) = atom(sym).ok_or_else(|| format!("unknown unit `{sym}`"))?;
            let e = exp.checked_mul(sign).ok_or("exponent too large")?;
            for (acc, x) in dimension.iter_mut().zip(d) {
                *acc = acc
                    .checked_add(x.checked_mul(e).ok_or("exponent too large")?)
                    .ok_or("exponent too large")?;
            }
            scale *= s.powi(e as i32);
        }
        if end == rest.len() {
            break;
        }
        sign = if rest[end..].starts_with('/') { -1 } else { 1 };
        rest = &rest[end + rest[end..].chars().next().map_or(1, char::len_utf8)..];
    }
    Ok(Unit {
        dimension,
        scale,
        text: t.to_string(),
    })
}

/// `s^2` → (`s`, 2); `s2` → (`s`, 2); `s^-1` → (`s`, -1); `m` → (`m`, 1).
fn split_exponent(factor: &str) -> Option<(&str, i8)> {
    if factor.is_empty() {
        return None;
    }
    if let Some((sym, exp)) = factor.split_once('^') {
        return Some((sym, exp.trim().parse().ok()?));
    }
    let digits = factor.trim_end_matches(|c: char| c.is_ascii_digit());
    if digits.is_empty() || digits.len() == factor.len() {
        return Some((factor, 1));
    }
    Some((digits, factor[digits.len()..].parse().ok()?))
}

/// How a value in `from` relates to `to`.
#[derive(Debug, PartialEq)]
pub enum UnitRelation {
    Same,
    /// Same dimension; multiply by the factor.
    Scaled(f64),
    DifferentDimension,
}

pub fn relate(from: &Unit, to: &Unit) -> UnitRelation {
    if from.dimension != to.dimension {
        return UnitRelation::DifferentDimension;
    }
    let factor = from.scale / to.scale;
    if (factor - 1.0).abs() < 1e-12 {
        UnitRelation::Same
    } else {
        UnitRelation::Scaled(factor)
    }
}

/// A scale factor as a message shows it: exact when short (`100`, `0.001`, `3.6`),
/// as a fraction of π when that is short (`180/π ≈ 57.3` for rad → deg), otherwise to four
/// significant digits (`≈ 0.2778`) rather than `57.29577951308232`.
pub fn describe_factor(f: f64) -> String {
    // `x` when it has at most six significant digits (up to rounding error).
    let short = |x: f64| {
        if !x.is_finite() || x == 0.0 {
            return None;
        }
        let rounded: f64 = significant(x, 6).parse().ok()?;
        ((rounded - x).abs() <= 1e-12 * x.abs()).then(|| format!("{rounded}"))
    };
    if let Some(text) = short(f) {
        return text;
    }
    let pi = std::f64::consts::PI;
    let approx = significant(f, 3);
    if let Some(n) = short(f * pi).filter(|n| !n.contains('.')) {
        return format!("{n}/π ≈ {approx}");
    }
    if let Some(n) = short(f / pi).filter(|n| !n.contains('.')) {
        return if n == "1" {
            format!("π ≈ {approx}")
        } else {
            format!("{n}π ≈ {approx}")
        };
    }
    if let Some(d) = short(1.0 / (f * pi)).filter(|n| !n.contains('.')) {
        return format!("1/({d}π) ≈ {}", significant(f, 4));
    }
    if let Some(d) = short(pi / f).filter(|n| !n.contains('.')) {
        return format!("π/{d} ≈ {}", significant(f, 4));
    }
    format!("≈ {}", significant(f, 4))
}

/// `x` rounded to `digits` significant digits, without trailing zeros.
fn significant(x: f64, digits: i32) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor() as i32;
    let decimals = (digits - 1 - magnitude).max(0) as usize;
    let text = format!("{x:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_read_as_people_write_them() {
        let pi = std::f64::consts::PI;
        assert_eq!(describe_factor(100.0), "100");
        assert_eq!(describe_factor(0.001), "0.001");
        assert_eq!(describe_factor(3.6), "3.6");
        assert_eq!(describe_factor(180.0 / pi), "180/π ≈ 57.3");
        assert_eq!(describe_factor(pi / 180.0), "π/180 ≈ 0.01745");
        assert_eq!(describe_factor(1.0 / 3.6), "≈ 0.2778");
        // rpm → rad/s and back.
        assert_eq!(describe_factor(2.0 * pi / 60.0), "π/30 ≈ 0.1047");
        assert_eq!(describe_factor(60.0 / (2.0 * pi)), "30/π ≈ 9.55");
        assert_eq!(describe_factor(1e9), "1000000000");
        assert_eq!(describe_factor(1e-9), "0.000000001");
    }

    fn u(s: &str) -> Unit {
        parse_unit(s).unwrap()
    }

    #[test]
    fn prefixes_and_compounds() {
        assert_eq!(relate(&u("m"), &u("mm")), UnitRelation::Scaled(1000.0));
        assert_eq!(relate(&u("m/s"), &u("m*s^-1")), UnitRelation::Same);
        assert_eq!(relate(&u("m/s2"), &u("m/s^2")), UnitRelation::Same);
        assert_eq!(relate(&u("Hz"), &u("1/s")), UnitRelation::Same);
        assert_eq!(relate(&u("kg"), &u("g")), UnitRelation::Scaled(1000.0));
        assert_eq!(relate(&u("min"), &u("s")), UnitRelation::Scaled(60.0));
        match relate(&u("km/h"), &u("m/s")) {
            UnitRelation::Scaled(f) => assert!((f - 1.0 / 3.6).abs() < 1e-12),
            other => panic!("{other:?}"),
        }
        match relate(&u("rpm"), &u("rad/s")) {
            UnitRelation::Scaled(f) => assert!((f - 0.10471975511965977).abs() < 1e-12),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn dimensions_differ() {
        assert_eq!(relate(&u("m"), &u("s")), UnitRelation::DifferentDimension);
        assert_eq!(relate(&u("rad"), &u("m")), UnitRelation::DifferentDimension);
        assert_eq!(
            relate(&u("Hz"), &u("rad/s")),
            UnitRelation::DifferentDimension
        );
        assert_eq!(describe_dimension(&u("m/s").dimension), "velocity (m·s^-1)");
        assert_eq!(describe_dimension(&u("kg*m^2").dimension), "m^2·kg");
    }

    #[test]
    fn rejects_nonsense() {
        for bad in ["", "furlong", "m/", "m^x", "xm", "m^100000", "/"] {
            assert!(parse_unit(bad).is_err(), "{bad}");
        }
    }
}

#[cfg(test)]
mod suggested_tests {
    #[test]
    fn every_suggested_unit_parses() {
        for u in super::SUGGESTED {
            assert!(super::parse_unit(u).is_ok(), "{u}");
        }
    }
}
