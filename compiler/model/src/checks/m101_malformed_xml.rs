//! M101 `malformed-xml`: The file is not well-formed XML.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M101",
    name: "malformed-xml",
    severity: Severity::Error,
    summary: "The file is not well-formed XML.",
    explanation:
        "A model, include or manifest that is not well-formed XML cannot be read at all: an unclosed
tag, a mismatched end tag, an attribute without quotes, an unknown entity, text after the root.

Bad:
    <application name=\"bot\" version=\"1\">
      <part name=\"robot\">
    </application>

Fix: close every element (`<part name=\"robot\"> ... </part>` or `<part name=\"robot\"/>`), quote
attribute values, escape `&` as `&amp;` and `<` as `&lt;`.",
    fixtures: "compiler/model/src/checks/m101_malformed_xml",
};
