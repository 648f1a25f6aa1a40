//! What changes when a running application's plan becomes an edited model's plan:
//! modules to create and to drop, modules that move to another thread container (they
//! keep running: same instance, new path), parameter values, connections to make and
//! to unmake, and the containers whose step order changes. What the running
//! application cannot take without a restart is named in `unsupported`.

use crate::plan::{Plan, PlannedConnection, PlannedModule};
use std::collections::{BTreeSet, HashMap};

/// The difference between two plans (see the [module docs](self)).
#[derive(Clone, Debug, Default)]
pub struct PlanDiff {
    /// Paths (old) of modules to drop.
    pub removed: Vec<String>,
    /// Indexes into the new plan's modules of the modules to create.
    pub added: Vec<usize>,
    /// Modules that move: old path → new path.
    pub moved: Vec<(String, String)>,
    /// Changed parameters of kept modules: module (new path), name, value.
    pub params: Vec<(String, String, ferroc_values::values::Value)>,
    /// Connections to unmake (old paths).
    pub disconnect: Vec<PlannedConnection>,
    /// Connections to make (new paths).
    pub connect: Vec<PlannedConnection>,
    /// Indexes into the new plan's threads whose step lists change.
    pub threads: Vec<usize>,
    /// Why the running application cannot take this change (restart it with the saved
    /// model instead), one sentence each.
    pub unsupported: Vec<String>,
}

impl PlanDiff {
    /// Whether nothing changes.
    pub fn is_empty(&self) -> bool {
        self.removed.is_empty()
            && self.added.is_empty()
            && self.moved.is_empty()
            && self.params.is_empty()
            && self.disconnect.is_empty()
            && self.connect.is_empty()
            && self.threads.is_empty()
    }
}

/// The key that says two planned connections are the same.
fn key(c: &PlannedConnection, rename: &dyn Fn(&str) -> String) -> String {
    format!(
        "{}/{} -> {}/{} {:?} {} {} {}",
        rename(&c.from.0),
        c.from.1,
        rename(&c.to.0),
        c.to.1,
        c.select,
        c.scale.to_bits(),
        c.offset.to_bits(),
        c.link.is_some()
    )
}

fn same_instance(a: &PlannedModule, b: &PlannedModule) -> bool {
    a.type_name == b.type_name
        && a.ports == b.ports
        && a.queues == b.queues
        && a.ib2c_violations == b.ib2c_violations
}

/// Compares the running plan `old` with `new`; `moved` are the edit's moves.
pub fn diff(old: &Plan, new: &Plan, moved: &[(String, String)]) -> PlanDiff {
    let renames: HashMap<&str, &str> = moved
        .iter()
        .map(|(a, b)| (a.as_str(), b.as_str()))
        .collect();
    let rename = |p: &str| {
        renames
            .get(p)
            .map_or_else(|| p.to_owned(), |n| (*n).to_owned())
    };
    let mut d = PlanDiff::default();
    compare_modules(old, new, &rename, &mut d);
    compare_connections(old, new, &rename, &mut d);
    compare_threads(old, new, &rename, &mut d);
    compare_rest(old, new, &rename, &mut d);
    d
}

/// Modules to drop, to create and to move, and the parameter changes of the kept ones.
fn compare_modules(old: &Plan, new: &Plan, rename: &dyn Fn(&str) -> String, d: &mut PlanDiff) {
    let new_modules: HashMap<&str, (usize, &PlannedModule)> = (new.modules.iter().enumerate())
        .map(|(i, m)| (m.path.as_str(), (i, m)))
        .collect();
    let mut kept = BTreeSet::new();
    for m in &old.modules {
        let path = rename(&m.path);
        match new_modules.get(path.as_str()) {
            Some((_, n)) if same_instance(m, n) => {
                kept.insert(path.clone());
                compare_kept(m, n, path, d);
            }
            _ => {
                d.removed.push(m.path.clone());
                if path != m.path {
                    d.unsupported
                        .push(format!("`{}` changes as it moves", m.path));
                }
            }
        }
    }
    for (i, m) in new.modules.iter().enumerate() {
        if !kept.contains(&m.path) {
            d.added.push(i);
        }
    }
}

/// A module kept across the edit (`path`: its new path): its move and its changed
/// parameter values; a value removed from the model is unsupported.
fn compare_kept(m: &PlannedModule, n: &PlannedModule, path: String, d: &mut PlanDiff) {
    if path != m.path {
        d.moved.push((m.path.clone(), path.clone()));
    }
    for (name, value) in &n.params {
        let before = m.params.iter().find(|(p, _)| p == name).map(|(_, v)| v);
        if before != Some(value) {
            d.params.push((path.clone(), name.clone(), value.clone()));
        }
    }
    if m.params
        .iter()
        .any(|(p, _)| !n.params.iter().any(|(q, _)| q == p))
    {
        d.unsupported.push(format!(
            "`{path}`: a parameter value is removed from the model; the running module keeps the value it has (set the value instead)"
        ));
    }
}

/// Connections to unmake and to make: the changed ones, and the kept ones whose ends
/// come together in one container or leave it.
fn compare_connections(old: &Plan, new: &Plan, rename: &dyn Fn(&str) -> String, d: &mut PlanDiff) {
    let same = |p: &str| p.to_owned();
    let old_keys: HashMap<String, &PlannedConnection> = old
        .connections
        .iter()
        .map(|c| (key(c, rename), c))
        .collect();
    let new_keys: HashMap<String, &PlannedConnection> =
        new.connections.iter().map(|c| (key(c, &same), c)).collect();
    let removed: BTreeSet<&str> = d.removed.iter().map(String::as_str).collect();
    let plain = |c: &PlannedConnection| c.select.is_empty() && c.scale == 1.0 && c.offset == 0.0;
    // A kept connection whose ends come to lie in one container, or leave it, is made
    // again: a connection between two modules of one container may take the ports'
    // same-container path (issue 18), which must not outlive a move.
    let (old_home, new_home) = (homes(old), homes(new));
    let regrouped = |c: &PlannedConnection| {
        let before = (
            old_home.get(c.from.0.as_str()),
            old_home.get(c.to.0.as_str()),
        );
        let after = (
            new_home.get(rename(&c.from.0).as_str()),
            new_home.get(rename(&c.to.0).as_str()),
        );
        (before.0 == before.1) != (after.0 == after.1)
    };
    for c in &old.connections {
        if new_keys.contains_key(&key(c, rename)) && !regrouped(c) {
            continue;
        }
        if c.link.is_some() {
            d.unsupported.push(format!(
                "`{}/{}` → `{}/{}` joins two parts: links between parts cannot change while they run",
                c.from.0, c.from.1, c.to.0, c.to.1
            ));
        } else if !plain(c) && !removed.contains(c.from.0.as_str()) {
            d.unsupported.push(format!(
                "`{}/{}` → `{}/{}` converts its values: a converting connection cannot be unmade while it runs",
                c.from.0, c.from.1, c.to.0, c.to.1
            ));
        }
        d.disconnect.push(c.clone());
    }
    let regrouped_new: BTreeSet<String> = (old.connections.iter())
        .filter(|c| regrouped(c))
        .map(|c| key(c, rename))
        .collect();
    for c in &new.connections {
        let k = key(c, &same);
        if old_keys.contains_key(&k) && !regrouped_new.contains(&k) {
            continue;
        }
        if c.link.is_some() {
            d.unsupported.push(format!(
                "`{}/{}` → `{}/{}` joins two parts: links between parts cannot change while they run",
                c.from.0, c.from.1, c.to.0, c.to.1
            ));
        } else if !plain(c) {
            d.unsupported.push(format!(
                "`{}/{}` → `{}/{}` converts its values (units, fields or elements): such a connection cannot be made while the application runs",
                c.from.0, c.from.1, c.to.0, c.to.1
            ));
        }
        d.connect.push(c.clone());
    }
}

/// The container each module's steps run in.
fn homes(plan: &Plan) -> HashMap<&str, &str> {
    (plan.threads.iter())
        .flat_map(|t| {
            t.steps
                .iter()
                .map(move |(m, _)| (m.as_str(), t.path.as_str()))
        })
        .collect()
}

fn compare_threads(old: &Plan, new: &Plan, rename: &dyn Fn(&str) -> String, d: &mut PlanDiff) {
    let old_threads: HashMap<&str, _> = old.threads.iter().map(|t| (t.path.as_str(), t)).collect();
    for (i, t) in new.threads.iter().enumerate() {
        let Some(o) = old_threads.get(t.path.as_str()) else {
            d.unsupported.push(format!(
                "the thread container `{}` is new: containers cannot be added while the application runs",
                t.path
            ));
            continue;
        };
        if o.period != t.period
            || o.continuous != t.continuous
            || o.wait != t.wait
            || o.priority != t.priority
            || o.cpu != t.cpu
        {
            d.unsupported.push(format!(
                "the thread container `{}` changes its timing or placement: restart to change them",
                t.path
            ));
        }
        let steps: Vec<(String, _)> = o.steps.iter().map(|(p, k)| (rename(p), *k)).collect();
        let replaced = (t.steps.iter()).any(|(p, _)| d.removed.iter().any(|r| rename(r) == *p));
        if steps != t.steps || replaced {
            d.threads.push(i);
        }
    }
    for t in &old.threads {
        if !new.threads.iter().any(|n| n.path == t.path) {
            d.unsupported.push(format!(
                "the thread container `{}` is removed: containers cannot be removed while the application runs",
                t.path
            ));
        }
    }
    // A container that loses its last module changes too.
    for t in &old.threads {
        let lost = t
            .steps
            .iter()
            .any(|(p, _)| d.removed.contains(p) || d.moved.iter().any(|(from, _)| from == p));
        if let Some(i) = new.threads.iter().position(|n| n.path == t.path) {
            if lost && !d.threads.contains(&i) {
                d.threads.push(i);
            }
        }
    }
    d.threads.sort_unstable();
}

fn compare_rest(old: &Plan, new: &Plan, rename: &dyn Fn(&str) -> String, d: &mut PlanDiff) {
    let calls = |p: &Plan, r: &dyn Fn(&str) -> String| -> BTreeSet<String> {
        (p.calls.iter())
            .map(|c| {
                format!(
                    "{}/{} -> {}/{}",
                    r(&c.client.0),
                    c.client.1,
                    r(&c.service.0),
                    c.service.1
                )
            })
            .collect()
    };
    if calls(old, rename) != calls(new, &|p| p.to_owned()) {
        d.unsupported.push(
            "service calls change: calls cannot be rewired while the application runs".into(),
        );
    }
    let params = |p: &Plan, r: &dyn Fn(&str) -> String| -> BTreeSet<String> {
        (p.param_links.iter())
            .map(|c| format!("{}/{} -> {}/{}", r(&c.from.0), c.from.1, r(&c.to.0), c.to.1))
            .collect()
    };
    if params(old, rename) != params(new, &|p| p.to_owned()) {
        d.unsupported.push(
            "connections to parameters change: they cannot be rewired while the application runs"
                .into(),
        );
    }
    let locks = |p: &Plan, r: &dyn Fn(&str) -> String| {
        let binds: BTreeSet<String> = (p.locks.binds.iter())
            .map(|(m, s, res)| format!("{} {s} {res}", r(m)))
            .collect();
        (p.locks.resources.clone(), binds, p.locks.orders.clone())
    };
    if locks(old, rename) != locks(new, &|p| p.to_owned()) {
        d.unsupported.push(
            "lock resources, bindings or orders change: restart the application with the saved model to change them".into(),
        );
    }
}
