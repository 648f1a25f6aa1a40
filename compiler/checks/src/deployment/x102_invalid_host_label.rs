//! X102 `invalid-host-label`: A `host` is not a valid host name.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_model::ir::ElementKind;

pub static CHECK: CheckInfo = CheckInfo {
    code: "X102",
    name: "invalid-host-label",
    severity: Severity::Error,
    summary: "A `host` is not a valid host name.",
    explanation:
        "`host` labels become host names in launch scripts and the distributed transport: letters,
digits and `-`, dot-separated labels of at most 63 characters, not starting or ending
with `-`.

Bad:
    <part name=\"robot\" host=\"robot pc\"/>

Fix: `host=\"robot-pc\"`.",
    fixtures: "compiler/checks/src/deployment/x102_invalid_host_label",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for e in &ctx.app.elements {
        let ElementKind::Part {
            host: Some((host, span)),
        } = &e.kind
        else {
            continue;
        };
        if let Err(why) = valid_host(host) {
            out.push(
                Diagnostic::new(
                    &CHECK,
                    *span,
                    format!("`{host}` is not a valid host name: {why}"),
                )
                .label("invalid host")
                .help("use letters, digits and `-` in dot-separated labels, e.g. `robot-pc`"),
            );
        }
    }
}

/// RFC 1123 host names. `ferroc bundle` names launch scripts after them with the same
/// rule, so a host that checks never makes a file name that climbs (`..`, `/`) or
/// reads as an option (`-rf`).
pub fn valid_host(host: &str) -> Result<(), String> {
    if host.is_empty() || host.len() > 253 {
        return Err("it must have 1 to 253 characters".into());
    }
    for label in host.split('.') {
        if label.is_empty() || label.len() > 63 {
            return Err("each dot-separated label must have 1 to 63 characters".into());
        }
        if label.starts_with('-') || label.ends_with('-') {
            return Err(format!("label `{label}` starts or ends with `-`"));
        }
        if let Some(c) = label
            .chars()
            .find(|c| !(c.is_ascii_alphanumeric() || *c == '-'))
        {
            return Err(format!("`{}` is not allowed", c.escape_default()));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::valid_host;

    #[test]
    fn host_labels_follow_rfc_1123_and_stay_plain_file_names() {
        for good in ["robot-1.local", "localhost", "pc1", "a.b.c"] {
            assert!(valid_host(good).is_ok(), "{good:?}");
        }
        let long = "a".repeat(64);
        for bad in [
            "..", "../etc", "a/b", "-rf", ".hidden", "a..b", "", "a_b", "end-", &long,
        ] {
            assert!(valid_host(bad).is_err(), "{bad:?}");
        }
    }
}
