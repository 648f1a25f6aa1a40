//! `ferroc run --inspect`: structural edits of the running application, as model
//! edits. The program keeps its model's text; an edit changes the TEXT
//! (`ferroc_compiler::edit`), the compiler checks the edited model with every check
//! (`check_model_text`, the same library path as the run), and only a model without
//! errors is applied: the difference between the running plan and the new one becomes
//! a runtime [`Reconfiguration`], which switches only the containers it touches, each
//! at its cycle boundary. Refused edits change nothing. The text, with parameter
//! changes written in, is what `ferroc inspect --save` saves.

use ferroc_compiler::diagnostic::Severity;
use ferroc_compiler::edit::{self, diff, Op};
use ferroc_compiler::plan::{self, Plan};
use ferroc_compiler::report::{self, ModelReport};
use ferroc_compiler::{check_model_text, CheckResult, Policy};
use ferroc_inspect::structure::{Refusal, Structure};
use ferroc_runtime::behaviour::ViolationPolicy;
use ferroc_runtime::builder::{Live, ModuleSpec, Reconfiguration};
use ferroc_runtime::inspect::{Inspector, Origin};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// The model of a running application and its live structure.
pub struct Editor {
    state: Mutex<State>,
    inspector: Arc<Inspector>,
}

struct State {
    /// The model file: includes and manifests are found from it.
    model: PathBuf,
    text: String,
    lib_path: Vec<PathBuf>,
    cmdline: Vec<(String, String)>,
    plan: Plan,
    live: Live,
    /// Why edits are off for this run (`--record`), if they are.
    off: Option<String>,
}

fn refusal(error: impl Into<String>) -> Refusal {
    Refusal {
        error: error.into(),
        diagnostics: Vec::new(),
    }
}

/// What the editor starts from.
pub struct Running {
    pub model: PathBuf,
    pub text: String,
    pub lib_path: Vec<PathBuf>,
    pub cmdline: Vec<(String, String)>,
    pub plan: Plan,
    pub live: Live,
    pub off: Option<String>,
}

impl Editor {
    /// An editor of the application `running` describes, keeping `inspector`'s view
    /// of it current.
    pub fn new(running: Running, inspector: Arc<Inspector>) -> Self {
        let state = State {
            model: running.model,
            text: running.text,
            lib_path: running.lib_path,
            cmdline: running.cmdline,
            plan: running.plan,
            live: running.live,
            off: running.off,
        };
        Editor {
            state: Mutex::new(state),
            inspector,
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// What the running ROS 2 nodes cannot take: their topics, services and clients are
/// bound to the modules' ports when the run starts, so an edit may neither change
/// `<ros2>` nor drop, replace or move a module one of them names.
fn ros2_unsupported(old: &Plan, new: &Plan, d: &diff::PlanDiff) -> Vec<String> {
    let mut why = Vec::new();
    if old.ros2 != new.ros2 {
        why.push(
            "it changes the model's ROS 2 nodes (`<ros2>`), which are declared when the run starts"
                .to_string(),
        );
    }
    let named = |path: &str| {
        (old.ros2.iter()).find_map(|node| {
            let topics = (node.topics.iter()).map(|t| (&t.port.0, &t.topic));
            let services =
                (node.services.iter().chain(&node.clients)).map(|s| (&s.port.0, &s.name));
            topics
                .chain(services)
                .find(|(module, _)| module.as_str() == path)
                .map(|(_, name)| name.clone())
        })
    };
    let dropped = (d.removed.iter()).chain(d.moved.iter().map(|(from, _)| from));
    for path in dropped {
        if let Some(name) = named(path) {
            why.push(format!(
                "`{path}` is bound to the ROS 2 topic or service `{name}` of the running node"
            ));
        }
    }
    why
}

/// The name diagnostics give the edited text.
fn edited_name(model: &std::path::Path) -> String {
    format!("{} (edited)", model.display())
}

/// The findings of `result` with severity error, rendered (human, no colour) and as
/// JSON; `None` when there are none.
pub fn errors_of(result: &CheckResult) -> Option<Refusal> {
    let errors: Vec<_> = (result.diagnostics.iter())
        .filter(|d| d.severity == Severity::Error)
        .cloned()
        .collect();
    if errors.is_empty() && result.app.is_some() {
        return None;
    }
    let model = ModelReport {
        sources: &result.sources,
        diagnostics: &errors,
    };
    let mut rendered = String::new();
    report::human::render(&model, false, &mut rendered);
    let diagnostics = (errors.iter())
        .map(|d| {
            serde_json::json!({
                "code": d.code(),
                "message": d.message,
                "help": d.help,
                "location": report::json::location(&result.sources, d.primary.span),
            })
        })
        .collect();
    Some(Refusal {
        error: format!(
            "the edited model has {} error(s); nothing changed\n{rendered}",
            errors.len()
        ),
        diagnostics,
    })
}

impl Structure for Editor {
    fn edit(&self, ops: &[u8]) -> Result<serde_json::Value, Refusal> {
        let ops = edit::parse_ops(ops).map_err(refusal)?;
        let mut state = self.lock();
        if let Some(why) = &state.off {
            return Err(refusal(why.clone()));
        }
        let edited =
            edit::apply(&state.text, &ops).map_err(|e| refusal(format!("{e}; nothing changed")))?;
        let options = crate::loader_options(&state.lib_path, false);
        let name = edited_name(&state.model);
        let result = check_model_text(
            &state.model,
            &name,
            &edited.text,
            &options,
            &Policy::default(),
        )
        .map_err(|e| {
            refusal(format!(
                "the edited model cannot be checked: {e}; nothing changed"
            ))
        })?;
        if let Some(r) = errors_of(&result) {
            return Err(r);
        }
        let app = result.app.as_ref().expect("checked above");
        let (new_plan, unsupported) = plan::plan(app, &result.libraries, &state.cmdline);
        if !unsupported.is_empty() {
            let what: Vec<String> = unsupported.iter().map(|u| u.what.clone()).collect();
            return Err(refusal(format!(
                "the edited model cannot run: {}; nothing changed",
                what.join("; ")
            )));
        }
        let mut d = diff::diff(&state.plan, &new_plan, &edited.moved);
        d.unsupported
            .extend(ros2_unsupported(&state.plan, &new_plan, &d));
        if !d.unsupported.is_empty() {
            return Err(refusal(format!(
                "the edited model checks clean, but the running application cannot take this change: {}; nothing changed (save the model and restart it to get there)",
                d.unsupported.join("; ")
            )));
        }
        let applied = apply_diff(&mut state.live, &d, &new_plan).map_err(|e| {
            refusal(format!(
                "the running application refused the change: {e}; nothing changed"
            ))
        })?;
        state.text = edited.text;
        state.plan = new_plan;
        self.inspector.rebuild(state.live.catalogue());
        describe(&self.inspector, &state.plan, &result);
        let warnings: Vec<String> = (result.diagnostics.iter())
            .filter(|d| d.severity != Severity::Error)
            .map(|d| format!("{}: {}", d.code(), d.message))
            .collect();
        Ok(serde_json::json!({
            "applied": true,
            "edit": edited.done,
            "runtime": applied,
            "warnings": warnings,
        }))
    }

    fn model(&self) -> serde_json::Value {
        let state = self.lock();
        // The model's folder as an absolute path: `ferroc inspect --save` (run in
        // another folder, maybe) writes the model's paths again relative to where it
        // saves it.
        let folder = std::fs::canonicalize(&state.model)
            .ok()
            .and_then(|m| m.parent().map(|p| p.display().to_string()));
        serde_json::json!({
            "model": state.model.display().to_string(),
            "folder": folder,
            "text": state.text,
        })
    }

    fn param_changed(&self, module: &str, name: &str, text: &str) {
        let mut state = self.lock();
        let op = Op::Set {
            param: format!("{module}/{name}"),
            value: text.to_owned(),
        };
        match edit::apply(&state.text, &[op]) {
            Ok(edited) => state.text = edited.text,
            Err(e) => ferroc_runtime::console::note(&format!(
                "inspect: the change of `{module}/{name}` is not in the model a save writes: {e}"
            )),
        }
    }
}

/// Records where every module comes from and what feeds each input.
pub fn describe(inspector: &Inspector, plan: &Plan, result: &CheckResult) {
    for m in &plan.modules {
        let origin = Origin {
            part: String::new(),
            source: Some(crate::sources::at(&result.sources, m.span)),
        };
        inspector.set_origin(&m.path, origin);
    }
    for c in &plan.connections {
        inspector.add_connection(
            (c.from.0.as_str(), c.from.1.as_str()),
            (c.to.0.as_str(), c.to.1.as_str()),
        );
    }
}

/// The plan difference as runtime calls.
fn apply_diff(live: &mut Live, d: &diff::PlanDiff, new: &Plan) -> Result<Vec<String>, String> {
    let added: Vec<ferroc_runner::plan::Module> = (d.added.iter())
        .map(|&i| crate::from_plan::module(&new.modules[i], None))
        .collect();
    let parts: Vec<_> = (added.iter())
        .map(|m| {
            (
                ferroc_runner::from_plan::queues_of(m),
                ferroc_runner::from_plan::ports_of(m),
            )
        })
        .collect();
    let add = (added.iter().zip(&parts))
        .map(|(m, (queues, ports))| ModuleSpec {
            path: &m.path,
            type_name: &m.type_name,
            params: &m.params,
            queues,
            ports,
            violations: ViolationPolicy::parse(&m.ib2c_violations).unwrap_or_default(),
        })
        .collect();
    let ends = |c: &plan::PlannedConnection| (c.from.clone(), c.to.clone());
    live.apply(Reconfiguration {
        remove: d.removed.clone(),
        add,
        moves: d.moved.clone(),
        disconnect: d.disconnect.iter().map(ends).collect(),
        connect: d.connect.iter().map(ends).collect(),
        params: (d.params.iter())
            .map(|(m, n, v)| {
                (
                    m.clone(),
                    n.clone(),
                    ferroc_inspect::param_value::runtime_value(v),
                )
            })
            .collect(),
        threads: (d.threads.iter())
            .map(|&i| {
                let t = &new.threads[i];
                let steps = (t.steps.iter())
                    .map(|(p, k)| {
                        let step = crate::from_plan::step(k);
                        (p.clone(), ferroc_runner::from_plan::step_kind(step))
                    })
                    .collect();
                (t.path.clone(), steps)
            })
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plan of the crash course as the ROS 2 node /fragile_bot.
    fn ros2_plan() -> Plan {
        let model = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../models/ros2_crash_course.xml");
        let options = crate::loader_options(&[], false);
        let result = ferroc_compiler::check_model(&model, &options, &Policy::default()).unwrap();
        assert!(errors_of(&result).is_none());
        plan::plan(result.app.as_ref().unwrap(), &result.libraries, &[]).0
    }

    #[test]
    fn an_edit_may_not_unbind_a_ros2_topic_from_its_module() {
        let old = ros2_plan();
        let published = old.ros2[0].topics[0].port.0.clone();
        let dropped = diff::PlanDiff {
            removed: vec![published.clone()],
            ..diff::PlanDiff::default()
        };
        let why = ros2_unsupported(&old, &old, &dropped);
        assert_eq!(why.len(), 1, "{why:?}");
        assert!(
            why[0].contains(&published) && why[0].contains("cmd_vel"),
            "{why:?}"
        );

        let mut new = old.clone();
        new.ros2[0].topics[0].qos.depth += 1;
        let why = ros2_unsupported(&old, &new, &diff::PlanDiff::default());
        assert_eq!(why.len(), 1, "{why:?}");
        assert!(why[0].contains("`<ros2>`"), "{why:?}");
    }

    #[test]
    fn an_edit_of_modules_the_node_does_not_name_is_taken() {
        let old = ros2_plan();
        let named: Vec<&str> = (old.ros2[0].topics.iter())
            .map(|t| t.port.0.as_str())
            .collect();
        let other = (old.modules.iter())
            .map(|m| m.path.clone())
            .find(|p| !named.contains(&p.as_str()))
            .unwrap();
        let d = diff::PlanDiff {
            removed: vec![other.clone()],
            moved: vec![(other.clone(), format!("{other}_moved"))],
            ..diff::PlanDiff::default()
        };
        assert_eq!(
            ros2_unsupported(&old, &old.clone(), &d),
            Vec::<String>::new()
        );
    }
}
