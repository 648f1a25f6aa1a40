//! `ferroc lsp`: the compiler's findings, navigation, hover, completion and quick fixes
//! in any editor that speaks the Language Server Protocol (docs/editors.md).
//!
//! One main loop answers the client; checks run on a worker thread (`worker.rs`) with
//! the editor's unsaved texts standing in for the files (`Options::overlay`), so the
//! findings are exactly `ferroc check`'s for the text on screen. A model is checked
//! when it is opened or changed; a fragment, manifest or config file re-checks the
//! models whose last check read it (`deps`). Requests that need the model
//! (definition, hover, completion of ports, code actions) wait for the check of the
//! current text when one is under way.

#![forbid(unsafe_code)]

mod actions;
mod capabilities;
mod complete;
mod convert;
mod discover;
mod documents;
mod fixes;
mod hover;
mod navigate;
pub mod position;
mod request;
mod server;
mod symbols;
pub mod transport;
mod worker;

use ferroc_compiler::load::Options;

/// Serves the protocol over standard input and output until the client says `exit`.
/// `Err` says why the server stopped early (the client's input ended without `exit`).
pub fn run_stdio(options: Options) -> Result<(), String> {
    let (connection, io) = transport::stdio();
    let outcome = server::serve(&connection, options);
    drop(connection);
    io.join();
    outcome
}

pub use server::serve;
