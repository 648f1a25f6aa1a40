//! Stress: several publishers and readers while another thread connects and
//! disconnects ports all the time. Asserts that values never tear or go back, and that
//! no buffer is lost or leaked (every buffer value counts itself while alive).
//!
//! Bounded by iteration counts, not time, and small enough for `cargo test` in debug.

// A scenario reads as one story from start to end; the function-length rule is for
// the code under test.
#![allow(clippy::too_many_lines)]
#![cfg(not(loom))]

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::thread;
use std::time::Duration;

use ferroc_ports::port::{
    connect, disconnect, ConnectOptions, CopyInputPort, CopyOutputPort, InputPort, OnFull,
    OutputPort, QueueConfig,
};

const PUBLISHES: u64 = 20_000;

/// A buffer value: `stamp` = source << 32 | sequence, repeated in `check` so a torn or
/// refilled-while-read buffer is visible; `live` counts buffers alive.
struct Stamped {
    stamp: u64,
    check: Vec<u64>,
    live: Arc<AtomicUsize>,
}

impl Stamped {
    fn new(live: &Arc<AtomicUsize>) -> Self {
        live.fetch_add(1, Ordering::SeqCst);
        Stamped {
            stamp: 0,
            check: vec![0; 8],
            live: Arc::clone(live),
        }
    }
    fn verify(&self) -> u64 {
        assert!(
            self.check.iter().all(|&c| c == self.stamp),
            "buffer changed while held"
        );
        self.stamp
    }
}

impl Drop for Stamped {
    fn drop(&mut self) {
        self.live.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Per-source sequences seen by one reader never decrease.
#[derive(Default)]
struct Monotonic([u64; 2]);

impl Monotonic {
    fn see(&mut self, stamp: u64) {
        if stamp == 0 {
            return;
        }
        let (src, seq) = ((stamp >> 32) as usize - 1, stamp & 0xFFFF_FFFF);
        assert!(
            seq >= self.0[src],
            "source {src} went back: {seq} < {}",
            self.0[src]
        );
        self.0[src] = seq;
    }
}

#[test]
fn publishers_readers_and_rewiring_under_load() {
    let live = Arc::new(AtomicUsize::new(0));
    let max_buffers;
    {
        let outs: Vec<Arc<OutputPort<Stamped>>> = (0..2)
            .map(|i| {
                let live = Arc::clone(&live);
                Arc::new(OutputPort::with_init(format!("out{i}"), move || {
                    Stamped::new(&live)
                }))
            })
            .collect();
        let latest: Vec<Arc<InputPort<Stamped>>> = (0..2)
            .map(|i| {
                Arc::new(InputPort::with_default(
                    format!("in{i}"),
                    Stamped::new(&live),
                ))
            })
            .collect();
        let queued = Arc::new(InputPort::queued_with_default(
            "q",
            QueueConfig::new(4),
            Stamped::new(&live),
        ));
        let blocking = Arc::new(InputPort::queued_with_default(
            "b",
            QueueConfig::new(2).on_full(OnFull::Block),
            Stamped::new(&live),
        ));
        for out in &outs {
            connect(&**out, &*blocking, ConnectOptions::default()).unwrap();
        }
        let done = Arc::new(AtomicBool::new(false));
        let mut threads = Vec::new();

        for (src, out) in outs.iter().enumerate() {
            let out = Arc::clone(out);
            threads.push(thread::spawn(move || {
                for seq in 1..=PUBLISHES {
                    let stamp = ((src as u64 + 1) << 32) | seq;
                    out.publish_with(|s| {
                        s.stamp = stamp;
                        s.check.iter_mut().for_each(|c| *c = stamp);
                    });
                    assert_eq!(
                        out.get().verify(),
                        stamp,
                        "one publisher: get sees its value"
                    );
                }
            }));
        }
        for inp in &latest {
            let inp = Arc::clone(inp);
            let done = Arc::clone(&done);
            threads.push(thread::spawn(move || {
                let mut seen = Monotonic::default();
                let mut held = Vec::new();
                while !done.load(Ordering::SeqCst) {
                    let v = inp.get();
                    seen.see(v.verify());
                    held.push(v);
                    if held.len() > 5 {
                        held.remove(0);
                    }
                    held.iter().for_each(|h| {
                        h.verify();
                    });
                }
            }));
        }
        for q in [&queued, &blocking] {
            let q = Arc::clone(q);
            let done = Arc::clone(&done);
            threads.push(thread::spawn(move || {
                let mut seen = Monotonic::default();
                while !done.load(Ordering::SeqCst) {
                    if let Some(v) = q.pop_timeout(Duration::from_millis(1)) {
                        seen.see(v.verify());
                    }
                }
                while q.try_pop().is_some() {}
            }));
        }
        {
            // Rewiring: connect and disconnect every output/latest-or-queued input pair.
            let outs = outs.clone();
            let ins: Vec<Arc<InputPort<Stamped>>> = latest
                .iter()
                .cloned()
                .chain([Arc::clone(&queued)])
                .collect();
            let done = Arc::clone(&done);
            threads.push(thread::spawn(move || {
                let mut round = 0usize;
                while !done.load(Ordering::SeqCst) {
                    let out = &outs[round % 2];
                    let inp = &ins[(round / 2) % ins.len()];
                    if round % 3 == 0 {
                        disconnect(&**out, &**inp);
                    } else {
                        let _ = connect(&**out, &**inp, ConnectOptions::default());
                    }
                    round += 1;
                    thread::yield_now();
                }
            }));
        }
        let (publishers, others) = threads.split_at_mut(2);
        for p in publishers
            .iter_mut()
            .map(|t| std::mem::replace(t, thread::spawn(|| {})))
        {
            p.join().unwrap();
        }
        done.store(true, Ordering::SeqCst);
        for t in others
            .iter_mut()
            .map(|t| std::mem::replace(t, thread::spawn(|| {})))
        {
            t.join().unwrap();
        }
        for t in threads {
            t.join().unwrap();
        }
        max_buffers = outs.iter().map(|o| o.stats().buffers).max().unwrap_or(0);
        // Held: 5 per latest reader, 4+2 queued, cells, one in flight per publisher.
        assert!(max_buffers <= 32, "pool grew to {max_buffers} buffers");
        assert!(live.load(Ordering::SeqCst) > 0);
    }
    assert_eq!(
        live.load(Ordering::SeqCst),
        0,
        "buffers leaked (max pool {max_buffers})"
    );
}

#[test]
fn copy_ports_under_load_and_rewiring() {
    let outs: Vec<Arc<CopyOutputPort<[u64; 4]>>> = (0..2)
        .map(|i| Arc::new(CopyOutputPort::new(format!("c{i}"))))
        .collect();
    let inp = Arc::new(CopyInputPort::<[u64; 4]>::new("ci"));
    let queued = Arc::new(CopyInputPort::<[u64; 4]>::queued("cq", QueueConfig::new(8)));
    let done = Arc::new(AtomicBool::new(false));
    let mut threads = Vec::new();
    for (src, out) in outs.iter().enumerate() {
        let out = Arc::clone(out);
        threads.push(thread::spawn(move || {
            for seq in 1..=PUBLISHES {
                let stamp = ((src as u64 + 1) << 32) | seq;
                out.publish([stamp; 4]);
            }
        }));
    }
    for port in [&inp, &queued] {
        let port = Arc::clone(port);
        let done = Arc::clone(&done);
        threads.push(thread::spawn(move || {
            // Popped (oldest first) and latest values are two separate orders.
            let (mut popped, mut latest) = (Monotonic::default(), Monotonic::default());
            while !done.load(Ordering::SeqCst) {
                let (v, seen) = match port.try_pop() {
                    Some(v) if port.queue_config().is_some() => (v, &mut popped),
                    Some(v) => (v, &mut latest),
                    None => (port.get(), &mut latest),
                };
                assert!(v.iter().all(|&x| x == v[0]), "torn value {v:?}");
                seen.see(v[0]);
            }
        }));
    }
    {
        let outs = outs.clone();
        let (inp, queued) = (Arc::clone(&inp), Arc::clone(&queued));
        let done = Arc::clone(&done);
        threads.push(thread::spawn(move || {
            let mut round = 0usize;
            while !done.load(Ordering::SeqCst) {
                let out = &outs[round % 2];
                let port = if round % 4 < 2 { &inp } else { &queued };
                if round % 3 == 0 {
                    disconnect(&**out, &**port);
                } else {
                    let _ = connect(&**out, &**port, ConnectOptions::default());
                }
                round += 1;
                thread::yield_now();
            }
        }));
    }
    let rest = threads.split_off(2);
    for t in threads {
        t.join().unwrap();
    }
    done.store(true, Ordering::SeqCst);
    for t in rest {
        t.join().unwrap();
    }
}
