//! Checks of area parameters.

pub mod p101_unknown_parameter;
pub mod p102_missing_required_parameter;
pub mod p103_unparsable_value;
pub use ferroc_model::checks::p104_out_of_range;
pub use ferroc_model::checks::p105_wrong_unit_dimension;
pub use ferroc_model::checks::p106_config_entry_missing;
pub mod p107_duplicate_parameter;
pub mod p108_invalid_pin_map;
pub mod p109_const_value_type;
pub mod p110_value_without_unit;

use crate::PassContext;
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{ElementId, ParamSource, ParamValue};
use ferroc_model::library::module_type::ModuleType;

/// The parameter `name` of a module of type `module_type` (qualified), with its text.
pub(crate) struct ParamText<'a> {
    pub id: ElementId,
    pub module_type: &'a ModuleType,
    pub param: &'a ParamValue,
    /// The value as the module receives it (inline or from its config file).
    pub text: &'a str,
}

impl ParamText<'_> {
    /// Where a byte range of the text stands in the file: exactly when the file holds
    /// the text as written (no entities), else the whole value.
    pub fn span_of(&self, r: std::ops::Range<usize>) -> Span {
        let p = self.param;
        if p.span.end.saturating_sub(p.span.start) as usize == self.text.len() {
            Span {
                file: p.span.file,
                start: p.span.start + r.start as u32,
                end: p.span.start + r.end as u32,
            }
        } else {
            p.span
        }
    }
}

/// Every module of type `module_type` whose parameter `name` has a text to check (a
/// value from the command line or a config entry that is missing is checked elsewhere).
pub(crate) fn texts_of<'a>(
    ctx: &'a PassContext<'_>,
    module_type: &'a str,
    name: &'a str,
) -> impl Iterator<Item = ParamText<'a>> + 'a {
    ctx.app.modules().filter_map(move |(id, module)| {
        let mt = ctx.app.module_type(ctx.libraries, id)?;
        if mt.qualified != module_type {
            return None;
        }
        let param = module.params.iter().find(|p| p.name == name)?;
        let text = match &param.source {
            ParamSource::Inline => param.text.as_str(),
            ParamSource::Config(Ok((text, _))) => text.as_str(),
            ParamSource::Config(Err(_)) | ParamSource::Cmdline => return None,
        };
        Some(ParamText {
            id,
            module_type: mt,
            param,
            text,
        })
    })
}
