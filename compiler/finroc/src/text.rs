//! Small text rules FINROC applies to names and values: percent-decoding of edge paths
//! (rrlib_uri), comma-separated lists with per-item spans, and the port names FINROC's
//! `port_name_builder` forms from C++ member names.

use ferroc_diagnostics::source::Span;

/// Where a value is written in the file.
#[derive(Clone, Copy, Debug)]
pub struct ValueSpan {
    pub whole: Span,
    /// Whether byte offsets into the value are offsets into the file from `whole.start`
    /// (false when entities such as `&amp;` make the written text longer).
    pub exact: bool,
}

impl ValueSpan {
    pub fn new(whole: Span, value: &str) -> Self {
        let exact = (whole.end - whole.start) as usize == value.len();
        ValueSpan { whole, exact }
    }

    /// The span of `part`, a sub-slice of `value`, or the whole value when not exact.
    pub fn of(&self, value: &str, part: &str) -> Span {
        let (v, p) = (value.as_ptr() as usize, part.as_ptr() as usize);
        if !self.exact || p < v || p + part.len() > v + value.len() {
            return self.whole;
        }
        let start = self.whole.start as usize + (p - v);
        Span::new(self.whole.file, start, start + part.len())
    }
}

/// The trimmed, non-empty items of a comma-separated list (FINROC's `dependencies`).
pub fn comma_items(value: &str) -> impl Iterator<Item = &str> {
    value.split(',').map(str::trim).filter(|s| !s.is_empty())
}

/// A percent escape that could not be decoded: its byte offset in the segment and why.
#[derive(Clone, Debug, PartialEq)]
pub struct BadEscape {
    pub offset: usize,
    pub reason: &'static str,
}

/// Percent-decodes one path segment as rrlib_uri does for files with `version`: `%XX`
/// is the byte XX; the decoded bytes must be UTF-8.
pub fn percent_decode(segment: &str) -> Result<String, BadEscape> {
    let bytes = segment.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = |b: u8| (b as char).to_digit(16);
            match (bytes.get(i + 1), bytes.get(i + 2)) {
                (Some(&a), Some(&b)) if hex(a).is_some() && hex(b).is_some() => {
                    out.push((hex(a).unwrap_or(0) * 16 + hex(b).unwrap_or(0)) as u8);
                    i += 3;
                }
                _ => {
                    return Err(BadEscape {
                        offset: i,
                        reason: "`%` must be followed by two hexadecimal digits",
                    })
                }
            }
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| BadEscape {
        offset: 0,
        reason: "the decoded bytes are not UTF-8",
    })
}

/// Characters FINROC's 1703 writer leaves unencoded in a path segment besides letters,
/// digits and `-._~` (`cUNENCODED_RESERVED_CHARACTERS_PATH`).
const UNENCODED: &str = "!$&'()*+,;= @-._~";

/// Percent-encodes one path segment as FINROC's 1703 writer does.
pub fn percent_encode(segment: &str) -> String {
    let mut out = String::with_capacity(segment.len());
    for &b in segment.as_bytes() {
        if b.is_ascii_alphanumeric() || UNENCODED.as_bytes().contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// The port name FINROC's `port_name_builder` forms from a C++ member name: split at
/// `_`, each word capitalised, joined with spaces (`ir_distance_front` → `Ir Distance
/// Front`). Type prefixes (`si_`, `co_`, …) are expected to be stripped already.
pub fn finroc_port_name(member: &str) -> String {
    member
        .split('_')
        .filter(|w| !w.is_empty())
        .map(|w| {
            let mut c = w.chars();
            match c.next() {
                Some(f) => f.to_uppercase().chain(c).collect::<String>(),
                None => String::new(),
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// The other way: a FINROC name as a ferroc identifier (`Ir Distance Front` →
/// `ir_distance_front`; anything not alphanumeric becomes `_`, a leading digit gets `_`).
pub fn ident_of(name: &str) -> String {
    let mut out = String::new();
    for c in name.trim().chars() {
        if c.is_ascii_alphanumeric() {
            out.extend(c.to_lowercase());
        } else if !out.ends_with('_') {
            out.push('_');
        }
    }
    let mut out = out.trim_matches('_').to_string();
    if out.is_empty() || out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert(0, '_');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_round_trip_on_test_file_names() {
        assert_eq!(
            percent_decode("Array%3Cuint8, 8%3E").unwrap(),
            "Array<uint8, 8>"
        );
        assert_eq!(percent_decode("String%5B2%5D").unwrap(), "String[2]");
        assert_eq!(percent_encode("Array<uint8, 8>"), "Array%3Cuint8, 8%3E");
        assert_eq!(
            percent_encode("vector<vector<uint8>>"),
            "vector%3Cvector%3Cuint8%3E%3E"
        );
        assert_eq!(percent_encode("double vector"), "double vector");
    }

    #[test]
    fn odd_escapes_are_reported_not_panicked_on() {
        assert_eq!(percent_decode("a%4").unwrap_err().offset, 1);
        assert_eq!(percent_decode("%zz").unwrap_err().offset, 0);
        assert!(percent_decode("%FF%FE").is_err());
        assert_eq!(percent_decode("%").unwrap_err().offset, 0);
    }

    #[test]
    fn port_names_as_finroc_builds_them() {
        assert_eq!(finroc_port_name("ir_distance_front"), "Ir Distance Front");
        assert_eq!(finroc_port_name("pose"), "Pose");
        assert_eq!(ident_of("Ir Distance Front"), "ir_distance_front");
        assert_eq!(ident_of("AddNoise Rear"), "addnoise_rear");
        assert_eq!(ident_of("3D"), "_3d");
    }
}
