//! Inspection served by a bundle's part program (`PROGRAM --inspect [ADDR]`): the same
//! keys as `ferroc run --inspect`, for the program's own part, with its own Zenoh
//! session and a token printed at start.
//!
//! A part program does not link the compiler, so a change is parsed here by the
//! parameter's type alone: a number may carry the parameter's own unit (`0.3 m/s` for
//! a parameter in m/s) but no other (`30 cm/s` is refused, not converted; `ferroc
//! run` converts it). The parameter's own checks (range, choices) run as always.

use crate::config;
use crate::server::{self, Server};
use ferroc_runtime::builder::RunningApp;
use ferroc_runtime::inspect::view::ParamView;
use ferroc_runtime::inspect::{Catalogue, Inspector, Origin};
use ferroc_runtime::module::{Value, ValueTable};
use ferroc_runtime::supervise::{parse_duration, Args};
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
        Box::new(parse),
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

/// A parameter's new value from its text, by the parameter's type; see the
/// [module docs](self) for units.
pub fn parse(param: &ParamView, text: &str) -> Result<Value, String> {
    let t = text.trim();
    let ty = param.r#type.as_str();
    let number = |t: &str| -> Result<String, String> {
        let end = t
            .find(|c: char| !(c.is_ascii_digit() || "+-.eE".contains(c)))
            .unwrap_or(t.len());
        let (n, unit) = (&t[..end], t[end..].trim());
        if n.is_empty() {
            return Err(format!("`{t}` is not a number"));
        }
        let own = param.unit.as_deref().map(|u| u.replace(' ', ""));
        match (unit, own) {
            ("", _) => Ok(n.to_owned()),
            (u, Some(own)) if u.replace(' ', "") == own => Ok(n.to_owned()),
            (_, None) => Err(format!("`{t}`: the parameter has no unit")),
            (_, Some(own)) => Err(format!(
                "`{t}`: this program converts no units; write the value in {own} (`ferroc run` converts)"
            )),
        }
    };
    let not = |what: &str| format!("`{t}` is not {what}");
    Ok(match ty {
        "bool" => Value::Bool(t.parse().map_err(|_| not("true or false"))?),
        "string" => Value::Text(t.to_owned()),
        "duration" => Value::Duration(parse_duration(t)?),
        "f32" | "f64" => {
            let x: f64 = number(t)?.parse().map_err(|_| not("a number"))?;
            if !x.is_finite() {
                return Err(not("a finite number"));
            }
            Value::Float(x)
        }
        "i8" | "i16" | "i32" | "i64" | "u8" | "u16" | "u32" | "u64" => {
            let i: i128 = number(t)?.parse().map_err(|_| not("an integer"))?;
            let bits: u32 = ty[1..].parse().unwrap_or(64);
            let (lo, hi) = match ty.starts_with('u') {
                true => (0, (1i128 << bits) - 1),
                false => (-(1i128 << (bits - 1)), (1i128 << (bits - 1)) - 1),
            };
            if !(lo..=hi).contains(&i) {
                return Err(format!("`{t}` does not fit in {ty} ({lo}..={hi})"));
            }
            Value::Int(i)
        }
        other => {
            return Err(format!(
                "parameters of type `{other}` cannot be changed by a part program"
            ))
        }
    })
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
    fn values_are_parsed_by_type_with_only_the_parameters_own_unit() {
        let speed = param("f64", Some("m/s"));
        assert_eq!(parse(&speed, "0.3"), Ok(Value::Float(0.3)));
        assert_eq!(parse(&speed, " 0.3 m/s "), Ok(Value::Float(0.3)));
        assert_eq!(parse(&speed, "3e-1m/s"), Ok(Value::Float(0.3)));
        let e = parse(&speed, "30 cm/s").unwrap_err();
        assert!(e.contains("converts no units") && e.contains("m/s"), "{e}");
        let e = parse(&param("f64", None), "3 m").unwrap_err();
        assert!(e.contains("has no unit"), "{e}");
        assert!(parse(&speed, "fast").unwrap_err().contains("not a number"));
        assert!(parse(&speed, "inf").is_err());
        assert_eq!(parse(&param("u8", None), "255"), Ok(Value::Int(255)));
        assert!(parse(&param("u8", None), "256")
            .unwrap_err()
            .contains("does not fit"));
        assert!(parse(&param("u32", None), "-1").is_err());
        assert_eq!(parse(&param("i8", None), "-128"), Ok(Value::Int(-128)));
        assert!(parse(&param("i64", None), "1.5").is_err());
        assert_eq!(parse(&param("bool", None), "true"), Ok(Value::Bool(true)));
        assert!(parse(&param("bool", None), "yes").is_err());
        assert_eq!(
            parse(&param("duration", None), "250ms"),
            Ok(Value::Duration(std::time::Duration::from_millis(250)))
        );
        assert_eq!(
            parse(&param("string", None), "right"),
            Ok(Value::Text("right".into()))
        );
        assert!(parse(&param("nav.Pose2D", None), "x").is_err());
    }

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
