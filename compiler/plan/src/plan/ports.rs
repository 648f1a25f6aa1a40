//! The port groups a flexible module instance declares, as the runtime creates them.

use super::PlannedPortGroup;
use ferroc_model::library::LibrarySet;

/// The flexible port groups behind an instance's extra ports. Resolving expands each
/// `<port name="in" count="3">` into `in/0` … `in/2` (no count: `in`) in model order,
/// so a declaration is a run `g/0, g/1, …` of one type, or a bare `g`.
pub(super) fn port_groups(
    libs: &LibrarySet,
    ty: &ferroc_model::library::ModuleType,
    extra: &[ferroc_model::library::PortDecl],
) -> Vec<PlannedPortGroup> {
    let mut groups: Vec<PlannedPortGroup> = Vec::new();
    for port in extra {
        let ferroc_model::library::module_type::PortType::Fixed(port_ty) = &port.ty else {
            continue;
        };
        let (group, k) = match port.name.split_once('/') {
            Some((g, k)) => match k.parse::<u32>() {
                Ok(k) => (g, Some(k)),
                Err(_) => continue,
            },
            None => (port.name.as_str(), None),
        };
        if !ty.flexible.iter().any(|f| f.port == group) {
            continue; // `inhibition/k`, fusion channels: implied by the kind
        }
        let ty_text = port_ty.to_string();
        if let (Some(k), Some(last)) = (k, groups.last_mut()) {
            if k > 0 && last.name == group && last.ty == ty_text && last.count == Some(k) {
                last.count = Some(k + 1);
                continue;
            }
        }
        let (library, rust, serde) = match port_ty {
            ferroc_values::types::Type::Named(id, _) => {
                let named = libs.named_type(*id);
                (
                    Some(libs.get(named.library).name.clone()),
                    Some(named.rust.clone()),
                    named.serde,
                )
            }
            _ => (None, None, false),
        };
        groups.push(PlannedPortGroup {
            name: group.to_string(),
            dir: port.dir,
            ty: ty_text,
            count: k.map(|_| 1),
            unit: port.unit.as_ref().map(|u| u.text.clone()),
            library,
            rust,
            serde,
        });
    }
    groups
}
