//! Reading cargo's output while a runner builds, and saying afterwards which library's
//! crate its errors belong to (at the library's manifest), so a user is not left with a
//! page of cargo errors about a package they never wrote.

use super::crates::LibraryCrate;
use std::path::Path;

/// `could not compile `NAME`` in one of cargo's lines (colours stripped).
pub(super) fn failed_package(line: &str) -> Option<String> {
    let plain = strip_ansi(line);
    let rest = plain.split("could not compile `").nth(1)?;
    Some(rest.split('`').next()?.to_string())
}

pub(super) fn strip_ansi(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        if c == '\x1b' {
            for c in chars.by_ref() {
                if c.is_ascii_alphabetic() {
                    break;
                }
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// Whether one of cargo's lines says the registry package `package` cannot be had
/// (unknown name, no such version, offline, download failed).
pub(super) fn unfetched(line: &str, package: &str) -> bool {
    let plain = strip_ansi(line);
    // `NAME` alone, or `NAME = "REQ"` in a requirement.
    let named = |what: &str| {
        plain.contains(&format!("{what} `{package}`"))
            || plain.contains(&format!("{what} `{package} "))
    };
    named("no matching package named")
        || named("failed to select a version for the requirement")
        || named("failed to download")
        || named("failed to get")
}

/// After cargo's own errors: which library's crate they belong to, at its manifest.
pub(super) fn report_failure(
    crates: &[LibraryCrate],
    failed: &[String],
    unavailable: &[String],
    runner: &str,
    dir: &Path,
) {
    let mut explained = false;
    for c in crates.iter().filter(|c| unavailable.contains(&c.package)) {
        eprintln!(
            "{}: error: the crate `{}` {} of library `{}` could not be fetched from the registry (cargo's errors above)\n  \
             help: check the name and version on crates.io and the network (cargo's `--offline` or CARGO_NET_OFFLINE forbid fetching); \
             or put the crate next to the manifest and write rust-crate=\"{}\"",
            c.manifest_at,
            c.package,
            c.version.as_deref().unwrap_or(""),
            c.library,
            c.package
        );
        explained = true;
    }
    for c in crates {
        if failed.contains(&c.package) && c.version.is_none() {
            eprintln!(
                "{}: error: the crate `{}` of library `{}` does not build (cargo's errors above)\n  \
                 = crate: {}\n  \
                 help: fix the crate; `cargo build --manifest-path {}` shows the same errors",
                c.manifest_at,
                c.package,
                c.library,
                c.dir.display(),
                c.dir.join("Cargo.toml").display()
            );
            explained = true;
        }
    }
    if failed.iter().any(|p| p == runner) {
        for c in crates {
            eprintln!(
                "{}: error: the runner could not call `{}::register` of library `{}` (cargo's errors above)\n  \
                 help: the crate `{}` must have `pub fn register(registry: &mut ferroc_runtime::builder::Registry)` registering its module types",
                c.manifest_at, c.package, c.library, c.package
            );
        }
        explained = true;
    }
    if !explained {
        eprintln!(
            "error: the runner for these libraries did not build (cargo's output above; package in {}):",
            dir.display()
        );
        for c in crates {
            eprintln!(
                "{}: note: library `{}`, crate `{}` at {}",
                c.manifest_at,
                c.library,
                c.package,
                c.dir.display()
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unfetched_registry_packages_are_read_from_cargo_lines() {
        let line = "error: no matching package named `my-arm` found";
        assert!(unfetched(line, "my-arm"));
        assert!(!unfetched(line, "my"), "the whole name");
        assert!(unfetched(
            "\x1b[31merror\x1b[0m: failed to select a version for the requirement `my-arm = \"^9\"`",
            "my-arm"
        ));
        assert!(!unfetched("   Compiling my-arm v0.3.0", "my-arm"));
    }

    #[test]
    fn failed_packages_are_read_from_cargo_lines_with_or_without_colour() {
        assert_eq!(
            failed_package("error: could not compile `my-lib` (lib) due to 1 previous error"),
            Some("my-lib".into())
        );
        assert_eq!(
            failed_package("\x1b[1m\x1b[31merror\x1b[0m: could not compile `x` (bin \"x\")"),
            Some("x".into())
        );
        assert_eq!(failed_package("   Compiling my-lib v0.1.0"), None);
    }
}
