//! Unit tests of services. They run under Miri too (`cargo +nightly miri test -p
//! ferroc-runtime --lib service`), so threads are few and waits are for events, never
//! for wall-clock time; timeouts are asserted by their error kind only.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;

use super::*;
use crate::port::{Notify, Wakeup};

const SHORT: Duration = Duration::from_millis(1);

fn pair(capacity: usize) -> (ServicePort<u32, u32>, ClientPort<u32, u32>) {
    let service = ServicePort::with_capacity("double", capacity);
    let client = ClientPort::new("caller");
    connect(&client, &service).unwrap();
    (service, client)
}

/// Counts notifications.
#[derive(Default)]
struct Counter(AtomicUsize);

impl Notify for Counter {
    fn notify(&self) {
        self.0.fetch_add(1, Ordering::SeqCst);
    }
}

impl Counter {
    fn get(&self) -> usize {
        self.0.load(Ordering::SeqCst)
    }
}

/// The payload of the panics these tests provoke.
struct Expected;

/// Keeps the panic hook quiet about [`Expected`] panics; every other panic is reported
/// as usual. Installed once and never restored, so parallel tests cannot race over the
/// hook.
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

#[test]
fn async_call_is_served_by_the_servers_step_in_order() {
    let (service, client) = pair(4);
    let a = client.call_async(1).unwrap();
    let b = client.call_async(2).unwrap();
    assert_eq!(service.pending_len(), 2);
    let a = a.try_take().expect_err("not served yet");
    assert!(!a.is_ready());
    let mut seen = Vec::new();
    assert_eq!(
        service.serve_pending(|x| {
            seen.push(x);
            x * 2
        }),
        2
    );
    assert_eq!(seen, [1, 2]);
    assert!(a.is_ready());
    assert_eq!(a.try_take().unwrap(), Ok(2));
    assert_eq!(b.wait(), Ok(4));
    assert_eq!(service.serve_pending(|x| x), 0);
}

#[test]
fn blocking_call_is_answered_by_the_server_thread() {
    let (service, client) = pair(4);
    let wakeup = Wakeup::new();
    service.set_notifier(wakeup.clone()).unwrap();
    std::thread::scope(|s| {
        let server = s.spawn(|| {
            wakeup.wait();
            service.serve_pending(|x| x + 100)
        });
        assert_eq!(client.call(1), Ok(101));
        assert_eq!(server.join().unwrap(), 1);
    });
}

#[test]
fn caller_executed_service_runs_inline_on_the_callers_thread() {
    let service = ServicePort::<u32, std::thread::ThreadId>::executed_by_caller("where", |_| {
        std::thread::current().id()
    });
    let client = ClientPort::new("caller");
    connect(&client, &service).unwrap();
    assert_eq!(service.executes(), Executes::Caller);
    assert_eq!(service.capacity(), None);
    assert_eq!(client.call(0), Ok(std::thread::current().id()));
    let p = client.call_async(0).unwrap();
    assert!(p.is_ready(), "already executed when call_async returns");
    assert_eq!(p.wait(), Ok(std::thread::current().id()));
    assert_eq!(service.pending_len(), 0);
}

#[test]
fn unconnected_calls_fail_at_once() {
    let client = ClientPort::<u32, u32>::new("lonely");
    assert!(!client.is_connected());
    assert_eq!(client.call(1), Err(CallError::NotConnected));
    assert_eq!(client.call_timeout(1, SHORT), Err(CallError::NotConnected));
    assert_eq!(client.call_async(1).unwrap_err(), CallError::NotConnected);
    assert!(!client.disconnect());
}

#[test]
fn a_call_nobody_serves_times_out_and_is_still_executed_later() {
    let (service, client) = pair(4);
    assert_eq!(client.call_timeout(7, SHORT), Err(CallError::Timeout));
    let client = client.with_timeout(SHORT);
    assert_eq!(client.call(8), Err(CallError::Timeout));
    let mut seen = Vec::new();
    service.serve_pending(|x| {
        seen.push(x);
        x
    });
    assert_eq!(
        seen,
        [7, 8],
        "accepted requests run even after their callers gave up"
    );
}

#[test]
fn pending_wait_timeout_gives_the_handle_back() {
    let (service, client) = pair(4);
    let p = client.call_async(3).unwrap();
    let p = p.wait_timeout(SHORT).expect_err("nobody served");
    service.serve_one(|x| x + 1);
    assert_eq!(p.wait_timeout(SHORT).unwrap(), Ok(4));
}

#[test]
fn a_full_queue_refuses_the_call() {
    let (service, client) = pair(2);
    let _a = client.call_async(1).unwrap();
    let _b = client.call_async(2).unwrap();
    assert_eq!(client.call_async(3).unwrap_err(), CallError::QueueFull);
    assert_eq!(client.call(3), Err(CallError::QueueFull));
    assert_eq!(
        service.pending_len(),
        2,
        "queued requests are never dropped"
    );
    service.serve_one(|x| x);
    assert!(client.call_async(3).is_ok());
}

#[test]
fn dropping_the_service_answers_queued_calls_with_disconnected() {
    let (service, client) = pair(4);
    let p = client.call_async(1).unwrap();
    drop(service);
    assert_eq!(p.wait(), Err(CallError::Disconnected));
    assert!(!client.is_connected());
    assert_eq!(client.call(2), Err(CallError::NotConnected));
}

#[test]
fn dropping_the_service_wakes_a_blocked_caller() {
    let (service, client) = pair(4);
    let wakeup = Wakeup::new();
    service.set_notifier(wakeup.clone()).unwrap();
    std::thread::scope(|s| {
        let caller = s.spawn(|| client.call(1));
        wakeup.wait(); // the request is queued
        drop(service);
        assert_eq!(caller.join().unwrap(), Err(CallError::Disconnected));
    });
}

#[test]
fn disconnecting_withdraws_only_that_clients_requests() {
    let (service, a) = pair(4);
    let b = ClientPort::new("b");
    connect(&b, &service).unwrap();
    assert_eq!(service.client_count(), 2);
    let pa = a.call_async(1).unwrap();
    let pb = b.call_async(2).unwrap();
    assert!(disconnect(&a, &service));
    assert!(!disconnect(&a, &service));
    assert_eq!(pa.wait(), Err(CallError::Disconnected));
    assert_eq!(service.pending_len(), 1);
    service.serve_pending(|x| x * 10);
    assert_eq!(pb.wait(), Ok(20));
    assert_eq!(service.client_count(), 1);
    drop(b);
    assert_eq!(service.client_count(), 0, "a dropped client disconnects");
}

#[test]
fn disconnect_all_keeps_the_service_usable() {
    let (service, client) = pair(4);
    let p = client.call_async(1).unwrap();
    service.disconnect_all();
    assert_eq!(p.wait(), Err(CallError::Disconnected));
    assert!(!client.is_connected());
    connect(&client, &service).unwrap();
    let p = client.call_async(2).unwrap();
    service.serve_pending(|x| x);
    assert_eq!(p.wait(), Ok(2));
}

#[test]
fn a_client_has_one_service_and_can_be_reconnected() {
    let (first, client) = pair(4);
    let second = ServicePort::<u32, u32>::executed_by_caller("second", |x| x + 2);
    assert_eq!(
        connect(&client, &first),
        Err(ServiceConnectError::AlreadyConnected {
            client: "caller".into(),
            service: "double".into()
        })
    );
    assert!(matches!(
        connect(&client, &second),
        Err(ServiceConnectError::ClientBusy { .. })
    ));
    assert_eq!(client.service_name().as_deref(), Some("double"));
    assert!(client.disconnect());
    connect(&client, &second).unwrap();
    assert_eq!(client.service_name().as_deref(), Some("second"));
    assert_eq!(client.call(1), Ok(3));
    assert_eq!(first.client_count(), 0);
}

#[test]
fn a_panicking_handler_fails_its_call_the_queue_and_later_calls() {
    let (service, client) = pair(4);
    let first = client.call_async(1).unwrap();
    let second = client.call_async(2).unwrap();
    silence_expected_panics();
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        service.serve_pending(|_| -> u32 { std::panic::panic_any(Expected) })
    }));
    assert!(
        outcome.is_err(),
        "serve_pending re-raises for the container"
    );
    assert!(service.is_stopped());
    assert_eq!(first.wait(), Err(CallError::ServerPanicked));
    assert_eq!(second.wait(), Err(CallError::ServerPanicked));
    assert_eq!(client.call(3), Err(CallError::ServerPanicked));
}

#[test]
fn a_panicking_inline_handler_surfaces_as_an_error() {
    silence_expected_panics();
    let service = ServicePort::<u32, u32>::executed_by_caller("fragile", |x| {
        if x == 0 {
            std::panic::panic_any(Expected)
        }
        x
    });
    let client = ClientPort::new("caller");
    connect(&client, &service).unwrap();
    assert_eq!(client.call(1), Ok(1));
    assert_eq!(client.call(0), Err(CallError::ServerPanicked));
    assert!(service.is_stopped());
    assert_eq!(client.call(1), Err(CallError::ServerPanicked));
}

#[test]
fn a_taken_request_can_be_answered_later_or_abandoned() {
    let (service, client) = pair(4);
    let p1 = client.call_async(1).unwrap();
    let p2 = client.call_async(2).unwrap();
    let r1 = service.take_request().unwrap();
    assert_eq!(*r1.request(), 1);
    let (req, responder) = service.take_request().unwrap().into_parts();
    assert_eq!(req, 2);
    std::thread::scope(|s| {
        s.spawn(move || responder.respond(req * 3));
    });
    assert_eq!(p2.wait(), Ok(6));
    drop(r1);
    assert_eq!(p1.wait(), Err(CallError::Disconnected));
    assert!(!service.is_stopped());
}

#[test]
fn a_panic_while_holding_a_taken_request_stops_the_service() {
    let (service, client) = pair(4);
    let p = client.call_async(1).unwrap();
    let queued = client.call_async(2).unwrap();
    let request = service.take_request().unwrap();
    silence_expected_panics();
    let outcome = catch_unwind(AssertUnwindSafe(move || {
        let _held = request;
        std::panic::panic_any(Expected);
    }));
    assert!(outcome.is_err());
    assert_eq!(p.wait(), Err(CallError::ServerPanicked));
    assert_eq!(queued.wait(), Err(CallError::ServerPanicked));
    assert!(service.is_stopped());
}

#[test]
fn notifiers_fire_for_requests_and_for_async_answers() {
    let (service, client) = pair(4);
    let (requests, answers) = (Arc::new(Counter::default()), Arc::new(Counter::default()));
    service.set_notifier(requests.clone()).unwrap();
    assert!(
        service.set_notifier(requests.clone()).is_err(),
        "one per port"
    );
    client.set_notifier(answers.clone()).unwrap();
    assert!(
        client.set_notifier(answers.clone()).is_err(),
        "one per port"
    );
    let p = client.call_async(1).unwrap();
    assert_eq!((requests.get(), answers.get()), (1, 0));
    service.serve_pending(|x| x);
    assert_eq!((requests.get(), answers.get()), (1, 1));
    assert_eq!(p.wait(), Ok(1));
    // Blocking calls wake their caller directly, not through the client's notifier.
    assert_eq!(client.call_timeout(2, SHORT), Err(CallError::Timeout));
    service.serve_pending(|x| x);
    assert_eq!((requests.get(), answers.get()), (2, 1));
}

#[test]
fn serve_pending_does_bounded_work_and_a_handler_may_call_its_own_service() {
    let (service, client) = pair(8);
    let _first = client.call_async(1).unwrap();
    let mut later = Vec::new();
    // The handler queues another request on its own service: no lock is held while it
    // runs, and the new request waits for the next serve.
    let served = service.serve_pending(|x| {
        later.push(client.call_async(x + 1).unwrap());
        x
    });
    assert_eq!(served, 1);
    assert_eq!(service.pending_len(), 1);
    assert_eq!(service.serve_pending(|x| x * 5), 1);
    assert_eq!(later.pop().unwrap().wait(), Ok(10));
}

#[test]
fn errors_read_well() {
    assert_eq!(
        CallError::NotConnected.to_string(),
        "the client is not connected to a service"
    );
    let e = ServiceConnectError::ClientBusy {
        client: "c".into(),
        connected_to: "s".into(),
    };
    assert!(e.to_string().contains("disconnect it first"), "{e}");
    assert_eq!(ServicePort::<u8, u8>::new("s").capacity(), Some(16));
    assert_eq!(
        ServicePort::<u8, u8>::with_capacity("s", 0).capacity(),
        Some(1)
    );
    assert_eq!(ServicePort::<u8, u8>::new("s").executes(), Executes::Server);
}
