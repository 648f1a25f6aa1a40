//! `ferroc run --inspect`: serve the running application's inspector on Zenoh
//! (docs/inspect.md), with the model's source locations and connections, parameter
//! changes parsed with the model's own value rules (units converted as in a model
//! file), and a random token for changes printed at start.

use ferroc_compiler::types::parse_type;
use ferroc_compiler::units::parse_unit;
use ferroc_compiler::values::{parse_value, ValueError};
use ferroc_inspect::config;
use ferroc_inspect::server::{self, Server};
use ferroc_runtime::builder::Registry;
use ferroc_runtime::inspect::view::ParamView;
use ferroc_runtime::inspect::{Catalogue, Inspector};
use ferroc_runtime::module::Value;
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
        Box::new(parse_param),
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

/// A parameter value as text, parsed as a model file's would be: the type's syntax,
/// a unit converted into the parameter's (or refused if it measures something else).
pub fn parse_param(param: &ParamView, text: &str) -> Result<Value, String> {
    let ty = parse_type(&param.r#type, &mut |_| None).map_err(|e| {
        format!(
            "parameters of type `{}` cannot be changed here ({e:?})",
            param.r#type
        )
    })?;
    let unit = match &param.unit {
        Some(u) => Some(parse_unit(u).map_err(|e| format!("the unit `{u}`: {e}"))?),
        None => None,
    };
    let value = parse_value(text, &ty, unit.as_ref()).map_err(|e| match e {
        ValueError::Syntax(s) | ValueError::WrongDimension(s) => s,
    })?;
    Ok(crate::from_plan::value(&value))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn param(ty: &str, unit: Option<&str>) -> ParamView {
        ParamView {
            module: "robot/m".into(),
            name: "p".into(),
            r#type: ty.into(),
            unit: unit.map(Into::into),
            min: None,
            max: None,
            choices: Vec::new(),
            value: String::new(),
        }
    }

    #[test]
    fn values_are_parsed_and_converted_like_a_models() {
        let speed = param("f64", Some("m/s"));
        assert_eq!(parse_param(&speed, "0.3 m/s"), Ok(Value::Float(0.3)));
        assert_eq!(parse_param(&speed, "0.3"), Ok(Value::Float(0.3)));
        let Ok(Value::Float(x)) = parse_param(&speed, "36 km/h") else {
            panic!("km/h converts")
        };
        assert!((x - 10.0).abs() < 1e-9);
        let e = parse_param(&speed, "3 kg").unwrap_err();
        assert!(e.contains("measures"), "{e}");
        let e = parse_param(&param("f64", None), "3 m").unwrap_err();
        assert!(e.contains("has no unit"), "{e}");
        assert_eq!(parse_param(&param("u32", None), "7"), Ok(Value::Int(7)));
        assert!(parse_param(&param("u8", None), "300").is_err());
        assert_eq!(
            parse_param(&param("duration", None), "250ms"),
            Ok(Value::Duration(std::time::Duration::from_millis(250)))
        );
        assert_eq!(
            parse_param(&param("bool", None), "true"),
            Ok(Value::Bool(true))
        );
        assert!(parse_param(&param("bool", None), "yes").is_err());
    }

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
