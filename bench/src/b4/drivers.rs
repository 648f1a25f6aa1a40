//! The publisher and the receivers of each B4 variant: ports, copy ports, a bare
//! container, and the baselines (mpsc, the runtime's wakeup, a condvar signalled
//! after unlocking, park/unpark).

use super::*;

/// What the receiver side shares with the publisher.
struct Shared {
    /// Sequence number of the last message the receiver recorded.
    seen: AtomicU64,
    /// Latency of message `seq` at `seq - 1` (`u64::MAX` until recorded).
    latency: Vec<AtomicU64>,
    /// CPU time of the receiver's thread when it recorded its last message (ns), for
    /// the variants that measure what their waiting costs.
    cpu_ns: AtomicU64,
}

impl Shared {
    fn new(n: u64) -> Arc<Self> {
        Arc::new(Shared {
            seen: AtomicU64::new(0),
            latency: (0..n).map(|_| AtomicU64::new(u64::MAX)).collect(),
            cpu_ns: AtomicU64::new(0),
        })
    }

    /// The receiver's part, right after it read `msg`.
    fn record(&self, stamp_ns: u64, seq: u64) {
        let latency = now_ns().saturating_sub(stamp_ns);
        if let Some(slot) = seq
            .checked_sub(1)
            .and_then(|i| self.latency.get(i as usize))
        {
            slot.store(latency, Ordering::Relaxed);
        }
        self.seen.store(seq, Ordering::Release);
    }

    /// Notes the receiver thread's CPU time (after [`Self::record`], so the reading
    /// is not in the measured latency).
    fn record_cpu(&self) {
        self.cpu_ns.store(thread_cpu_ns(), Ordering::Relaxed);
    }

    /// The publisher's pacing: wait until `seq` was recorded, then `gap` more.
    fn wait_seen(&self, seq: u64, gap: Duration) -> Result<(), String> {
        let started = Instant::now();
        let mut spins = 0u32;
        while self.seen.load(Ordering::Acquire) < seq {
            spins = spins.saturating_add(1);
            if spins < 20_000 {
                std::hint::spin_loop();
            } else {
                std::thread::yield_now();
                if started.elapsed() > LOST_AFTER {
                    return Err(format!(
                        "message {seq} not seen within {} s",
                        LOST_AFTER.as_secs()
                    ));
                }
            }
        }
        let seen_at = Instant::now();
        while seen_at.elapsed() < gap {
            std::hint::spin_loop();
        }
        Ok(())
    }

    /// Latencies after the warm-up.
    fn collect(&self) -> Vec<u64> {
        self.latency
            .iter()
            .skip(WARM_UP as usize)
            .map(|a| a.load(Ordering::Relaxed))
            .collect()
    }
}

/// CPU time of the calling thread, nanoseconds.
fn thread_cpu_ns() -> u64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: writes one timespec we own.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    t.tv_sec as u64 * 1_000_000_000 + t.tv_nsec as u64
}

/// Publishes `n` messages plus the warm-up with `publish(seq)`, each paced by
/// [`Shared::wait_seen`].
fn drive(
    shared: &Shared,
    n: u64,
    gap: Duration,
    mut publish: impl FnMut(u64),
) -> Result<(), String> {
    for seq in 1..=n + WARM_UP {
        publish(seq);
        shared.wait_seen(seq, gap)?;
    }
    Ok(())
}

/// Runs `receive` as the one step of a data-triggered container woken by `wakeup`
/// (pinned to `cpu` if given), drives the publisher, then stops the container.
fn with_container(
    options: ThreadOptions,
    wakeup: Arc<Wakeup>,
    shared: &Shared,
    n: u64,
    gap: Duration,
    receive: impl FnMut() + Send + 'static,
    publish: impl FnMut(u64),
) -> Result<(), String> {
    let stop = Arc::new(AtomicBool::new(false));
    let running = ThreadContainer::new(
        "listener",
        Trigger::Data(wakeup),
        vec![Step::new("listener/receive (update)", receive)],
    )
    .spawn(options, Arc::clone(&stop), None)
    .map_err(|e| format!("cannot start a thread container: {e}"))?;
    let result = drive(shared, n, gap, publish);
    stop.store(true, Ordering::SeqCst);
    running.nudge();
    running.join();
    result
}

/// The receiving container's options: pinned to `cpu` if given, waiting as `wait`.
fn placed(cpu: Option<usize>, wait: WaitMode) -> ThreadOptions {
    ThreadOptions {
        cpu,
        wait,
        ..ThreadOptions::default()
    }
}

/// A plain receiver thread (pinned to `cpu` if given).
fn spawn_thread(
    cpu: Option<usize>,
    body: impl FnOnce() + Send + 'static,
) -> Result<std::thread::JoinHandle<()>, String> {
    std::thread::Builder::new()
        .name("listener".into())
        .spawn(move || {
            if let Some(cpu) = cpu {
                // Checked by `Placement::new`; a refusal here only loses the pinning.
                let _ = pin_current(cpu);
            }
            body()
        })
        .map_err(|e| format!("cannot start a thread: {e}"))
}

/// A wakeup registered as the notifier of an input (via `set`).
fn wakeup_for(set: impl FnOnce(Notifier) -> Result<(), Notifier>) -> Result<Arc<Wakeup>, String> {
    let wakeup = Wakeup::new();
    set(wakeup.clone()).map_err(|_| "input already has a notifier".to_string())?;
    Ok(wakeup)
}

/// A message passed through two atomics (stamp, then sequence number with Release),
/// for the variants without ports.
#[derive(Default)]
struct Mailbox {
    stamp: AtomicU64,
    seq: AtomicU64,
}

impl Mailbox {
    fn put(&self, seq: u64) {
        self.stamp.store(now_ns(), Ordering::Relaxed);
        self.seq.store(seq, Ordering::Release);
    }

    /// Records the message if it is new since `last`.
    fn take(&self, last: &mut u64, shared: &Shared) {
        let seq = self.seq.load(Ordering::Acquire);
        if seq != *last {
            *last = seq;
            shared.record(self.stamp.load(Ordering::Relaxed), seq);
        }
    }
}

/// What one run of a variant measured.
pub(super) struct Run {
    /// Latencies after the warm-up, ns.
    pub latencies: Vec<u64>,
    /// The receiver thread's CPU time over the run, ns (0: not measured).
    pub cpu_ns: u64,
    /// Wall time of the run (publishing and pacing), ns.
    pub wall_ns: u64,
}

/// One run of `variant`: `n` recorded messages.
pub(super) fn run_variant(
    variant: Variant,
    n: u64,
    gap: Duration,
    cpu: Option<usize>,
) -> Result<Run, String> {
    let shared = Shared::new(n + WARM_UP);
    let started = Instant::now();
    let pace = Pace { n, gap, cpu };
    match variant {
        Variant::Ports | Variant::PortsSpin | Variant::PortsAdaptive => {
            let wait = match variant {
                Variant::PortsSpin => WaitMode::Spin,
                Variant::PortsAdaptive => WaitMode::Adaptive,
                _ => WaitMode::Park,
            };
            ports(&shared, pace, wait)?
        }
        Variant::CopyPorts => copy_ports(&shared, pace)?,
        Variant::Container => container(&shared, pace)?,
        Variant::CondvarUnlocked => condvar_unlocked(&shared, pace)?,
        Variant::WaitTimeout | Variant::Wait | Variant::Park => waits(variant, &shared, pace)?,
        Variant::Mpsc => channel(&shared, pace)?,
    }
    Ok(Run {
        latencies: shared.collect(),
        cpu_ns: shared.cpu_ns.load(Ordering::Relaxed),
        wall_ns: started.elapsed().as_nanos() as u64,
    })
}

/// How a run goes: `n` recorded messages, each `gap` after the previous was seen, the
/// receiver pinned to `cpu` if given.
#[derive(Clone, Copy)]
struct Pace {
    n: u64,
    gap: Duration,
    cpu: Option<usize>,
}

/// Ports (`Variant::Ports*`): an output port and an input in a data-triggered
/// container waiting as `wait`.
fn ports(shared: &Arc<Shared>, pace: Pace, wait: WaitMode) -> Result<(), String> {
    let s = Arc::clone(shared);
    let out = OutputPort::<Msg>::new("talker/out");
    let input = InputPort::<Msg>::new("listener/in");
    connect(&out, &input, ConnectOptions::default()).map_err(|e| e.to_string())?;
    let wakeup = wakeup_for(|w| input.set_notifier(w))?;
    let receive = move || {
        if input.take_changed() {
            let m = *input.get();
            s.record(m.stamp_ns, m.seq);
            s.record_cpu();
        }
    };
    let Pace { n, gap, cpu } = pace;
    with_container(placed(cpu, wait), wakeup, shared, n, gap, receive, |seq| {
        out.publish_with(|m| {
            m.seq = seq;
            m.stamp_ns = now_ns();
        })
    })
}

/// Copy ports: the values copied, not shared.
fn copy_ports(shared: &Arc<Shared>, pace: Pace) -> Result<(), String> {
    let s = Arc::clone(shared);
    let out = CopyOutputPort::<Msg>::new("talker/out");
    let input = CopyInputPort::<Msg>::new("listener/in");
    connect(&out, &input, ConnectOptions::default()).map_err(|e| e.to_string())?;
    let wakeup = wakeup_for(|w| input.set_notifier(w))?;
    let receive = move || {
        if input.take_changed() {
            let m = input.get();
            s.record(m.stamp_ns, m.seq);
        }
    };
    let Pace { n, gap, cpu } = pace;
    let options = placed(cpu, WaitMode::Park);
    with_container(options, wakeup, shared, n, gap, receive, |seq| {
        out.publish(Msg {
            seq,
            stamp_ns: now_ns(),
            ..Msg::default()
        })
    })
}

/// A bare container: its wakeup notified by the publisher, no ports.
fn container(shared: &Arc<Shared>, pace: Pace) -> Result<(), String> {
    let s = Arc::clone(shared);
    let mailbox = Arc::new(Mailbox::default());
    let wakeup = Wakeup::new();
    let (mb, w) = (Arc::clone(&mailbox), Arc::clone(&wakeup));
    let mut last = 0;
    let receive = move || mb.take(&mut last, &s);
    let Pace { n, gap, cpu } = pace;
    let options = placed(cpu, WaitMode::Park);
    with_container(options, wakeup, shared, n, gap, receive, |seq| {
        mailbox.put(seq);
        w.notify();
    })
}

/// A thread waiting on a condition variable signalled after unlocking its mutex.
fn condvar_unlocked(shared: &Arc<Shared>, pace: Pace) -> Result<(), String> {
    let s = Arc::clone(shared);
    let mailbox = Arc::new(Mailbox::default());
    let pair = Arc::new((Mutex::new(false), Condvar::new()));
    let stop = Arc::new(AtomicBool::new(false));
    let (mb, p, halt) = (Arc::clone(&mailbox), Arc::clone(&pair), Arc::clone(&stop));
    let receiver = spawn_thread(pace.cpu, move || {
        let mut last = 0;
        while !halt.load(Ordering::Relaxed) {
            let mut pending = p.0.lock().unwrap_or_else(|e| e.into_inner());
            while !*pending {
                pending = p.1.wait(pending).unwrap_or_else(|e| e.into_inner());
            }
            *pending = false;
            drop(pending);
            mb.take(&mut last, &s);
        }
    })?;
    let notify = || {
        *pair.0.lock().unwrap_or_else(|e| e.into_inner()) = true;
        pair.1.notify_one();
    };
    let result = drive(shared, pace.n, pace.gap, |seq| {
        mailbox.put(seq);
        notify();
    });
    stop.store(true, Ordering::SeqCst);
    notify();
    let _ = receiver.join();
    result
}

/// A plain thread in the runtime's wakeup (`wait_timeout`, `wait`) or parked
/// (`Variant::Park`).
fn waits(variant: Variant, shared: &Arc<Shared>, pace: Pace) -> Result<(), String> {
    let s = Arc::clone(shared);
    let mailbox = Arc::new(Mailbox::default());
    let wakeup = Wakeup::new();
    let stop = Arc::new(AtomicBool::new(false));
    let (mb, w, halt) = (Arc::clone(&mailbox), Arc::clone(&wakeup), Arc::clone(&stop));
    let receiver = spawn_thread(pace.cpu, move || {
        let mut last = 0;
        while !halt.load(Ordering::Relaxed) {
            match variant {
                Variant::WaitTimeout => {
                    w.wait_timeout(Duration::from_millis(50));
                }
                Variant::Wait => w.wait(),
                _ => std::thread::park(),
            }
            mb.take(&mut last, &s);
            s.record_cpu();
        }
    })?;
    let thread = receiver.thread().clone();
    let result = drive(shared, pace.n, pace.gap, |seq| {
        mailbox.put(seq);
        if variant == Variant::Park {
            thread.unpark();
        } else {
            wakeup.notify();
        }
    });
    stop.store(true, Ordering::SeqCst);
    thread.unpark();
    wakeup.notify();
    let _ = receiver.join();
    result
}

/// A plain thread receiving from std's mpsc channel.
fn channel(shared: &Arc<Shared>, pace: Pace) -> Result<(), String> {
    let s = Arc::clone(shared);
    let (tx, rx) = mpsc::channel::<Msg>();
    let receiver = spawn_thread(pace.cpu, move || {
        while let Ok(m) = rx.recv() {
            s.record(m.stamp_ns, m.seq);
        }
    })?;
    let result = drive(shared, pace.n, pace.gap, |seq| {
        // The receiver lives until `tx` is dropped below.
        let _ = tx.send(Msg {
            seq,
            stamp_ns: now_ns(),
            ..Msg::default()
        });
    });
    drop(tx);
    let _ = receiver.join();
    result
}
