//! Recording in `ferroc run`: what it tells the recording modules of `ferroc_std`
//! before the application is built (the log folder of `--log-dir`, the part of every
//! module for channel metadata), and the recorders `--record` adds.

use ferroc_compiler::ir::Application;
use ferroc_compiler::library::PortDir;
use ferroc_compiler::plan::{Plan, PlannedConnection, PlannedModule, PlannedPortGroup};
use ferroc_compiler::schedule::StepKind;
use ferroc_compiler::values::Value as ModelValue;
use ferroc_runtime::builder::Registry;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Sets the log folder and the parts of the plan's modules.
pub fn configure(app: &Application, plan: &Plan, log_dir: Option<PathBuf>) {
    ferroc_std::recording::set_log_dir(log_dir);
    ferroc_std::recording::set_parts(
        plan.modules
            .iter()
            .filter_map(|m| {
                let part = app.element(m.element).part?;
                Some((m.path.clone(), app.element(part).name.clone()))
            })
            .collect(),
    );
}

/// `--record FILE`: a `ferroc_std.Recorder` at the end of every thread container,
/// connected to each output of the container's modules that feeds a connection (or
/// those matching a `--record-filter`). The model is not edited: only the plan this
/// run builds. Outputs whose type has no serde are left out, named on stderr.
pub fn add_recorders(
    plan: &mut Plan,
    registry: &mut Registry,
    file: &Path,
    filters: &[String],
) -> Result<(), String> {
    // A command-line path: relative to the working directory, whatever --log-dir says.
    let file = &std::path::absolute(file).map_err(|e| format!("--record: {e}"))?;
    ferroc_std::check_log_path(file).map_err(|e| format!("--record: {e}"))?;
    registry.register::<ferroc_std::Recorder>();
    let mut recorded = BTreeSet::new();
    let mut skipped = Vec::new();
    let mut recorders: Vec<(usize, Vec<(String, String)>)> = Vec::new();
    for c in &plan.connections {
        let topic = format!("{}/{}", c.from.0, c.from.1);
        if !filters.is_empty() && !filters.iter().any(|f| glob(f, &topic)) {
            continue;
        }
        if !recorded.insert(topic.clone()) {
            continue;
        }
        let Some(thread) = plan
            .threads
            .iter()
            .position(|t| t.steps.iter().any(|(p, _)| *p == c.from.0))
        else {
            continue;
        };
        let Some(ty) = output_type(plan, registry, &c.from.0, &c.from.1) else {
            skipped.push(format!("{topic} (type unknown)"));
            continue;
        };
        if registry.values().get(&ty).and_then(|v| v.wire()).is_none() {
            skipped.push(format!("{topic} ({ty} has no serde)"));
            continue;
        }
        match recorders.iter_mut().find(|(t, _)| *t == thread) {
            Some((_, ports)) => ports.push((topic, ty)),
            None => recorders.push((thread, vec![(topic, ty)])),
        }
    }
    if !skipped.is_empty() {
        eprintln!(
            "note: --record leaves out {} output(s) whose values cannot be encoded: {}",
            skipped.len(),
            skipped.join(", ")
        );
    }
    if recorders.is_empty() {
        return Err(format!(
            "--record {}: no connection between modules{} can be recorded",
            file.display(),
            if filters.is_empty() {
                ""
            } else {
                " matches --record-filter"
            }
        ));
    }
    let Some(template) = plan.modules.first().cloned() else {
        return Ok(());
    };
    for (thread, ports) in recorders {
        let path = format!("ferroc-record/{}", plan.threads[thread].path);
        for (topic, _) in &ports {
            let (module, output) = topic.rsplit_once('/').unwrap_or((topic, ""));
            plan.connections.push(PlannedConnection {
                from: (module.to_owned(), output.to_owned()),
                to: (path.clone(), topic.clone()),
                select: Vec::new(),
                scale: 1.0,
                offset: 0.0,
                link: None,
                span: template.span,
            });
        }
        plan.modules.push(PlannedModule {
            path: path.clone(),
            type_name: "ferroc_std.Recorder".into(),
            rust: "ferroc_std::Recorder".into(),
            params: vec![(
                "file".into(),
                ModelValue::Str(file.to_string_lossy().into_owned()),
            )],
            queues: Vec::new(),
            ports: ports
                .into_iter()
                .map(|(topic, ty)| PlannedPortGroup {
                    name: topic,
                    dir: PortDir::In,
                    ty,
                    count: None,
                    unit: None,
                    library: None,
                    rust: None,
                    serde: false,
                })
                .collect(),
            ..template.clone()
        });
        plan.threads[thread].steps.push((path, StepKind::Update));
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

/// Whether `text` matches `pattern`, where `*` stands for any characters.
pub fn glob(pattern: &str, text: &str) -> bool {
    let mut parts = pattern.split('*');
    let first = parts.next().unwrap_or("");
    let Some(mut rest) = text.strip_prefix(first) else {
        return false;
    };
    let parts: Vec<&str> = parts.collect();
    let Some((last, middle)) = parts.split_last() else {
        return rest.is_empty();
    };
    for part in middle {
        match rest.find(part) {
            Some(at) => rest = &rest[at + part.len()..],
            None => return false,
        }
    }
    rest.len() >= last.len() && rest.ends_with(last)
}

#[cfg(test)]
mod tests {
    use super::glob;

    #[test]
    fn globs_match_whole_topics() {
        assert!(glob("robot/*", "robot/laser/scan"));
        assert!(glob("*scan", "robot/laser/scan"));
        assert!(glob("robot/*/scan", "robot/laser/scan"));
        assert!(glob("robot/laser/scan", "robot/laser/scan"));
        assert!(!glob("robot/laser", "robot/laser/scan"));
        assert!(!glob("*/pose", "robot/laser/scan"));
        assert!(!glob("a*a", "a"), "the two `a`s may not overlap");
    }
}
