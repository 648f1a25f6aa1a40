//! Model-checked tests of connections local to one thread container (`port/local.rs`):
//! the owner thread publishes and reads through plain cells while another thread
//! changes the connection. Loom's cells report any access to the local value not
//! ordered with the owner's (a data race), and the assertions check that the change
//! lands at a cycle boundary with the owner's latest values.
//!
//! Run: `RUSTFLAGS="--cfg loom" cargo test -p ferroc-runtime --release --test loom_local`
#![cfg(loom)]

use ferroc_ports::port::{
    connect, make_local, ConnectOptions, CopyInputPort, CopyOutputPort, Home,
};
use loom::sync::Arc;
use loom::thread;

fn model(f: impl Fn() + Sync + Send + 'static) {
    let mut builder = loom::model::Builder::new();
    if builder.preemption_bound.is_none() {
        builder.preemption_bound = Some(3);
    }
    builder.check(f);
}

/// A local pair, and the owner thread running two cycles: publish, read locally,
/// boundary; publish, read locally; end of the session.
fn local_pair() -> (CopyOutputPort<u64>, CopyInputPort<u64>, Arc<Home>) {
    let out = CopyOutputPort::<u64>::new("out");
    let inp = CopyInputPort::<u64>::new("in");
    connect(&out, &inp, ConnectOptions::default()).unwrap();
    let home = Arc::new(Home::new());
    assert!(make_local(&out, &inp, &home));
    (out, inp, home)
}

fn run_owner(
    home: Arc<Home>,
    out: CopyOutputPort<u64>,
    inp: CopyInputPort<u64>,
) -> thread::JoinHandle<(CopyOutputPort<u64>, CopyInputPort<u64>, Vec<u64>)> {
    thread::spawn(move || {
        let session = Home::enter(&home);
        let mut seen = Vec::new();
        out.publish(1);
        seen.push(inp.get());
        session.boundary();
        out.publish(2);
        seen.push(inp.get());
        drop(session);
        (out, inp, seen)
    })
}

/// A reader from outside the container joins while the owner publishes: the change is
/// applied on the owner's thread (or after its session), the new reader's first value
/// is one the owner published or the initial one, and it ends with the owner's last.
#[test]
fn a_reader_joining_from_another_thread_falls_back_to_the_lock_free_path() {
    model(|| {
        let (out, inp, home) = local_pair();
        let handle = out.handle();
        let owner = run_owner(home, out, inp);
        let probe = CopyInputPort::<u64>::new("probe");
        handle
            .connect(&probe.handle(), ConnectOptions::default())
            .unwrap();
        let first = probe.get();
        let (out, inp, seen) = owner.join().unwrap();
        assert_eq!(seen, [1, 2], "the local reader follows every publish");
        assert!(first <= 2);
        assert_eq!(
            probe.get(),
            2,
            "the joined reader gets the owner's last value"
        );
        drop((out, inp));
    });
}

/// The local reader is disconnected from another thread while the owner publishes:
/// from the boundary where that is applied on, it keeps the value it had and no
/// longer follows the output.
#[test]
fn a_local_reader_disconnected_from_another_thread_keeps_its_last_value() {
    model(|| {
        let (out, inp, home) = local_pair();
        let (out_handle, in_handle) = (out.handle(), inp.handle());
        let owner = run_owner(Arc::clone(&home), out, inp);
        assert!(out_handle.disconnect(&in_handle));
        let (out, inp, seen) = owner.join().unwrap();
        // Applied before the session (the input keeps its default), at the boundary
        // after the first publish, or after the session: the owner read its own values
        // until then, and the input keeps the last one it read.
        assert!(
            [[0, 0], [1, 1], [1, 2]].contains(&[seen[0], seen[1]]),
            "{seen:?}"
        );
        let kept = inp.get();
        assert_eq!(kept, seen[1]);
        let session = Home::enter(&home);
        out.publish(3);
        drop(session);
        assert_eq!(inp.get(), kept, "a disconnected input no longer follows");
    });
}
