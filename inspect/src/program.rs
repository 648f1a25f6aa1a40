//! Inspection served by a bundle's part program (`PROGRAM --inspect [ADDR]`): the same
//! keys as `ferroc run --inspect`, for the program's own part, with its own Zenoh
//! session and a token printed at start.
//!
//! A part program does not link the compiler; a change is parsed with the model's own
//! value and unit rules all the same ([`crate::param_value`]), as `ferroc run` parses it.

use crate::config;
use crate::server::{self, Server};
use ferroc_runtime::builder::RunningApp;
use ferroc_runtime::inspect::{Catalogue, Inspector, Origin};
use ferroc_runtime::module::ValueTable;
use ferroc_runtime::supervise::Args;
use std::sync::Arc;

/// Checks `--inspect`'s address before anything starts: a non-local one needs
/// `--inspect-public`.
pub fn check(args: &Args) -> Result<(), String> {
    let Some(address) = &args.inspect else {
        return Ok(());
    };
    config::endpoint(address, "--inspect")?;
    if !config::is_local(address) && !args.inspect_public {
        return Err(format!(
            "--inspect {address}: not a loopback address; anyone who reaches it can read every value of this part. \
             Add --inspect-public to serve it there anyway, or use 127.0.0.1:{}",
            config::DEFAULT_PORT
        ));
    }
    Ok(())
}

/// What the model says that the running part does not know: its connections (writer
/// module, output, reader module, input) and where each module is declared (module,
/// `FILE:LINE:COL`).
pub type Model<'a> = (
    &'a [(&'a str, &'a str, &'a str, &'a str)],
    &'a [(&'a str, &'a str)],
);

/// Starts serving the application `app` as `args` ask (nothing without `--inspect`);
/// prints the keys and the token. Keep the server until the program ends.
pub fn serve(
    app: &str,
    args: &Args,
    catalogue: Catalogue,
    (connections, sources): Model<'_>,
    running: &RunningApp,
    values: &ValueTable,
) -> Result<Option<Server>, String> {
    let Some(address) = &args.inspect else {
        return Ok(None);
    };
    check(args)?;
    let inspector = Inspector::new(catalogue, running.stats(), values);
    for (writer, output, reader, input) in connections {
        inspector.add_connection((writer, output), (reader, input));
    }
    for (module, source) in sources {
        let source = Some(source.to_string());
        let origin = Origin {
            part: String::new(),
            source,
        };
        inspector.set_origin(module, origin);
    }
    let token = crate::token::generate()?;
    let server = server::serve(
        config::server(address)?,
        app,
        Arc::new(inspector),
        token.clone(),
        Box::new(crate::param_value::parse),
    )?;
    if !config::is_local(address) {
        eprintln!(
            "warning: inspection is served on {address}, not only on this computer: anyone who reaches it can read every value (changes still need the token)"
        );
    }
    eprintln!(
        "inspect: serving ferroc/{app}/inspect/** on tcp/{address}; token for changes: {token}"
    );
    Ok(Some(server))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_loopback_is_served_without_the_public_flag() {
        let args = |a: &[&str]| {
            let a: Vec<String> = a.iter().map(|s| s.to_string()).collect();
            Args::parse(&a).unwrap().unwrap()
        };
        assert!(check(&args(&[])).is_ok());
        assert!(check(&args(&["--inspect"])).is_ok());
        let e = check(&args(&["--inspect", "0.0.0.0:47900"])).unwrap_err();
        assert!(e.contains("--inspect-public"), "{e}");
        assert!(check(&args(&["--inspect", "0.0.0.0:1", "--inspect-public"])).is_ok());
        assert!(check(&args(&["--inspect", "nonsense"])).is_err());
    }
}
