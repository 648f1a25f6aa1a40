//! The stable identity and documentation of a check, without its logic.
//!
//! A check's [`CheckInfo`] is a `static` in the crate that raises it: the reader's and
//! validator's checks in `ferroc-syntax`, the loader's, libraries' and resolver's in
//! `ferroc-model`, the passes over the IR in `ferroc-checks`, the FINROC checks in
//! `ferroc-finroc`. The logic is registered where it runs (`ferroc_checks::PASSES`);
//! `ferroc_compiler::checks::REGISTRY` lists every check.

use crate::diagnostic::Severity;

/// The stable identity and documentation of a check.
#[derive(Debug)]
pub struct CheckInfo {
    /// Area letter and three digits: `T102`.
    pub code: &'static str,
    /// Kebab-case name: `incompatible-types`.
    pub name: &'static str,
    pub severity: Severity,
    /// One line, used as SARIF `shortDescription` and in `explain --list`.
    pub summary: &'static str,
    /// What the rule protects, a minimal bad model, the fix (`ferroc explain CODE`).
    pub explanation: &'static str,
    /// Where the fixtures live, relative to the repository's root: the folder named
    /// like the check's file, next to it.
    pub fixtures: &'static str,
}
