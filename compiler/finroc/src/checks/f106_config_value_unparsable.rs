//! F106 `config-value-unparsable`: a config value FINROC does not read as meant.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "F106",
    name: "config-value-unparsable",
    severity: Severity::Error,
    summary: "A config value does not parse as FINROC parses numbers, or lacks the unit its parameter has.",
    explanation: "FINROC reads numbers in config files with C++ streams in the C locale: the
decimal separator is `.`, and what follows the number must be a unit rrlib_si_units
knows. A comma decimal (`-1,47 1/m`, typed on a German keyboard) is read as `-1`
followed by `,47 1/m`, which is no unit: the value does not load as written. A value
linked to a parameter that has a unit (a tLength, a tVelocity) but written without one
leaves the reader to guess the scale (warning).

Bad:
    <value name=\"Curvature Lookup\"><element><key>-1,47 1/m</key>…
    <value name=\"destructive_collision_speed\">0.1</value>   (a velocity)

Fix: write `-1.47 1/m`; write the unit (`0.1 m/s`).",
    fixtures: "compiler/finroc/src/checks/f106_config_value_unparsable",
};

use super::Context;
use crate::config::{ConfigFile, ConfigValue};
use crate::finstructable::Named;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

/// Whether `text` is a number with a comma as decimal separator (`-1,47`, `3,5 m`).
pub fn comma_decimal(text: &str) -> bool {
    let number = text.split_whitespace().next().unwrap_or("");
    let body = number.strip_prefix(['-', '+']).unwrap_or(number);
    match body.split_once(',') {
        Some((a, b)) => {
            !a.is_empty()
                && !b.is_empty()
                && a.chars().all(|c| c.is_ascii_digit())
                && b.chars().all(|c| c.is_ascii_digit())
        }
        None => false,
    }
}

fn texts(value: &ConfigValue) -> Vec<&Named> {
    match value {
        ConfigValue::Text(t) => vec![t],
        ConfigValue::List(l) => l.iter().collect(),
        ConfigValue::Table(rows) => rows.iter().flat_map(|(k, v)| [k, v]).collect(),
    }
}

/// Comma decimals in a config file.
pub fn check(cfg: &ConfigFile, out: &mut Diagnostics) {
    for entry in &cfg.entries {
        for t in texts(&entry.value) {
            if comma_decimal(&t.text) {
                let fixed = t.text.replacen(',', ".", 1);
                out.push(
                    Diagnostic::new(
                        &CHECK,
                        t.span,
                        format!("`{}` has a comma as decimal separator", t.text),
                    )
                    .label("FINROC reads the number up to the comma; the rest is not a unit")
                    .secondary(entry.name.span, format!("in `{}`", entry.path))
                    .help(format!("write `{fixed}`")),
                );
            }
        }
    }
}

/// Whether a value's text is a bare number (no unit after it).
fn bare_number(text: &str) -> bool {
    let t = text.trim();
    !t.is_empty() && t.parse::<f64>().is_ok()
}

/// Linked config values without the unit their parameter has (catalogue).
pub fn check_linked_units(ctx: &Context<'_>, out: &mut Diagnostics) {
    for link in &ctx.doc.links {
        let Some(config) = &link.config else { continue };
        let Some((_, entry)) = ctx.checkout.config_entry(&config.text) else {
            continue;
        };
        let ConfigValue::Text(value) = &entry.value else {
            continue;
        };
        let Some((param, unit)) =
            super::f108_config_link_missing::linked_param_unit(ctx, &link.path)
        else {
            continue;
        };
        if bare_number(&value.text) {
            out.push(
                Diagnostic::new(
                    &CHECK,
                    value.span,
                    format!(
                        "`{}` has no unit, but `{param}` is measured in {unit}",
                        value.text
                    ),
                )
                .label(format!("a bare number for a quantity in {unit}"))
                .secondary(config.span, "linked to the parameter here")
                .severity(Severity::Warning)
                .help(format!("write `{} {unit}` (or the unit meant)", value.text)),
            );
        }
    }
}
