//! L107 `duplicate-make-lib`: A make.xml target lists the same library twice.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "L107",
    name: "duplicate-make-lib",
    severity: Severity::Warning,
    summary: "A make.xml target lists the same library twice.",
    explanation: "A library named twice in `libs` is harmless for FINROC's build but usually a
merge or copy-paste leftover; one named in both `libs` and `optionallibs` is a
contradiction: it is required, so the optional entry has no effect, and whoever reads
the file cannot tell which was meant. (A target that lists itself is a cycle: L106.)

Bad:
    <library name=\"vision\" libs=\"opencv_all boost opencv_all\" optionallibs=\"boost\">

Fix: name each library once, in `libs` if the target cannot build without it, in
`optionallibs` if it only uses it when present.",
    fixtures: "compiler/finroc/src/checks/l107_duplicate_make_lib",
};

use crate::make_xml::MakeFile;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use std::collections::HashMap;

/// Reports each repeated `libs`/`optionallibs` entry of a target, at the repetition.
pub fn check(make: &MakeFile, out: &mut Diagnostics) {
    for target in &make.targets {
        let mut first = HashMap::new();
        for lib in &target.libs {
            let Some(earlier) = first.get(lib.name.as_str()).copied() else {
                first.insert(lib.name.as_str(), lib);
                continue;
            };
            let list = |optional| if optional { "optionallibs" } else { "libs" };
            let (message, help) = if earlier.optional == lib.optional {
                (
                    format!(
                        "`{}` is listed twice in the `{}` of `{}`",
                        lib.name,
                        list(lib.optional),
                        target.display_name()
                    ),
                    "remove the repetition",
                )
            } else {
                (
                    format!(
                        "`{}` is both required and optional for `{}`",
                        lib.name,
                        target.display_name()
                    ),
                    "keep it in `libs` if the target cannot build without it, otherwise only in `optionallibs`",
                )
            };
            out.push(
                Diagnostic::new(&CHECK, lib.span, message)
                    .label(format!("again in `{}`", list(lib.optional)))
                    .secondary(
                        earlier.span,
                        format!("first in `{}`", list(earlier.optional)),
                    )
                    .help(help),
            );
        }
    }
}
