//! Model-checked tests of services with loom: every interleaving (up to a preemption
//! bound) of a call racing the server's step, a disconnect, the server's drop, or a
//! handler's panic. The property checked throughout is "no hang, no leak": loom fails a
//! model in which every thread is blocked (a caller waiting for an answer that can no
//! longer come) and one that leaks an `Arc` (a client and its service keeping each
//! other alive).
//!
//! Run: `RUSTFLAGS="--cfg loom" cargo test -p ferroc-runtime --release --test
//! loom_services` (`runtime/verify.sh` does). Only waits without a time limit are
//! modelled: loom's condition variable never times out.
#![cfg(loom)]

use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};

use ferroc_ports::service::{connect, disconnect, CallError, ClientPort, ServicePort};
use loom::sync::atomic::{AtomicUsize, Ordering};
use loom::sync::Arc;
use loom::thread;

fn model(f: impl Fn() + Sync + Send + 'static) {
    silence_expected_panics();
    let mut builder = loom::model::Builder::new();
    if builder.preemption_bound.is_none() {
        builder.preemption_bound = Some(3);
    }
    builder.check(f);
}

fn pair() -> (ServicePort<u32, u32>, Arc<ClientPort<u32, u32>>) {
    let service = ServicePort::with_capacity("svc", 4);
    let client = ClientPort::new("client");
    connect(&client, &service).unwrap();
    (service, Arc::new(client))
}

/// A blocking call (no time limit) races the server's one serve and then its drop:
/// whenever the request arrives, the caller gets an answer or an error, never a hang.
#[test]
fn blocking_call_races_serve_and_drop() {
    model(|| {
        let (service, client) = pair();
        let caller = {
            let client = Arc::clone(&client);
            thread::spawn(move || client.call(1))
        };
        let served = service.serve_one(|x| x + 1);
        drop(service);
        let result = caller.join().unwrap();
        match result {
            Ok(2) => assert!(served),
            Err(CallError::Disconnected) | Err(CallError::NotConnected) => assert!(!served),
            other => panic!("unexpected {other:?}"),
        }
        assert!(!client.is_connected());
    });
}

/// An asynchronous call races a disconnect and the server's serve: a request is either
/// served or withdrawn (answered `Disconnected`), never both, never left waiting.
#[test]
fn async_call_races_disconnect_and_serve() {
    model(|| {
        let (service, client) = pair();
        let service = Arc::new(service);
        let caller = {
            let client = Arc::clone(&client);
            thread::spawn(move || client.call_async(1).map(|p| p.wait()))
        };
        let rewire = {
            let (client, service) = (Arc::clone(&client), Arc::clone(&service));
            thread::spawn(move || assert!(disconnect(&client, &service)))
        };
        let served = service.serve_one(|x| x * 10);
        rewire.join().unwrap();
        match caller.join().unwrap() {
            Err(CallError::NotConnected) => assert!(!served),
            Ok(Ok(10)) => assert!(served),
            Ok(Err(CallError::Disconnected)) => assert!(!served),
            other => panic!("unexpected {other:?}"),
        }
        assert_eq!(service.pending_len(), 0);
        assert_eq!(service.client_count(), 0);
    });
}

/// Two clients call while one of them is dropped and the server serves: the survivor's
/// call is answered exactly once, and the dropped client's core is freed (loom checks
/// that no `Arc` leaks).
#[test]
fn concurrent_clients_with_one_dropped() {
    model(|| {
        let service = Arc::new(ServicePort::<u32, u32>::with_capacity("svc", 4));
        let stays = ClientPort::new("stays");
        let leaves = ClientPort::new("leaves");
        connect(&stays, &service).unwrap();
        connect(&leaves, &service).unwrap();
        let pending = stays.call_async(1).unwrap();
        let leaving = thread::spawn(move || {
            let p = leaves.call_async(2).unwrap();
            drop(leaves);
            p.wait()
        });
        let served = AtomicUsize::new(0);
        let count = |x: u32| {
            served.fetch_add(1, Ordering::Relaxed);
            x
        };
        service.serve_pending(count);
        let left = leaving.join().unwrap();
        service.serve_pending(count);
        assert_eq!(pending.wait(), Ok(1));
        match left {
            Ok(2) => assert_eq!(served.load(Ordering::Relaxed), 2),
            Err(CallError::Disconnected) => assert_eq!(served.load(Ordering::Relaxed), 1),
            other => panic!("unexpected {other:?}"),
        }
        assert_eq!(service.client_count(), 1);
    });
}

/// A handler panics while another call arrives: that call fails with `ServerPanicked`
/// (or finds the service gone after its drop), never waits forever.
#[test]
fn panicking_handler_races_a_call() {
    model(|| {
        let (service, client) = pair();
        let early = client.call_async(1).unwrap();
        let caller = {
            let client = Arc::clone(&client);
            thread::spawn(move || client.call(2))
        };
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            service.serve_one(|_| -> u32 { std::panic::panic_any(Expected) })
        }));
        match outcome {
            Err(payload) if payload.is::<Expected>() => {}
            Err(other) => resume_unwind(other),
            Ok(served) => panic!("the handler must panic (served: {served})"),
        }
        assert_eq!(early.wait(), Err(CallError::ServerPanicked));
        drop(service);
        let late = caller.join().unwrap();
        assert!(
            matches!(
                late,
                Err(CallError::ServerPanicked) | Err(CallError::NotConnected)
            ),
            "{late:?}"
        );
    });
}

/// The payload of the panics these tests provoke.
struct Expected;

/// Keeps the panic hook quiet about [`Expected`] panics (one per explored
/// interleaving); every other panic is reported as usual. Installed once, never
/// restored, so concurrent tests cannot race over the hook.
fn silence_expected_panics() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !info.payload().is::<Expected>() {
                previous(info);
            }
        }));
    });
}

/// Inline (caller-executed) calls on two threads while one handler panics: the stop
/// flag is seen by every call that starts after it is set.
#[test]
fn inline_calls_race_a_panic() {
    model(|| {
        let service = Arc::new(ServicePort::<u32, u32>::executed_by_caller("inline", |x| {
            if x == 0 {
                std::panic::panic_any(Expected)
            }
            x
        }));
        let other = {
            let service = Arc::clone(&service);
            thread::spawn(move || {
                let client = ClientPort::new("other");
                connect(&client, &service).unwrap();
                client.call(5)
            })
        };
        let client = ClientPort::new("panicky");
        connect(&client, &service).unwrap();
        assert_eq!(client.call(0), Err(CallError::ServerPanicked));
        assert!(service.is_stopped());
        assert_eq!(client.call(1), Err(CallError::ServerPanicked));
        let r = other.join().unwrap();
        assert!(matches!(r, Ok(5) | Err(CallError::ServerPanicked)), "{r:?}");
    });
}
