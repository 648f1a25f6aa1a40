//! Services between modules on real thread containers: the serving module's container
//! executes requests (woken by them, like by data), callers block or poll.
//!
//! Every wait here is for an event (a wakeup, a join), never for wall-clock time;
//! timeouts are asserted by their error kind only.
#![cfg(not(loom))]

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::Duration;

use ferroc_runtime::container::{RunningContainer, Step, ThreadContainer, ThreadOptions, Trigger};
use ferroc_runtime::port::Wakeup;
use ferroc_runtime::service::{connect, disconnect, CallError, ClientPort, Executes, ServicePort};

/// A request tagged with who sent it, so that misrouted answers would show.
type Req = (u32, u64);

/// A module serving `(client, x) → (client, x * factor)` on its own data-triggered
/// container, counting what it served and on which thread.
struct Multiplier {
    /// Shared so that the test can rewire it while the module runs, as a runtime
    /// builder would.
    service: Arc<ServicePort<Req, Req>>,
    factor: u64,
    served: Arc<AtomicU64>,
    threads: Arc<Mutex<Vec<Option<String>>>>,
}

impl Multiplier {
    fn new(name: &str, factor: u64) -> Self {
        Multiplier {
            service: Arc::new(ServicePort::new(name)),
            factor,
            served: Arc::default(),
            threads: Arc::default(),
        }
    }

    /// The module's `update`: serve whatever is queued.
    fn update(&mut self) {
        let factor = self.factor;
        let threads = &self.threads;
        let n = self.service.serve_pending(|(client, x)| {
            threads
                .lock()
                .unwrap()
                .push(thread::current().name().map(str::to_owned));
            (client, x * factor)
        });
        self.served.fetch_add(n as u64, Ordering::SeqCst);
    }
}

/// The module running in a data-triggered container woken by its service.
struct Running {
    service: Arc<ServicePort<Req, Req>>,
    container: RunningContainer,
    stop: Arc<AtomicBool>,
    served: Arc<AtomicU64>,
    threads: Arc<Mutex<Vec<Option<String>>>>,
}

impl Running {
    fn start(container: &str, mut module: Multiplier) -> Self {
        let wakeup = Wakeup::new();
        module.service.set_notifier(wakeup.clone()).unwrap();
        let service = Arc::clone(&module.service);
        let (served, threads) = (Arc::clone(&module.served), Arc::clone(&module.threads));
        let step = Step::new(format!("{container}/update"), move || module.update());
        let stop = Arc::new(AtomicBool::new(false));
        let container = ThreadContainer::new(container, Trigger::Data(wakeup), vec![step])
            .spawn(ThreadOptions::default(), Arc::clone(&stop), None)
            .unwrap();
        Running {
            service,
            container,
            stop,
            served,
            threads,
        }
    }

    /// Stops the container (which drops its step and the module) and drops the
    /// service; returns how many requests the module served.
    fn stop(self) -> u64 {
        self.stop.store(true, Ordering::SeqCst);
        self.container.nudge();
        self.container.join();
        drop(self.service);
        self.served.load(Ordering::SeqCst)
    }
}

#[test]
fn round_trip_is_executed_by_the_servers_container() {
    let module = Multiplier::new("double", 2);
    let client = ClientPort::new("caller");
    connect(&client, &module.service).unwrap();
    let server = Running::start("srv", module);
    assert_eq!(client.call((0, 21)), Ok((0, 42)));
    assert_eq!(client.call((0, 5)), Ok((0, 10)));
    let threads = server.threads.lock().unwrap().clone();
    assert_eq!(threads, [Some("srv".to_owned()), Some("srv".to_owned())]);
    assert_eq!(server.stop(), 2);
    // The module (and with it the service) is gone with its container.
    assert_eq!(client.call((0, 1)), Err(CallError::NotConnected));
}

#[test]
fn caller_executed_service_runs_inline_on_each_callers_thread() {
    // State shared between the serving module and its inline handler: an atomic here;
    // anything larger goes behind a Mutex. `Fn + Send + Sync` enforces this.
    let calls = Arc::new(AtomicU64::new(0));
    let handler_calls = Arc::clone(&calls);
    let service =
        ServicePort::<u64, (u64, thread::ThreadId)>::executed_by_caller("where", move |x| {
            handler_calls.fetch_add(1, Ordering::SeqCst);
            (x, thread::current().id())
        });
    assert_eq!(service.executes(), Executes::Caller);
    thread::scope(|s| {
        for i in 0..3 {
            let service = &service;
            s.spawn(move || {
                let client = ClientPort::new(format!("c{i}"));
                connect(&client, service).unwrap();
                for x in 0..10 {
                    assert_eq!(client.call(x), Ok((x, thread::current().id())));
                }
            });
        }
    });
    assert_eq!(calls.load(Ordering::SeqCst), 30);
}

#[test]
fn a_call_to_a_server_that_does_not_serve_times_out() {
    // Connected, alive, never served (its container is not running).
    let module = Multiplier::new("idle", 2);
    let client = ClientPort::new("caller").with_timeout(Duration::from_millis(2));
    connect(&client, &module.service).unwrap();
    assert_eq!(client.call((0, 1)), Err(CallError::Timeout));
    assert_eq!(
        client.call_timeout((0, 2), Duration::from_millis(2)),
        Err(CallError::Timeout)
    );
    let pending = client.call_async((0, 3)).unwrap();
    assert!(pending.wait_timeout(Duration::from_millis(2)).is_err());
}

#[test]
fn a_call_on_an_unconnected_client_fails_at_once() {
    let client = ClientPort::<Req, Req>::new("lonely");
    assert_eq!(client.call((0, 1)), Err(CallError::NotConnected));
    assert_eq!(
        client.call_async((0, 1)).unwrap_err(),
        CallError::NotConnected
    );
}

#[test]
fn server_dropped_while_calls_are_pending() {
    let service = ServicePort::<Req, Req>::new("doomed");
    let wakeup = Wakeup::new();
    service.set_notifier(wakeup.clone()).unwrap();
    let blocking = ClientPort::new("blocking");
    let asynchronous = ClientPort::new("async");
    connect(&blocking, &service).unwrap();
    connect(&asynchronous, &service).unwrap();
    let pending = asynchronous.call_async((1, 1)).unwrap();
    wakeup.wait();
    thread::scope(|s| {
        let caller = s.spawn(|| blocking.call((0, 1)));
        wakeup.wait(); // the blocking call is queued
        assert_eq!(service.pending_len(), 2);
        drop(service);
        assert_eq!(caller.join().unwrap(), Err(CallError::Disconnected));
    });
    assert_eq!(pending.wait(), Err(CallError::Disconnected));
    assert!(!blocking.is_connected());
}

#[test]
fn async_call_is_polled_until_answered() {
    let module = Multiplier::new("triple", 3);
    let client = ClientPort::new("poller");
    // The client's notifier: what would wake the calling module's data-triggered
    // container when the answer arrives. Polling waits on it, not on the clock.
    let answered = Wakeup::new();
    client.set_notifier(answered.clone()).unwrap();
    connect(&client, &module.service).unwrap();
    let server = Running::start("srv3", module);
    let mut pending = client.call_async((7, 5)).unwrap();
    let mut polls = 0;
    let result = loop {
        polls += 1;
        match pending.try_take() {
            Ok(result) => break result,
            Err(still) => {
                pending = still;
                answered.wait();
            }
        }
    };
    assert_eq!(result, Ok((7, 15)));
    assert!(polls <= 2, "one wakeup is enough: {polls} polls");
    assert_eq!(server.stop(), 1);
}

#[test]
fn many_clients_concurrently_lose_no_response() {
    const CLIENTS: u32 = 8;
    const CALLS: u64 = 200;
    let module = Multiplier::new("busy", 2);
    let clients: Vec<ClientPort<Req, Req>> = (0..CLIENTS)
        .map(|i| {
            let c = ClientPort::new(format!("client{i}"));
            connect(&c, &module.service).unwrap();
            c
        })
        .collect();
    // Each client has at most two calls outstanding: the queue (16) never fills.
    let server = Running::start("srvN", module);
    let answered = AtomicU64::new(0);
    thread::scope(|s| {
        for (i, client) in clients.iter().enumerate() {
            let (answered, i) = (&answered, i as u32);
            s.spawn(move || {
                for x in 0..CALLS {
                    if x % 2 == 0 {
                        assert_eq!(client.call((i, x)), Ok((i, 2 * x)));
                        answered.fetch_add(1, Ordering::SeqCst);
                    } else {
                        let a = client.call_async((i, x)).unwrap();
                        let b = client.call_async((i, x + 1000)).unwrap();
                        assert_eq!(b.wait(), Ok((i, 2 * (x + 1000))));
                        assert_eq!(a.wait(), Ok((i, 2 * x)));
                        answered.fetch_add(2, Ordering::SeqCst);
                    }
                }
            });
        }
    });
    let expected = u64::from(CLIENTS) * (CALLS + CALLS / 2);
    assert_eq!(answered.load(Ordering::SeqCst), expected);
    assert_eq!(
        server.stop(),
        expected,
        "the server served each request once"
    );
}

#[test]
fn a_client_is_reconnected_to_another_server() {
    let first = Running::start("s2", Multiplier::new("x2", 2));
    let second = Running::start("s10", Multiplier::new("x10", 10));
    let client = ClientPort::new("caller");
    connect(&client, &first.service).unwrap();
    assert_eq!(client.call((0, 3)), Ok((0, 6)));
    // Rewired while both servers run.
    assert!(disconnect(&client, &first.service));
    connect(&client, &second.service).unwrap();
    assert_eq!(client.service_name().as_deref(), Some("x10"));
    assert_eq!(client.call((0, 3)), Ok((0, 30)));
    assert_eq!(first.service.client_count(), 0);
    assert_eq!(second.service.client_count(), 1);
    assert!(client.disconnect());
    assert_eq!(client.call((0, 3)), Err(CallError::NotConnected));
    assert_eq!((first.stop(), second.stop()), (1, 1));
}

#[test]
fn disconnecting_withdraws_a_queued_request() {
    // A server that has not run yet: the request waits in its queue.
    let idle = Multiplier::new("idle", 2);
    let client = ClientPort::new("caller");
    connect(&client, &idle.service).unwrap();
    let pending = client.call_async((0, 1)).unwrap();
    assert!(disconnect(&client, &idle.service));
    assert_eq!(pending.wait(), Err(CallError::Disconnected));
    assert_eq!(idle.service.pending_len(), 0);
    let server = Running::start("late", idle);
    assert_eq!(server.stop(), 0, "the withdrawn request is never executed");
}
