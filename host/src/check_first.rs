//! Commands that use a model (`schedule`, `run`, `bundle`) check it first and stop on
//! errors: [`without_errors`].

use ferroc_compiler::diagnostic::Severity;
use ferroc_compiler::report::{self, ModelReport};
use ferroc_compiler::{check_model, CheckResult, Policy};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Checks `model`; on errors prints them (human format) and gives the exit code.
/// Warnings and notes do not stop the command and are not repeated here.
pub fn without_errors(model: &Path, lib_path: &[PathBuf]) -> Result<CheckResult, ExitCode> {
    let options = crate::loader_options(lib_path, false);
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
