//! `--record` in the programs `ferroc bundle` generates: the generated `main.rs` lists
//! the outputs its modules write into connections or publish as ROS 2 topics and the
//! inputs subscribed from ROS 2 topics ([`Recordable`], with the model types the
//! compiler knows) and hands them to [`Recorders`], which adds the same
//! recorders `ferroc run --record` adds to its plan.

use super::select::{select, RecorderPlan, RECORDER_TYPE};
use ferroc_runtime::behaviour::ViolationPolicy;
use ferroc_runtime::builder::{
    BuildError, Builder, Conversion, ModuleSpec, Registry, StepKind, ThreadSpec,
};
use ferroc_runtime::module::{Direction, PortGroup, Value};
use ferroc_runtime::port::ConnectOptions;
use ferroc_runtime::supervise::Args;
use std::path::PathBuf;

/// An output of a generated program's module that feeds a connection or is published
/// as a ROS 2 topic, or an input subscribed from one: what `--record` may record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Recordable {
    /// The module's path and the output port.
    pub module: &'static str,
    pub port: &'static str,
    /// The output's model type (`f64`, `crash_course.Pose2D`).
    pub model_type: &'static str,
    /// The thread container running the module.
    pub thread: &'static str,
    /// An input subscribed from a ROS 2 topic, not an output: its end's number.
    pub subscribed: Option<u32>,
}

impl Recordable {
    /// An output of a module.
    pub const fn new(
        module: &'static str,
        port: &'static str,
        model_type: &'static str,
        thread: &'static str,
    ) -> Self {
        Recordable {
            module,
            port,
            model_type,
            thread,
            subscribed: None,
        }
    }

    /// An input subscribed from the ROS 2 end `id` (its topic's receiving end feeds the
    /// recorder).
    pub const fn subscribed(
        module: &'static str,
        port: &'static str,
        model_type: &'static str,
        thread: &'static str,
        id: u32,
    ) -> Self {
        Recordable {
            subscribed: Some(id),
            ..Recordable::new(module, port, model_type, thread)
        }
    }
}

/// The recorders a generated program adds for `--record` (none without it).
#[derive(Debug, Default)]
pub struct Recorders {
    file: PathBuf,
    plans: Vec<RecorderPlan>,
}

impl Recorders {
    /// The recorders `args` ask for among `outputs`, the recorder type registered in
    /// `registry` when there are any. Tells the recording modules (these and the
    /// model's `Logger`s) that every module of the program is in `part`. An error
    /// (to be reported as a bad argument) for an unusable file or nothing to record.
    pub fn from_args(
        args: &Args,
        registry: &mut Registry,
        part: &str,
        outputs: &[Recordable],
    ) -> Result<Recorders, String> {
        crate::recording::set_parts(vec![(part.to_owned(), part.to_owned())]);
        crate::recording::set_overwrite(args.force);
        let Some(file) = &args.record else {
            return Ok(Recorders::default());
        };
        // A command-line path: relative to the working directory, whatever the log
        // folder is.
        let file = std::path::absolute(file).map_err(|e| format!("--record: {e}"))?;
        crate::check_log_path(&file).map_err(|e| format!("--record: {e}"))?;
        crate::recording::check_overwrite(&file).map_err(|e| format!("--record: {e}"))?;
        let outputs = outputs.iter().map(|o| super::Candidate {
            module: o.module,
            port: o.port,
            model_type: o.model_type,
            thread: o.thread,
            subscribed: o.subscribed,
        });
        let plans = select(registry.values(), outputs, &args.record_filter)
            .map_err(|e| format!("--record {}: {e}", file.display()))?;
        registry.register::<super::Recorder>();
        Ok(Recorders { file, plans })
    }

    /// Adds the recorders and connects them to what they record (after every other
    /// module of the program is added).
    pub fn add_to(&self, builder: &mut Builder<'_>) -> Result<(), BuildError> {
        let params = [(
            "file".to_owned(),
            Value::Text(self.file.to_string_lossy().into_owned()),
        )];
        for plan in &self.plans {
            let ports: Vec<PortGroup<'_>> = (plan.ports.iter())
                .map(|p| PortGroup::new(&p.topic, Direction::In, &p.model_type, None))
                .collect();
            builder.add_module(ModuleSpec {
                path: &plan.path,
                type_name: RECORDER_TYPE,
                params: &params,
                queues: &[],
                ports: &ports,
                violations: ViolationPolicy::Warn,
            })?;
            for p in &plan.ports {
                builder.connect(
                    (&p.module, &p.port),
                    (&plan.path, &p.topic),
                    Conversion::default(),
                    ConnectOptions::default(),
                )?;
            }
        }
        Ok(())
    }

    /// `spec` with the recorder of its container as its last step, if it has one.
    pub fn thread(&self, mut spec: ThreadSpec) -> ThreadSpec {
        for plan in self.plans.iter().filter(|p| p.thread == spec.path) {
            spec.steps.push((plan.path.clone(), StepKind::Update));
        }
        spec
    }
}
