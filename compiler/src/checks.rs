//! Every check's metadata ([`REGISTRY`]) and the passes ([`ferroc_checks`]), under the
//! paths they had when the compiler was one crate.
//!
//! A check's [`CheckInfo`] lives in the crate that raises it (`ferroc_syntax::checks`,
//! `ferroc_model::checks`, `ferroc_checks`, `ferroc_finroc::checks`, and M118 here, raised
//! by [`crate::check_model`]); this registry is what `ferroc explain`, the report
//! formats and the fixture tests read.

pub use ferroc_checks::*;

pub mod m118_unknown_code_in_allow;

/// Every check, in code order.
pub static REGISTRY: &[&CheckInfo] = &[
    &ferroc_checks::model::m101_malformed_xml::CHECK,
    &ferroc_checks::model::m102_unknown_element::CHECK,
    &ferroc_checks::model::m103_unknown_attribute::CHECK,
    &ferroc_checks::model::m104_missing_attribute::CHECK,
    &ferroc_checks::model::m105_misplaced_element::CHECK,
    &ferroc_checks::model::m106_duplicate_attribute::CHECK,
    &ferroc_checks::model::m107_invalid_name::CHECK,
    &ferroc_checks::model::m108_invalid_attribute_value::CHECK,
    &ferroc_checks::model::m109_duplicate_name::CHECK,
    &ferroc_checks::model::m110_unresolved_path::CHECK,
    &ferroc_checks::model::m111_unknown_type::CHECK,
    &ferroc_checks::model::m112_module_not_executed::CHECK,
    &ferroc_checks::model::m113_include_outside_root::CHECK,
    &ferroc_checks::model::m114_include_cycle::CHECK,
    &ferroc_checks::model::m115_file_not_found::CHECK,
    &ferroc_checks::model::m116_limit_exceeded::CHECK,
    &ferroc_checks::model::m117_recursive_group_type::CHECK,
    &m118_unknown_code_in_allow::CHECK,
    &ferroc_checks::model::m119_wrong_root_element::CHECK,
    &ferroc_checks::connections::t101_wrong_direction::CHECK,
    &ferroc_checks::connections::t102_incompatible_types::CHECK,
    &ferroc_checks::connections::t103_unit_dimension_mismatch::CHECK,
    &ferroc_checks::connections::t104_implicit_unit_scale::CHECK,
    &ferroc_checks::connections::t105_unit_on_one_end::CHECK,
    &ferroc_checks::connections::t106_narrowing_without_convert::CHECK,
    &ferroc_checks::connections::t107_duplicate_connection::CHECK,
    &ferroc_checks::connections::t108_multiple_writers::CHECK,
    &ferroc_checks::connections::t109_required_input_unconnected::CHECK,
    &ferroc_checks::connections::t110_unused_output::CHECK,
    &ferroc_checks::connections::t111_not_serialisable_across_parts::CHECK,
    &ferroc_checks::connections::t112_double_scaling::CHECK,
    &ferroc_checks::connections::t113_invalid_convert::CHECK,
    &ferroc_checks::connections::t114_queue_memory_unbounded::CHECK,
    &ferroc_checks::parameters::p101_unknown_parameter::CHECK,
    &ferroc_checks::parameters::p102_missing_required_parameter::CHECK,
    &ferroc_checks::parameters::p103_unparsable_value::CHECK,
    &ferroc_checks::parameters::p104_out_of_range::CHECK,
    &ferroc_checks::parameters::p105_wrong_unit_dimension::CHECK,
    &ferroc_checks::parameters::p106_config_entry_missing::CHECK,
    &ferroc_checks::parameters::p107_duplicate_parameter::CHECK,
    &ferroc_checks::parameters::p108_invalid_pin_map::CHECK,
    &ferroc_checks::parameters::p109_const_value_type::CHECK,
    &ferroc_checks::parameters::p110_value_without_unit::CHECK,
    &ferroc_checks::ros2::r101_invalid_ros2_end::CHECK,
    &ferroc_checks::ros2::r102_ros2_type_mismatch::CHECK,
    &ferroc_checks::ros2::r103_ros2_unit_convention::CHECK,
    &ferroc_checks::ros2::r104_invalid_ros2_name::CHECK,
    &ferroc_checks::ros2::r105_topic_type_conflict::CHECK,
    &ferroc_checks::ros2::r106_ros2_qos_incompatible::CHECK,
    &ferroc_checks::ros2::r107_ros2_topic_without_publisher::CHECK,
    &ferroc_checks::ros2::r108_ros2_service_mismatch::CHECK,
    &ferroc_checks::ros2::r109_invalid_ros2_interfaces::CHECK,
    &ferroc_checks::behaviour::b101_meta_constant_out_of_range::CHECK,
    &ferroc_checks::behaviour::b102_meta_input_from_number::CHECK,
    &ferroc_checks::behaviour::b103_never_stimulated::CHECK,
    &ferroc_checks::behaviour::b104_stimulation_ignored::CHECK,
    &ferroc_checks::behaviour::b105_inhibition_sources::CHECK,
    &ferroc_checks::behaviour::b106_self_inhibition::CHECK,
    &ferroc_checks::behaviour::b107_stimulation_loop::CHECK,
    &ferroc_checks::behaviour::b108_incomplete_fusion_channel::CHECK,
    &ferroc_checks::behaviour::b109_mixed_fusion_channel::CHECK,
    &ferroc_checks::behaviour::b110_characteristic_behaviours::CHECK,
    &ferroc_model::checks::l101_unknown_library::CHECK,
    &ferroc_model::checks::l102_invalid_manifest::CHECK,
    &ferroc_model::checks::l103_dependency_cycle::CHECK,
    &ferroc_model::checks::l104_library_not_used::CHECK,
    &ferroc_model::checks::l105_conflicting_library::CHECK,
    &ferroc_finroc::checks::l106_make_cycle::CHECK,
    &ferroc_finroc::checks::l107_duplicate_make_lib::CHECK,
    &ferroc_checks::deadlocks::d101_call_cycle::CHECK,
    &ferroc_checks::deadlocks::d102_response_context::CHECK,
    &ferroc_checks::deadlocks::d103_lock_order_inversion::CHECK,
    &ferroc_checks::deadlocks::d104_recursive_lock::CHECK,
    &ferroc_checks::deadlocks::d105_mixed_wait_cycle::CHECK,
    &ferroc_checks::deadlocks::d106_empty_queue_ring::CHECK,
    &ferroc_checks::deadlocks::d107_full_queue_ring::CHECK,
    &ferroc_checks::deadlocks::d108_pool_exhaustion::CHECK,
    &ferroc_checks::deadlocks::d109_wait_never_served::CHECK,
    &ferroc_checks::deadlocks::d110_same_thread_queue_read::CHECK,
    &ferroc_checks::deadlocks::d111_unconnected_call::CHECK,
    &ferroc_checks::deadlocks::d112_deadlock_unverified::CHECK,
    &ferroc_checks::deadlocks::d113_call_always_times_out::CHECK,
    &ferroc_checks::deadlocks::d114_timeout_race::CHECK,
    &ferroc_checks::deadlocks::d115_trigger_cycle_never_runs::CHECK,
    &ferroc_checks::deadlocks::d116_lock_level_violation::CHECK,
    &ferroc_checks::deadlocks::d117_latent_lock_inversion::CHECK,
    &ferroc_checks::scheduling::s101_data_flow_loop::CHECK,
    &ferroc_checks::scheduling::s102_period_overrun::CHECK,
    &ferroc_checks::scheduling::s103_high_utilisation::CHECK,
    &ferroc_checks::scheduling::s104_host_overload::CHECK,
    &ferroc_checks::scheduling::s105_flow_latency::CHECK,
    &ferroc_checks::scheduling::s106_flow_not_connected::CHECK,
    &ferroc_checks::scheduling::s107_priority_inversion::CHECK,
    &ferroc_checks::scheduling::s108_inline_step_may_block::CHECK,
    &ferroc_checks::deployment::x101_part_without_threads::CHECK,
    &ferroc_checks::deployment::x102_invalid_host_label::CHECK,
    &ferroc_checks::deployment::x103_host_label_conflict::CHECK,
    &ferroc_checks::deployment::x104_pointless_connection_settings::CHECK,
    &ferroc_checks::deployment::x105_bundle_output_collision::CHECK,
    &ferroc_checks::deployment::x106_nondeterministic_in_lockstep::CHECK,
    &ferroc_finroc::checks::f101_finroc_structure::CHECK,
    &ferroc_finroc::checks::f102_edge_end_missing::CHECK,
    &ferroc_finroc::checks::f103_duplicate_edge::CHECK,
    &ferroc_finroc::checks::f104_sensor_controller_mix::CHECK,
    &ferroc_finroc::checks::f105_group_output_unwritten::CHECK,
    &ferroc_finroc::checks::f106_config_value_unparsable::CHECK,
    &ferroc_finroc::checks::f107_lookup_keys_not_monotonic::CHECK,
    &ferroc_finroc::checks::f108_config_link_missing::CHECK,
    &ferroc_finroc::checks::f109_dependency_missing::CHECK,
    &ferroc_finroc::checks::f110_unknown_component_type::CHECK,
    &ferroc_finroc::checks::f111_edge_type_mismatch::CHECK,
    &ferroc_finroc::checks::f112_library_not_built::CHECK,
    &ferroc_finroc::checks::f113_parameter_link_target_missing::CHECK,
    &ferroc_finroc::checks::f114_edge_to_itself::CHECK,
];

/// Looks a check up by code (`t102` works too) or by name.
pub fn find(code_or_name: &str) -> Option<&'static CheckInfo> {
    REGISTRY
        .iter()
        .copied()
        .find(|c| c.code.eq_ignore_ascii_case(code_or_name) || c.name == code_or_name)
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
            assert!("MTPLBDSXFR".contains(chars.next().unwrap()), "{}", c.code);
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
