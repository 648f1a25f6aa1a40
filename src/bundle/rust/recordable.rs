//! The table `RECORDABLE` of a generated `main.rs`: the outputs `--record` may record
//! (found by `layout/recordable.rs`), which `ferroc_std::Recorders` reads when the
//! program is started with `--record`; and the table `UNITS`, the unit of each port,
//! which the program tells the recording modules for their channel metadata.

use super::super::code::Code;
use super::super::layout::Part;
use super::super::literals::call;
use super::super::text::rust_str;

/// `const RECORDABLE: &[Recordable] = &[…];`, module paths by their constants.
pub fn table(part: &Part<'_>, name_of: &dyn Fn(&str) -> String) -> String {
    let items: Vec<String> = (part.recordable.iter())
        .map(|o| {
            let mut args = vec![
                name_of(&o.module),
                rust_str(&o.port),
                rust_str(&o.model_type),
                rust_str(&o.thread),
            ];
            match o.subscribed {
                Some(id) => {
                    args.push(id.to_string());
                    call("Recordable::subscribed", &args)
                }
                None => call("Recordable::new", &args),
            }
        })
        .collect();
    let mut code = Code::default();
    code.list(0, "const RECORDABLE: &[Recordable] = &[", &items, "];");
    let units: Vec<String> = (part.units.iter())
        .map(|(port, unit)| format!("({}, {})", rust_str(port), rust_str(unit)))
        .collect();
    code.line(
        0,
        "/// The unit of each port the modules connect (for recordings).",
    );
    code.list(0, "const UNITS: &[(&str, &str)] = &[", &units, "];");
    code.text.trim_end_matches('\n').to_string()
}
