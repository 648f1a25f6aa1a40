//! `ferroc run --inspect`: serve the running application's inspector on Zenoh
//! (docs/inspect.md), with the model's source locations and connections, parameter
//! changes parsed with the model's own value rules (units converted as in a model
//! file), and a random token for changes printed at start.

use ferroc_inspect::config;
use ferroc_inspect::server::{self, Server};
use ferroc_runtime::builder::Registry;
use ferroc_runtime::inspect::{Catalogue, Inspector};
use std::sync::Arc;

/// Where and how to serve.
pub struct Serve<'a> {
    /// `HOST:PORT` to listen on.
    pub address: &'a str,
    /// A non-local address was allowed explicitly (`--inspect-public`).
    pub public: bool,
    /// The application's name (the `APP` of the keys).
    pub app: &'a str,
}

/// Checks the address before anything starts: a non-local one needs `--inspect-public`.
pub fn check_address(serve: &Serve<'_>) -> Result<(), String> {
    config::endpoint(serve.address, "--inspect")?;
    if !config::is_local(serve.address) && !serve.public {
        return Err(format!(
            "--inspect {}: not a loopback address; anyone who reaches it can read every value of the application. \
             Add --inspect-public to serve it there anyway, or use 127.0.0.1:{}",
            serve.address,
            config::DEFAULT_PORT
        ));
    }
    Ok(())
}

/// Starts serving; prints the keys and the change token. `running` is what
/// structural edits change (`edit.rs`).
pub fn start(
    serve: &Serve<'_>,
    catalogue: Catalogue,
    app: &ferroc_runtime::builder::RunningApp,
    result: &ferroc_compiler::CheckResult,
    registry: &Registry,
    running: crate::edit::Running,
) -> Result<Server, String> {
    let inspector = Arc::new(Inspector::new(catalogue, app.stats(), registry.values()));
    crate::edit::describe(&inspector, &running.plan, result);
    let editor = crate::edit::Editor::new(running, Arc::clone(&inspector));
    let token = ferroc_inspect::token::generate()?;
    let config = config::server(serve.address)?;
    let server = server::serve_structure(
        config,
        serve.app,
        inspector,
        token.clone(),
        Box::new(ferroc_inspect::param_value::parse),
        Some(Arc::new(editor)),
    )?;
    if !config::is_local(serve.address) {
        eprintln!(
            "warning: inspection is served on {}, not only on this computer: anyone who reaches it can read every value (changes still need the token)",
            serve.address
        );
    }
    eprintln!(
        "inspect: serving ferroc/{}/inspect/** on tcp/{}; token for changes: {token}",
        serve.app, serve.address
    );
    Ok(server)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_loopback_is_served_without_the_public_flag() {
        let serve = |address, public| Serve {
            address,
            public,
            app: "a",
        };
        assert!(check_address(&serve("127.0.0.1:47900", false)).is_ok());
        let e = check_address(&serve("0.0.0.0:47900", false)).unwrap_err();
        assert!(e.contains("--inspect-public"), "{e}");
        assert!(check_address(&serve("0.0.0.0:47900", true)).is_ok());
        assert!(check_address(&serve("nonsense", true)).is_err());
    }
}
