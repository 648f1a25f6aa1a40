//! Witness text (`reference/deadlocks.md` §2.8): the ordered cycle, each step with its
//! thread container, part, host, module, what it holds and what it waits for; a
//! lockdep-style "possible scenario" table with one column per thread; the cheapest fix.

use super::{Cycle, CycleKind, EcId, Held, Hop, Model, WaitId, WaitKind};
use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::{Diagnostic, Label, ThreadFlow};
use ferroc_model::ir::{Application, ElementKind};
use ferroc_model::library::LibrarySet;
use std::fmt::Write;

pub struct Ctx<'a> {
    pub app: &'a Application,
    pub libs: &'a LibrarySet,
    pub m: &'a Model,
}

impl Ctx<'_> {
    pub fn thread(&self, ec: EcId) -> String {
        format!("`{}`", self.app.path(self.m.ecs[ec as usize].thread))
    }

    /// `thread container `robot/T1` (part `robot`, host `pc1`)`.
    pub fn where_(&self, ec: EcId) -> String {
        let t = self.m.ecs[ec as usize].thread;
        let mut s = format!("thread container {}", self.thread(ec));
        if let Some(p) = self.app.element(t).part {
            let part = self.app.element(p);
            let _ = write!(s, " (part `{}`", part.name);
            if let ElementKind::Part { host: Some((h, _)) } = &part.kind {
                let _ = write!(s, ", host `{h}`");
            }
            s.push(')');
        }
        if let Some(n) = self.m.ecs[ec as usize].pool {
            let _ = write!(s, " [pool of {n} workers]");
        }
        s
    }

    pub fn held(&self, h: Held) -> String {
        match h {
            Held::Ec(e) => format!("thread container {}", self.thread(e)),
            Held::Lock(l) => format!("lock `{}`", self.m.locks[l as usize].name),
        }
    }

    pub fn queue(&self, q: u32) -> String {
        let q = &self.m.queues[q as usize];
        let name = self
            .app
            .module_ports(self.libs, q.module)
            .find(|(i, _)| *i == q.port)
            .map_or("?".to_string(), |(_, p)| p.name.clone());
        format!("`{}/{name}`", self.app.path(q.module))
    }

    fn activity(&self, w: WaitId) -> String {
        let wait = &self.m.waits[w as usize];
        format!("`{}` {}", self.app.path(wait.root), wait.activity)
    }

    /// What the step does: "sync call `map` → `robot/T1/Map`.get".
    pub fn step(&self, w: WaitId) -> String {
        let wait = &self.m.waits[w as usize];
        let to = |t: Option<f64>| match t {
            Some(s) => format!("timeout {}", seconds(s)),
            None => "no timeout".to_string(),
        };
        let body = match &wait.kind {
            WaitKind::Call {
                client, targets, ..
            } => {
                let servers: Vec<String> = targets
                    .iter()
                    .map(|t| {
                        let name = self
                            .app
                            .module_type(self.libs, t.module)
                            .map_or("?", |mt| mt.services[t.service].name.as_str());
                        format!("`{}`.{name}", self.app.path(t.module))
                    })
                    .collect();
                if servers.is_empty() {
                    format!(
                        "sync call `{client}` (no server connected, {})",
                        to(wait.timeout)
                    )
                } else {
                    format!(
                        "sync call `{client}` → {} ({})",
                        servers.join(", "),
                        to(wait.timeout)
                    )
                }
            }
            WaitKind::Lock { lock } => format!("lock `{}`", self.m.locks[*lock as usize].name),
            WaitKind::Write { queues, .. } => {
                let q: Vec<String> = queues.iter().map(|q| self.queue(*q)).collect();
                format!("write into {} (on-full=\"block\")", q.join(", "))
            }
            WaitKind::Read { queue } => {
                format!(
                    "blocking read of {} ({})",
                    self.queue(*queue),
                    to(wait.timeout)
                )
            }
        };
        let inline = match wait.inline {
            Some((m, s)) => {
                let name = self
                    .app
                    .module_type(self.libs, m)
                    .map_or("?", |mt| mt.services[s].name.as_str());
                format!(" in inline service `{}`.{name}", self.app.path(m))
            }
            None => String::new(),
        };
        format!("step {}{inline}: {body}", wait.step_no)
    }

    /// What the hop out of `w` waits for, naming the next wait-state's thread.
    pub fn waits_for(&self, c: &Cycle, i: usize) -> String {
        let (w, hop) = c.steps[i];
        let k = c.steps.len();
        let next = c.steps[(i + 1) % k].0;
        let nx = &self.m.waits[next as usize];
        let back = if (i + 1) % k == 0 && k > 1 {
            " (step 1 above)".to_string()
        } else if k == 1 {
            " — this same thread".to_string()
        } else {
            format!(" ({} below)", (i + 1) % k + 1)
        };
        let wait = &self.m.waits[w as usize];
        match hop {
            Hop::Call => match &wait.kind {
                WaitKind::Call { .. } if nx.ec == wait.ec => format!(
                    "{} must run the service, but it is this thread, busy in this call",
                    self.thread(nx.ec)
                ),
                _ => format!("{} to run the service; it is blocked in {}{back}", self.thread(nx.ec), self.activity(next)),
            },
            Hop::Pool => match c.pool {
                Some((p, n, d)) => format!(
                    "a free worker of pool {} ({n} workers, up to {d} parked in nested calls: all can be blocked)",
                    self.thread(p)
                ),
                None => "a free pool worker".into(),
            },
            Hop::Response => format!(
                "the response must be processed by {} (response-via=\"caller\"), which is blocked in this call",
                self.thread(wait.ec)
            ),
            Hop::Lock(l) => format!(
                "lock `{}`, held by {} in {}{back}",
                self.m.locks[l as usize].name,
                self.thread(nx.ec),
                self.activity(next)
            ),
            Hop::Full(q) => format!(
                "space in {} (full{}), which only {} drains{back}",
                self.queue(q),
                self.m.queues[q as usize].capacity.map_or(String::new(), |c| format!(", {c}/{c}")),
                self.thread(nx.ec)
            ),
            Hop::Empty(q) => {
                let queue = &self.m.queues[q as usize];
                let writers: Vec<String> = queue
                    .writers
                    .iter()
                    .map(|(m, _, _)| {
                        let cross = self.app.element(*m).part != self.app.element(queue.module).part;
                        format!("`{}`{}", self.app.path(*m), if cross { " (crosses process boundary)" } else { "" })
                    })
                    .collect();
                format!("an item in {} (empty), written only by {}{back}", self.queue(q), writers.join(", "))
            }
        }
    }

    /// The numbered cycle, one block per wait-state.
    pub fn cycle_text(&self, c: &Cycle) -> String {
        let mut s =
            String::from("cycle (read top to bottom; the last step waits for the first):\n");
        for (i, (w, _)) in c.steps.iter().enumerate() {
            let wait = &self.m.waits[*w as usize];
            let _ = writeln!(
                s,
                "  {}. {} is in {}",
                i + 1,
                self.where_(wait.ec),
                self.activity(*w)
            );
            let locks: Vec<String> = wait
                .held_sites
                .iter()
                .filter(|(h, _)| matches!(h, Held::Lock(_)))
                .map(|(h, _)| self.held(*h))
                .collect();
            if !locks.is_empty() {
                let _ = writeln!(s, "       holds: {}", locks.join(", "));
            }
            let _ = writeln!(s, "       {}", self.step(*w));
            let _ = writeln!(s, "       waits for: {}", self.waits_for(c, i));
        }
        s
    }

    /// One column per thread: what each does, in the order that deadlocks.
    pub fn scenario(&self, c: &Cycle) -> String {
        let cols: Vec<String> = c
            .steps
            .iter()
            .map(|(w, _)| {
                let wait = &self.m.waits[*w as usize];
                let name = self
                    .app
                    .element(self.m.ecs[wait.ec as usize].thread)
                    .name
                    .clone();
                if c.steps.len() > 1
                    && c.steps
                        .iter()
                        .filter(|(x, _)| self.m.waits[*x as usize].ec == wait.ec)
                        .count()
                        > 1
                {
                    format!("{name} #{}", wait.step_no)
                } else {
                    name
                }
            })
            .collect();
        let width = cols.iter().map(|c| c.len()).max().unwrap_or(8).max(26) + 2;
        let mut s = String::from("possible scenario:\n");
        let row = |col: usize, text: &str| format!("  {}{}\n", " ".repeat(col * width), text);
        s += &format!(
            "  {}\n",
            cols.iter()
                .map(|c| format!("{c:<width$}"))
                .collect::<String>()
                .trim_end()
        );
        s += &format!(
            "  {}\n",
            cols.iter()
                .map(|c| format!("{:<width$}", "-".repeat(c.len())))
                .collect::<String>()
                .trim_end()
        );
        // First every thread takes what it holds, then every thread blocks.
        for (col, (w, _)) in c.steps.iter().enumerate() {
            for (h, _) in &self.m.waits[*w as usize].held_sites {
                if let Held::Lock(l) = h {
                    s += &row(col, &format!("lock({})", self.m.locks[*l as usize].name));
                }
            }
        }
        for (col, (w, _)) in c.steps.iter().enumerate() {
            let short = match &self.m.waits[*w as usize].kind {
                WaitKind::Call { client, .. } => format!("call {client}"),
                WaitKind::Lock { lock } => format!("lock({})", self.m.locks[*lock as usize].name),
                WaitKind::Write { .. } => "write (queue full)".to_string(),
                WaitKind::Read { .. } => "read (queue empty)".to_string(),
            };
            s += &row(col, &format!("{short}  *** blocked ***"));
        }
        s
    }

    /// The cheapest fix for a cycle.
    pub fn fix(&self, c: &Cycle) -> String {
        let first = &self.m.waits[c.steps[0].0 as usize];
        match c.kind {
            CycleKind::Call if c.steps.len() == 1 => format!(
                "move the server module to another thread container, declare the service executes=\"caller\", call it asynchronously, or add a timeout to client `{}` (then every call times out instead of hanging)",
                client_name(first)
            ),
            CycleKind::Call => "break the call cycle: make one of these calls asynchronous (mode=\"async\"), or give it a timeout (it then fails instead of hanging)".into(),
            CycleKind::Response => "give the client its own response context: run the caller in a thread container with pool=\"2\" or more (a reentrant group), or call asynchronously".into(),
            CycleKind::Lock => "take the locks in the same order everywhere (or together), or add a timeout to one of the lock steps".into(),
            CycleKind::Mixed => "release the lock before the blocking step (call or write), or give that step a timeout, or make the queue drop (on-full=\"drop-oldest\")".into(),
            CycleKind::QueueEmpty => "add initial=\"1\" (an initial item) to one <connect> of the ring, or let one member write before it waits".into(),
            CycleKind::QueueFull => "make one hop drop instead of block (on-full=\"drop-oldest\"), give a write a timeout, or make the over-producing member write once per item it reads".into(),
            CycleKind::Pool => "give the pool more workers than the calls that can park in it, or make the nested call asynchronous or inline (executes=\"caller\")".into(),
            CycleKind::SelfQueue => "run the writer before the reader (or in another thread container), or add initial=\"1\" to the <connect>".into(),
        }
    }

    /// A complete diagnostic for a cycle: primary label on the first step's model site,
    /// secondary labels on every step (model site and manifest step).
    pub fn diagnostic(&self, check: &'static CheckInfo, c: &Cycle, headline: String) -> Diagnostic {
        let first = &self.m.waits[c.steps[0].0 as usize];
        let mut d = Diagnostic::new(check, first.site, headline).label(format!(
            "{} blocks here: {}",
            self.thread(first.ec),
            self.step(c.steps[0].0)
        ));
        for (i, (w, _)) in c.steps.iter().enumerate() {
            let wait = &self.m.waits[*w as usize];
            if i > 0 && wait.site != first.site {
                d = d.secondary(
                    wait.site,
                    format!("{}. {} blocks here", i + 1, self.thread(wait.ec)),
                );
            }
            d = d.secondary(wait.step_span, format!("{}. {}", i + 1, self.step(*w)));
            for (h, at) in &wait.held_sites {
                if matches!(h, Held::Lock(_)) && *at != wait.site {
                    d = d.secondary(*at, format!("{}. {} is taken here", i + 1, self.held(*h)));
                }
            }
        }
        let certainty = if c.unverified {
            "certainty: not established (the search budget ran out; this is the shortest cycle, whose consistency was not checked)"
        } else if c.certain {
            "certainty: certain (one request chain closes the cycle: it happens every time)"
        } else {
            "certainty: race (happens when the threads block at overlapping times)"
        };
        d.help(format!(
            "{}{}{certainty}\nfix: {}",
            self.cycle_text(c),
            self.scenario(c),
            self.fix(c)
        ))
        .witness(self.thread_flows(c))
    }

    /// The witness as one flow per thread container, in order of first appearance on the
    /// cycle: for each of its steps, where it took each lock it holds, then where it blocks.
    pub fn thread_flows(&self, c: &Cycle) -> Vec<ThreadFlow> {
        let mut flows: Vec<(EcId, ThreadFlow)> = Vec::new();
        for (i, (w, _)) in c.steps.iter().enumerate() {
            let wait = &self.m.waits[*w as usize];
            let k = match flows.iter().position(|(ec, _)| *ec == wait.ec) {
                Some(k) => k,
                None => {
                    flows.push((
                        wait.ec,
                        ThreadFlow {
                            thread: self.app.path(self.m.ecs[wait.ec as usize].thread),
                            message: self.where_(wait.ec),
                            locations: Vec::new(),
                        },
                    ));
                    flows.len() - 1
                }
            };
            let locations = &mut flows[k].1.locations;
            for (h, at) in &wait.held_sites {
                if matches!(h, Held::Lock(_)) {
                    locations.push(Label {
                        span: *at,
                        message: format!("{}. takes {} (holds it from here)", i + 1, self.held(*h)),
                    });
                }
            }
            locations.push(Label {
                span: wait.site,
                message: format!(
                    "{}. in {}: {}; blocks waiting for {}",
                    i + 1,
                    self.activity(*w),
                    self.step(*w),
                    self.waits_for(c, i)
                ),
            });
        }
        flows.into_iter().map(|(_, f)| f).collect()
    }

    /// `T1 → T2 → T1` for headlines.
    pub fn ring(&self, c: &Cycle) -> String {
        let mut names: Vec<String> = c
            .steps
            .iter()
            .map(|(w, _)| self.thread(self.m.waits[*w as usize].ec))
            .collect();
        names.push(names[0].clone());
        names.join(" → ")
    }
}

fn client_name(w: &super::Wait) -> &str {
    match &w.kind {
        WaitKind::Call { client, .. } => client,
        _ => "?",
    }
}

pub fn seconds(s: f64) -> String {
    if s >= 1.0 {
        format!("{s} s")
    } else if s >= 1e-3 {
        format!("{} ms", (s * 1e6).round() / 1e3)
    } else {
        format!("{} us", (s * 1e9).round() / 1e3)
    }
}
