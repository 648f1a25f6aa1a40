//! A message definition compiled once per [`Shape`](super::Shape) for the codecs: every
//! message type the shape reaches is a node, each field a slot with its arity and its
//! element resolved (a primitive, a string, or the node of a nested message), so a
//! sample is written and read with no lookup by name in the registry, no string
//! compare of package names and no allocation.
//!
//! A port's type names its fields with `&'static str`s (serde's derive): a slot keeps
//! the address of the last key found equal to its name, so the names are compared once
//! per type and after that only an address is (a `&'static str` at the same address and
//! of the same length is the same text; ferroc links value types into its programs and
//! unloads no library, which could give an address other text).

use crate::def::{Arity, BaseType, Field, Message, Primitive, TypeName};
use crate::wire::{self, MAX_DEPTH};
use crate::Registry;
use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};

/// One element of a field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Elem {
    Prim(Primitive),
    Str(Option<u32>),
    /// Parsed and hashed, refused by CDR.
    WStr,
    /// A nested message: its node in the plan.
    Msg(usize),
}

/// A message ferroc's own types stand for on the wire.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Builtin {
    No,
    /// `builtin_interfaces/msg/Time` (ferroc's `Timestamp { nanos }`).
    Time,
    /// `builtin_interfaces/msg/Duration` (`std::time::Duration { secs, nanos }`).
    Duration,
}

/// A field of a message, compiled.
pub(crate) struct Slot<'r> {
    pub field: &'r Field,
    /// The field's name (here, not behind `field`: compared for every sample).
    pub name: &'r str,
    pub arity: Arity,
    pub elem: Elem,
    /// The address of the last key found equal to the field's name.
    seen: AtomicUsize,
}

impl Slot<'_> {
    /// Whether the port's field `key` is this field (see the module documentation).
    #[inline]
    pub fn named(&self, key: &'static str) -> bool {
        let at = key.as_ptr() as usize;
        if self.seen.load(Ordering::Relaxed) == at && key.len() == self.name.len() {
            return true;
        }
        let same = key == self.name;
        if same {
            self.seen.store(at, Ordering::Relaxed);
        }
        same
    }
}

/// A message type, compiled.
pub(crate) struct Node<'r> {
    pub message: &'r Message,
    pub builtin: Builtin,
    pub slots: Vec<Slot<'r>>,
    /// The address of the last list of field names (a derived `Deserialize`'s) found
    /// equal to the message's.
    seen: AtomicUsize,
}

impl Node<'_> {
    /// Whether a struct of the fields `ours` (in this order) is this message.
    #[inline]
    pub fn named(&self, ours: &'static [&'static str]) -> bool {
        let at = ours.as_ptr() as usize;
        if self.seen.load(Ordering::Relaxed) == at && ours.len() == self.slots.len() {
            return true;
        }
        let same = ours.len() == self.slots.len()
            && (ours.iter().zip(&self.slots)).all(|(o, s)| *o == s.field.name);
        if same {
            self.seen.store(at, Ordering::Relaxed);
        }
        same
    }

    /// The message's field names.
    pub fn names(&self) -> Vec<&str> {
        self.slots.iter().map(|s| s.field.name.as_str()).collect()
    }
}

/// The compiled message and every message it nests; node 0 is the message.
pub(crate) struct Plan<'r> {
    pub reg: &'r Registry,
    pub nodes: Vec<Node<'r>>,
}

impl<'r> Plan<'r> {
    /// Compiles `root` and what it nests (each type once); a cycle of nested types or
    /// nesting deeper than [`MAX_DEPTH`] is refused.
    pub fn new(reg: &'r Registry, root: &'r Message) -> Result<Self, String> {
        let mut plan = Plan {
            reg,
            nodes: Vec::new(),
        };
        let mut index = HashMap::new();
        plan.add(root, &mut index, &mut Vec::new())?;
        Ok(plan)
    }

    /// The node of the message `m` (added with what it nests if new).
    fn add(
        &mut self,
        m: &'r Message,
        index: &mut HashMap<&'r TypeName, usize>,
        open: &mut Vec<&'r TypeName>,
    ) -> Result<usize, String> {
        if open.contains(&&m.name) {
            return Err(format!("`{}` contains itself", m.name));
        }
        if let Some(at) = index.get(&m.name) {
            return Ok(*at);
        }
        if open.len() > MAX_DEPTH {
            return Err("messages are nested too deeply".into());
        }
        open.push(&m.name);
        let mut slots = Vec::with_capacity(m.fields.len());
        for field in &m.fields {
            let elem = match &field.ty.base {
                BaseType::Primitive(p) => Elem::Prim(*p),
                BaseType::String { bound } => Elem::Str(*bound),
                BaseType::WString { .. } => Elem::WStr,
                BaseType::Nested(n) => {
                    Elem::Msg(self.add(wire::message(self.reg, n)?, index, open)?)
                }
            };
            slots.push(Slot {
                field,
                name: &field.name,
                arity: field.ty.arity,
                elem,
                seen: AtomicUsize::new(0),
            });
        }
        open.pop();
        let builtin = match (m.name.package.as_str(), m.name.name.as_str()) {
            ("builtin_interfaces", "Time") => Builtin::Time,
            ("builtin_interfaces", "Duration") => Builtin::Duration,
            _ => Builtin::No,
        };
        let at = self.nodes.len();
        self.nodes.push(Node {
            message: m,
            builtin,
            slots,
            seen: AtomicUsize::new(0),
        });
        index.insert(&m.name, at);
        Ok(at)
    }

    /// The node of the message itself.
    pub fn root(&self) -> usize {
        self.nodes.len() - 1
    }
}
