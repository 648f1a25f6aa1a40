//! Unit tests of the port core, small enough for Miri (which checks the unsafe code:
//! `cargo +nightly miri test -p ferroc-runtime --lib`).

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::thread;
use std::time::Duration;

use super::*;

/// A value that counts how many of its kind are alive, to prove buffers are neither
/// leaked nor freed twice.
#[derive(Debug)]
struct Tracked {
    value: u64,
    live: Arc<AtomicUsize>,
}

impl Tracked {
    fn new(live: &Arc<AtomicUsize>, value: u64) -> Self {
        live.fetch_add(1, Ordering::SeqCst);
        Tracked {
            value,
            live: Arc::clone(live),
        }
    }
}

impl Drop for Tracked {
    fn drop(&mut self) {
        self.live.fetch_sub(1, Ordering::SeqCst);
    }
}

fn tracked_out(live: &Arc<AtomicUsize>) -> OutputPort<Tracked> {
    let live = Arc::clone(live);
    OutputPort::with_init("out", move || Tracked::new(&live, 0))
}

fn set(value: u64) -> impl FnOnce(&mut Tracked) {
    move |t| t.value = value
}

fn opts() -> ConnectOptions {
    ConnectOptions::default()
}

#[test]
fn publish_then_get_on_output_and_input() {
    let out = OutputPort::<[f64; 4]>::new("out");
    let inp = InputPort::<[f64; 4]>::new("in");
    assert_eq!(*out.get(), [0.0; 4]);
    connect(&out, &inp, opts()).unwrap();
    out.publish([1.0, 2.0, 3.0, 4.0]);
    assert_eq!(*inp.get(), [1.0, 2.0, 3.0, 4.0]);
    assert!(
        PortRef::ptr_eq(&out.get(), &inp.get()),
        "zero-copy: same buffer"
    );
    out.publish_with(|m| m[0] = 9.0);
    assert_eq!(inp.get()[0], 9.0);
}

#[test]
fn buffers_are_reused_and_never_leaked() {
    let live = Arc::new(AtomicUsize::new(0));
    {
        let out = tracked_out(&live);
        let inp = InputPort::with_default("in", Tracked::new(&live, 7));
        assert_eq!(inp.get().value, 7);
        connect(&out, &inp, opts()).unwrap();
        for i in 0..50 {
            out.publish_with(set(i));
            assert_eq!(inp.get().value, i);
        }
        // out cell + input cell + one being written: the pool stays tiny.
        assert!(out.stats().buffers <= 3, "{:?}", out.stats());
        let held: Vec<_> = (0..5)
            .map(|i| {
                out.publish_with(set(100 + i));
                inp.get()
            })
            .collect();
        assert!(out.stats().buffers >= 5, "held buffers force growth");
        assert_eq!(
            held.iter().map(|r| r.value).collect::<Vec<_>>(),
            [100, 101, 102, 103, 104]
        );
    }
    assert_eq!(
        live.load(Ordering::SeqCst),
        0,
        "every buffer freed exactly once"
    );
}

#[test]
fn port_refs_outlive_their_ports() {
    let live = Arc::new(AtomicUsize::new(0));
    let kept = {
        let out = tracked_out(&live);
        let inp = InputPort::with_default("in", Tracked::new(&live, 0));
        connect(&out, &inp, opts()).unwrap();
        out.publish_with(set(42));
        let r = inp.get();
        out.publish_with(set(43));
        r
    };
    assert_eq!(kept.value, 42);
    assert_eq!(
        live.load(Ordering::SeqCst),
        1,
        "only the held buffer is alive"
    );
    let clone = kept.clone();
    drop(kept);
    assert_eq!(clone.value, 42);
    drop(clone);
    assert_eq!(live.load(Ordering::SeqCst), 0);
}

#[test]
fn acquired_buffers_go_back_unpublished() {
    let out = OutputPort::<Vec<u8>>::new("out");
    out.publish(vec![1, 2, 3]);
    {
        let mut buf = out.acquire();
        buf.push(4);
    }
    assert_eq!(*out.get(), [1, 2, 3]);
    let mut buf = out.acquire();
    buf.clear();
    buf.extend_from_slice(b"ok");
    buf.publish();
    assert_eq!(*out.get(), *b"ok");
    out.reserve(8);
    assert!(out.stats().buffers >= 8);
}

#[test]
fn fan_out_and_fan_in() {
    let a = OutputPort::<u32>::new("a");
    let b = OutputPort::<u32>::new("b");
    let x = InputPort::<u32>::new("x");
    let y = InputPort::<u32>::new("y");
    connect(&a, &x, opts()).unwrap();
    connect(&a, &y, opts()).unwrap();
    connect(&b, &x, opts()).unwrap();
    assert_eq!(a.connection_count(), 2);
    assert_eq!(x.connection_count(), 2);
    a.publish(1);
    assert_eq!((*x.get(), *y.get()), (1, 1));
    b.publish(2);
    assert_eq!((*x.get(), *y.get()), (2, 1), "last writer wins at x");
    assert_eq!(
        connect(&a, &x, opts()),
        Err(ConnectError::AlreadyConnected {
            output: "a".into(),
            input: "x".into()
        })
    );
    assert!(disconnect(&a, &x));
    assert!(!disconnect(&a, &x));
    a.publish(3);
    assert_eq!((*x.get(), *y.get()), (2, 3));
    drop(y);
    assert_eq!(a.connection_count(), 0, "dropping an input disconnects it");
    drop(b);
    assert_eq!(x.connection_count(), 0, "dropping an output disconnects it");
}

#[test]
fn initial_push_rules() {
    let out = OutputPort::<u32>::new("out");
    let fresh = InputPort::<u32>::with_default("fresh", 5);
    connect(&out, &fresh, opts()).unwrap();
    assert_eq!(
        *fresh.get(),
        5,
        "nothing published yet: the input keeps its default"
    );
    out.publish(7);
    let late = InputPort::<u32>::new("late");
    connect(&out, &late, opts()).unwrap();
    assert_eq!(*late.get(), 7, "initial push of the current value");
    assert!(late.has_changed());
    let other = OutputPort::<u32>::new("other");
    other.publish(1);
    connect(&other, &fresh, opts()).unwrap();
    assert_eq!(
        *fresh.get(),
        7,
        "no initial push into an input with another source"
    );
    let quiet = InputPort::<u32>::new("quiet");
    connect(&out, &quiet, opts().with_initial_push(false)).unwrap();
    assert_eq!(*quiet.get(), 0);
}

#[test]
fn changed_flag() {
    let out = OutputPort::<u8>::new("out");
    let inp = InputPort::<u8>::new("in");
    connect(&out, &inp, opts()).unwrap();
    assert!(!inp.has_changed());
    out.publish(1);
    assert!(inp.has_changed());
    assert!(inp.take_changed());
    assert!(!inp.has_changed());
    assert!(!inp.take_changed());
    assert_eq!(inp.try_pop(), None, "latest-value pop: nothing new");
    out.publish(2);
    assert_eq!(inp.try_pop().as_deref(), Some(&2));
    assert_eq!(inp.try_pop(), None);
}

#[test]
fn queue_drop_oldest_and_drop_newest() {
    let live = Arc::new(AtomicUsize::new(0));
    {
        let out = tracked_out(&live);
        let oldest =
            InputPort::queued_with_default("o", QueueConfig::new(2), Tracked::new(&live, 0));
        let newest = InputPort::queued_with_default(
            "n",
            QueueConfig::new(2).on_full(OnFull::DropNewest),
            Tracked::new(&live, 0),
        );
        connect(&out, &oldest, opts()).unwrap();
        connect(&out, &newest, opts()).unwrap();
        for i in 1..=4 {
            out.publish_with(set(i));
        }
        assert_eq!(oldest.queued_len(), 2);
        assert_eq!(
            oldest.get().value,
            4,
            "a queued input also has a latest value"
        );
        let o: Vec<_> = std::iter::from_fn(|| oldest.try_pop())
            .map(|r| r.value)
            .collect();
        let n: Vec<_> = std::iter::from_fn(|| newest.try_pop())
            .map(|r| r.value)
            .collect();
        assert_eq!(o, [3, 4]);
        assert_eq!(n, [1, 2]);
        out.publish_with(set(5));
        assert_eq!(oldest.pop().value, 5);
        assert!(oldest.pop_timeout(Duration::from_millis(1)).is_none());
    }
    assert_eq!(live.load(Ordering::SeqCst), 0);
}

#[test]
fn queue_block_waits_for_the_consumer() {
    let out = Arc::new(OutputPort::<u32>::new("out"));
    let inp = InputPort::<u32>::queued("in", QueueConfig::new(1).on_full(OnFull::Block));
    connect(&*out, &inp, opts()).unwrap();
    out.publish(1);
    let publisher = {
        let out = Arc::clone(&out);
        thread::spawn(move || {
            out.publish(2);
            out.publish(3);
        })
    };
    let got: Vec<u32> = (0..3).map(|_| *inp.pop()).collect();
    publisher.join().unwrap();
    assert_eq!(got, [1, 2, 3], "block: nothing dropped");
}

#[test]
fn blocked_publisher_is_released_by_disconnect() {
    let out = Arc::new(OutputPort::<u32>::new("out"));
    let inp = InputPort::<u32>::queued("in", QueueConfig::new(1).on_full(OnFull::Block));
    connect(&*out, &inp, opts()).unwrap();
    out.publish(1);
    let publisher = {
        let out = Arc::clone(&out);
        thread::spawn(move || out.publish(2))
    };
    while *inp.get() != 2 {
        thread::yield_now();
    }
    assert!(disconnect(&*out, &inp));
    publisher.join().unwrap();
    assert_eq!(inp.try_pop().as_deref(), Some(&1));
    assert_eq!(
        inp.try_pop(),
        None,
        "the blocked value was dropped, not queued"
    );
}

#[test]
fn blocking_pop_is_woken_by_a_publish() {
    let out = Arc::new(OutputPort::<u32>::new("out"));
    let inp = InputPort::<u32>::queued("in", QueueConfig::new(4));
    connect(&*out, &inp, opts()).unwrap();
    let publisher = {
        let out = Arc::clone(&out);
        thread::spawn(move || {
            thread::sleep(Duration::from_millis(5));
            out.publish(9);
        })
    };
    assert_eq!(*inp.pop(), 9);
    publisher.join().unwrap();
    let latest = InputPort::<u32>::new("latest");
    connect(&*out, &latest, opts().with_initial_push(false)).unwrap();
    let publisher = {
        let out = Arc::clone(&out);
        thread::spawn(move || {
            thread::sleep(Duration::from_millis(5));
            out.publish(10);
        })
    };
    assert_eq!(
        latest.pop_timeout(Duration::from_secs(20)).as_deref(),
        Some(&10)
    );
    publisher.join().unwrap();
}

#[test]
fn notifier_and_wakeup() {
    let out = OutputPort::<u32>::new("out");
    let inp = InputPort::<u32>::new("in");
    let calls = Arc::new(AtomicUsize::new(0));
    let c = Arc::clone(&calls);
    inp.set_notifier(Arc::new(move || {
        c.fetch_add(1, Ordering::SeqCst);
    }))
    .unwrap();
    assert!(inp.set_notifier(Arc::new(|| {})).is_err(), "set once");
    connect(&out, &inp, opts()).unwrap();
    out.publish(1);
    out.publish(2);
    assert_eq!(calls.load(Ordering::SeqCst), 2);

    let wake = Wakeup::new();
    let copy_in = CopyInputPort::<u16>::new("c");
    copy_in.set_notifier(wake.clone()).unwrap();
    let copy_out = CopyOutputPort::<u16>::new("co");
    connect(&copy_out, &copy_in, opts()).unwrap();
    assert!(!wake.wait_timeout(Duration::from_millis(1)));
    copy_out.publish(3);
    wake.wait();
    assert_eq!(copy_in.get(), 3);
}

#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::NoUninit)]
#[repr(C)]
struct Pose {
    x: f64,
    y: f64,
    theta: f32,
    id: u16,
    flags: [u8; 2],
}

#[test]
fn copy_ports() {
    let out = CopyOutputPort::<Pose>::new("pose");
    let inp = CopyInputPort::<Pose>::with_default(
        "in",
        Pose {
            id: 1,
            ..Pose::default()
        },
    );
    connect(&out, &inp, opts()).unwrap();
    assert_eq!(inp.get().id, 1, "no initial push before the first publish");
    let p = Pose {
        x: 1.5,
        y: -2.0,
        theta: 0.25,
        id: 7,
        flags: [1, 2],
    };
    out.publish(p);
    assert_eq!(out.get(), p);
    assert_eq!(inp.get(), p);
    assert!(inp.take_changed());
    assert_eq!(inp.try_pop(), None);

    let late = CopyInputPort::<Pose>::new("late");
    connect(&out, &late, opts()).unwrap();
    assert_eq!(late.get(), p, "initial push");

    let q = CopyInputPort::<Pose>::queued("q", QueueConfig::new(2).on_full(OnFull::DropNewest));
    connect(&out, &q, opts()).unwrap();
    for id in 10..13 {
        out.publish(Pose { id, ..p });
    }
    let ids: Vec<_> = std::iter::from_fn(|| q.try_pop()).map(|p| p.id).collect();
    assert_eq!(ids, [10, 11]);
    assert_eq!(q.get().id, 12);
    assert!(q.pop_timeout(Duration::from_millis(1)).is_none());
    assert!(disconnect(&out, &q));

    // Tiny and zero-sized values take the same path.
    let b = CopyOutputPort::<bool>::new("b");
    let bi = CopyInputPort::<bool>::new("bi");
    connect(&b, &bi, opts()).unwrap();
    b.publish(true);
    assert!(bi.get());
    let unit = CopyOutputPort::<()>::new("unit");
    let unit_in = CopyInputPort::<()>::new("unit_in");
    connect(&unit, &unit_in, opts()).unwrap();
    unit.publish(());
    assert!(
        unit_in.try_pop().is_some(),
        "a unit publish still counts as an event"
    );
}

#[test]
fn concurrent_publishers_and_readers() {
    // Small enough for Miri; the stress test in tests/ports_stress.rs goes further.
    let live = Arc::new(AtomicUsize::new(0));
    {
        let a = Arc::new(tracked_out(&live));
        let b = Arc::new(tracked_out(&live));
        let inp = Arc::new(InputPort::with_default("in", Tracked::new(&live, 0)));
        connect(&*a, &*inp, opts()).unwrap();
        connect(&*b, &*inp, opts()).unwrap();
        let n = if cfg!(miri) { 20 } else { 2000 };
        let pubs: Vec<_> = [(Arc::clone(&a), 1u64), (Arc::clone(&b), 1 << 32)]
            .into_iter()
            .map(|(out, base)| {
                thread::spawn(move || {
                    for i in 0..n {
                        out.publish_with(set(base + i));
                    }
                })
            })
            .collect();
        let reader = {
            let inp = Arc::clone(&inp);
            thread::spawn(move || {
                let mut last = [0u64; 2];
                for _ in 0..n {
                    let v = inp.get().value;
                    let src = usize::from(v >= 1 << 32);
                    let seq = v & 0xFFFF_FFFF;
                    assert!(
                        v == 0 || seq >= last[src],
                        "values of one source never go back"
                    );
                    last[src] = seq;
                }
            })
        };
        for p in pubs {
            p.join().unwrap();
        }
        reader.join().unwrap();
        let copy_out = Arc::new(CopyOutputPort::<[u64; 3]>::new("c"));
        let copy_in = CopyInputPort::<[u64; 3]>::new("ci");
        connect(&*copy_out, &copy_in, opts()).unwrap();
        let w = {
            let o = Arc::clone(&copy_out);
            thread::spawn(move || (0..n).for_each(|i| o.publish([i, i, i])))
        };
        for _ in 0..n {
            let [x, y, z] = copy_in.get();
            assert!(x == y && y == z, "never torn");
        }
        w.join().unwrap();
    }
    assert_eq!(live.load(Ordering::SeqCst), 0);
}

/// A value that logs its drop.
struct Logged(u32, Arc<std::sync::Mutex<Vec<String>>>);

impl Drop for Logged {
    fn drop(&mut self) {
        self.1.lock().unwrap().push(format!("drop {}", self.0));
    }
}

/// `publish` drops the old value of the buffer it reuses after the inputs were handed
/// the new one: an input's notifier may run the reader's cycle (`wait="inline"`), and
/// dropping a received value (a shared-memory buffer, its bookkeeping) before that only
/// delays the reader (bench/README.md, b3-parts).
#[test]
fn publish_drops_the_reused_buffers_old_value_after_the_inputs_have_the_new_one() {
    let log = Arc::new(std::sync::Mutex::new(Vec::new()));
    let l = Arc::clone(&log);
    let out = OutputPort::with_init("out", move || Logged(0, Arc::clone(&l)));
    let inp = InputPort::with_default("in", Logged(0, Arc::clone(&log)));
    let l = Arc::clone(&log);
    inp.set_notifier(Arc::new(move || l.lock().unwrap().push("notify".into())))
        .map_err(|_| ())
        .unwrap();
    connect(&out, &inp, opts()).unwrap();
    for n in 1..=5 {
        log.lock().unwrap().push(format!("publish {n}"));
        out.publish(Logged(n, Arc::clone(&log)));
        assert_eq!(inp.get().0, n);
    }
    let log = log.lock().unwrap().clone();
    for (i, entry) in log.iter().enumerate() {
        if entry.starts_with("publish") {
            assert_eq!(log[i + 1], "notify", "{log:?}");
        }
    }
    assert!(log.iter().any(|e| e.starts_with("drop ")), "{log:?}");
}
