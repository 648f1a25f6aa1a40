//! Recording in a run: what it tells the recording modules of `ferroc_std` before the
//! application is built (the log folder of `--log-dir`, the part of every module for
//! channel metadata), and the recorders `--record` adds.

use crate::plan::{Connection, Module, PortGroup, RunOptions, RunPlan, Step};
use ferroc_runtime::builder::Registry;
use ferroc_runtime::module::{Direction, Value};
use std::path::Path;

/// Sets the log folder, whether files that are not recordings may be replaced
/// (`--force`), the parts of the plan's modules and the units of their ports.
pub fn configure(plan: &RunPlan) {
    ferroc_std::recording::set_log_dir(plan.run.log_dir.clone());
    ferroc_std::recording::set_overwrite(plan.run.force);
    ferroc_std::recording::set_parts(
        (plan.modules.iter())
            .filter_map(|m| Some((m.path.clone(), m.part.clone()?)))
            .collect(),
    );
    ferroc_std::recording::set_units(&plan.units);
}

/// `--record FILE` (none: nothing to do): a `ferroc_std.Recorder` at the end of every
/// thread container, connected to each output of the container's modules that feeds a
/// connection or is published as a ROS 2 topic, and to the receiving end of each input
/// subscribed from a ROS 2 topic (or those matching a `--record-filter`); which ones is
/// `ferroc_std::recorder::select`'s choice, as in generated programs. The model is not
/// edited: only the plan this run builds. Outputs whose type has no serde are left
/// out, named on stderr.
pub fn add_recorders(plan: &mut RunPlan, registry: &mut Registry) -> Result<(), String> {
    let RunOptions {
        record: Some(file),
        record_filter,
        ..
    } = plan.run.clone()
    else {
        return Ok(());
    };
    // A command-line path: relative to the working directory, whatever --log-dir says.
    let file = &std::path::absolute(&file).map_err(|e| format!("--record: {e}"))?;
    ferroc_std::check_log_path(file).map_err(|e| format!("--record: {e}"))?;
    ferroc_std::recording::check_overwrite(file).map_err(|e| format!("--record: {e}"))?;
    registry.register::<ferroc_std::Recorder>();
    let thread_of =
        |module: &str| (plan.threads.iter()).find(|t| t.steps.iter().any(|(p, _)| *p == module));
    let mut outputs: Vec<(&str, &str, String, &str, Option<u32>)> = Vec::new();
    for c in &plan.connections {
        let Some(thread) = thread_of(&c.from.0) else {
            continue;
        };
        let ty = output_type(plan, registry, &c.from.0, &c.from.1).unwrap_or_default();
        outputs.push((&c.from.0, &c.from.1, ty, &thread.path, None));
    }
    // Outputs published as ROS 2 topics, also those that feed no connection, and inputs
    // subscribed from ROS 2 topics (recorded from the topic's receiving end).
    for t in plan.ros2.iter().flat_map(|n| &n.topics) {
        if let Some(thread) = thread_of(&t.port.0) {
            let subscribed = (!t.publish).then_some(t.id);
            let ty = t.model_type.clone();
            outputs.push((&t.port.0, &t.port.1, ty, &thread.path, subscribed));
        }
    }
    let outputs = (outputs.iter()).map(|(m, p, ty, t, s)| ferroc_std::recorder::Candidate {
        module: m,
        port: p,
        model_type: ty,
        thread: t,
        subscribed: *s,
    });
    let recorders = ferroc_std::recorder::select(registry.values(), outputs, &record_filter)
        .map_err(|e| format!("--record {}: {e}", file.display()))?;
    let Some(template) = plan.modules.first().cloned() else {
        return Ok(());
    };
    for recorder in recorders {
        add_recorder(plan, &template, recorder, file);
    }
    Ok(())
}

/// One recorder module, its connections and its step.
fn add_recorder(
    plan: &mut RunPlan,
    template: &Module,
    recorder: ferroc_std::recorder::RecorderPlan,
    file: &Path,
) {
    for p in &recorder.ports {
        plan.connections.push(Connection {
            from: (p.module.clone(), p.port.clone()),
            to: (recorder.path.clone(), p.topic.clone()),
            select: Vec::new(),
            scale: 1.0,
            offset: 0.0,
            link: None,
            // A recorder runs in a container of its own.
            local: false,
        });
    }
    plan.modules.push(Module {
        path: recorder.path.clone(),
        type_name: ferroc_std::recorder::RECORDER_TYPE.into(),
        params: vec![(
            "file".into(),
            Value::Text(file.to_string_lossy().into_owned()),
        )],
        queues: Vec::new(),
        ports: (recorder.ports.into_iter())
            .map(|p| PortGroup {
                name: p.topic,
                dir: Direction::In,
                ty: p.model_type,
                count: None,
            })
            .collect(),
        ..template.clone()
    });
    if let Some(t) = plan.threads.iter_mut().find(|t| t.path == recorder.thread) {
        t.steps.push((recorder.path, Step::Update));
    }
}

/// The model type of output `port` of the planned module `module`.
fn output_type(plan: &RunPlan, registry: &Registry, module: &str, port: &str) -> Option<String> {
    let m = plan.modules.iter().find(|m| m.path == module)?;
    let in_group = |g: &&PortGroup| match g.count {
        Some(n) => (0..n).any(|k| format!("{}/{k}", g.name) == port),
        None => g.name == port,
    };
    if let Some(g) = m.ports.iter().find(in_group) {
        return Some(g.ty.clone());
    }
    let ty = registry
        .interface(&m.type_name)?
        .port(port)?
        .model_type
        .clone();
    match ty.strip_prefix('$') {
        Some(group) => m
            .ports
            .iter()
            .find(|g| g.name == group)
            .map(|g| g.ty.clone()),
        None => Some(ty),
    }
}
