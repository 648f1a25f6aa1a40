//! The few `--name value` options of the benchmarks, parsed by hand.
//!
//! Every mistake is a plain message (the caller prints it and exits with 2); nothing
//! here panics on user input.

use std::fmt::Display;
use std::str::FromStr;

/// `--name value` / `--name=value` pairs and `--flag`s of one benchmark, checked
/// against the names it knows.
pub struct Options {
    id: &'static str,
    values: Vec<(String, String)>,
}

impl Options {
    /// Parses `args` (what follows the benchmark id). `known` lists the names of options
    /// with a value, `flags` those without, both without dashes.
    pub fn parse(
        id: &'static str,
        args: &[String],
        known: &[&str],
        flags: &[&str],
    ) -> Result<Self, String> {
        let all: Vec<&str> = known.iter().chain(flags).copied().collect();
        let mut values: Vec<(String, String)> = Vec::new();
        let mut rest = args.iter();
        while let Some(arg) = rest.next() {
            let Some(body) = arg.strip_prefix("--") else {
                return Err(format!("{id}: unexpected argument `{arg}`{}", hint(&all)));
            };
            let (name, value) = match body.split_once('=') {
                Some((n, _)) if flags.contains(&n) => {
                    return Err(format!("{id}: `--{n}` takes no value"));
                }
                None if flags.contains(&body) => (body.to_string(), String::new()),
                Some((n, v)) => (n.to_string(), v.to_string()),
                None => {
                    let Some(v) = rest.next() else {
                        return Err(format!("{id}: option `--{body}` needs a value"));
                    };
                    (body.to_string(), v.clone())
                }
            };
            if !all.contains(&name.as_str()) {
                return Err(format!("{id}: unknown option `--{name}`{}", hint(&all)));
            }
            if values.iter().any(|(n, _)| *n == name) {
                return Err(format!("{id}: option `--{name}` given twice"));
            }
            values.push((name, value));
        }
        Ok(Options { id, values })
    }

    /// Was the flag `--name` given?
    pub fn flag(&self, name: &str) -> bool {
        self.values.iter().any(|(n, _)| n == name)
    }

    /// The value of `--name` as given, if it was.
    pub fn text(&self, name: &str) -> Option<&str> {
        let found = self.values.iter().find(|(n, _)| n == name);
        found.map(|(_, v)| v.as_str())
    }

    /// The value of `--name` as a number, `default` when absent; `Err` when it does not
    /// parse or lies outside `min..=max`.
    pub fn number<T>(&self, name: &str, default: T, min: T, max: T) -> Result<T, String>
    where
        T: FromStr + PartialOrd + Display + Copy,
    {
        let Some((_, text)) = self.values.iter().find(|(n, _)| n == name) else {
            return Ok(default);
        };
        let parsed = text.replace('_', "").parse::<T>().ok();
        match parsed {
            Some(v) if v >= min && v <= max => Ok(v),
            _ => Err(format!(
                "{}: `--{name} {text}`: expected a number from {min} to {max}",
                self.id
            )),
        }
    }
}

impl Options {
    /// `--cycles N --rounds R`, the options of the loop benchmarks (b2, b5).
    pub fn cycles_and_rounds(
        id: &'static str,
        args: &[String],
        default_cycles: u64,
        default_rounds: u64,
    ) -> Result<(u64, u64), String> {
        let o = Options::parse(id, args, &["cycles", "rounds"], &[])?;
        Ok((
            o.number("cycles", default_cycles, 1000, 10_000_000_000)?,
            o.number("rounds", default_rounds, 1, 100)?,
        ))
    }
}

fn hint(known: &[&str]) -> String {
    if known.is_empty() {
        " (this benchmark takes no options)".into()
    } else {
        let list: Vec<String> = known.iter().map(|k| format!("--{k}")).collect();
        format!(" (options: {})", list.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(a: &[&str]) -> Vec<String> {
        a.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn both_spellings_and_defaults() {
        let o = Options::parse(
            "b4",
            &args(&["--messages", "1_000", "--pin", "--gap-us=5"]),
            &["messages", "gap-us", "rounds"],
            &["pin"],
        )
        .unwrap();
        assert!(o.flag("pin"));
        assert_eq!(o.number("messages", 7u64, 1, u64::MAX).unwrap(), 1000);
        assert_eq!(o.number("gap-us", 0u64, 0, 10).unwrap(), 5);
        assert_eq!(o.number("rounds", 4u64, 1, 10).unwrap(), 4);
    }

    #[test]
    fn mistakes_are_messages() {
        let known = &["seconds"];
        let bad = |a: &[&str]| {
            Options::parse("b3", &args(a), known, &["pin"])
                .err()
                .unwrap()
        };
        assert!(bad(&["--second", "1"]).contains("unknown option `--second`"));
        assert!(bad(&["--seconds"]).contains("needs a value"));
        assert!(bad(&["5"]).contains("unexpected argument"));
        assert!(bad(&["--seconds", "1", "--seconds", "2"]).contains("twice"));
        assert!(bad(&["--pin=1"]).contains("takes no value"));
        let o = Options::parse("b3", &args(&["--seconds", "x"]), known, &[]).unwrap();
        assert!(!o.flag("pin"));
        assert!(o.number("seconds", 5.0, 0.1, 60.0).is_err());
        let o = Options::parse("b3", &args(&["--seconds", "0"]), known, &[]).unwrap();
        assert!(o.number("seconds", 5.0, 0.1, 60.0).is_err());
    }
}
