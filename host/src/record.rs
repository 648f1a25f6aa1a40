//! Recording in `ferroc run`: what it tells the recording modules of `ferroc_std`
//! before the application is built (the log folder of `--log-dir`, the part of every
//! module for channel metadata), and the recorders `--record` adds.

use ferroc_compiler::ir::Application;
use ferroc_compiler::library::PortDir;
use ferroc_compiler::plan::{Plan, PlannedConnection, PlannedModule, PlannedPortGroup};
use ferroc_compiler::schedule::StepKind;
use ferroc_compiler::values::Value as ModelValue;
use ferroc_runtime::builder::Registry;
use std::path::{Path, PathBuf};

/// Sets the log folder, whether files that are not recordings may be replaced
/// (`--force`), the parts of the plan's modules and the units of their ports.
pub fn configure(app: &Application, plan: &Plan, log_dir: Option<PathBuf>, force: bool) {
    ferroc_std::recording::set_log_dir(log_dir);
    ferroc_std::recording::set_overwrite(force);
    ferroc_std::recording::set_parts(
        plan.modules
            .iter()
            .filter_map(|m| {
                let part = app.element(m.element).part?;
                Some((m.path.clone(), app.element(part).name.clone()))
            })
            .collect(),
    );
    ferroc_std::recording::set_units(&plan.units);
}

/// `--record FILE`: a `ferroc_std.Recorder` at the end of every thread container,
/// connected to each output of the container's modules that feeds a connection (or
/// those matching a `--record-filter`); which ones is `ferroc_std::recorder::select`'s
/// choice, as in generated programs. The model is not edited: only the plan this run
/// builds. Outputs whose type has no serde are left out, named on stderr.
pub fn add_recorders(
    plan: &mut Plan,
    registry: &mut Registry,
    file: &Path,
    filters: &[String],
) -> Result<(), String> {
    // A command-line path: relative to the working directory, whatever --log-dir says.
    let file = &std::path::absolute(file).map_err(|e| format!("--record: {e}"))?;
    ferroc_std::check_log_path(file).map_err(|e| format!("--record: {e}"))?;
    ferroc_std::recording::check_overwrite(file).map_err(|e| format!("--record: {e}"))?;
    registry.register::<ferroc_std::Recorder>();
    let mut outputs: Vec<(&str, &str, String, &str)> = Vec::new();
    for c in &plan.connections {
        let Some(thread) =
            (plan.threads.iter()).find(|t| t.steps.iter().any(|(p, _)| *p == c.from.0))
        else {
            continue;
        };
        let ty = output_type(plan, registry, &c.from.0, &c.from.1).unwrap_or_default();
        outputs.push((&c.from.0, &c.from.1, ty, &thread.path));
    }
    let outputs = (outputs.iter()).map(|(m, p, ty, t)| (*m, *p, ty.as_str(), *t));
    let recorders = ferroc_std::recorder::select(registry.values(), outputs, filters)
        .map_err(|e| format!("--record {}: {e}", file.display()))?;
    let Some(template) = plan.modules.first().cloned() else {
        return Ok(());
    };
    for recorder in recorders {
        for p in &recorder.ports {
            plan.connections.push(PlannedConnection {
                from: (p.module.clone(), p.port.clone()),
                to: (recorder.path.clone(), p.topic.clone()),
                select: Vec::new(),
                scale: 1.0,
                offset: 0.0,
                link: None,
                // A recorder runs in a container of its own.
                local: false,
                span: template.span,
            });
        }
        plan.modules.push(PlannedModule {
            path: recorder.path.clone(),
            type_name: ferroc_std::recorder::RECORDER_TYPE.into(),
            rust: "ferroc_std::Recorder".into(),
            params: vec![(
                "file".into(),
                ModelValue::Str(file.to_string_lossy().into_owned()),
            )],
            queues: Vec::new(),
            ports: (recorder.ports.into_iter())
                .map(|p| PlannedPortGroup {
                    name: p.topic,
                    dir: PortDir::In,
                    ty: p.model_type,
                    count: None,
                    unit: None,
                    library: None,
                    rust: None,
                    serde: false,
                })
                .collect(),
            ..template.clone()
        });
        if let Some(t) = plan.threads.iter_mut().find(|t| t.path == recorder.thread) {
            t.steps.push((recorder.path, StepKind::Update));
        }
    }
    Ok(())
}

/// The model type of output `port` of the planned module `module`.
fn output_type(plan: &Plan, registry: &Registry, module: &str, port: &str) -> Option<String> {
    let m = plan.modules.iter().find(|m| m.path == module)?;
    let in_group = |g: &&PlannedPortGroup| match g.count {
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
