//! Structural edits of a model, as FINSTRUCT makes them in a running application — but
//! applied to the model's TEXT, so that the edited model is checked by the compiler
//! like any other (`check_model_text`) and can be saved with its comments and layout.
//!
//! An edit is a JSON list of operations ([`Op`]); element paths are absolute, as the
//! inspector's tree shows them (`robot/main/filter`, ports `robot/main/filter/in/0`).
//! [`apply`] edits the text one operation after the other (`text.rs` knows where an
//! element starts and ends); [`diff`] compares the running plan with the edited one.
//! Operations touch only the model's own file: elements defined in an included
//! fragment or inside a group type are refused with a message saying so.
//! [`set_attribute`] and [`swap_attributes`] edit one element of any model text, found
//! by a byte offset in it, and [`add_to_root`] adds a child to its root element
//! (`ferroc lsp`'s quick fixes know where a finding points).

mod attribute;
pub mod diff;
mod relocate;
mod splice;
mod text;

pub use attribute::{add_to_root, set_attribute, swap_attributes};
pub use relocate::relocate;
use serde::Deserialize;
use std::collections::BTreeMap;

/// One structural change (`{"op": "add", …}`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(tag = "op", rename_all = "lowercase", deny_unknown_fields)]
pub enum Op {
    /// A new module of a registered type, in the thread container (or group) its path's
    /// parent names.
    Add {
        /// Its path: the parent element's path and its name (`robot/main/filter`).
        module: String,
        /// The qualified type (`ferroc_std.Filter`).
        r#type: String,
        /// Parameter values as a model writes them (`"0.3 m/s"`).
        #[serde(default)]
        params: BTreeMap<String, String>,
        /// The instance's flexible port groups (`<port name dir type unit count>`).
        #[serde(default)]
        ports: Vec<PortGroup>,
    },
    /// Removes a module and every `<connect>` of the model file that joins it.
    Remove {
        /// Its path.
        module: String,
    },
    /// A new connection from an output to an input (absolute port paths).
    Connect {
        /// `MODULE/PATH/PORT` of the output.
        from: String,
        /// `MODULE/PATH/PORT` of the input.
        to: String,
    },
    /// Removes the `<connect>` that joins exactly these two ports.
    Disconnect {
        /// `MODULE/PATH/PORT` of the output.
        from: String,
        /// `MODULE/PATH/PORT` of the input.
        to: String,
    },
    /// Moves a module into another thread container (its path changes to
    /// `TO/NAME`; its connections follow it).
    Move {
        /// Its path.
        module: String,
        /// The path of the thread container (or group) it moves into.
        to: String,
    },
    /// Sets a parameter's value in the model (what a parameter change at run time
    /// writes, so that a saved model keeps it).
    Set {
        /// `MODULE/PATH/NAME` of the parameter.
        param: String,
        /// The value as a model writes it.
        value: String,
    },
}

/// One `<port>` of an added flexible module.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PortGroup {
    pub name: String,
    /// `in` or `out`.
    pub dir: String,
    pub r#type: String,
    #[serde(default)]
    pub unit: Option<String>,
    #[serde(default)]
    pub count: Option<u32>,
}

/// Edits larger than this many operations are refused unread.
pub const MAX_OPS: usize = 1000;

/// Reads an edit: a JSON list of operations (or an object `{"ops": [...]}`).
pub fn parse_ops(json: &[u8]) -> Result<Vec<Op>, String> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Edit {
        List(Vec<Op>),
        Wrapped { ops: Vec<Op> },
    }
    let edit: Edit = serde_json::from_slice(json).map_err(|_| {
        // serde's untagged error says nothing useful: read again as a list for the cause.
        let why = serde_json::from_slice::<Vec<Op>>(json)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        format!("an edit is a JSON list of operations ({why}); see docs/inspect.md, \"Structural edits\"")
    })?;
    let ops = match edit {
        Edit::List(ops) | Edit::Wrapped { ops } => ops,
    };
    if ops.is_empty() {
        return Err("the edit has no operations".into());
    }
    if ops.len() > MAX_OPS {
        return Err(format!(
            "the edit has {} operations; at most {MAX_OPS}",
            ops.len()
        ));
    }
    Ok(ops)
}

/// The result of applying operations to a model's text.
#[derive(Clone, Debug, PartialEq)]
pub struct Edited {
    /// The whole edited text.
    pub text: String,
    /// Modules moved: old path → new path (their instances keep running).
    pub moved: Vec<(String, String)>,
    /// What each operation did, one line each (`removed <connect from=… to=…>`).
    pub done: Vec<String>,
}

/// Applies `ops` to the model text `text`, one after the other; the first operation
/// that cannot be applied refuses the whole edit (numbered from 1).
pub fn apply(text: &str, ops: &[Op]) -> Result<Edited, String> {
    let mut edited = Edited {
        text: text.to_owned(),
        moved: Vec::new(),
        done: Vec::new(),
    };
    for (i, op) in ops.iter().enumerate() {
        text::apply_one(&mut edited, op)
            .map_err(|why| format!("operation {} ({}): {why}", i + 1, op.name()))?;
    }
    Ok(edited)
}

impl Op {
    /// The operation's `op` name.
    pub fn name(&self) -> &'static str {
        match self {
            Op::Add { .. } => "add",
            Op::Remove { .. } => "remove",
            Op::Connect { .. } => "connect",
            Op::Disconnect { .. } => "disconnect",
            Op::Move { .. } => "move",
            Op::Set { .. } => "set",
        }
    }
}
