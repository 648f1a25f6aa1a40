//! Walks step lists into wait-states: locks, blocking reads and writes, calls, with what is held.

use super::{Builder, Root};
use crate::{Held, Target, Wait, WaitKind};
use crate::{StepFinding, StepFindingKind};
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{ElementId, Endpoint, Profile};
use ferroc_model::library::steps::{StepDecl, StepOp};
use ferroc_model::library::ModuleType;
use petgraph::Direction::Outgoing;

/// Inline calls nest at most this deep (deadlocks.md §2.2).
const MAX_INLINE_DEPTH: usize = 16;

/// The running state of one activation.
struct Walk {
    held: Vec<(Held, Span)>,
    /// Output ports written so far in this activation.
    written: Vec<(ElementId, u32)>,
    step_no: u32,
    inline: Vec<(ElementId, usize)>,
}

impl<'a> Builder<'a> {
    pub(super) fn walk_root(&mut self, root: &Root, steps: &[StepDecl]) {
        let mut w = Walk {
            held: Vec::new(),
            written: Vec::new(),
            step_no: 0,
            inline: Vec::new(),
        };
        if self.m.ecs[root.ec as usize].pool.is_none() {
            let t = self.m.ecs[root.ec as usize].thread;
            w.held
                .push((Held::Ec(root.ec), self.app.element(t).name_span));
        }
        self.walk(root, root.module, steps, &mut w);
    }

    /// Records a finding about one step of `root`'s activity, found in `module`.
    fn step_finding(
        &mut self,
        root: &Root,
        module: ElementId,
        step: Span,
        site: Span,
        inline: Option<(ElementId, usize)>,
        kind: StepFindingKind,
    ) {
        self.m.step_findings.push(StepFinding {
            kind,
            module,
            root: root.module,
            ec: root.ec,
            activity: root.activity.clone(),
            step,
            site,
            inline,
        });
    }

    fn walk(&mut self, root: &Root, module: ElementId, steps: &[StepDecl], w: &mut Walk) {
        let Some(mt) = self.app.module_type(self.libs, module) else {
            return;
        };
        for step in steps {
            w.step_no += 1;
            match step.op {
                StepOp::Lock { slot } => self.walk_lock(root, module, mt, step, slot, w),
                StepOp::Unlock { slot } => {
                    let (lock, _) = self.lock_of(module, mt, slot);
                    if let Some(i) = w.held.iter().rposition(|(h, _)| *h == Held::Lock(lock)) {
                        w.held.remove(i);
                    }
                }
                StepOp::Read { port } => self.walk_read(root, module, mt, step, port, w),
                StepOp::Write { port, .. } => {
                    self.walk_write(root, module, step, port as u32, w);
                    w.written.push((module, port as u32));
                }
                StepOp::Call { client, sync: true } | StepOp::Await { client } => {
                    self.walk_call(root, module, mt, step, client, w)
                }
                StepOp::Call { sync: false, .. } => {} // asynchronous: never waits
            }
        }
    }

    /// Taking a lock: a finding when it is held already (and not recursive) or when a
    /// held lock's level does not allow it; else a wait, and the lock is held.
    fn walk_lock(
        &mut self,
        root: &Root,
        module: ElementId,
        mt: &ModuleType,
        step: &StepDecl,
        slot: usize,
        w: &mut Walk,
    ) {
        let (lock, site) = self.lock_of(module, mt, slot);
        if let Some((_, first)) = w.held.iter().find(|(h, _)| *h == Held::Lock(lock)) {
            if !self.m.locks[lock as usize].recursive {
                self.step_finding(
                    root,
                    module,
                    step.span,
                    site,
                    w.inline.last().copied(),
                    StepFindingKind::Recursive {
                        lock,
                        first: *first,
                    },
                );
            }
            return;
        }
        if let Some(level) = self.m.locks[lock as usize].level {
            for (h, at) in &w.held {
                let Held::Lock(m) = *h else { continue };
                if self.m.locks[m as usize].level.is_some_and(|lm| level >= lm) {
                    self.step_finding(
                        root,
                        module,
                        step.span,
                        site,
                        None,
                        StepFindingKind::Level {
                            lock,
                            outer: m,
                            outer_site: *at,
                        },
                    );
                }
            }
        }
        self.push_wait(root, module, step, w, site, WaitKind::Lock { lock });
        w.held.push((Held::Lock(lock), site));
    }

    /// A blocking read of a queue, or of a latest-value input nobody writes, waits.
    fn walk_read(
        &mut self,
        root: &Root,
        module: ElementId,
        mt: &ModuleType,
        step: &StepDecl,
        port: usize,
        w: &Walk,
    ) {
        if !mt.ports[port].blocking_read {
            return;
        }
        let q = self.queue(module, port as u32);
        let queue = &self.m.queues[q as usize];
        if !queue.is_queue && !queue.writers.is_empty() {
            return; // latest value: never waits
        }
        let site = queue.span;
        self.push_wait(root, module, step, w, site, WaitKind::Read { queue: q });
    }

    /// A write by a blocking writer waits on the queues that block when full.
    fn walk_write(&mut self, root: &Root, module: ElementId, step: &StepDecl, port: u32, w: &Walk) {
        if !self.block_writers.contains(&(module, port)) {
            return;
        }
        let out = Endpoint::Port {
            element: module,
            port,
        };
        let mut queues = Vec::new();
        let mut site = None;
        for r in self.follow(out, Outgoing) {
            let Endpoint::Port { element, port } = r.end else {
                continue;
            };
            let Some(c) = r.queued.map(|hop| &self.app.connections[hop]) else {
                continue;
            };
            if c.blocks_when_full() {
                queues.push(self.queue(element, port));
                site.get_or_insert(c.to_span);
            }
        }
        if let Some(site) = site {
            self.push_wait(
                root,
                module,
                step,
                w,
                site,
                WaitKind::Write { port, queues },
            );
        }
    }

    /// A blocking call or an await: inline targets are spliced in (for a call), the
    /// others make one wait; a FINROC client connected to nothing is a finding.
    fn walk_call(
        &mut self,
        root: &Root,
        module: ElementId,
        mt: &ModuleType,
        step: &StepDecl,
        client: usize,
        w: &mut Walk,
    ) {
        let app = self.app;
        let targets = self.targets(module, mt, client);
        let is_call = matches!(step.op, StepOp::Call { .. });
        let mut remote = Vec::new();
        for t in targets {
            if !t.inline {
                remote.push(t);
            } else if is_call {
                self.splice(root, &t, w);
            }
        }
        let c = &mt.clients[client];
        let inline_only = remote.is_empty() && !self.targets(module, mt, client).is_empty();
        if inline_only {
            return;
        }
        if remote.is_empty() && app.profile == Profile::Finroc {
            self.step_finding(
                root,
                module,
                step.span,
                app.element(module).name_span,
                None,
                StepFindingKind::Unconnected {
                    client: c.name.clone(),
                },
            );
            return;
        }
        let site = remote
            .first()
            .map_or(app.element(module).name_span, |t| t.connect);
        let response = if c.response_via_caller && self.m.ecs[root.ec as usize].pool.is_none() {
            Some(root.ec)
        } else {
            None
        };
        let kind = WaitKind::Call {
            client: c.name.clone(),
            targets: remote,
            response,
        };
        self.push_wait(root, module, step, w, site, kind);
    }

    /// An inline service body runs in the caller's activation (held set continues).
    fn splice(&mut self, root: &Root, t: &Target, w: &mut Walk) {
        let key = (t.module, t.service);
        if w.inline.len() >= MAX_INLINE_DEPTH || w.inline.contains(&key) {
            return;
        }
        let Some(mt) = self.app.module_type(self.libs, t.module) else {
            return;
        };
        let body = mt.services[t.service].body.clone();
        w.inline.push(key);
        self.walk(root, t.module, &body, w);
        w.inline.pop();
    }

    fn push_wait(
        &mut self,
        root: &Root,
        module: ElementId,
        step: &StepDecl,
        w: &Walk,
        site: Span,
        kind: WaitKind,
    ) {
        let mut held: Vec<Held> = w.held.iter().map(|(h, _)| *h).collect();
        held.sort();
        self.m.waits.push(Wait {
            ec: root.ec,
            root: root.module,
            module,
            activity: root.activity.clone(),
            service: root.service,
            inline: w.inline.last().copied(),
            step_no: w.step_no,
            step_span: step.span,
            site,
            kind,
            timeout: step.timeout,
            held,
            held_sites: w.held.clone(),
            written_before: w.written.clone(),
        });
    }
}
