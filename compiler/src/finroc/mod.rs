//! FINROC files checked as they are (the "audit existing configurations" job).
//!
//! For now: build descriptions (`make.xml`), whose targets depend on each other through
//! `libs`/`optionallibs` (checks L106 and L107). FINROC application models
//! (`<Finstructable>`) are not read yet.

pub mod make_xml;

use crate::checks::libraries::{l106_make_cycle, l107_duplicate_make_lib};
use crate::diagnostic::Diagnostics;
use crate::load::{root_element, Loader};
use std::path::Path;

/// Whether `path` is a FINROC build description: its root element is `<targets>`, or it is
/// named `make.xml` (as FINROC finds them) and is not a ferroc `<application>`.
pub fn is_make_file(path: &Path) -> bool {
    let named = path
        .file_name()
        .is_some_and(|n| n.eq_ignore_ascii_case("make.xml"));
    match root_element(path).as_deref() {
        Some("targets") => true,
        Some("application") => false,
        _ => named,
    }
}

/// Reads one `make.xml` and runs the make-file checks; findings go to the loader's
/// diagnostics. `Err` only when the file cannot be read (as for a model).
pub fn check_make_file(loader: &mut Loader<'_>, path: &Path) -> Result<(), String> {
    let (file, root) = loader.load_make_file(path)?;
    if let Some(root) = root {
        let prefix = make_xml::target_prefix(&loader.sources.get(file).path);
        let make = make_xml::read(file, &root, prefix.as_deref());
        check_make(&make, loader.diags);
    }
    Ok(())
}

/// Runs every make-file check on the targets of one `make.xml`.
pub fn check_make(make: &make_xml::MakeFile, out: &mut Diagnostics) {
    l106_make_cycle::check(make, out);
    l107_duplicate_make_lib::check(make, out);
}
