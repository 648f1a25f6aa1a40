//! Commands that use a model (`schedule`, `run`, `bundle`) check it first and stop on
//! errors: [`without_errors`].

use ferroc_compiler::checks::deployment::x106_nondeterministic_in_lockstep::CHECK as X106;
use ferroc_compiler::diagnostic::Severity;
use ferroc_compiler::report::{self, ModelReport};
use ferroc_compiler::{check_model, CheckResult, Policy};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Checks `model`; on errors prints them (human format) and gives the exit code.
/// Warnings and notes do not stop the command and are not repeated here.
pub fn without_errors(model: &Path, lib_path: &[PathBuf]) -> Result<CheckResult, ExitCode> {
    without_errors_as(model, lib_path, false)
}

/// [`without_errors`], judging the model as run in lockstep when `lockstep` is set
/// (`ferroc run --lockstep`: X106 then reports what makes the run differ from the
/// next; [`print_lockstep_findings`] shows it).
pub fn without_errors_as(
    model: &Path,
    lib_path: &[PathBuf],
    lockstep: bool,
) -> Result<CheckResult, ExitCode> {
    let mut options = crate::loader_options(lib_path, false);
    options.lockstep = lockstep;
    let result = match check_model(model, &options, &Policy::default()) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return Err(ExitCode::from(2));
        }
    };
    let errors = result
        .diagnostics
        .iter()
        .any(|d| d.severity == Severity::Error);
    if errors || result.app.is_none() {
        let mut out = String::new();
        let errors_only: Vec<_> = result
            .diagnostics
            .iter()
            .filter(|d| d.severity == Severity::Error)
            .cloned()
            .collect();
        report::short(
            &ModelReport {
                sources: &result.sources,
                diagnostics: &errors_only,
            },
            &mut out,
        );
        eprint!("{out}");
        eprintln!(
            "error: {} has errors; `ferroc check {}` explains them",
            model.display(),
            model.display()
        );
        return Err(ExitCode::from(1));
    }
    Ok(result)
}

/// Prints the X106 findings of a check made for a lockstep run (warnings, which do not
/// stop it) on standard error, before the run starts: a lockstep run that will differ
/// from the next should say so where the user looks.
pub fn print_lockstep_findings(result: &CheckResult) {
    let found: Vec<_> = result
        .diagnostics
        .iter()
        .filter(|d| std::ptr::eq(d.check, &X106))
        .cloned()
        .collect();
    if found.is_empty() {
        return;
    }
    let mut out = String::new();
    report::short(
        &ModelReport {
            sources: &result.sources,
            diagnostics: &found,
        },
        &mut out,
    );
    eprint!("{out}");
}
