//! Tag and attribute names of a syntax tree.
//!
//! A model of 100,000 modules holds ~1.1 million tag and attribute names, nearly all of
//! them words of the language (`connect`, `from`, `to`, `name`, `type`). A [`Name`] of
//! the vocabulary is a reference to the vocabulary's own string: 16 bytes, no
//! allocation, where a `CompactString` took 24 (B1 peak memory). Any other name (a
//! misspelt attribute, a FINROC file's words) keeps its text.

use super::vocabulary::{COMMON_ATTRS, ELEMENTS, ROOT_ATTRS};
use hashbrown::HashMap;
use std::fmt;
use std::sync::OnceLock;

/// A tag or attribute name as written (the validator may replace a misspelt attribute's
/// name by the one it was meant to be).
#[derive(Clone)]
pub enum Name {
    /// A name of the vocabulary: a reference to the vocabulary's string (a thin pointer,
    /// which keeps the whole enum at 16 bytes).
    Known(&'static &'static str),
    /// Any other name.
    Other(Box<str>),
}

impl Name {
    /// The name for `text`: the vocabulary's string when it is one of its names.
    pub fn new(text: &str) -> Name {
        match known_id(text) {
            Some(id) => Name::Known(known_name(id)),
            None => Name::Other(text.into()),
        }
    }

    pub fn as_str(&self) -> &str {
        match self {
            Name::Known(s) => s,
            Name::Other(s) => s,
        }
    }
}

/// The vocabulary's tag and attribute names, each once, and their numbers.
struct Known {
    names: Vec<&'static str>,
    ids: HashMap<&'static str, u16>,
}

fn known() -> &'static Known {
    static KNOWN: OnceLock<Known> = OnceLock::new();
    KNOWN.get_or_init(|| {
        let tags = ELEMENTS.iter().map(|spec| spec.tag);
        let attrs = ELEMENTS.iter().flat_map(|s| s.attrs.iter().map(|a| a.name));
        let free = COMMON_ATTRS.iter().chain(ROOT_ATTRS).copied();
        let mut known = Known {
            names: Vec::new(),
            ids: HashMap::new(),
        };
        for name in tags.chain(attrs).chain(free) {
            let next = known.names.len() as u16;
            if *known.ids.entry(name).or_insert(next) == next {
                known.names.push(name);
            }
        }
        known
    })
}

/// The number of a name of the vocabulary (below [`OTHER`]).
pub(super) fn known_id(text: &str) -> Option<u16> {
    known().ids.get(text).copied()
}

/// The vocabulary's name number `id` (from [`known_id`]).
pub(super) fn known_name(id: u16) -> &'static &'static str {
    &known().names[usize::from(id)]
}

/// The number that stands for "not a name of the vocabulary" (the vocabulary has a few
/// hundred names).
pub(super) const OTHER: u16 = u16::MAX;

impl std::ops::Deref for Name {
    type Target = str;
    fn deref(&self) -> &str {
        self.as_str()
    }
}

impl AsRef<str> for Name {
    fn as_ref(&self) -> &str {
        self.as_str()
    }
}

impl From<&str> for Name {
    fn from(text: &str) -> Name {
        Name::new(text)
    }
}

impl PartialEq for Name {
    fn eq(&self, other: &Name) -> bool {
        match (self, other) {
            (Name::Known(a), Name::Known(b)) => std::ptr::eq(*a, *b) || a == b,
            _ => self.as_str() == other.as_str(),
        }
    }
}

impl Eq for Name {}

impl PartialEq<str> for Name {
    fn eq(&self, other: &str) -> bool {
        self.as_str() == other
    }
}

impl PartialEq<&str> for Name {
    fn eq(&self, other: &&str) -> bool {
        self.as_str() == *other
    }
}

impl PartialEq<Name> for str {
    fn eq(&self, other: &Name) -> bool {
        self == other.as_str()
    }
}

impl PartialEq<Name> for &str {
    fn eq(&self, other: &Name) -> bool {
        *self == other.as_str()
    }
}

impl std::hash::Hash for Name {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.as_str().hash(state)
    }
}

impl fmt::Display for Name {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl fmt::Debug for Name {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.as_str(), f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vocabulary_names_are_references_and_others_keep_their_text() {
        for word in ["connect", "from", "to", "module", "doc", "xmlns:xsi"] {
            let name = Name::new(word);
            assert!(matches!(name, Name::Known(_)), "{word}");
            assert_eq!(name, word);
            assert_eq!(name.to_string(), word);
        }
        let odd = Name::new("perod");
        assert!(matches!(odd, Name::Other(_)));
        assert_eq!(odd.as_str(), "perod");
        assert_ne!(odd, Name::new("period"));
        assert_eq!(Name::new("period"), Name::new("period"));
        assert_eq!(Name::from("x-y"), Name::Other("x-y".into()));
    }

    /// Names are what most of a syntax tree's attributes consist of (B1).
    #[test]
    fn a_name_is_two_words() {
        assert_eq!(std::mem::size_of::<Name>(), 16);
    }
}
