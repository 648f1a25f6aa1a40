//! One B3 configuration, measured in a child process: the producer, the consumers,
//! the measurement window.

use super::*;

/// Frames one consumer saw inside the measurement window; written by its container's
/// thread once per frame, read after the thread ended.
#[derive(Default)]
struct Seen {
    frames: u64,
    first_ns: u64,
    last_ns: u64,
    missed: u64,
    last_seq: u64,
    /// Sum of the bytes read, so the read cannot be optimised away.
    checksum: u64,
}

/// The measurement window, in nanoseconds since `epoch` (both `u64::MAX` until set).
struct Window {
    epoch: Instant,
    start: AtomicU64,
    end: AtomicU64,
}

impl Window {
    fn now(&self) -> u64 {
        self.epoch.elapsed().as_nanos() as u64
    }
    fn contains(&self, t: u64) -> bool {
        t >= self.start.load(Ordering::Relaxed) && t < self.end.load(Ordering::Relaxed)
    }
}

/// The child process: `__b3-child MODE SECONDS`. Prints one `B3CHILD` line.
pub fn child(args: &[String]) -> u8 {
    let parsed = (
        args.first().and_then(|a| Mode::parse(a)),
        args.get(1)
            .and_then(|a| a.parse::<f64>().ok())
            .filter(|s| (0.0..=3600.0).contains(s)),
    );
    let (Some(mode), Some(seconds)) = parsed else {
        eprintln!(
            "{CHILD_ARG}: internal use by `b3`: {CHILD_ARG} baseline|ports:N|wakeups:N|threads:N \
             SECONDS"
        );
        return 2;
    };
    match measure_child(mode, Duration::from_secs_f64(seconds)) {
        Ok(line) => {
            println!("B3CHILD {line}");
            0
        }
        Err(e) => {
            eprintln!("{CHILD_ARG}: {e}");
            1
        }
    }
}

fn source_frame() -> Vec<u8> {
    (0..FRAME_BYTES).map(|i| (i % 251) as u8).collect()
}

fn measure_child(mode: Mode, window_len: Duration) -> Result<String, String> {
    let mut consumers = Consumers {
        window: Arc::new(Window {
            epoch: Instant::now(),
            start: AtomicU64::new(u64::MAX),
            end: AtomicU64::new(u64::MAX),
        }),
        stop: Arc::new(AtomicBool::new(false)),
        containers: Vec::new(),
        seen: Vec::new(),
        threads: Vec::new(),
    };
    let source = source_frame();
    // The producer's step and the consumers.
    let mut port: Option<Arc<OutputPort<Image>>> = None;
    let produce: Step = match mode {
        Mode::Baseline => {
            let mut dst = vec![0u8; FRAME_BYTES];
            Step::new("camera/producer (baseline)", move || {
                dst.copy_from_slice(&source);
                std::hint::black_box(&mut dst);
            })
        }
        Mode::Ports(n) => {
            let (out, step) = ports_producer(n, source, &mut consumers)?;
            port = Some(out);
            step
        }
        Mode::Wakeups(n) => wakeups_producer(n, source, &mut consumers)?,
        Mode::Threads(n) => threads_producer(n, source, &mut consumers)?,
    };
    // A second step counts the producer's cycles the way consumers count frames.
    let produced = Arc::new(Mutex::new(Seen::default()));
    let tick = {
        let (p, w, mut n) = (Arc::clone(&produced), Arc::clone(&consumers.window), 0);
        Step::new("camera/tick", move || {
            n += 1;
            count(&p, &w, n, 0);
        })
    };
    let producer = ThreadContainer::new("camera", Trigger::Periodic(PERIOD), vec![produce, tick])
        .spawn(ThreadOptions::default(), Arc::clone(&consumers.stop), None)
        .map_err(|e| format!("cannot start a thread container: {e}"))?;

    std::thread::sleep(WARM_UP);
    let overruns0 = producer.stats.overruns();
    let cpu0 = process_cpu_time();
    let t0 = Instant::now();
    let window = &consumers.window;
    window.start.store(window.now(), Ordering::Relaxed);
    std::thread::sleep(window_len);
    window.end.store(window.now(), Ordering::Relaxed);
    let cpu = process_cpu_time().saturating_sub(cpu0);
    let wall = t0.elapsed();
    let overruns = producer.stats.overruns() - overruns0;

    consumers.stop.store(true, Ordering::SeqCst);
    producer.join();
    let seen = consumers.join();
    let wall_s = wall.as_secs_f64();
    let (fps_mean, fps_min, missed) = consumer_rates(&seen, wall_s);
    let producer_fps = rate(&produced.lock().unwrap_or_else(|e| e.into_inner()), wall_s);
    let buffers = port.as_ref().map_or(0, |p| p.stats().buffers);
    Ok(format!(
        "consumers={} fps_mean={fps_mean:.3} fps_min={fps_min:.3} missed={missed} \
         producer_fps={producer_fps:.3} overruns={overruns} cpu_pct={:.3} buffers={buffers} \
         window_s={wall_s:.3}",
        mode.consumers(),
        cpu.as_secs_f64() / wall_s * 100.0,
    ))
}

/// The consumers of one configuration (containers, or bare threads), what each saw,
/// the measurement window they count in and the flag that stops them.
struct Consumers {
    window: Arc<Window>,
    stop: Arc<AtomicBool>,
    containers: Vec<RunningContainer>,
    seen: Vec<Arc<Mutex<Seen>>>,
    threads: Vec<std::thread::JoinHandle<()>>,
}

impl Consumers {
    /// Consumer container `i`, woken by `wakeup`, reading with `read`.
    fn add(&mut self, i: usize, wakeup: Arc<Wakeup>, read: Reader) -> Result<(), String> {
        let (running, s) = consumer(i, wakeup, read, &self.window, &self.stop)?;
        self.containers.push(running);
        self.seen.push(s);
        Ok(())
    }

    /// Ends every consumer (the stop flag is set) and gives what each saw.
    fn join(self) -> Vec<Arc<Mutex<Seen>>> {
        for c in &self.containers {
            c.nudge();
        }
        for c in self.containers {
            c.join();
        }
        for t in &self.threads {
            t.thread().unpark();
        }
        for t in self.threads {
            let _ = t.join();
        }
        self.seen
    }
}

/// `ports:N`: the producer publishes each frame on an output port that N consumer
/// containers' inputs read, woken by the input's notifier.
fn ports_producer(
    n: usize,
    source: Vec<u8>,
    consumers: &mut Consumers,
) -> Result<(Arc<OutputPort<Image>>, Step), String> {
    let out = Arc::new(OutputPort::<Image>::with_init("camera/image", || Image {
        seq: 0,
        data: vec![0; FRAME_BYTES],
    }));
    for i in 0..n {
        let input = InputPort::<Image>::new(format!("viewer{i}/image"));
        connect(&*out, &input, ConnectOptions::default()).map_err(|e| e.to_string())?;
        let wakeup = Wakeup::new();
        let notifier: Notifier = wakeup.clone();
        input
            .set_notifier(notifier)
            .map_err(|_| "input already has a notifier".to_string())?;
        let read = move || {
            if !input.take_changed() {
                return None;
            }
            let img = input.get();
            if img.data.is_empty() {
                return None;
            }
            // One byte, somewhere else in every frame: a real read of the
            // shared buffer. `img` is dropped on return, so the buffer can go
            // back to the pool at once.
            let byte = img.data[(img.seq as usize).wrapping_mul(4099) % img.data.len()];
            Some((img.seq, byte))
        };
        consumers.add(i, wakeup, Box::new(read))?;
    }
    let port = Arc::clone(&out);
    let mut seq = 0u64;
    let step = Step::new("camera/producer (update)", move || {
        seq += 1;
        out.publish_with(|img| {
            // Reused buffers already have the capacity: this is one memcpy.
            img.data.clear();
            img.data.extend_from_slice(&source);
            img.seq = seq;
        });
    });
    Ok((port, step))
}

/// `wakeups:N`: the producer copies the frame, counts it and wakes N consumer
/// containers directly.
fn wakeups_producer(n: usize, source: Vec<u8>, consumers: &mut Consumers) -> Result<Step, String> {
    let frame = Arc::new(AtomicU64::new(0));
    let mut wakeups = Vec::new();
    for i in 0..n {
        let wakeup = Wakeup::new();
        wakeups.push(Arc::clone(&wakeup));
        let (frame, mut last) = (Arc::clone(&frame), 0);
        let read = move || {
            let seq = frame.load(Ordering::Acquire);
            (seq != last).then(|| {
                last = seq;
                (seq, 0)
            })
        };
        consumers.add(i, wakeup, Box::new(read))?;
    }
    let mut dst = vec![0u8; FRAME_BYTES];
    Ok(Step::new("camera/producer (wakeups)", move || {
        dst.copy_from_slice(&source);
        std::hint::black_box(&mut dst);
        frame.fetch_add(1, Ordering::Release);
        for w in &wakeups {
            w.notify();
        }
    }))
}

/// `threads:N`: the producer copies the frame, counts it and unparks N plain threads.
fn threads_producer(n: usize, source: Vec<u8>, consumers: &mut Consumers) -> Result<Step, String> {
    let frame = Arc::new(AtomicU64::new(0));
    for _ in 0..n {
        let (frame, stop, window) = (
            Arc::clone(&frame),
            Arc::clone(&consumers.stop),
            Arc::clone(&consumers.window),
        );
        let s = Arc::new(Mutex::new(Seen::default()));
        consumers.seen.push(Arc::clone(&s));
        let thread = std::thread::Builder::new()
            .name("viewer".into())
            .spawn(move || {
                let mut last = 0;
                while !stop.load(Ordering::Relaxed) {
                    std::thread::park();
                    let seq = frame.load(Ordering::Acquire);
                    if seq != last {
                        last = seq;
                        count(&s, &window, seq, 0);
                    }
                }
            })
            .map_err(|e| format!("cannot start a thread: {e}"))?;
        consumers.threads.push(thread);
    }
    let unpark: Vec<std::thread::Thread> = (consumers.threads.iter())
        .map(|t| t.thread().clone())
        .collect();
    let mut dst = vec![0u8; FRAME_BYTES];
    Ok(Step::new("camera/producer (threads)", move || {
        dst.copy_from_slice(&source);
        std::hint::black_box(&mut dst);
        frame.fetch_add(1, Ordering::Release);
        for t in &unpark {
            t.unpark();
        }
    }))
}

/// Frames per second between the first and the last frame seen in the window (not
/// frames / window, which is off by up to one frame in 50 × window).
fn rate(s: &Seen, wall_s: f64) -> f64 {
    if s.frames >= 2 {
        (s.frames - 1) as f64 * 1e9 / (s.last_ns - s.first_ns) as f64
    } else {
        s.frames as f64 / wall_s
    }
}

/// The consumers' mean and lowest frame rates, and the frames they missed.
fn consumer_rates(seen: &[Arc<Mutex<Seen>>], wall_s: f64) -> (f64, f64, u64) {
    let mut fps: Vec<f64> = Vec::new();
    let mut missed = 0;
    for s in seen {
        let s = s.lock().unwrap_or_else(|e| e.into_inner());
        missed += s.missed;
        fps.push(rate(&s, wall_s));
        std::hint::black_box(s.checksum);
    }
    if fps.is_empty() {
        (0.0, 0.0, missed)
    } else {
        (
            fps.iter().sum::<f64>() / fps.len() as f64,
            fps.iter().copied().fold(f64::INFINITY, f64::min),
            missed,
        )
    }
}

/// Counts frame `seq` if it arrived inside the measurement window.
fn count(seen: &Mutex<Seen>, window: &Window, seq: u64, byte: u8) {
    let now = window.now();
    let mut s = seen.lock().unwrap_or_else(|e| e.into_inner());
    if window.contains(now) {
        if s.frames == 0 {
            s.first_ns = now;
        } else {
            s.missed += seq.saturating_sub(s.last_seq + 1);
        }
        s.frames += 1;
        s.last_ns = now;
    }
    s.last_seq = seq;
    s.checksum = s.checksum.wrapping_add(u64::from(byte));
}

/// A consumer's read of new data: `(frame number, one byte of it)`, or `None` when
/// nothing new arrived.
type Reader = Box<dyn FnMut() -> Option<(u64, u8)> + Send>;

/// Consumer `i`: a data-triggered container woken by `wakeup`, whose one step calls
/// `read` and counts the frames inside the measurement window.
fn consumer(
    i: usize,
    wakeup: Arc<Wakeup>,
    mut read: Reader,
    window: &Arc<Window>,
    stop: &Arc<AtomicBool>,
) -> Result<(RunningContainer, Arc<Mutex<Seen>>), String> {
    let seen = Arc::new(Mutex::new(Seen::default()));
    let (s, w) = (Arc::clone(&seen), Arc::clone(window));
    let step = Step::new(format!("viewer{i}/count (update)"), move || {
        if let Some((seq, byte)) = read() {
            count(&s, &w, seq, byte);
        }
    });
    let running = ThreadContainer::new(format!("viewer{i}"), Trigger::Data(wakeup), vec![step])
        .spawn(ThreadOptions::default(), Arc::clone(stop), None)
        .map_err(|e| format!("cannot start a thread container: {e}"))?;
    Ok((running, seen))
}
