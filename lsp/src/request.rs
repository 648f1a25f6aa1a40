//! What the features share: reading a request's parameters and finding the check
//! result of the document they name.

use crate::server::Server;
use ferroc_compiler::source::{FileId, Span};
use ferroc_compiler::CheckResult;
use lsp_server::Request;
use lsp_types::TextDocumentPositionParams;
use serde::de::DeserializeOwned;
use serde_json::Value;
use std::path::PathBuf;
use std::sync::Arc;

/// A feature's answer: `Ok(Some(value))` now, `Ok(None)` after the check under way,
/// `Err` invalid parameters.
pub type Reply = Result<Option<Value>, String>;

pub fn params<P: DeserializeOwned>(req: &Request) -> Result<P, String> {
    serde_json::from_value(req.params.clone())
        .map_err(|e| format!("cannot read the parameters of `{}`: {e}", req.method))
}

/// The document and byte offset a position request names.
pub struct At {
    pub path: PathBuf,
    pub offset: usize,
}

pub fn at(server: &Server, p: &TextDocumentPositionParams) -> Option<At> {
    let path = crate::documents::path_of(&p.text_document.uri)?;
    let doc = server.docs.get(&path)?;
    let offset = doc.lines.offset(&doc.text, p.position, server.enc);
    Some(At { path, offset })
}

/// The check result of the document a position request names, and the cursor as an
/// empty span in it: `Err(reply)` when there is no document (`null`) or no result yet.
pub fn checked_at(
    server: &Server,
    p: &TextDocumentPositionParams,
) -> Result<(Arc<CheckResult>, Span), Reply> {
    let Some(at) = at(server, p) else {
        return Err(Ok(Some(Value::Null)));
    };
    let (result, file) = checked(server, &at)?;
    Ok((result, Span::new(file, at.offset, at.offset)))
}

/// The check result of the document's current text: `Ok(Err(reply))` when there is
/// none — wait for the one under way, or answer `null`.
pub fn checked(server: &Server, at: &At) -> Result<(Arc<CheckResult>, FileId), Reply> {
    match server.fresh(&at.path) {
        Ok(found) => Ok(found),
        Err(true) => Err(Ok(None)),
        Err(false) => Err(Ok(Some(Value::Null))),
    }
}
