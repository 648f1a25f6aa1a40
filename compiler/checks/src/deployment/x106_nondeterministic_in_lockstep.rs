//! X106 `nondeterministic-in-lockstep`: A module of a model run in lockstep reads the
//! wall clock or the OS's randomness, so the run differs from the next.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_model::ir::{ElementId, ModuleInstance, ParamSource};
use ferroc_model::library::ParamDecl;

pub static CHECK: CheckInfo = CheckInfo {
    code: "X106",
    name: "nondeterministic-in-lockstep",
    severity: Severity::Warning,
    summary: "A module of a model run in lockstep reads the wall clock or the OS's randomness.",
    explanation: "A lockstep run promises the same output, and the same recordings, on every run:
model time instead of the wall clock, and randomness from the run seed (`--seed`) through
each module's random source. A module that takes the wall clock or the OS's entropy breaks
that silently. Applies when the model is judged as run in lockstep (`ferroc check
--lockstep`, `ferroc run --lockstep`); the runtime also warns about every module that reads
them through its APIs.

It reports a module whose type the manifest marks `nondeterministic=\"true\"`, and a
parameter left at the value at which its module reads the clock or the OS's randomness
(`nondeterministic-value=\"0\"` in the manifest, or a `doc` such as \"0 seeds from the
system clock\").

Bad (`seed`: \"0 seeds from the system clock\"):
    <module name=\"noise\" type=\"sim.Noise\"/>

Fix: give the parameter a fixed value, `<param name=\"seed\">42</param>`; for a type that
reads the clock, use a deterministic one in lockstep runs (or `<allow code=\"X106\"/>` where
the difference does not matter).",
    fixtures: "compiler/checks/src/deployment/x106_nondeterministic_in_lockstep",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    if !ctx.lockstep {
        return;
    }
    for (id, m) in ctx.app.modules() {
        let Some(mt) = ctx.app.module_type(ctx.libraries, id) else {
            continue;
        };
        let path = ctx.app.path(id);
        if let Some(marked) = mt.nondeterministic {
            let d = Diagnostic::new(
                &CHECK,
                m.type_span,
                format!(
                    "`{path}` is a `{}`, which reads the wall clock or the OS's randomness: this lockstep run will differ from the next",
                    mt.qualified
                ),
            )
            .label("nondeterministic module type")
            .secondary(marked, "marked nondeterministic here")
            .help("use a deterministic module type in lockstep runs (randomness from `Setup::random()`, time from `Timestamp::now()`), or allow X106 here if the difference does not matter");
            out.push(in_instance(ctx, id, d));
        }
        for decl in &mt.params {
            if let Some(d) = param_at_nondeterministic_value(ctx, id, m, decl, &path) {
                out.push(in_instance(ctx, id, d));
            }
        }
    }
}

/// The finding for `decl` when the instance leaves it at its nondeterministic value.
fn param_at_nondeterministic_value(
    ctx: &PassContext<'_>,
    id: ElementId,
    m: &ModuleInstance,
    decl: &ParamDecl,
    path: &str,
) -> Option<Diagnostic> {
    let (bad, said) = decl.nondeterministic_value.as_ref()?;
    let given = m.params.iter().find(|p| p.name == decl.name);
    let (text, span, cmdline) = match given {
        Some(p) => {
            let text = match &p.source {
                ParamSource::Inline => p.text.as_str(),
                ParamSource::Config(Ok((text, _))) => text.as_str(),
                // Given at start-up, or missing (P106 says so): not known here.
                ParamSource::Config(Err(_)) | ParamSource::Cmdline => return None,
            };
            (text, p.span, p.cmdline.as_ref().map(|(n, _)| n.as_str()))
        }
        None => (
            decl.default.as_deref()?,
            ctx.app.element(id).name_span,
            None,
        ),
    };
    if !same_value(text, bad) {
        return None;
    }
    let how = if given.is_some() { "is" } else { "is left at" };
    let mut help = format!(
        "give it a fixed value: <param name=\"{}\">42</param> (any value but {bad})",
        decl.name
    );
    if let Some(name) = cmdline {
        help.push_str(&format!(", or run with --param {name}=42"));
    }
    Some(
        Diagnostic::new(
            &CHECK,
            span,
            format!(
                "`{path}`: `{}` {how} {bad}, at which the module reads the wall clock or the OS's randomness: this lockstep run will differ from the next",
                decl.name
            ),
        )
        .label(format!("`{}` = {bad}", decl.name))
        .secondary(*said, "the manifest says what this value does")
        .help(help),
    )
}

/// The finding with where the module's group type was instantiated, if it was.
fn in_instance(ctx: &PassContext<'_>, id: ElementId, d: Diagnostic) -> Diagnostic {
    match ctx.app.element(id).instantiated_at {
        Some(at) => d.secondary(at, "in this instance"),
        None => d,
    }
}

/// `0`, `0.0` and ` 0 ` are one value; texts that are not numbers compare as written.
fn same_value(a: &str, b: &str) -> bool {
    match (a.trim().parse::<f64>(), b.trim().parse::<f64>()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a.trim() == b.trim(),
    }
}
