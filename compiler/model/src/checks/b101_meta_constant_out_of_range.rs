//! B101 `meta-constant-out-of-range`: A constant given for an iB2C meta signal lies
//! outside [0, 1].
//!
//! Raised by the parameter value check (`check_value` in `library/module_type/params.rs`), which
//! sees `<param>` values in models (inline or from config files) and `default`s in
//! manifests: one parse, every verdict.

use crate::library::module_type::ParamDecl;
use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::{Diagnostic, Severity};
use ferroc_diagnostics::source::Span;

pub static CHECK: CheckInfo = CheckInfo {
    code: "B101",
    name: "meta-constant-out-of-range",
    severity: Severity::Error,
    summary: "A constant given for an iB2C meta signal lies outside [0, 1].",
    explanation: "Stimulation, inhibition, activity and target rating are meta signals in [0, 1]: a
behaviour's activation is `s · (1 − i)`, and its activity may never exceed it. FINROC throws
\"Meta signal out of bounds!\" at run time when a value leaves the range; ferroc rejects a
constant that would do so before anything runs. Constants for meta signals are parameters
whose declared type is `Stimulation`, `Inhibition`, `Activity` or `TargetRating` — for
example the value of `ferroc_std.ConstantActivity`, the way to give a stimulation or
inhibition input a fixed value — in a model or as a manifest `default`.

Bad:
    <module name=\"always_on\" type=\"ferroc_std.ConstantActivity\">
      <param name=\"value\">1.5</param>
    </module>
    <connect from=\"always_on/activity\" to=\"follow_goal/stimulation\"/>

Fix: give a value between 0 (no stimulation) and 1 (full stimulation).",
    fixtures: "compiler/model/src/checks/b101_meta_constant_out_of_range",
};

/// The finding for a meta-typed parameter whose value `n` (written `text` at `span`)
/// lies outside [0, 1]; `context` is the parameter's declaration, when it is elsewhere.
pub fn report(
    decl: &ParamDecl,
    text: &str,
    n: f64,
    span: Span,
    context: Option<Span>,
) -> Diagnostic {
    let d = Diagnostic::new(
        &CHECK,
        span,
        format!(
            "`{}` is a meta signal (`{}`) in [0, 1], but the value is {}",
            decl.name,
            decl.ty,
            text.trim()
        ),
    )
    .label(if n < 0.0 { "below 0" } else { "above 1" })
    .help(if n > 1.0 {
        "use a value in 0 ..= 1 (0: none, 1: full); a percentage such as 75 % is written 0.75"
    } else {
        "use a value in 0 ..= 1 (0: none, 1: full); a meta signal cannot be negative"
    });
    match context {
        Some(c) => d.secondary(c, format!("declared `{}` here", decl.ty)),
        None => d,
    }
}
