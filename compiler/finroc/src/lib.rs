//! FINROC files checked as they are (the "audit existing configurations" job).
//!
//! - `make_xml.rs`: build descriptions (`make.xml`), checks L106 and L107;
//! - `finstructable.rs`, `read.rs`: application and group files (`*.finroc`, `*.h.xml`,
//!   `*.cpp.xml`), `config.rs`: config files, `text.rs`: FINROC's name and path rules;
//! - `checkout.rs`: the files around the one checked (groups, config files);
//! - `catalogue.rs`: FINROC component types (ports, types, units, C++-built content);
//! - the checks themselves live in `checks/finroc/` (area F).
//!
//! `check_model` hands every FINROC file here instead of the model pipeline.

#![forbid(unsafe_code)]

pub mod catalogue;
pub mod checkout;
pub mod checks;
pub mod config;
pub mod export;
pub mod finstructable;
pub mod import;
pub mod make_xml;
pub mod read;
pub mod resolve;
pub mod text;
pub mod write;

use crate::checks::{l106_make_cycle, l107_duplicate_make_lib};
use ferroc_diagnostics::diagnostic::Diagnostics;
use ferroc_model::load::{root_element, Loader};
use std::path::Path;

/// The kinds of FINROC file the front end reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `make.xml`: build targets.
    Make,
    /// An application (`*.finroc`) or group file: root `<Finstructable>` or
    /// `<FinstructableGroup>` (FINROC does not check the name).
    Structure,
    /// A parameter config file: root `<root>`.
    Config,
    /// A `finroc_sync` deployment description: root `<sync_config>`.
    SyncConfig,
}

impl Kind {
    pub fn describe(self) -> &'static str {
        match self {
            Kind::Make => "FINROC make.xml",
            Kind::Structure => "FINROC application/group",
            Kind::Config => "FINROC config file",
            Kind::SyncConfig => "finroc_sync deployment config",
        }
    }
}

/// What kind of FINROC file `path` is, by its root element (a `.finroc` file or one
/// named `make.xml` also when its XML is broken, so that the breakage is reported).
pub fn kind_of(path: &Path) -> Option<Kind> {
    kind_of_root(root_element(path).as_deref(), path)
}

/// [`kind_of`] for a file whose root element was already read (standard input, which
/// cannot be read twice).
pub fn kind_of_root(root: Option<&str>, path: &Path) -> Option<Kind> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match root {
        Some("targets") => Some(Kind::Make),
        Some("Finstructable" | "FinstructableGroup") => Some(Kind::Structure),
        Some("root") => Some(Kind::Config),
        Some("sync_config") => Some(Kind::SyncConfig),
        Some("application") => None,
        _ if name == "make.xml" => Some(Kind::Make),
        _ if name.ends_with(".finroc") => Some(Kind::Structure),
        _ => None,
    }
}

/// Whether `path` is a FINROC build description.
pub fn is_make_file(path: &Path) -> bool {
    kind_of(path) == Some(Kind::Make)
}

/// Checks one FINROC file; findings go to the loader's diagnostics. Returns what was
/// not checked and why (one sentence each). `Err` only when the file cannot be read.
pub fn check_file(loader: &mut Loader<'_>, path: &Path, kind: Kind) -> Result<Vec<String>, String> {
    let (file, root) = loader.load_make_file(path)?;
    let Some(root) = root else {
        return Ok(vec![format!(
            "{}: not well-formed XML, nothing else checked",
            path.display()
        )]);
    };
    let mut not_checked = Vec::new();
    match kind {
        Kind::Make => {
            let prefix = loader
                .options
                .finroc_prefix
                .clone()
                .or_else(|| make_xml::target_prefix(&loader.sources.get(file).path));
            let make = make_xml::read(file, &root, prefix.as_deref());
            if prefix.is_none() {
                not_checked.push(format!(
                    "{}: its folder tells no FINROC target prefix, so only names FINROC forms without one resolve (give it with --finroc-prefix)",
                    path.display()
                ));
            }
            check_make(&make, loader.diags);
            config_in_make_root(&root, !make.targets.is_empty(), loader.diags);
        }
        Kind::Config => {
            let cfg = config::read(file, &root, loader.diags);
            crate::checks::check_config(&cfg, loader.diags);
        }
        Kind::Structure => {
            let doc = read::read(file, &root, loader.diags);
            let root_dir = checkout::Checkout::root_of(path, loader.options.finroc_root.as_deref());
            let checkout = checkout::Checkout::discover(
                &root_dir,
                path,
                loader.options,
                loader.options.finroc_prefix.clone(),
                loader.sources,
            );
            let ctx = crate::checks::Context {
                doc: &doc,
                path,
                checkout: &checkout,
                catalogue: catalogue::builtin(),
                sources: loader.sources,
            };
            crate::checks::check_structure(&ctx, loader.diags, &mut not_checked);
        }
        Kind::SyncConfig => not_checked.push(format!(
            "{}: a finroc_sync deployment config; only its XML was checked (no ferroc check applies)",
            path.display()
        )),
    }
    Ok(not_checked)
}

/// A file whose root is `<targets>` but which holds config entries in a `<root>` (the
/// corpus has an `etc/config.xml` like that, with a build target pasted beside them): a
/// config file under a wrong outer element. FINROC's
/// `tConfigFile` looks for `<node>`/`<value>` directly below the document's root element
/// (whatever its name), so entries wrapped in a further `<root>` are never found.
fn config_in_make_root(root: &ferroc_syntax::Element, has_targets: bool, out: &mut Diagnostics) {
    use crate::checks::f101_finroc_structure::CHECK;
    use ferroc_diagnostics::diagnostic::Diagnostic;
    if let Some(inner) = root.children.iter().find(|c| c.name == "root") {
        out.push(
            Diagnostic::new(&CHECK, inner.name_span, "the config entries are inside <root> inside <targets>")
                .label("FINROC's config file looks for <node>/<value> right below the document's root element: none of these entries is found")
                .secondary(root.name_span, "the document's root element")
                .help(if has_targets {
                    "remove the outer <targets> element and the build targets beside <root> (they belong in make.xml, where make_builder reads them)"
                } else {
                    "remove the outer <targets> element (and its end tag)"
                }),
        );
        let cfg = config::read(inner.span.file, inner, out);
        crate::checks::check_config(&cfg, out);
    }
}

/// Runs every make-file check on the targets of one `make.xml`.
pub fn check_make(make: &make_xml::MakeFile, out: &mut Diagnostics) {
    l106_make_cycle::check(make, out);
    l107_duplicate_make_lib::check(make, out);
}
