//! Tests of connections local to one thread container (`local.rs`, `copy_local.rs`),
//! small enough for Miri. The "container" here is a thread holding a [`Session`].

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{mpsc, Arc};
use std::thread;

use super::*;

fn pair(default: f64) -> (CopyOutputPort<f64>, CopyInputPort<f64>) {
    let out = CopyOutputPort::<f64>::new("out");
    let inp = CopyInputPort::with_default("in", default);
    connect(&out, &inp, ConnectOptions::default()).unwrap();
    (out, inp)
}

#[test]
fn a_local_connection_reads_what_was_published_and_sees_each_change_once() {
    let (out, inp) = pair(7.0);
    let home = Arc::new(Home::new());
    assert!(make_local(&out, &inp, &home));
    let session = Home::enter(&home);
    // Before the first publish the input keeps its own default, as on the lock-free path.
    assert_eq!(inp.get(), 7.0);
    assert!(!inp.has_changed());
    out.publish(1.5);
    assert!(inp.has_changed());
    assert_eq!(inp.get(), 1.5);
    assert!(inp.take_changed());
    assert!(!inp.take_changed());
    out.publish(2.5);
    out.publish(3.5);
    assert_eq!(inp.get(), 3.5);
    assert_eq!(out.get(), 3.5);
    assert!(inp.take_changed());
    assert!(!inp.has_changed());
    drop(session);
}

#[test]
fn a_delivery_not_taken_before_the_connection_became_local_is_still_seen() {
    let (out, inp) = pair(0.0);
    out.publish(4.0);
    let home = Arc::new(Home::new());
    assert!(make_local(&out, &inp, &home));
    let _session = Home::enter(&home);
    assert_eq!(inp.get(), 4.0);
    assert!(inp.take_changed());
    assert!(!inp.take_changed());
}

#[test]
fn queued_inputs_and_inputs_with_two_sources_stay_lock_free() {
    let home = Arc::new(Home::new());
    let out = CopyOutputPort::<f64>::new("out");
    let queued = CopyInputPort::<f64>::queued("q", QueueConfig::new(2).on_full(OnFull::DropOldest));
    connect(&out, &queued, ConnectOptions::default()).unwrap();
    assert!(!make_local(&out, &queued, &home));
    let other = CopyOutputPort::<f64>::new("other");
    let (out2, inp2) = pair(0.0);
    connect(&other, &inp2, ConnectOptions::default()).unwrap();
    assert!(!make_local(&out2, &inp2, &home));
    // Not connected at all: nothing to make local.
    let loose = CopyInputPort::<f64>::new("loose");
    assert!(!make_local(&out, &loose, &home));
    // Lock-free ports work from any thread, without a session.
    out.publish(1.0);
    assert_eq!(queued.try_pop(), Some(1.0));
}

#[test]
fn an_output_local_to_one_home_is_not_made_local_to_another() {
    let out = CopyOutputPort::<f64>::new("out");
    let a = CopyInputPort::<f64>::new("a");
    let b = CopyInputPort::<f64>::new("b");
    connect(&out, &a, ConnectOptions::default()).unwrap();
    connect(&out, &b, ConnectOptions::default()).unwrap();
    let (one, two) = (Arc::new(Home::new()), Arc::new(Home::new()));
    assert!(make_local(&out, &a, &one));
    assert!(!make_local(&out, &b, &two));
    // b is still fed on the lock-free path, by the session of `one`.
    let session = Home::enter(&one);
    out.publish(5.0);
    assert_eq!(a.get(), 5.0);
    assert_eq!(b.get(), 5.0);
    drop(session);
}

#[test]
fn using_a_local_port_from_another_thread_panics_instead_of_racing() {
    let (out, inp) = pair(0.0);
    let home = Arc::new(Home::new());
    assert!(make_local(&out, &inp, &home));
    // No session at all: this thread may not touch the cells either.
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| out.publish(1.0)));
    let message = *outcome.unwrap_err().downcast::<String>().unwrap();
    assert!(message.contains("`out` is connected inside its thread container"));
    let _session = Home::enter(&home);
    out.publish(2.0);
    let read = thread::scope(|s| s.spawn(|| inp.get()).join());
    assert!(read.is_err(), "a read from another thread must panic");
    assert_eq!(inp.get(), 2.0);
}

/// A reader from outside the container connects while the container runs: the change
/// is applied at the container's next cycle boundary, and from then on the output
/// feeds the new reader on the lock-free path while its local reader keeps reading
/// directly. Disconnecting the local reader from outside works the same way.
#[test]
fn a_connection_leaving_the_container_falls_back_to_the_lock_free_path() {
    let (out, inp) = pair(0.0);
    let (out_handle, in_handle) = (out.handle(), inp.handle());
    let home = Arc::new(Home::new());
    assert!(make_local(&out, &inp, &home));
    let stop = Arc::new(AtomicBool::new(false));
    let published = Arc::new(AtomicU64::new(0));
    let container = {
        let (home, stop, published) = (home.clone(), stop.clone(), published.clone());
        thread::spawn(move || {
            let session = Home::enter(&home);
            let mut n = 0.0;
            let mut followed = true;
            while !stop.load(Ordering::Relaxed) {
                session.boundary();
                n += 1.0;
                out.publish(n);
                followed &= inp.get() == n || inp.connection_count() == 0;
                published.store(n as u64, Ordering::Release);
                thread::yield_now();
            }
            drop(session);
            (out, inp, followed)
        })
    };
    let wait_for = |at_least: u64| {
        while published.load(Ordering::Acquire) < at_least {
            thread::yield_now();
        }
    };
    wait_for(1);
    let probe = CopyInputPort::<f64>::new("probe");
    out_handle
        .connect(&probe.handle(), ConnectOptions::default())
        .unwrap();
    // The change waited for a boundary, so the initial push carried a value the
    // container had published, never the stale shared one (0).
    let first = probe.get();
    assert!(first >= 1.0, "probe read {first}");
    let seen = published.load(Ordering::Acquire);
    wait_for(seen + 3);
    assert!(
        probe.get() > first,
        "the probe follows on the lock-free path"
    );
    // The local reader leaves too: from the next boundary on it reads its own cell.
    assert!(out_handle.disconnect(&in_handle));
    let after = published.load(Ordering::Acquire);
    wait_for(after + 3);
    stop.store(true, Ordering::Relaxed);
    let (out, inp, followed) = container.join().unwrap();
    assert!(
        followed,
        "the local reader saw every publish while connected"
    );
    // The input reads its own cell again, from any thread.
    let kept = inp.get();
    // The output still belongs to its container: used in a session of its home.
    let session = Home::enter(&home);
    let last = out.get();
    assert!(
        kept >= 1.0 && kept < last,
        "disconnected at {kept}, output at {last}"
    );
    out.publish(100.0);
    drop(session);
    assert_eq!(probe.get(), 100.0);
    assert_eq!(inp.get(), kept);
}

#[test]
fn a_change_asked_for_while_the_container_is_stuck_gives_up_with_a_clear_error() {
    let (out, inp) = pair(0.0);
    let home = Arc::new(Home::new());
    assert!(make_local(&out, &inp, &home));
    let (entered_tx, entered_rx) = mpsc::channel();
    let (release_tx, release_rx) = mpsc::channel::<()>();
    let out_handle = out.handle();
    let stuck = {
        let home = home.clone();
        thread::spawn(move || {
            let _session = Home::enter(&home);
            entered_tx.send(()).unwrap();
            // A step that never returns within the wait: no boundary is reached.
            release_rx.recv().unwrap();
            drop(out);
            drop(inp);
        })
    };
    entered_rx.recv().unwrap();
    let probe = CopyInputPort::<f64>::new("probe");
    let err = out_handle
        .connect(&probe.handle(), ConnectOptions::default())
        .unwrap_err();
    assert!(
        err.to_string().contains("did not reach a cycle boundary"),
        "{err}"
    );
    assert_eq!(probe.connection_count(), 0);
    release_tx.send(()).unwrap();
    stuck.join().unwrap();
}

/// The thread mark the ownership checks compare: stable on one thread, never 0 (0 is
/// "no owner"), and different for threads alive at the same time.
#[test]
fn each_live_thread_has_its_own_mark() {
    let here = local::mark();
    assert_ne!(here, 0);
    assert_eq!(here, local::mark());
    // Three threads that all stay alive until each has taken its mark.
    let all_marked = Arc::new(std::sync::Barrier::new(3));
    let others: Vec<_> = (0..3)
        .map(|_| {
            let all_marked = Arc::clone(&all_marked);
            thread::spawn(move || {
                let mark = local::mark();
                all_marked.wait();
                assert_eq!(mark, local::mark());
                mark
            })
        })
        .collect();
    let mut marks: Vec<usize> = others.into_iter().map(|t| t.join().unwrap()).collect();
    assert!(marks.iter().all(|m| *m != 0 && *m != here));
    marks.sort_unstable();
    marks.dedup();
    assert_eq!(marks.len(), 3, "two live threads had the same mark");
}

/// The fast path's gate follows the session: open while this thread holds it, shut
/// when the session ends (a publish then takes the checked path and panics), open again
/// for the next session.
#[test]
fn the_gate_opens_and_shuts_with_the_session() {
    let (out, inp) = pair(0.0);
    let home = Arc::new(Home::new());
    assert!(make_local(&out, &inp, &home));
    let session = Home::enter(&home);
    out.publish(1.0);
    assert_eq!(inp.get(), 1.0);
    drop(session);
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| out.publish(2.0)));
    assert!(
        outcome.is_err(),
        "a publish after the session ended must panic"
    );
    let _session = Home::enter(&home);
    out.publish(3.0);
    assert_eq!(inp.get(), 3.0);
}

/// An output that also feeds a reader on the lock-free path keeps its gate shut: every
/// publish is checked (another thread still panics) and reaches both readers.
#[test]
fn an_output_on_both_paths_is_checked_on_every_publish() {
    let out = CopyOutputPort::<f64>::new("out");
    let (near, far) = (
        CopyInputPort::<f64>::new("near"),
        CopyInputPort::<f64>::new("far"),
    );
    connect(&out, &near, ConnectOptions::default()).unwrap();
    connect(&out, &far, ConnectOptions::default()).unwrap();
    let home = Arc::new(Home::new());
    assert!(make_local(&out, &near, &home));
    let _session = Home::enter(&home);
    out.publish(4.0);
    assert_eq!((near.get(), far.get()), (4.0, 4.0));
    let from_elsewhere = thread::scope(|s| s.spawn(|| out.publish(5.0)).join());
    assert!(
        from_elsewhere.is_err(),
        "a publish from another thread must panic"
    );
    assert_eq!((near.get(), far.get()), (4.0, 4.0));
}

/// A home outlives its outputs: a dropped output's gate is forgotten, so the next
/// session does not write to freed memory (Miri checks this test).
#[test]
fn a_dropped_output_leaves_no_gate_behind() {
    let home = Arc::new(Home::new());
    {
        let (out, inp) = pair(0.0);
        assert!(make_local(&out, &inp, &home));
        let _session = Home::enter(&home);
        out.publish(1.0);
    }
    let session = Home::enter(&home);
    drop(session);
    let (out, inp) = pair(0.0);
    assert!(make_local(&out, &inp, &home));
    let _session = Home::enter(&home);
    out.publish(6.0);
    assert_eq!(inp.get(), 6.0);
}
