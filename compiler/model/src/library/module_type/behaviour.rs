//! The iB2C ports and parameters every behaviour and fusion module type has by its kind.

use super::{ModuleKind, ModuleType, ParamDecl, PortDecl, PortDir, PortRole, PortType};
use ferroc_values::types::{Meta, Type};

/// The iB2C interface every behaviour has (docs/model-language.md §4, `kind`). Instance-sized ports
/// (`inhibition/k`, fusion channels) are added per instance by the resolver.
pub(super) fn add_behaviour_interface(mt: &mut ModuleType) {
    let span = mt.span;
    let meta = |name: &str, dir, m| PortDecl {
        name: name.to_string(),
        dir,
        role: PortRole::Meta,
        ty: PortType::Fixed(Type::Meta(m)),
        unit: None,
        required: false,
        blocking_read: false,
        read_timeout: None,
        merge: false,
        span,
    };
    mt.ports
        .push(meta("stimulation", PortDir::In, Meta::Stimulation));
    mt.ports
        .push(meta("activity", PortDir::Out, Meta::Activity));
    mt.ports
        .push(meta("target_rating", PortDir::Out, Meta::TargetRating));
    for d in &mt.derived_activities {
        mt.ports
            .push(meta(&format!("activity/{d}"), PortDir::Out, Meta::Activity));
    }
    let param = |name: &str, ty: Type, default: &str, choices: &[&str]| ParamDecl {
        name: name.to_string(),
        ty,
        unit: None,
        min: None,
        max: None,
        default: Some(default.to_string()),
        required: false,
        choices: choices.iter().map(|c| c.to_string()).collect(),
        nondeterministic_value: None,
        span,
    };
    let u32t = Type::Int {
        signed: false,
        bits: 32,
    };
    mt.params.push(param(
        "stimulation_mode",
        Type::String,
        "auto",
        &["auto", "enabled", "disabled"],
    ));
    mt.params.push(param("inhibitions", u32t.clone(), "1", &[]));
    if mt.kind == ModuleKind::Fusion {
        mt.params.push(param("channels", u32t, "2", &[]));
        mt.params.push(param(
            "method",
            Type::String,
            "max",
            &["max", "weighted_average", "weighted_sum"],
        ));
    }
}
