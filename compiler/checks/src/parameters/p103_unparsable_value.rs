//! P103 `unparsable-value`: A parameter value does not parse as its declared type.
//!
//! The pass; the check's code, name and explanation are in `ferroc_model::checks`,
//! since the resolver raises it too.

use crate::PassContext;
use ferroc_diagnostics::diagnostic::Diagnostics;
pub use ferroc_model::checks::p103_unparsable_value::CHECK;
use ferroc_model::ir::ParamSource;
use ferroc_model::library::module_type::check_value;

/// Parses every parameter value; raises P103, and P104/P105 for values that parse but
/// lie out of range or carry a unit of another dimension (one parse, three verdicts).
pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, m) in ctx.app.modules() {
        let Some(mt) = ctx.app.module_type(ctx.libraries, id) else {
            continue;
        };
        for p in &m.params {
            let Some(decl) = mt.param(&p.name) else {
                continue;
            };
            let text = match &p.source {
                ParamSource::Inline => p.text.as_str(),
                ParamSource::Config(Ok((text, _))) => text.as_str(),
                ParamSource::Config(Err(_)) | ParamSource::Cmdline => continue,
            };
            check_value(decl, text, p.span, Some(decl.span), out);
        }
    }
}
