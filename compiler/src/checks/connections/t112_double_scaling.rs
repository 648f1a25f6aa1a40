//! T112 `double-scaling`: A `<convert scale>` on a connection whose units are scaled already.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T112",
    name: "double-scaling",
    severity: Severity::Warning,
    summary: "A `<convert scale>` on a connection whose units are scaled already.",
    explanation: "Between `m` and `mm` the checker already inserts the factor 1000. A `<convert scale>` on
the same connection would scale a second time.

Bad:
    <connect from=\"a/dist_m\" to=\"b/dist_mm\"><convert scale=\"1000\"/></connect>

Fix: remove the `scale`; declared units do the conversion.",
    pass: None,
    fixtures: "connections/t112_double_scaling",
};
