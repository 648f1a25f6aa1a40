//! The checks that are passes over the resolved application, and their registry
//! ([`PASSES`]).
//!
//! Every check is one file under an area folder holding its code, name, severity,
//! explanation and logic. Next to the file, a folder of the same name holds its
//! fixtures: `fires*.xml` (models where it must fire, each with an
//! `<!-- expect: CODE at LINE:COL -->` comment, or `at FILE:LINE:COL` for a finding in
//! another file of the fixture folder) and `silent*.xml` (look-alikes where it must stay
//! silent). Adding a pass means adding one file, one fixture folder, one line in
//! [`PASSES`] and one in `ferroc_compiler::checks::REGISTRY` (every check's metadata,
//! for `ferroc explain` and the report formats).
//!
//! Checks found while reading files (malformed XML, unknown elements, …) live where they
//! are raised: `ferroc_syntax::checks`, `ferroc_model::checks`, `ferroc_finroc::checks`.
//! T102 and P103 are raised there too; their metadata lives in `ferroc_model::checks`
//! and their passes here. The area modules re-export those, so `model::m108_…` names
//! every check of area M wherever it lives.

#![forbid(unsafe_code)]

pub use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Diagnostics;
use ferroc_diagnostics::source::SourceMap;
use ferroc_model::ir::{Application, Connection, PortView};
use ferroc_model::library::LibrarySet;

pub mod behaviour;
pub mod connections;
pub mod deadlocks;
pub mod deployment;
pub mod model;
pub mod parameters;
pub mod ros2;
pub mod scheduling;

/// What a pass over the IR sees. Passes never mutate the IR.
pub struct PassContext<'a> {
    pub app: &'a Application,
    pub libraries: &'a LibrarySet,
    pub sources: &'a SourceMap,
    /// The model is judged as run in lockstep (`Options::lockstep`): X106 applies.
    pub lockstep: bool,
    /// Both ends of each connection (by index), looked up once for all passes: a dozen
    /// passes look at every connection, and resolving a port is not free.
    ends: Vec<Option<(PortView<'a>, PortView<'a>)>>,
    /// The deadlock analysis model, built on first use: the D checks, S103 (timeouts)
    /// and S107 (hard waits) all read it, and building it walks every module that can
    /// wait, which is a noticeable share of checking a large model.
    deadlock: std::cell::OnceCell<ferroc_deadlock::Model>,
    /// The shipped ROS 2 packages with the model's own (`<ros2-interfaces>`), parsed
    /// on first use by the checks of area R.
    ros2_team: std::cell::OnceCell<ros2::Team>,
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
            lockstep: false,
            ends,
            deadlock: std::cell::OnceCell::new(),
            ros2_team: std::cell::OnceCell::new(),
        }
    }

    /// Contexts, locks, queues and wait-states ([`ferroc_deadlock::model`]), built once.
    pub fn deadlock_model(&self) -> &ferroc_deadlock::Model {
        self.deadlock
            .get_or_init(|| ferroc_deadlock::model(self.app, self.libraries))
    }

    /// The model's ROS 2 registry and what is wrong in its team packages, built once.
    pub(crate) fn ros2_team(&self) -> &ros2::Team {
        self.ros2_team
            .get_or_init(|| ros2::Team::read(self.app, self.sources))
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

/// A check's logic: a pass over the resolved application, reporting into `out`.
pub type Pass = fn(&PassContext<'_>, &mut Diagnostics);

macro_rules! passes {
    ($($area:ident :: $check:ident),* $(,)?) => {
        /// Every pass with the check it raises (passes may raise others of their area
        /// too), in code order; [`run_passes`] runs them in this order.
        pub static PASSES: &[(&CheckInfo, Pass)] = &[$((&$area::$check::CHECK, $area::$check::run)),*];
    };
}

passes![
    model::m112_module_not_executed,
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
    connections::t114_queue_memory_unbounded,
    parameters::p101_unknown_parameter,
    parameters::p102_missing_required_parameter,
    parameters::p103_unparsable_value,
    parameters::p107_duplicate_parameter,
    parameters::p108_invalid_pin_map,
    parameters::p109_const_value_type,
    parameters::p110_value_without_unit,
    behaviour::b102_meta_input_from_number,
    behaviour::b103_never_stimulated,
    behaviour::b104_stimulation_ignored,
    behaviour::b105_inhibition_sources,
    behaviour::b106_self_inhibition,
    behaviour::b107_stimulation_loop,
    behaviour::b108_incomplete_fusion_channel,
    behaviour::b109_mixed_fusion_channel,
    behaviour::b110_characteristic_behaviours,
    deadlocks::d101_call_cycle,
    scheduling::s101_data_flow_loop,
    scheduling::s102_period_overrun,
    scheduling::s103_high_utilisation,
    scheduling::s104_host_overload,
    scheduling::s105_flow_latency,
    scheduling::s106_flow_not_connected,
    scheduling::s107_priority_inversion,
    scheduling::s108_inline_step_may_block,
    deployment::x101_part_without_threads,
    deployment::x102_invalid_host_label,
    deployment::x103_host_label_conflict,
    deployment::x104_pointless_connection_settings,
    deployment::x105_bundle_output_collision,
    deployment::x106_nondeterministic_in_lockstep,
    ros2::r101_invalid_ros2_end,
    ros2::r102_ros2_type_mismatch,
    ros2::r103_ros2_unit_convention,
    ros2::r104_invalid_ros2_name,
    ros2::r105_topic_type_conflict,
    ros2::r106_ros2_qos_incompatible,
    ros2::r107_ros2_topic_without_publisher,
    ros2::r108_ros2_service_mismatch,
    ros2::r109_invalid_ros2_interfaces,
];

/// Runs every pass.
pub fn run_passes(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (_, pass) in PASSES {
        pass(ctx, out);
    }
}
