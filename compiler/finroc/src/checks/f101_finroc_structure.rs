//! F101 `finroc-structure`: part of a FINROC file that FINROC cannot read or ignores.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "F101",
    name: "finroc-structure",
    severity: Severity::Error,
    summary: "Part of a FINROC file cannot be read, or FINROC ignores it.",
    explanation: "FINROC's loader (`tFinstructable::LoadXml`, `tConfigFile`) is tolerant: an
element without `name`, `group` or `type` is not created (with everything inside), an
edge with an undecodable path or an unknown flag is not connected, an unknown tag is
logged as `Unknown XML tag` and skipped. None of this stops the program, so the
application silently runs with less than the file describes. ferroc reports each such
place (errors for what FINROC cannot create, warnings for what it ignores) and reads
the rest of the file.

Bad:
    <Finstructable version=\"1703\">
      <element name=\"Control\" type=\"Control\"/>       (no group: not created)
      <edge src=\"A/Output/Array%3Cuint8\" dest=\"B/Input/x%zz\"/>   (bad escape)
      <edges/>                                          (unknown tag)
    </Finstructable>

Fix: write what FINROC's format expects (see the help of each finding).",
    fixtures: "compiler/finroc/src/checks/f101_finroc_structure",
};
