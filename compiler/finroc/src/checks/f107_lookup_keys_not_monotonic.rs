//! F107 `lookup-keys-not-monotonic`: a lookup table whose keys change direction.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "F107",
    name: "lookup-keys-not-monotonic",
    severity: Severity::Error,
    summary: "A lookup table's keys are not strictly increasing or strictly decreasing.",
    explanation:
        "A config lookup table (`<value>` of `<element><key>…</key><value>…</value></element>`)
maps a measured key to a value by searching the keys in order and interpolating between
neighbours. That only works when the keys run one way: a key that turns back, or repeats,
makes two rows claim the same interval and the lookup returns whichever it meets first.
(Tables that run downwards throughout, as several calibration tables do, are fine.)
A key that does not parse (F106) is not judged here.

Bad:
    <element><key>0 m/s</key>…</element>
    <element><key>0.5 m/s</key>…</element>
    <element><key>0.3 m/s</key>…</element>

Fix: sort the rows by key and remove repeated keys.",
    fixtures: "compiler/finroc/src/checks/f107_lookup_keys_not_monotonic",
};

use crate::config::{ConfigFile, ConfigValue};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

/// The number a key starts with (`0.29 m/s` → 0.29), if it is one.
fn number(text: &str) -> Option<f64> {
    text.split_whitespace().next()?.parse().ok()
}

pub fn check(cfg: &ConfigFile, out: &mut Diagnostics) {
    for entry in &cfg.entries {
        let ConfigValue::Table(rows) = &entry.value else {
            continue;
        };
        let Some(keys) = rows
            .iter()
            .map(|(k, _)| number(&k.text))
            .collect::<Option<Vec<f64>>>()
        else {
            continue; // a key that does not parse is F106's (or not a number table)
        };
        let mut direction = 0.0f64;
        for i in 1..keys.len() {
            let step = keys[i] - keys[i - 1];
            let turns = step == 0.0 || (direction != 0.0 && step.signum() != direction);
            if turns {
                let (key, prev) = (&rows[i].0, &rows[i - 1].0);
                let what = if step == 0.0 {
                    "repeats"
                } else {
                    "turns back after"
                };
                out.push(
                    Diagnostic::new(
                        &CHECK,
                        key.span,
                        format!(
                            "key `{}` {what} `{}` in `{}`",
                            key.text, prev.text, entry.path
                        ),
                    )
                    .label(format!(
                        "the keys ran {} so far",
                        if direction > 0.0 {
                            "upwards"
                        } else {
                            "downwards"
                        }
                    ))
                    .secondary(prev.span, "previous key")
                    .help("sort the rows by key and remove repeated keys"),
                );
                break;
            }
            direction = step.signum();
        }
    }
}
