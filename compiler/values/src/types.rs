//! Data types of ports and parameters, and the connection compatibility rules of
//! docs/model-language.md §3.

use std::fmt;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Meta {
    Stimulation,
    Inhibition,
    Activity,
    TargetRating,
}

/// Index of a library-defined type in the library set.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct NamedTypeId(pub u32);

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Type {
    Bool,
    Int {
        signed: bool,
        bits: u8,
    },
    Float {
        bits: u8,
    },
    String,
    Duration,
    Timestamp,
    Meta(Meta),
    Array(Box<Type>, u32),
    Seq(Box<Type>),
    /// A library type, with its qualified name for messages.
    Named(NamedTypeId, Box<str>),
}

impl fmt::Display for Type {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Type::Bool => f.write_str("bool"),
            Type::Int { signed, bits } => write!(f, "{}{bits}", if *signed { 'i' } else { 'u' }),
            Type::Float { bits } => write!(f, "f{bits}"),
            Type::String => f.write_str("string"),
            Type::Duration => f.write_str("duration"),
            Type::Timestamp => f.write_str("timestamp"),
            Type::Meta(m) => write!(f, "{m:?}"),
            Type::Array(t, n) => write!(f, "{t}[{n}]"),
            Type::Seq(t) => write!(f, "[{t}]"),
            Type::Named(_, name) => f.write_str(name),
        }
    }
}

impl Type {
    pub fn is_numeric(&self) -> bool {
        matches!(self, Type::Int { .. } | Type::Float { .. } | Type::Meta(_))
    }

    /// Element type of an array or sequence.
    pub fn element(&self) -> Option<&Type> {
        match self {
            Type::Array(t, _) | Type::Seq(t) => Some(t),
            _ => None,
        }
    }
}

/// A built-in type name, or `None` when the text names no built-in type.
pub fn builtin(name: &str) -> Option<Type> {
    Some(match name {
        "bool" => Type::Bool,
        "i8" => Type::Int {
            signed: true,
            bits: 8,
        },
        "i16" => Type::Int {
            signed: true,
            bits: 16,
        },
        "i32" => Type::Int {
            signed: true,
            bits: 32,
        },
        "i64" => Type::Int {
            signed: true,
            bits: 64,
        },
        "u8" => Type::Int {
            signed: false,
            bits: 8,
        },
        "u16" => Type::Int {
            signed: false,
            bits: 16,
        },
        "u32" => Type::Int {
            signed: false,
            bits: 32,
        },
        "u64" => Type::Int {
            signed: false,
            bits: 64,
        },
        "f32" => Type::Float { bits: 32 },
        "f64" => Type::Float { bits: 64 },
        "string" => Type::String,
        "duration" => Type::Duration,
        "timestamp" => Type::Timestamp,
        "Stimulation" => Type::Meta(Meta::Stimulation),
        "Inhibition" => Type::Meta(Meta::Inhibition),
        "Activity" => Type::Meta(Meta::Activity),
        "TargetRating" => Type::Meta(Meta::TargetRating),
        _ => return None,
    })
}

pub const BUILTIN_NAMES: &[&str] = &[
    "bool",
    "i8",
    "i16",
    "i32",
    "i64",
    "u8",
    "u16",
    "u32",
    "u64",
    "f32",
    "f64",
    "string",
    "duration",
    "timestamp",
    "Stimulation",
    "Inhibition",
    "Activity",
    "TargetRating",
];

/// Why a type expression did not resolve.
#[derive(Debug, PartialEq)]
pub enum TypeError {
    Syntax(String),
    /// `lib.Name` where `lib` has no type `Name` (or is unknown): the qualified name.
    Unknown(String),
}

/// Parses `f64`, `f64[3]`, `[f64]`, `nav.Pose2D`; `lookup` resolves qualified names.
pub fn parse_type(
    text: &str,
    lookup: &mut dyn FnMut(&str) -> Option<NamedTypeId>,
) -> Result<Type, TypeError> {
    let t = text.trim();
    if let Some(inner) = t.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
        return Ok(Type::Seq(Box::new(parse_type(inner, lookup)?)));
    }
    if let Some(open) = t.rfind('[') {
        if let Some(count) = t[open + 1..].strip_suffix(']') {
            let n: u32 = count
                .trim()
                .parse()
                .ok()
                .filter(|n| *n > 0)
                .ok_or_else(|| {
                    TypeError::Syntax(format!("array length `{count}` is not a positive number"))
                })?;
            return Ok(Type::Array(Box::new(parse_type(&t[..open], lookup)?), n));
        }
    }
    if let Some(b) = builtin(t) {
        return Ok(b);
    }
    if t.contains('.') {
        return match lookup(t) {
            Some(id) => Ok(Type::Named(id, t.into())),
            None => Err(TypeError::Unknown(t.to_string())),
        };
    }
    if t.is_empty() {
        return Err(TypeError::Syntax("empty type name".into()));
    }
    Err(TypeError::Unknown(t.to_string()))
}

/// How a value of one type may flow into a port of another.
#[derive(Debug, PartialEq, Eq, Clone, Copy)]
pub enum Compat {
    Identical,
    /// Implicit and lossless.
    Widening,
    /// Possible with an explicit `<convert to-type>` (narrowing, sign change, float→int).
    NeedsConvert,
    Incompatible,
}

fn bits_of(t: &Type) -> Option<(bool, bool, u8)> {
    // (is_float, signed, bits)
    match t {
        Type::Int { signed, bits } => Some((false, *signed, *bits)),
        Type::Float { bits } => Some((true, true, *bits)),
        Type::Meta(_) => Some((true, true, 64)),
        _ => None,
    }
}

/// The rules of docs/model-language.md §3 (1, 2 and 5; units are judged separately).
pub fn compat(from: &Type, to: &Type) -> Compat {
    if from == to {
        return Compat::Identical;
    }
    match (from, to) {
        // iB2C meta signals are numbers in [0, 1]. Which sources may feed stimulation and
        // inhibition is an iB2C rule (area B), not a type rule.
        (Type::Meta(_), Type::Meta(_)) => return Compat::Widening,
        (Type::Meta(_), Type::Float { .. }) | (Type::Float { .. }, Type::Meta(_)) => {
            return Compat::Widening
        }
        (Type::Array(a, n), Type::Array(b, m)) if n == m => return compat(a, b),
        (Type::Seq(a), Type::Seq(b)) | (Type::Array(a, _), Type::Seq(b)) => {
            return match compat(a, b) {
                Compat::Identical => Compat::Widening,
                other => other,
            }
        }
        _ => {}
    }
    let (Some((ff, fs, fb)), Some((tf, ts, tb))) = (bits_of(from), bits_of(to)) else {
        return Compat::Incompatible;
    };
    let lossless = match (ff, tf) {
        (true, true) => tb >= fb,
        (false, false) => match (fs, ts) {
            (true, true) | (false, false) => tb >= fb,
            (false, true) => tb > fb,
            (true, false) => false,
        },
        // Integers into floats whose mantissa holds them exactly.
        (false, true) => fb <= if tb == 32 { 16 } else { 32 },
        (true, false) => false,
    };
    if lossless {
        Compat::Widening
    } else {
        Compat::NeedsConvert
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(s: &str) -> Type {
        parse_type(s, &mut |n| (n == "nav.Pose2D").then_some(NamedTypeId(0))).unwrap()
    }

    #[test]
    fn parses_compound_types() {
        assert_eq!(t("f64[3]").to_string(), "f64[3]");
        assert_eq!(t("[nav.Pose2D]").to_string(), "[nav.Pose2D]");
        assert_eq!(t("[u8[4]]").to_string(), "[u8[4]]");
        let mut none = |_: &str| None;
        assert_eq!(
            parse_type("nav.Map", &mut none),
            Err(TypeError::Unknown("nav.Map".into()))
        );
        assert!(matches!(
            parse_type("f64[0]", &mut none),
            Err(TypeError::Syntax(_))
        ));
        assert!(matches!(
            parse_type("double", &mut none),
            Err(TypeError::Unknown(_))
        ));
    }

    #[test]
    fn widening_follows_the_language_rules() {
        use Compat::*;
        let cases = [
            ("i8", "i64", Widening),
            ("u8", "i16", Widening),
            ("u16", "i16", NeedsConvert),
            ("u32", "i64", Widening),
            ("i8", "u64", NeedsConvert),
            ("f32", "f64", Widening),
            ("f64", "f32", NeedsConvert),
            ("u16", "f32", Widening),
            ("i32", "f32", NeedsConvert),
            ("i32", "f64", Widening),
            ("i64", "f64", NeedsConvert),
            ("f64", "i32", NeedsConvert),
            ("bool", "i32", Incompatible),
            ("string", "f64", Incompatible),
            ("f64[3]", "f64[3]", Identical),
            ("f32[3]", "f64[3]", Widening),
            ("f64[3]", "f64[4]", Incompatible),
            ("f64[3]", "[f64]", Widening),
            ("nav.Pose2D", "f64", Incompatible),
            ("Activity", "Stimulation", Widening),
        ];
        for (a, b, expected) in cases {
            assert_eq!(compat(&t(a), &t(b)), expected, "{a} -> {b}");
        }
    }
}
