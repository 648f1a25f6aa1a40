//! Structural edits and the model as it runs, served on `ferroc/APP/inspect/PART/edit`
//! and `…/model`. The server checks the token and the payload's shape; what an edit
//! means (a model edit checked by the compiler, then applied to the running
//! application) is the runner's [`Structure`]: this crate does not know the compiler.

use crate::request::EditRequest;

/// What an edit answers when it is refused: a summary, and for a model the compiler
/// found errors in, its diagnostics.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Refusal {
    /// What went wrong and that nothing changed, in plain words (with the rendered
    /// diagnostics, for clients that show only this).
    pub error: String,
    /// The compiler's findings on the edited model, as JSON (empty when the edit did
    /// not get that far).
    pub diagnostics: Vec<serde_json::Value>,
}

/// The running application's model, to edit and to save.
pub trait Structure: Send + Sync {
    /// Applies the operations `ops` (a JSON list): the edited model is checked with
    /// every check and applied only if it checks clean. The answer says what changed.
    fn edit(&self, ops: &[u8]) -> Result<serde_json::Value, Refusal>;
    /// The model as it runs now: `{"model": FILE, "text": TEXT}`.
    fn model(&self) -> serde_json::Value;
    /// A parameter was changed at run time to the value `text` (as a model writes it):
    /// the model keeps it, so a saved model has it.
    fn param_changed(&self, module: &str, name: &str, text: &str);
}

/// Reads an edit request; the token is compared by the caller.
pub(crate) fn read(bytes: &[u8]) -> Result<EditRequest, Refusal> {
    serde_json::from_slice(bytes).map_err(|e| Refusal {
        error: format!(
            "an edit is the JSON {{\"token\": \"TOKEN\", \"ops\": [...]}} (docs/inspect.md, \"Structural edits\"): {e}"
        ),
        diagnostics: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_edit_request_has_exactly_a_token_and_operations() {
        let ok = read(br#"{"token": "t", "ops": [{"op": "remove", "module": "a/b/c"}]}"#).unwrap();
        assert_eq!(ok.token, "t");
        assert!(ok.ops.is_array());
        for bad in [
            &b""[..],
            b"[]",
            b"{\"ops\": []}",
            b"{\"token\": \"t\"}",
            b"{\"token\": \"t\", \"ops\": [], \"x\": 1}",
            b"\xff\xfe",
        ] {
            let e = read(bad).unwrap_err();
            assert!(e.error.contains("\"token\""), "{e:?}");
        }
    }
}
