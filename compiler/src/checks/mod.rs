//! The registry of checks.
//!
//! Every check is one file under an area folder holding its code, name, severity,
//! explanation and — for checks that are passes over the IR — its logic. Next to the file,
//! a folder of the same name holds its fixtures: `fires*.xml` (models where it must fire,
//! each with an `<!-- expect: CODE at LINE:COL -->` comment, or `at FILE:LINE:COL` for a
//! finding in another file of the fixture folder) and `silent*.xml` (look-alikes
//! where it must stay silent). Adding a check means adding one file, one fixture folder
//! and one line in [`REGISTRY`].
//!
//! Checks found while reading files (malformed XML, unknown elements, …) are raised by the
//! loader and the resolver, which cite the check's [`CheckInfo`]; their files hold the
//! documentation and fixtures only.

use crate::diagnostic::{Diagnostics, Severity};
use crate::ir::{Application, Connection, PortView};
use crate::library::LibrarySet;
use crate::source::SourceMap;

pub mod behaviour;
pub mod connections;
pub mod deadlocks;
pub mod deployment;
pub mod finroc;
pub mod libraries;
pub mod model;
pub mod parameters;
pub mod scheduling;

/// What a pass over the IR sees. Passes never mutate the IR.
pub struct PassContext<'a> {
    pub app: &'a Application,
    pub libraries: &'a LibrarySet,
    pub sources: &'a SourceMap,
    /// Both ends of each connection (by index), looked up once for all passes: a dozen
    /// passes look at every connection, and resolving a port is not free.
    ends: Vec<Option<(PortView<'a>, PortView<'a>)>>,
    /// The deadlock analysis model, built on first use: the D checks, S103 (timeouts)
    /// and S107 (hard waits) all read it, and building it walks every module that can
    /// wait, which is a noticeable share of checking a large model.
    deadlock: std::cell::OnceCell<crate::deadlock::Model>,
}

impl<'a> PassContext<'a> {
    pub fn new(app: &'a Application, libraries: &'a LibrarySet, sources: &'a SourceMap) -> Self {
        let ends = app
            .connections
            .iter()
            .map(|c| connections::ends(app, libraries, c))
            .collect();
        PassContext {
            app,
            libraries,
            sources,
            ends,
            deadlock: std::cell::OnceCell::new(),
        }
    }

    /// Contexts, locks, queues and wait-states ([`crate::deadlock::model`]), built once.
    pub fn deadlock_model(&self) -> &crate::deadlock::Model {
        self.deadlock
            .get_or_init(|| crate::deadlock::model(self.app, self.libraries))
    }

    /// The connections whose two ends resolve, with those ends.
    pub fn connections_with_ends(
        &self,
    ) -> impl Iterator<Item = (&'a Connection, &PortView<'a>, &PortView<'a>)> + '_ {
        self.app
            .connections
            .iter()
            .zip(&self.ends)
            .filter_map(|(c, e)| e.as_ref().map(|(from, to)| (c, from, to)))
    }
}

pub type Pass = fn(&PassContext<'_>, &mut Diagnostics);

/// The stable identity and documentation of a check.
#[derive(Debug)]
pub struct CheckInfo {
    /// Area letter and three digits: `T102`.
    pub code: &'static str,
    /// Kebab-case name: `incompatible-types`.
    pub name: &'static str,
    pub severity: Severity,
    /// One line, used as SARIF `shortDescription` and in `explain --list`.
    pub summary: &'static str,
    /// What the rule protects, a minimal bad model, the fix (`ferroc explain CODE`).
    pub explanation: &'static str,
    /// The logic, for checks that are passes over the resolved application.
    pub pass: Option<Pass>,
    /// Where the fixtures live, relative to `compiler/src/checks`.
    pub fixtures: &'static str,
}

macro_rules! registry {
    ($($area:ident :: $check:ident),* $(,)?) => {
        /// Every check, in code order.
        pub static REGISTRY: &[&CheckInfo] = &[$(&$area::$check::CHECK),*];
    };
}

registry![
    model::m101_malformed_xml,
    model::m102_unknown_element,
    model::m103_unknown_attribute,
    model::m104_missing_attribute,
    model::m105_misplaced_element,
    model::m106_duplicate_attribute,
    model::m107_invalid_name,
    model::m108_invalid_attribute_value,
    model::m109_duplicate_name,
    model::m110_unresolved_path,
    model::m111_unknown_type,
    model::m112_module_not_executed,
    model::m113_include_outside_root,
    model::m114_include_cycle,
    model::m115_file_not_found,
    model::m116_limit_exceeded,
    model::m117_recursive_group_type,
    model::m118_unknown_code_in_allow,
    model::m119_wrong_root_element,
    connections::t101_wrong_direction,
    connections::t102_incompatible_types,
    connections::t103_unit_dimension_mismatch,
    connections::t104_implicit_unit_scale,
    connections::t105_unit_on_one_end,
    connections::t106_narrowing_without_convert,
    connections::t107_duplicate_connection,
    connections::t108_multiple_writers,
    connections::t109_required_input_unconnected,
    connections::t110_unused_output,
    connections::t111_not_serialisable_across_parts,
    connections::t112_double_scaling,
    connections::t113_invalid_convert,
    parameters::p101_unknown_parameter,
    parameters::p102_missing_required_parameter,
    parameters::p103_unparsable_value,
    parameters::p104_out_of_range,
    parameters::p105_wrong_unit_dimension,
    parameters::p106_config_entry_missing,
    parameters::p107_duplicate_parameter,
    parameters::p108_invalid_pin_map,
    parameters::p109_const_value_type,
    behaviour::b101_meta_constant_out_of_range,
    behaviour::b102_meta_input_from_number,
    behaviour::b103_never_stimulated,
    behaviour::b104_stimulation_ignored,
    behaviour::b105_inhibition_sources,
    behaviour::b106_self_inhibition,
    behaviour::b107_stimulation_loop,
    behaviour::b108_incomplete_fusion_channel,
    behaviour::b109_mixed_fusion_channel,
    behaviour::b110_characteristic_behaviours,
    libraries::l101_unknown_library,
    libraries::l102_invalid_manifest,
    libraries::l103_dependency_cycle,
    libraries::l104_library_not_used,
    libraries::l105_conflicting_library,
    libraries::l106_make_cycle,
    libraries::l107_duplicate_make_lib,
    deadlocks::d101_call_cycle,
    deadlocks::d102_response_context,
    deadlocks::d103_lock_order_inversion,
    deadlocks::d104_recursive_lock,
    deadlocks::d105_mixed_wait_cycle,
    deadlocks::d106_empty_queue_ring,
    deadlocks::d107_full_queue_ring,
    deadlocks::d108_pool_exhaustion,
    deadlocks::d109_wait_never_served,
    deadlocks::d110_same_thread_queue_read,
    deadlocks::d111_unconnected_call,
    deadlocks::d112_deadlock_unverified,
    deadlocks::d113_call_always_times_out,
    deadlocks::d114_timeout_race,
    deadlocks::d115_trigger_cycle_never_runs,
    deadlocks::d116_lock_level_violation,
    deadlocks::d117_latent_lock_inversion,
    scheduling::s101_data_flow_loop,
    scheduling::s102_period_overrun,
    scheduling::s103_high_utilisation,
    scheduling::s104_host_overload,
    scheduling::s105_flow_latency,
    scheduling::s106_flow_not_connected,
    scheduling::s107_priority_inversion,
    deployment::x101_part_without_threads,
    deployment::x102_invalid_host_label,
    deployment::x103_host_label_conflict,
    deployment::x104_pointless_connection_settings,
    deployment::x105_bundle_output_collision,
    finroc::f101_finroc_structure,
    finroc::f102_edge_end_missing,
    finroc::f103_duplicate_edge,
    finroc::f104_sensor_controller_mix,
    finroc::f105_group_output_unwritten,
    finroc::f106_config_value_unparsable,
    finroc::f107_lookup_keys_not_monotonic,
    finroc::f108_config_link_missing,
    finroc::f109_dependency_missing,
    finroc::f110_unknown_component_type,
    finroc::f111_edge_type_mismatch,
    finroc::f112_library_not_built,
    finroc::f113_parameter_link_target_missing,
];

/// Looks a check up by code (`t102` works too) or by name.
pub fn find(code_or_name: &str) -> Option<&'static CheckInfo> {
    REGISTRY
        .iter()
        .copied()
        .find(|c| c.code.eq_ignore_ascii_case(code_or_name) || c.name == code_or_name)
}

/// Runs every IR pass.
pub fn run_passes(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for check in REGISTRY {
        if let Some(pass) = check.pass {
            pass(ctx, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_are_unique_sorted_and_well_formed() {
        let mut seen = std::collections::HashSet::new();
        for c in REGISTRY {
            assert!(seen.insert(c.code), "duplicate code {}", c.code);
            assert!(seen.insert(c.name), "duplicate name {}", c.name);
            let mut chars = c.code.chars();
            assert!("MTPLBDSXF".contains(chars.next().unwrap()), "{}", c.code);
            assert!(
                c.code.len() == 4 && chars.all(|d| d.is_ascii_digit()),
                "{}",
                c.code
            );
            assert!(
                c.explanation.len() > 150,
                "{} explanation too short",
                c.code
            );
            assert!(
                c.explanation.contains("<"),
                "{} explanation shows no model",
                c.code
            );
        }
        assert!(REGISTRY
            .windows(2)
            .all(|w| w[0].code < w[1].code || w[0].code.as_bytes()[0] != w[1].code.as_bytes()[0]));
    }
}
