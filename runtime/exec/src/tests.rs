use super::*;
use std::sync::atomic::AtomicUsize;
use std::sync::Mutex;

/// A step that logs its name into `log` and advances the manual clock by `takes`.
fn step(
    log: &Arc<Mutex<Vec<&'static str>>>,
    clock: &ManualClock,
    name: &'static str,
    takes: Duration,
) -> Step {
    let (log, clock) = (Arc::clone(log), clock.clone());
    Step::new(name, move || {
        log.lock().unwrap().push(name);
        clock.advance(takes);
    })
}

#[test]
fn steps_run_in_the_given_order_every_cycle() {
    let clock = ManualClock::new();
    let log = Arc::new(Mutex::new(Vec::new()));
    let ms = Duration::from_millis(1);
    let mut c = ThreadContainer::new(
        "robot/main",
        Trigger::Periodic(10 * ms),
        vec![
            step(&log, &clock, "sense", ms),
            step(&log, &clock, "control", ms),
        ],
    )
    .with_clock(Arc::new(clock.clone()));
    c.run(&AtomicBool::new(false), Some(3));
    assert_eq!(*log.lock().unwrap(), ["sense", "control"].repeat(3));
    let stats = c.stats();
    assert_eq!(stats.cycles(), 3);
    assert_eq!(stats.overruns(), 0);
    assert_eq!(stats.steps[0].1.runs(), 3);
    assert_eq!(stats.steps[0].1.mean(), ms);
    // 2 ms of work in each 10 ms period.
    assert!((stats.load() - 0.2).abs() < 1e-9, "{}", stats.load());
    // Absolute deadlines: three cycles started at 0, 10 and 20 ms; no drift from the
    // 2 ms each took. The clock stands at the end of the third cycle.
    assert_eq!(clock.now(), 22 * ms);
}

#[test]
fn an_overrun_is_counted_and_the_phase_is_kept() {
    let clock = ManualClock::new();
    let log = Arc::new(Mutex::new(Vec::new()));
    let ms = Duration::from_millis(1);
    let slow = Arc::new(AtomicBool::new(true));
    let (slow2, clock2) = (Arc::clone(&slow), clock.clone());
    // The first cycle takes 25 ms of a 10 ms period, later ones 1 ms.
    let mut c = ThreadContainer::new(
        "robot/main",
        Trigger::Periodic(10 * ms),
        vec![
            Step::new("work", move || {
                clock2.advance(if slow2.swap(false, Ordering::SeqCst) {
                    25 * ms
                } else {
                    ms
                })
            }),
            step(&log, &clock, "log", Duration::ZERO),
        ],
    )
    .with_clock(Arc::new(clock.clone()));
    c.run(&AtomicBool::new(false), Some(2));
    let stats = c.stats();
    assert_eq!(stats.overruns(), 1);
    assert_eq!(stats.cycles(), 2);
    // Cycle 1 ran 0..25 ms and missed the deadlines at 10 and 20 ms; cycle 2 starts at
    // the next one on the grid, 30 ms, and ends at 31 ms.
    assert_eq!(clock.now(), 31 * ms);
}

#[test]
fn a_panicking_step_is_stopped_and_the_others_keep_running() {
    let clock = ManualClock::new();
    let log = Arc::new(Mutex::new(Vec::new()));
    let mut c = ThreadContainer::new(
        "robot/main",
        Trigger::Periodic(Duration::from_millis(10)),
        vec![
            step(&log, &clock, "before", Duration::ZERO),
            Step::new("robot/main/faulty (update)", || {
                panic!("sensor cable unplugged")
            }),
            step(&log, &clock, "after", Duration::ZERO),
        ],
    )
    .with_clock(Arc::new(clock.clone()));
    c.run(&AtomicBool::new(false), Some(2));
    assert_eq!(*log.lock().unwrap(), ["before", "after", "before", "after"]);
    let panics = c.stats().panics();
    assert_eq!(panics.len(), 1, "{panics:?}");
    assert!(
        panics[0].contains("robot/main/faulty (update)"),
        "{}",
        panics[0]
    );
    assert!(
        panics[0].contains("sensor cable unplugged"),
        "{}",
        panics[0]
    );
    assert_eq!(c.stats().steps[1].1.runs(), 1);
}

#[test]
#[cfg_attr(miri, ignore)] // threads spinning and blocking with timeouts
fn every_wait_mode_wakes_on_data_and_stops_on_request() {
    use ferroc_ports::port::WaitMode;
    for mode in [
        WaitMode::Park,
        WaitMode::Spin,
        WaitMode::Adaptive,
        WaitMode::Inline,
    ] {
        let wakeup = Wakeup::new();
        let log = Arc::new(Mutex::new(Vec::new()));
        let clock = ManualClock::new();
        let container = ThreadContainer::new(
            "robot/vision",
            Trigger::Data(Arc::clone(&wakeup)),
            vec![step(&log, &clock, "detect", Duration::ZERO)],
        );
        let stop = Arc::new(AtomicBool::new(false));
        let options = ThreadOptions {
            wait: mode,
            ..ThreadOptions::default()
        };
        let running = container.spawn(options, Arc::clone(&stop), None).unwrap();
        for n in 1..=3 {
            ferroc_ports::port::Notify::notify(&*wakeup);
            while running.stats.cycles() < n {
                std::thread::yield_now();
            }
        }
        // Three notifications, three cycles: none lost, none invented.
        assert_eq!(log.lock().unwrap().len(), 3, "{mode:?}");
        assert!(!running.is_finished(), "{mode:?} waits for more data");
        stop.store(true, Ordering::SeqCst);
        running.nudge();
        running.join();
        assert_eq!(
            log.lock().unwrap().len(),
            3,
            "{mode:?}: a stop runs no cycle"
        );
    }
}

#[test]
#[cfg_attr(miri, ignore)] // threads blocking on a condition variable with timeouts
fn a_data_triggered_container_runs_once_per_wakeup_and_stops_on_request() {
    let wakeup = Wakeup::new();
    let log = Arc::new(Mutex::new(Vec::new()));
    let clock = ManualClock::new();
    let container = ThreadContainer::new(
        "robot/vision",
        Trigger::Data(Arc::clone(&wakeup)),
        vec![step(&log, &clock, "detect", Duration::ZERO)],
    );
    let stop = Arc::new(AtomicBool::new(false));
    let running = container
        .spawn(ThreadOptions::default(), Arc::clone(&stop), Some(2))
        .unwrap();
    ferroc_ports::port::Notify::notify(&*wakeup);
    while running.stats.cycles() < 1 {
        std::thread::yield_now();
    }
    ferroc_ports::port::Notify::notify(&*wakeup);
    running.join();
    assert_eq!(*log.lock().unwrap(), ["detect", "detect"]);

    // Stopping without data: the flag plus a nudge ends the thread.
    let container = ThreadContainer::new(
        "robot/idle",
        Trigger::Data(Wakeup::new()),
        vec![step(&log, &clock, "never", Duration::ZERO)],
    );
    let stop = Arc::new(AtomicBool::new(false));
    let running = container
        .spawn(ThreadOptions::default(), Arc::clone(&stop), None)
        .unwrap();
    stop.store(true, Ordering::SeqCst);
    running.nudge();
    running.join();
    assert!(!log.lock().unwrap().contains(&"never"));
}

#[test]
#[cfg_attr(miri, ignore)] // system calls
fn refused_placement_is_a_warning_not_a_failure() {
    let container = ThreadContainer::new(
        "robot/main",
        Trigger::Periodic(Duration::from_millis(1)),
        vec![],
    );
    let running = container
        .spawn(
            ThreadOptions {
                priority: None,
                cpu: Some(100_000),
                ..ThreadOptions::default()
            },
            Arc::new(AtomicBool::new(false)),
            Some(1),
        )
        .unwrap();
    assert_eq!(running.warnings.len(), 1, "{:?}", running.warnings);
    assert!(
        running.warnings[0].contains("CPU 100000"),
        "{:?}",
        running.warnings
    );
    running.join();
}

#[test]
fn a_continuous_container_runs_exactly_the_limit_and_samples_step_times() {
    let clock = ManualClock::new();
    let log = Arc::new(Mutex::new(Vec::new()));
    let us = Duration::from_micros(1);
    let mut c = ThreadContainer::new(
        "bench/ring",
        Trigger::Continuous,
        vec![step(&log, &clock, "a", us), step(&log, &clock, "b", 2 * us)],
    )
    .with_clock(Arc::new(clock.clone()));
    // 150 cycles of 3 µs: batches of 1, 2, 4, … 64 (doubling while a batch takes less
    // than BATCH_TIME), then the 23 left; each with one cycle timed step by step.
    c.run(&AtomicBool::new(false), Some(150));
    assert_eq!(*log.lock().unwrap(), ["a", "b"].repeat(150));
    let stats = c.stats();
    assert_eq!(stats.cycles(), 150);
    assert_eq!(stats.steps[0].1.runs(), 8);
    assert_eq!(stats.steps[1].1.mean(), 2 * us);
    // No sleeping: the clock advanced only by the work done, 3 µs per cycle.
    assert_eq!(clock.now(), 450 * us);
    assert_eq!(stats.mean_cycle(), 3 * us);
    assert_eq!(stats.last_cycle(), 3 * us);
    assert_eq!(stats.load(), 1.0);
    assert_eq!(stats.overruns(), 0);
}

#[test]
fn a_continuous_container_stops_inside_a_batch() {
    let stop = Arc::new(AtomicBool::new(false));
    let runs = Arc::new(std::sync::atomic::AtomicU64::new(0));
    let (stop2, runs2) = (Arc::clone(&stop), Arc::clone(&runs));
    let mut c = ThreadContainer::new(
        "bench/ring",
        Trigger::Continuous,
        vec![Step::new("count", move || {
            // The stop request comes in the tenth cycle of the first batch.
            if runs2.fetch_add(1, Ordering::SeqCst) + 1 == 10 {
                stop2.store(true, Ordering::SeqCst);
            }
        })],
    );
    c.run(&stop, None);
    assert_eq!(runs.load(Ordering::SeqCst), 10);
    assert_eq!(c.stats().cycles(), 10);
}

/// Seven containers refused real-time priority for one reason are one warning naming
/// them all; another reason, or a CPU, is a line of its own; one container keeps the
/// one-thread wording.
#[test]
fn refusals_are_summarised_per_request_and_reason() {
    let eperm = "Operation not permitted (os error 1)";
    let mut refusals: Vec<(String, Refusal)> = (0..7)
        .map(|i| {
            let asked = Placement::Priority(70 - i);
            let why = eperm.to_string();
            (format!("robot/t{i}"), Refusal { asked, why })
        })
        .collect();
    refusals.push((
        "robot/t0".into(),
        Refusal {
            asked: Placement::Cpu(9),
            why: "Invalid argument (os error 22)".into(),
        },
    ));
    let lines = summarise_refusals(&refusals);
    assert_eq!(lines.len(), 2, "{lines:#?}");
    assert!(
        lines[0].starts_with(
            "real-time priority refused for 7 thread containers \
             (Operation not permitted (os error 1)): `robot/t0` 70, `robot/t1` 69,"
        ),
        "{}",
        lines[0]
    );
    assert!(lines[0].contains("`robot/t6` 64; they run with normal priority"));
    assert_eq!(
        lines[1],
        "thread container `robot/t0`: pinning to CPU 9 refused (Invalid argument (os error \
         22)); the thread may run on any CPU"
    );
    assert!(summarise_refusals(&[]).is_empty());
}

#[test]
fn a_continuous_batch_grows_while_short_shrinks_while_long_and_stays_bounded() {
    let short = BATCH_TIME / 4;
    let mut size = 1;
    for _ in 0..30 {
        size = next_batch(size, size, short);
    }
    assert_eq!(size, MAX_BATCH, "grows to the cap and no further");
    // A batch cut short by the cycle limit or a stop says nothing about its size.
    assert_eq!(next_batch(64, 10, short), 64);
    // Between BATCH_TIME and twice it: kept.
    assert_eq!(next_batch(64, 64, BATCH_TIME * 3 / 2), 64);
    // Longer: halved, down to one cycle a batch (slow steps are timed every cycle).
    assert_eq!(next_batch(64, 64, BATCH_TIME * 3), 32);
    let mut size = MAX_BATCH;
    for _ in 0..30 {
        size = next_batch(size, size, BATCH_TIME * 3);
    }
    assert_eq!(size, 1);
}

/// A step reads its container's period (`ferroc_module::cycle::period`): a periodic
/// container's, run freely or cycle by cycle (as the lockstep driver does), none for a
/// data-triggered or continuous one, and none outside a cycle.
#[test]
fn a_step_reads_the_period_of_its_container() {
    use ferroc_module::cycle;
    let seen = Arc::new(Mutex::new(Vec::new()));
    type Seen = Arc<Mutex<Vec<(Option<Duration>, bool)>>>;
    let reader = |seen: &Seen| {
        let seen = Arc::clone(seen);
        Step::new("read", move || {
            seen.lock()
                .unwrap()
                .push((cycle::period(), cycle::in_cycle()));
        })
    };
    let ms = Duration::from_millis(1);
    let clock = ManualClock::new();
    let mut periodic = ThreadContainer::new("p", Trigger::Periodic(40 * ms), vec![reader(&seen)])
        .with_clock(Arc::new(clock.clone()));
    periodic.run(&AtomicBool::new(false), Some(2));
    periodic.run_cycle();
    let mut continuous = ThreadContainer::new("c", Trigger::Continuous, vec![reader(&seen)]);
    continuous.run(&AtomicBool::new(false), Some(1));
    let mut data = ThreadContainer::new("d", Trigger::Data(Wakeup::new()), vec![reader(&seen)]);
    data.run_cycle();
    assert_eq!(
        *seen.lock().unwrap(),
        [
            (Some(40 * ms), true),
            (Some(40 * ms), true),
            (Some(40 * ms), true),
            (None, true),
            (None, true)
        ]
    );
    assert!(!cycle::in_cycle(), "after the cycles");
    assert_eq!(cycle::period(), None);
}

/// A manual clock that counts its readings.
struct Counting(ManualClock, Arc<AtomicUsize>);

impl Clock for Counting {
    fn now(&self) -> Duration {
        self.1.fetch_add(1, Ordering::SeqCst);
        self.0.now()
    }
    fn sleep_until(&self, deadline: Duration) {
        self.0.sleep_until(deadline);
    }
}

/// A cycle reads the clock once before its first step and once after each step: each
/// step is timed from the end of the one before (an inline cycle runs in a network
/// callback, where every reading counts). The times are those of the steps.
#[test]
fn a_cycle_reads_the_clock_once_a_step_and_once_more() {
    let clock = ManualClock::new();
    let log = Arc::new(Mutex::new(Vec::new()));
    let ms = Duration::from_millis(1);
    let readings = Arc::new(AtomicUsize::new(0));
    let mut c = ThreadContainer::new(
        "robot/view",
        Trigger::Data(Wakeup::new()),
        vec![
            step(&log, &clock, "decode", 2 * ms),
            step(&log, &clock, "detect", 3 * ms),
            step(&log, &clock, "draw", ms),
        ],
    )
    .with_clock(Arc::new(Counting(clock.clone(), Arc::clone(&readings))));
    c.run_cycle();
    assert_eq!(readings.load(Ordering::SeqCst), 4);
    let stats = c.stats();
    let means: Vec<Duration> = stats.steps.iter().map(|(_, s)| s.mean()).collect();
    assert_eq!(means, [2 * ms, 3 * ms, ms]);
    assert_eq!(stats.cycles(), 1);
}
