//! Checks of area scheduling and timing (S), and what the timing checks share: the load
//! of each thread container from declared budgets (`docs/model-language.md`: `budget`, `<flow>`;
//! `reference/deadlocks.md` §1(f)).

use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{Application, ElementId, ElementKind};
use ferroc_model::library::LibrarySet;

pub mod s101_data_flow_loop;
pub mod s102_period_overrun;
pub mod s103_high_utilisation;
pub mod s104_host_overload;
pub mod s105_flow_latency;
pub mod s106_flow_not_connected;
pub mod s107_priority_inversion;
pub mod s108_inline_step_may_block;

/// Relative slack for comparing sums of decimal durations (10 × 1 ms is not over 10 ms).
pub(crate) const EPS: f64 = 1e-9;

/// One module's budget in a container.
#[derive(Debug, Clone)]
pub struct Budget {
    pub module: ElementId,
    pub seconds: f64,
    /// The instance's `budget` value, or the instance's name when the type declares it.
    pub span: Span,
    pub from_type: bool,
}

/// The declared load of one thread container.
#[derive(Debug, Clone)]
pub struct Load {
    pub thread: ElementId,
    /// `period`, seconds (`None`: data-triggered or invalid).
    pub period: Option<f64>,
    /// Modules the container executes that have a budget, largest first.
    pub budgets: Vec<Budget>,
    /// Modules without a budget (they count as 0).
    pub unbudgeted: usize,
    /// Blocking steps with a timeout: (timeout, the model element that makes it wait).
    pub timeouts: Vec<(f64, Span)>,
}

impl Load {
    pub fn total(&self) -> f64 {
        self.budgets.iter().map(|b| b.seconds).sum()
    }

    pub fn timeout_total(&self) -> f64 {
        self.timeouts.iter().map(|t| t.0).sum()
    }

    /// Σ budgets / period, for periodic containers.
    pub fn utilisation(&self) -> Option<f64> {
        self.period.map(|p| self.total() / p)
    }
}

/// The load of every thread container that declares at least one budget, in element
/// order. Each module's budget covers everything it does in one cycle. The timeouts of
/// blocking steps come from the deadlock model, when one is given.
pub fn loads(
    app: &Application,
    libs: &LibrarySet,
    timeouts: Option<&ferroc_deadlock::Model>,
) -> Vec<Load> {
    let mut index = hashbrown::HashMap::new();
    let mut out: Vec<Load> = Vec::new();
    for (i, e) in app.elements.iter().enumerate() {
        if let ElementKind::Thread { period, pool, .. } = e.kind {
            index.insert(ElementId(i as u32), out.len());
            out.push(Load {
                thread: ElementId(i as u32),
                // A pool is not one exclusive context: its load is not one thread's.
                period: if pool.is_some() { None } else { period },
                budgets: Vec::new(),
                unbudgeted: 0,
                timeouts: Vec::new(),
            });
        }
    }
    for (id, _) in app.modules() {
        let Some(&k) = app.element(id).thread.and_then(|t| index.get(&t)) else {
            continue;
        };
        let own = match &app.element(id).kind {
            ElementKind::Module(m) => m.budget(),
            _ => None,
        };
        match app.budget(libs, id) {
            Some((seconds, _)) => out[k].budgets.push(Budget {
                module: id,
                seconds,
                span: own.map_or(app.element(id).name_span, |o| o.1),
                from_type: own.is_none(),
            }),
            None => out[k].unbudgeted += 1,
        }
    }
    if let Some(m) = timeouts.filter(|_| out.iter().any(|l| !l.budgets.is_empty())) {
        for w in &m.waits {
            let thread = m.ecs[w.ec as usize].thread;
            if let (Some(t), Some(&k)) = (w.timeout, index.get(&thread)) {
                out[k].timeouts.push((t, w.site));
            }
        }
    }
    out.retain(|l| !l.budgets.is_empty());
    for l in &mut out {
        l.budgets.sort_by(|a, b| {
            b.seconds
                .total_cmp(&a.seconds)
                .then(a.module.cmp(&b.module))
        });
    }
    out
}

/// `2.5 ms`, `120 us`, `1.2 s` for messages.
pub fn duration(s: f64) -> String {
    ferroc_deadlock::render::seconds(s)
}

/// `85 %` (whole percent unless that hides the difference from 100 %).
pub fn percent(f: f64) -> String {
    let p = f * 100.0;
    if (p - p.round()).abs() < 1e-6 || p >= 1000.0 {
        format!("{} %", p.round())
    } else {
        format!("{:.1} %", p)
    }
}
