//! Model-checked tests of the port core with loom: every interleaving (up to a
//! preemption bound) of small scenarios, with loom's atomics, mutexes and Arcs inside
//! the crate (see `src/sync.rs`).
//!
//! Run: `RUSTFLAGS="--cfg loom" cargo test -p ferroc-runtime --release --test loom_ports`
//! (`LOOM_MAX_PREEMPTIONS` overrides the default bound of 3; the suite takes seconds
//! at 3 and about half a minute at 4).
//!
//! Buffer contents are `Probe`s: loom cells that report any write not ordered with a
//! read (a buffer refilled while a reader still sees it), and that count how many
//! buffers are alive (a buffer lost or freed twice).
#![cfg(loom)]

use std::sync::atomic::{AtomicUsize, Ordering};

use ferroc_ports::port::{
    connect, disconnect, ConnectOptions, CopyInputPort, CopyOutputPort, InputPort, OnFull,
    OutputPort, QueueConfig,
};
use loom::cell::UnsafeCell;
use loom::sync::Arc;
use loom::thread;

/// A buffer value whose every access is checked by loom.
struct Probe {
    value: UnsafeCell<u64>,
    live: Arc<AtomicUsize>,
}

// SAFETY: the ports hand out `&Probe` to several threads; whether those accesses are
// properly ordered is exactly what loom checks through the inner cell.
unsafe impl Sync for Probe {}

impl Probe {
    fn new(live: &Arc<AtomicUsize>) -> Self {
        live.fetch_add(1, Ordering::SeqCst);
        Probe {
            value: UnsafeCell::new(0),
            live: Arc::clone(live),
        }
    }
    fn get(&self) -> u64 {
        self.value.with(|p| unsafe { *p })
    }
    fn set(&mut self, v: u64) {
        self.value.with_mut(|p| unsafe { *p = v })
    }
}

impl Drop for Probe {
    fn drop(&mut self) {
        self.live.fetch_sub(1, Ordering::SeqCst);
    }
}

fn model(f: impl Fn() + Sync + Send + 'static) {
    let mut builder = loom::model::Builder::new();
    if builder.preemption_bound.is_none() {
        builder.preemption_bound = Some(3);
    }
    builder.check(f);
}

fn probe_output(live: &Arc<AtomicUsize>) -> OutputPort<Probe> {
    let live = Arc::clone(live);
    OutputPort::with_init("out", move || Probe::new(&live))
}

fn probe_input(live: &Arc<AtomicUsize>) -> InputPort<Probe> {
    InputPort::with_default("in", Probe::new(live))
}

/// A publisher recycles buffers while a reader takes references: the reader never sees
/// a buffer being refilled, values never go back, and every buffer is freed once.
#[test]
fn publish_races_get() {
    model(|| {
        let live = Arc::new(AtomicUsize::new(0));
        let out = Arc::new(probe_output(&live));
        let inp = Arc::new(probe_input(&live));
        connect(&*out, &*inp, ConnectOptions::default()).unwrap();
        let publisher = {
            let out = Arc::clone(&out);
            thread::spawn(move || {
                for v in 1..=2 {
                    out.publish_with(|p| p.set(v));
                }
            })
        };
        let first = inp.get().get();
        let second = inp.get();
        assert!(second.get() >= first);
        drop(second);
        publisher.join().unwrap();
        assert_eq!(inp.get().get(), 2);
        assert_eq!(out.get().get(), 2);
        drop(inp);
        drop(out);
        assert_eq!(live.load(Ordering::SeqCst), 0);
    });
}

/// Readers of the output's own value race a publisher that must reuse the buffer they
/// read (the pool has two buffers and the reader holds one at most briefly).
#[test]
fn output_get_races_buffer_reuse() {
    model(|| {
        let live = Arc::new(AtomicUsize::new(0));
        let out = Arc::new(probe_output(&live));
        out.reserve(2);
        let publisher = {
            let out = Arc::clone(&out);
            thread::spawn(move || {
                for v in 1..=3 {
                    out.publish_with(|p| p.set(v));
                }
            })
        };
        let a = out.get().get();
        let b = out.get().get();
        assert!(b >= a);
        publisher.join().unwrap();
        drop(out);
        assert_eq!(live.load(Ordering::SeqCst), 0);
    });
}

/// Two threads publish on one output: concurrent pops from the pool's free list.
#[test]
fn concurrent_publishers_share_a_pool() {
    model(|| {
        let live = Arc::new(AtomicUsize::new(0));
        let out = Arc::new(probe_output(&live));
        out.reserve(3);
        let other = {
            let out = Arc::clone(&out);
            thread::spawn(move || out.publish_with(|p| p.set(1)))
        };
        out.publish_with(|p| p.set(2));
        other.join().unwrap();
        let v = out.get().get();
        assert!(v == 1 || v == 2);
        drop(out);
        assert_eq!(live.load(Ordering::SeqCst), 0);
    });
}

/// The last handles of a pool go away (ports dropped) while another thread still holds
/// and then drops a reference: the pool is orphaned exactly once and nothing leaks.
#[test]
fn ports_dropped_while_a_reference_is_released() {
    model(|| {
        let live = Arc::new(AtomicUsize::new(0));
        let out = probe_output(&live);
        let inp = probe_input(&live);
        connect(&out, &inp, ConnectOptions::default()).unwrap();
        out.publish_with(|p| p.set(1));
        let held = inp.get();
        let reader = thread::spawn(move || {
            assert_eq!(held.get(), 1);
            drop(held);
        });
        out.publish_with(|p| p.set(2));
        drop(out);
        drop(inp);
        reader.join().unwrap();
        assert_eq!(live.load(Ordering::SeqCst), 0);
    });
}

/// Connecting races a publish: whichever comes first, the new input ends up with the
/// published value (seen by the publisher's list load or by the initial push), and a
/// disconnect during the publish loses or delivers the value but leaks nothing.
#[test]
fn connect_and_disconnect_race_publish() {
    model(|| {
        let live = Arc::new(AtomicUsize::new(0));
        let out = Arc::new(probe_output(&live));
        let old = Arc::new(probe_input(&live));
        let new = Arc::new(probe_input(&live));
        connect(&*out, &*old, ConnectOptions::default()).unwrap();
        let publisher = {
            let out = Arc::clone(&out);
            thread::spawn(move || out.publish_with(|p| p.set(7)))
        };
        connect(&*out, &*new, ConnectOptions::default()).unwrap();
        assert!(disconnect(&*out, &*old));
        publisher.join().unwrap();
        assert_eq!(new.get().get(), 7, "a concurrent publish is never missed");
        let o = old.get().get();
        assert!(o == 0 || o == 7);
        drop(out);
        drop(old);
        drop(new);
        assert_eq!(live.load(Ordering::SeqCst), 0);
    });
}

/// Two publishers read the input list while it is replaced twice: the retired lists are
/// freed only when no publisher can still use them (by the writer or by the last
/// publisher leaving).
#[test]
fn connection_lists_retired_under_two_publishers() {
    model(|| {
        let out = Arc::new(OutputPort::<u64>::new("out"));
        let a = Arc::new(InputPort::<u64>::new("a"));
        let b = Arc::new(InputPort::<u64>::new("b"));
        connect(&*out, &*a, ConnectOptions::default()).unwrap();
        let publishers: Vec<_> = (1..=2)
            .map(|v| {
                let out = Arc::clone(&out);
                thread::spawn(move || out.publish(v))
            })
            .collect();
        connect(
            &*out,
            &*b,
            ConnectOptions::default().with_initial_push(false),
        )
        .unwrap();
        assert!(disconnect(&*out, &*a));
        for p in publishers {
            p.join().unwrap();
        }
        // Concurrent publishers on one output are not ordered with each other: b may
        // miss one (it connected without initial push) and hold the other.
        assert!(*b.get() <= 2);
        assert!(*out.get() == 1 || *out.get() == 2);
    });
}

/// A drop-oldest queue: the publisher displaces queued buffers while the consumer pops
/// them; every buffer is accounted for.
#[test]
fn queue_drop_oldest_races_pop() {
    model(|| {
        let live = Arc::new(AtomicUsize::new(0));
        let out = Arc::new(probe_output(&live));
        let inp = Arc::new(InputPort::queued_with_default(
            "q",
            QueueConfig::new(1).on_full(OnFull::DropOldest),
            Probe::new(&live),
        ));
        connect(&*out, &*inp, ConnectOptions::default()).unwrap();
        let publisher = {
            let out = Arc::clone(&out);
            thread::spawn(move || {
                out.publish_with(|p| p.set(1));
                out.publish_with(|p| p.set(2));
            })
        };
        let first = inp.try_pop().map(|r| r.get());
        publisher.join().unwrap();
        let rest = inp.try_pop().map(|r| r.get());
        match (first, rest) {
            (None, Some(2)) | (Some(1), Some(2)) | (Some(2), None) => {}
            other => panic!("unexpected pops {other:?}"),
        }
        drop(out);
        drop(inp);
        assert_eq!(live.load(Ordering::SeqCst), 0);
    });
}

/// A blocking reader is woken by a delivery (no lost wakeup: loom reports a deadlock
/// if the reader could sleep forever).
#[test]
fn blocking_pop_is_not_lost() {
    model(|| {
        let out = Arc::new(OutputPort::<u64>::new("out"));
        let inp = Arc::new(InputPort::<u64>::queued("q", QueueConfig::new(1)));
        connect(&*out, &*inp, ConnectOptions::default()).unwrap();
        let publisher = {
            let out = Arc::clone(&out);
            thread::spawn(move || out.publish(5))
        };
        assert_eq!(*inp.pop(), 5);
        publisher.join().unwrap();
    });
}

/// Seqlock cells: a reader never sees a torn value while a writer rewrites the slots,
/// and two outputs writing into one input at once leave one of their values.
#[test]
fn copy_ports_never_tear() {
    model(|| {
        let a = Arc::new(CopyOutputPort::<[u64; 2]>::new("a"));
        let b = Arc::new(CopyOutputPort::<[u64; 2]>::new("b"));
        let inp = Arc::new(CopyInputPort::<[u64; 2]>::new("in"));
        connect(&*a, &*inp, ConnectOptions::default()).unwrap();
        connect(&*b, &*inp, ConnectOptions::default()).unwrap();
        let ta = {
            let a = Arc::clone(&a);
            thread::spawn(move || {
                a.publish([1, 1]);
                a.publish([2, 2]);
            })
        };
        let tb = {
            let b = Arc::clone(&b);
            thread::spawn(move || b.publish([3, 3]))
        };
        let [x, y] = inp.get();
        assert_eq!(x, y, "torn read");
        ta.join().unwrap();
        tb.join().unwrap();
        let [x, y] = inp.get();
        assert!(x == y && (x == 2 || x == 3), "final value {x},{y}");
    });
}
