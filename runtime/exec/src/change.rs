//! Changing a running container's steps at a cycle boundary (FINROC's runtime
//! construction): whoever reconfigures the application posts a [`Change`] in the
//! container's [`ChangeSlot`]; the container's own thread takes it between two cycles
//! (a periodic one before it sleeps, so it keeps its period), runs the change's
//! actions (connections made or unmade between its own modules, so their ports are
//! never rewired in the middle of a cycle), rearranges its steps and reports back.
//! Other containers never wait for it. While nothing is posted the check costs the
//! loop one relaxed load per cycle.

use super::Step;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex, OnceLock};
use std::thread::Thread;
use std::time::{Duration, Instant};

/// A change of one container's steps.
#[derive(Default)]
pub struct Change {
    /// The module steps (`path:update`, `path:sense`, …) in their new order; a step
    /// not named is dropped with the steps after it that are not module steps (its
    /// converters), unless its module is exported.
    pub order: Vec<String>,
    /// Steps new to the container (created modules, or exported by another one), each
    /// module step followed by its converters.
    pub steps: Vec<Step>,
    /// Modules whose steps (with their converters) leave for another container.
    pub export: Vec<String>,
    /// Modules that keep their instance but change their path: old → new.
    pub renames: Vec<(String, String)>,
    /// Run on the container's thread before the steps change (connections between
    /// the container's own modules).
    pub actions: Vec<Box<dyn FnOnce() + Send>>,
}

/// Where a change waits for its container (see the [module docs](self)).
#[derive(Default)]
pub struct ChangeSlot {
    pending: AtomicBool,
    state: Mutex<State>,
    applied: Condvar,
    /// The thread a post wakes: the own thread of a container whose cycles run
    /// elsewhere (`wait="inline"`), which sleeps until there is something to do.
    /// Other containers look between their cycles.
    waker: OnceLock<Thread>,
}

#[derive(Default)]
struct State {
    change: Option<Change>,
    /// The exported steps of the change applied last, until fetched.
    exported: Option<Vec<Step>>,
}

impl ChangeSlot {
    /// Posts `change`; it is applied at the container's next cycle boundary. Refused
    /// (given back) while another change waits.
    pub fn post(&self, change: Change) -> Result<(), Change> {
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        if state.change.is_some() {
            return Err(change);
        }
        state.change = Some(change);
        state.exported = None;
        self.pending.store(true, Ordering::Release);
        drop(state);
        if let Some(thread) = self.waker.get() {
            thread.unpark();
        }
        Ok(())
    }

    /// Makes every [`post`](Self::post) from now on unpark `thread` (the first
    /// thread set stays).
    pub(crate) fn wake_on_post(&self, thread: Thread) {
        let _ = self.waker.set(thread);
    }

    /// Waits up to `timeout` until the posted change has been applied; gives the
    /// steps it exported. `None`: not applied in time (it still will be, at the
    /// container's next boundary, unless [`withdraw`](Self::withdraw)n).
    pub fn wait(&self, timeout: Duration) -> Option<Vec<Step>> {
        let deadline = Instant::now() + timeout;
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        loop {
            if let Some(steps) = state.exported.take() {
                return Some(steps);
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return None;
            }
            state = match self.applied.wait_timeout(state, left) {
                Ok((s, _)) => s,
                Err(e) => e.into_inner().0,
            };
        }
    }

    /// Takes back a change not applied yet; `None` if the container has taken it.
    pub fn withdraw(&self) -> Option<Change> {
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        let change = state.change.take();
        self.pending.store(false, Ordering::Release);
        change
    }

    /// Applies a posted change to `steps` (called by the container between cycles).
    pub(crate) fn apply_pending(&self, steps: &mut Vec<Step>) {
        if !self.pending.load(Ordering::Relaxed) {
            return;
        }
        let change = {
            let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
            self.pending.store(false, Ordering::Relaxed);
            state.change.take()
        };
        let Some(change) = change else { return };
        let exported = rearrange(steps, change);
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        state.exported = Some(exported);
        self.applied.notify_all();
    }
}

/// The module path and step kind of a module step's name (`robot/a/x:update`).
fn module_step(name: &str) -> Option<(&str, &str)> {
    name.rsplit_once(':')
        .filter(|(_, kind)| matches!(*kind, "update" | "sense" | "control"))
}

/// Module steps with the steps after them (converters), in order.
fn groups(steps: Vec<Step>) -> Vec<(String, Vec<Step>)> {
    let mut out: Vec<(String, Vec<Step>)> = Vec::new();
    for step in steps {
        match (module_step(&step.name), out.last_mut()) {
            (None, Some((_, group))) => group.push(step),
            _ => out.push((step.name.clone(), vec![step])),
        }
    }
    out
}

/// Applies `change` to `steps`; gives the exported steps.
fn rearrange(steps: &mut Vec<Step>, change: Change) -> Vec<Step> {
    for action in change.actions {
        action();
    }
    let mut exported = Vec::new();
    let mut by_name: HashMap<String, Vec<Step>> = HashMap::new();
    let mut leading = Vec::new();
    for (head, group) in groups(std::mem::take(steps)) {
        match module_step(&head) {
            None => leading.extend(group),
            Some((path, _)) if change.export.iter().any(|e| e == path) => {
                exported.extend(group.into_iter().map(|mut s| {
                    // Its figures belong to this container's statistics.
                    s.stat = None;
                    s
                }))
            }
            Some(_) => {
                by_name.insert(head, group);
            }
        }
    }
    for (head, group) in groups(change.steps) {
        by_name.insert(head, group);
    }
    for (old, new) in &change.renames {
        let names: Vec<String> = by_name.keys().cloned().collect();
        for name in names {
            if let Some((path, kind)) = module_step(&name) {
                if path == old {
                    let mut group = by_name.remove(&name).expect("listed");
                    let renamed = format!("{new}:{kind}");
                    group[0].name = renamed.clone();
                    by_name.insert(renamed, group);
                }
            }
        }
    }
    steps.extend(leading);
    for name in &change.order {
        if let Some(group) = by_name.remove(name) {
            steps.extend(group);
        }
    }
    // What is left is dropped here, on the container's thread: removed modules.
    drop(by_name);
    exported
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicU32;
    use std::sync::Arc;

    fn step(name: &str, log: &Arc<Mutex<Vec<String>>>) -> Step {
        let (log, n) = (Arc::clone(log), name.to_owned());
        Step::new(name, move || log.lock().unwrap().push(n.clone()))
    }

    fn names(steps: &[Step]) -> Vec<&str> {
        steps.iter().map(|s| s.name.as_str()).collect()
    }

    #[test]
    fn steps_are_reordered_added_exported_renamed_and_dropped_with_their_converters() {
        let log = Arc::default();
        let mut steps = vec![
            step("p/a:update", &log),
            step("p/a/out → p/b/in", &log),
            step("p/b:update", &log),
            step("p/c:sense", &log),
            step("p/d:update", &log),
            step("p/c:control", &log),
        ];
        let ran = Arc::new(AtomicU32::new(0));
        let r = Arc::clone(&ran);
        let change = Change {
            order: [
                "p/new:update",
                "p/b2:update",
                "p/a:update",
                "p/c:sense",
                "p/c:control",
            ]
            .map(String::from)
            .into(),
            steps: vec![step("p/new:update", &log)],
            export: vec!["p/d".into()],
            renames: vec![("p/b".into(), "p/b2".into())],
            actions: vec![Box::new(move || {
                r.fetch_add(1, Ordering::Relaxed);
            })],
        };
        let slot = ChangeSlot::default();
        slot.post(change).map_err(|_| ()).unwrap();
        assert!(
            slot.post(Change::default()).is_err(),
            "one change at a time"
        );
        slot.apply_pending(&mut steps);
        assert_eq!(ran.load(Ordering::Relaxed), 1);
        assert_eq!(
            names(&steps),
            [
                "p/new:update",
                "p/b2:update",
                "p/a:update",
                "p/a/out → p/b/in",
                "p/c:sense",
                "p/c:control"
            ]
        );
        let exported = slot.wait(Duration::from_secs(1)).unwrap();
        assert_eq!(names(&exported), ["p/d:update"]);
        // Nothing pending: nothing happens.
        slot.apply_pending(&mut steps);
        assert_eq!(steps.len(), 6);
        assert!(slot.wait(Duration::from_millis(1)).is_none());
    }

    #[test]
    fn a_withdrawn_change_is_not_applied() {
        let log = Arc::default();
        let mut steps = vec![step("p/a:update", &log)];
        let slot = ChangeSlot::default();
        slot.post(Change::default()).map_err(|_| ()).unwrap();
        assert!(slot.withdraw().is_some());
        slot.apply_pending(&mut steps);
        assert_eq!(names(&steps), ["p/a:update"]);
    }
}
