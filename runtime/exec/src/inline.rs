//! `wait="inline"`: a data-triggered container whose cycles run in the thread that
//! delivers its trigger value — a link's network callback, or an in-process writer's
//! container — instead of in a thread of its own woken for each value. A quiet
//! machine's idle CPU takes tens of microseconds to wake a parked thread; a bare Zenoh
//! subscriber works in its callback and pays nothing of it (bench/README.md, b4-large).
//!
//! The container keeps its guarantees: one cycle at a time, its steps in order, its
//! home's local connections touched only by the thread running the cycle (that thread
//! holds the home's session during the cycle, `ferroc_ports`' `port/local.rs`). The
//! [`InlineGate`] decides who runs: a value arriving while a cycle runs is owed one more
//! cycle, which the running thread runs after its own; the delivering thread never
//! waits. So a step must be short and must not block (the delivering thread, maybe the
//! network's, waits for it): the compiler's S108 refuses what the model shows.
//!
//! A thread of the container's own stays, sleeping until there is something to do: a
//! change of the steps posted while no value comes ([`ChangeSlot`](crate::ChangeSlot)
//! wakes it; changes of local connections are served by the session each cycle opens,
//! and at once between cycles), the end of the run, or the cycle limit (it then closes
//! the gate, after which no cycle runs). It is what [`RunningContainer`] joins. It does
//! not wake periodically: a thread wakeup costs tens of microseconds of CPU on a virtual
//! machine, and every 50 ms that was as much as an inline container saves a
//! 50 fps consumer (bench/README.md, b3-parts). In lockstep the driver runs the cycles
//! and the mode changes nothing.

use crate::{ChangeSlot, RunningContainer, ThreadContainer};
use ferroc_ports::port::{Home, InlineGate, Notify, Wakeup};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Duration;

/// How long the container's own thread sleeps when nothing wakes it: a safety net
/// only (a post, the stop and the cycle limit each wake it).
const IDLE_CHECK: Duration = Duration::from_secs(10);

/// When a cycle ran as the own thread came for its chores: it looks again this soon.
const CHORES_RETRY: Duration = Duration::from_millis(50);

/// A cycle longer than this is reported (once per container): it held up the thread
/// that delivered its data. The compiler's S108 holds declared budgets to the same bound.
const SLOW_CYCLE: Duration = Duration::from_millis(1);

/// The warning for a cycle of `name` that took `took`, the first time one is slow.
fn slow_warning(name: &str, took: Duration, reported: &AtomicBool) -> Option<String> {
    if took <= SLOW_CYCLE || reported.swap(true, Ordering::Relaxed) {
        return None;
    }
    Some(format!(
        "warning: `{name}` runs inline (wait=\"inline\") and a cycle of it took {took:.1?}, \
         holding up the thread that delivers its data (a link's network thread) as long; \
         help: make its step shorter, or keep wait=\"park\" for it (reported once)"
    ))
}

/// An inline container while it runs: what a notification of its wakeup calls.
struct Inline {
    gate: InlineGate,
    /// Taken only by the thread the gate lets in (so never contended), and by the
    /// container's own thread once the gate is closed, to end it.
    container: Mutex<Option<ThreadContainer>>,
    stop: Arc<AtomicBool>,
    limit: Option<u64>,
    done: AtomicU64,
    /// A slow cycle was reported.
    slow: AtomicBool,
    /// The container's own thread, woken when the cycle limit is reached.
    owner: OnceLock<std::thread::Thread>,
}

impl Inline {
    fn over(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
            || (self.limit).is_some_and(|l| self.done.load(Ordering::Relaxed) >= l)
    }

    fn container(&self) -> std::sync::MutexGuard<'_, Option<ThreadContainer>> {
        self.container.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// One cycle on the calling thread (the gate lets one thread at a time in). The
    /// caller may be inside a cycle of its own container (an in-process writer): what
    /// that cycle's steps can ask of their thread (`cycle::period`, the stop flag the
    /// port core's waits watch) is put back afterwards.
    fn cycle(&self) {
        if self.over() {
            return;
        }
        let mut guard = self.container();
        let Some(container) = guard.as_mut() else {
            return;
        };
        let outer_period = ferroc_module::cycle::in_cycle().then(ferroc_module::cycle::period);
        let outer_stop = ferroc_ports::stopping::swap(Some(Arc::clone(&self.stop)));
        // `run_cycle` holds the home's session for the cycle; entering serves the
        // changes of local connections queued meanwhile (a cycle boundary).
        container.run_cycle();
        let slow = slow_warning(
            &container.stats.name,
            container.stats.last_cycle(),
            &self.slow,
        );
        container.changes.apply_pending(&mut container.steps);
        ferroc_ports::stopping::swap(outer_stop);
        match outer_period {
            Some(period) => ferroc_module::cycle::set_period(period),
            None => ferroc_module::cycle::leave_cycle(),
        }
        drop(guard);
        if let Some(warning) = slow {
            ferroc_ports::console::line(&warning);
        }
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        if self.limit.is_some_and(|l| done >= l) {
            if let Some(owner) = self.owner.get() {
                owner.unpark();
            }
        }
    }

    /// Between cycles, on the container's own thread: its changes.
    fn chores(&self) {
        let mut guard = self.container();
        if let Some(container) = guard.as_mut() {
            drop(Home::enter(&container.home));
            container.changes.apply_pending(&mut container.steps);
        }
    }
}

impl Notify for Inline {
    fn notify(&self) {
        self.gate.arrive(|| self.cycle());
    }
}

/// Starts `container` (data-triggered on `wakeup`) inline: its wakeup's notifications
/// run its cycles from now on; its own thread sleeps until the run ends.
pub(crate) fn spawn(
    container: ThreadContainer,
    wakeup: Arc<Wakeup>,
    stop: Arc<AtomicBool>,
    limit: Option<u64>,
) -> std::io::Result<RunningContainer> {
    let stats = container.stats();
    let changes = container.changes();
    let inline = Arc::new(Inline {
        gate: InlineGate::new(),
        container: Mutex::new(Some(container)),
        stop,
        limit,
        done: AtomicU64::new(0),
        slow: AtomicBool::new(false),
        owner: OnceLock::new(),
    });
    let runner: Arc<dyn Notify> = Arc::clone(&inline) as Arc<dyn Notify>;
    if wakeup.run_inline(runner).is_err() {
        return Err(std::io::Error::other(format!(
            "the wakeup of `{}` already runs another container inline",
            stats.name
        )));
    }
    let thread_name: String = stats.name.chars().take(15).collect();
    let own = Arc::clone(&inline);
    let watched = Arc::clone(&wakeup);
    let join = std::thread::Builder::new()
        .name(thread_name)
        .spawn(move || serve(&own, &watched, &changes))?;
    Ok(RunningContainer {
        stats,
        join,
        wakeup: Some(wakeup),
        warnings: Vec::new(),
        refusals: Vec::new(),
        ends_run: true,
    })
}

/// The container's own thread: changes between cycles, and its end. It sleeps until
/// unparked: by a posted change, by [`RunningContainer::nudge`] (the stop) or by the
/// cycle that reached the limit.
fn serve(inline: &Inline, wakeup: &Wakeup, changes: &ChangeSlot) {
    let _ = inline.owner.set(std::thread::current());
    // Before the first look at the slot: a change posted earlier is seen by it, one
    // posted later unparks this thread.
    changes.wake_on_post(std::thread::current());
    ferroc_ports::stopping::watch(Arc::clone(&inline.stop));
    while !inline.over() {
        // A notification that came before the container ran inline left the flag set.
        if wakeup.take() {
            inline.gate.arrive(|| inline.cycle());
        }
        // A cycle running now applies what was posted before its end; one posted
        // after that is looked at again soon.
        let done = inline.gate.chores(|| inline.chores(), || inline.cycle());
        std::thread::park_timeout(if done { IDLE_CHECK } else { CHORES_RETRY });
    }
    // No cycle after this; one running now (in another thread) ends first.
    while !inline.gate.close() {
        std::thread::sleep(Duration::from_millis(1));
    }
    // Dropping the container here (its steps, ports and their notifier) breaks the
    // cycle wakeup → runner → container → input → wakeup. Taken out first: what its
    // ports do as they go runs without the lock held.
    let container = inline.container().take();
    drop(container);
}

#[cfg(test)]
mod tests {
    use crate::{Change, Step, ThreadContainer, ThreadOptions, Trigger};
    use ferroc_ports::port::{Notify, WaitMode, Wakeup};
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::{mpsc, Arc, Mutex};
    use std::thread::ThreadId;
    use std::time::Duration;

    fn inline() -> ThreadOptions {
        ThreadOptions {
            wait: WaitMode::Inline,
            ..ThreadOptions::default()
        }
    }

    /// Every cycle runs on the thread that notified, the cycle's own steps in order.
    #[test]
    #[cfg_attr(miri, ignore)] // a thread sleeping with a timeout
    fn a_cycle_runs_in_the_delivering_thread() {
        let wakeup = Wakeup::new();
        let log: Arc<Mutex<Vec<(&str, ThreadId)>>> = Arc::default();
        let steps = ["decode", "detect"].map(|name| {
            let log = Arc::clone(&log);
            Step::new(name, move || {
                log.lock()
                    .unwrap()
                    .push((name, std::thread::current().id()))
            })
        });
        let container = ThreadContainer::new(
            "robot/vision",
            Trigger::Data(Arc::clone(&wakeup)),
            steps.into(),
        );
        let stop = Arc::new(AtomicBool::new(false));
        let running = container.spawn(inline(), Arc::clone(&stop), None).unwrap();
        wakeup.notify();
        let here = std::thread::current().id();
        assert_eq!(*log.lock().unwrap(), [("decode", here), ("detect", here)]);
        let w = Arc::clone(&wakeup);
        let there = std::thread::spawn(move || {
            w.notify();
            std::thread::current().id()
        })
        .join()
        .unwrap();
        assert_eq!(
            log.lock().unwrap()[2..],
            [("decode", there), ("detect", there)]
        );
        assert_eq!(running.stats.cycles(), 2);
        stop.store(true, Ordering::SeqCst);
        running.nudge();
        running.join();
        wakeup.notify();
        assert_eq!(log.lock().unwrap().len(), 4, "no cycle after the stop");
    }

    /// A value that arrives from another thread while a cycle runs does not wait: the
    /// running thread runs one more cycle for it, and nothing runs twice at once.
    #[test]
    #[cfg_attr(miri, ignore)] // threads
    fn a_value_during_a_cycle_is_run_by_the_running_thread() {
        let wakeup = Wakeup::new();
        let (entered_tx, entered_rx) = mpsc::channel::<()>();
        let (go_tx, go_rx) = mpsc::channel::<()>();
        let runs: Arc<Mutex<Vec<ThreadId>>> = Arc::default();
        let (r, go) = (Arc::clone(&runs), Mutex::new(go_rx));
        let step = Step::new("detect", move || {
            let first = r.lock().unwrap().is_empty();
            r.lock().unwrap().push(std::thread::current().id());
            if first {
                // Hold the first cycle until the other thread has arrived.
                entered_tx.send(()).unwrap();
                go.lock().unwrap().recv().unwrap();
            }
        });
        let container = ThreadContainer::new(
            "robot/vision",
            Trigger::Data(Arc::clone(&wakeup)),
            vec![step],
        );
        let stop = Arc::new(AtomicBool::new(false));
        let running = container.spawn(inline(), Arc::clone(&stop), None).unwrap();
        let w = Arc::clone(&wakeup);
        let first = std::thread::spawn(move || w.notify());
        entered_rx.recv().unwrap();
        // The first cycle runs over there: this notification returns at once.
        wakeup.notify();
        assert_eq!(runs.lock().unwrap().len(), 1);
        go_tx.send(()).unwrap();
        let first_id = first.thread().id();
        first.join().unwrap();
        assert_eq!(*runs.lock().unwrap(), [first_id, first_id]);
        stop.store(true, Ordering::SeqCst);
        running.nudge();
        running.join();
    }

    /// A cycle over 1 ms is reported once; shorter ones never.
    #[test]
    fn a_slow_cycle_is_reported_once() {
        let reported = AtomicBool::new(false);
        let fast = super::slow_warning("robot/view", Duration::from_micros(900), &reported);
        assert_eq!(fast, None);
        let slow = super::slow_warning("robot/view", Duration::from_millis(3), &reported);
        let slow = slow.expect("a 3 ms cycle is reported");
        assert!(
            slow.contains("`robot/view` runs inline") && slow.contains("3.0ms"),
            "{slow}"
        );
        assert!(slow.contains("help: "), "{slow}");
        let again = super::slow_warning("robot/view", Duration::from_millis(5), &reported);
        assert_eq!(again, None, "once");
    }

    /// A change posted while no value comes is applied by the container's own thread,
    /// woken by the post: it sleeps [`super::IDLE_CHECK`] (10 s) otherwise, so without
    /// the wake the change would not be applied within the 5 s waited here.
    #[test]
    #[cfg_attr(miri, ignore)] // a thread sleeping with a timeout
    fn a_change_posted_while_no_value_comes_wakes_the_own_thread() {
        let wakeup = Wakeup::new();
        let step = Step::new("robot/idle/a:update", || {});
        let container =
            ThreadContainer::new("robot/idle", Trigger::Data(Arc::clone(&wakeup)), vec![step]);
        let slot = container.changes();
        let stop = Arc::new(AtomicBool::new(false));
        let running = container.spawn(inline(), Arc::clone(&stop), None).unwrap();
        let (acted_tx, acted_rx) = mpsc::channel::<ThreadId>();
        let change = || {
            let acted = acted_tx.clone();
            Change {
                order: vec!["robot/idle/a:update".into()],
                actions: vec![Box::new(move || {
                    acted.send(std::thread::current().id()).unwrap();
                })],
                ..Change::default()
            }
        };
        // The first may be applied by the thread's first look at the slot; once it
        // was, the thread sleeps, and only the post of the second wakes it.
        for _ in 0..2 {
            slot.post(change()).map_err(|_| ()).unwrap();
            assert!(
                slot.wait(Duration::from_secs(5)).is_some(),
                "the posted change was not applied: the own thread was not woken"
            );
            let acted = acted_rx.recv().unwrap();
            assert_eq!(
                acted,
                running.join.thread().id(),
                "on the container's own thread"
            );
        }
        assert_eq!(running.stats.cycles(), 0, "no value came, no cycle ran");
        stop.store(true, Ordering::SeqCst);
        running.nudge();
        running.join();
    }

    /// A cycle limit ends the container (its thread), as for one with a thread.
    #[test]
    #[cfg_attr(miri, ignore)] // a thread sleeping with a timeout
    fn the_cycle_limit_ends_an_inline_container() {
        let wakeup = Wakeup::new();
        let count = Arc::new(Mutex::new(0));
        let c = Arc::clone(&count);
        let step = Step::new("count", move || *c.lock().unwrap() += 1);
        let container = ThreadContainer::new(
            "robot/count",
            Trigger::Data(Arc::clone(&wakeup)),
            vec![step],
        );
        let stop = Arc::new(AtomicBool::new(false));
        let running = container.spawn(inline(), stop, Some(2)).unwrap();
        for _ in 0..3 {
            wakeup.notify();
        }
        running.join();
        assert_eq!(*count.lock().unwrap(), 2);
    }
}
