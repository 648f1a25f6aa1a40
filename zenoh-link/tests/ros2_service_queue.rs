//! The bounds of a module's ROS 2 service (zenoh-link/src/ros2/service.rs, docs/ros2.md
//! "On the wire"), exactly, with calls from a client in this process (queries of the
//! same Zenoh session, no network) and no module: the test answers, so nothing depends
//! on timing.
//!
//! - At most `MAX_WAITING` (64) requests wait for the module's answers: more are
//!   refused with an error reply saying so; an answer frees a place.
//! - An answer the module could not give (its request queue full) is an error reply to
//!   the caller and a warning naming the service once.
//! - A call under another type hash gets an error reply naming both hashes and never
//!   reaches the module; calls with ours reach it whatever the query target.
//! - In lockstep every waiting request reaches the next instant (none dropped while it
//!   still holds a place).

use ferroc_ros2::def::TypeName;
use ferroc_ros2::rmw_zenoh::{self, Attachment};
use ferroc_ros2::{cdr, Registry, Value};
use ferroc_runtime::link::ros2 as ends;
use ferroc_runtime::link::transport::Delivery;
use ferroc_runtime::link::{Frame, Inbox};
use ferroc_zenoh::ros2::network::Ros2Ends;
use ferroc_zenoh::ros2::service::{Ros2Server, ServiceSpec, MAX_WAITING};
use ferroc_zenoh::ros2::{NodeSpec, Ros2Node};
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use zenoh::handlers::FifoChannelHandler;
use zenoh::query::{QueryTarget, Reply};
use zenoh::{Session, Wait};

const NAME: &str = "/switch_bot/set_enabled";

/// A session that reaches nobody: its own queries go to its own queryables.
fn session() -> Session {
    let mut config = zenoh::Config::default();
    for (key, value) in [
        ("mode", "\"peer\""),
        ("listen/endpoints", "[]"),
        ("connect/endpoints", "[]"),
        ("scouting/multicast/enabled", "false"),
    ] {
        config.insert_json5(key, value).unwrap();
    }
    zenoh::open(config).wait().unwrap()
}

fn set_bool() -> TypeName {
    TypeName::parse("std_srvs/srv/SetBool").unwrap()
}

/// The service's key with `hash` (ours when `None`).
fn key(hash: Option<&str>) -> String {
    let ours = ferroc_ros2::hash::rihs01(&Registry::shipped(), &set_bool()).unwrap();
    rmw_zenoh::topic_key(0, NAME, &set_bool(), hash.unwrap_or(&ours))
}

/// A SetBool request as rmw_zenoh's client sends it (to complete queryables).
fn call(session: &Session, key: &str, sequence: i64) -> FifoChannelHandler<Reply> {
    call_to(session, key, sequence, QueryTarget::AllComplete)
}

fn call_to(
    session: &Session,
    key: &str,
    sequence: i64,
    target: QueryTarget,
) -> FifoChannelHandler<Reply> {
    let attachment = Attachment {
        sequence_number: sequence,
        source_timestamp: 0,
        gid: [7; 16],
    };
    session
        .get(key)
        .payload([&cdr::HEADER[..], &[1]].concat())
        .attachment(attachment.encode().to_vec())
        .target(target)
        .timeout(Duration::from_secs(60))
        .wait()
        .unwrap()
}

/// Waits (a guard against hanging, not a timing assertion) until `done` holds.
fn until(what: &str, mut done: impl FnMut() -> bool) {
    let deadline = Instant::now() + Duration::from_secs(30);
    while !done() {
        assert!(Instant::now() < deadline, "never: {what}");
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// The error text of the first reply, or `None` for an answer.
fn error_of(replies: &FifoChannelHandler<Reply>) -> Option<String> {
    let reply = replies.recv().unwrap();
    reply
        .result()
        .err()
        .map(|e| e.payload().try_to_string().unwrap().into_owned())
}

/// The node `switch_bot` offering `std_srvs/srv/SetBool` as [`NAME`], and the requests
/// its server delivered to the module's side.
fn switch_bot(session: &Session) -> (Ros2Node, Ros2Server, Arc<Mutex<Vec<Vec<u8>>>>) {
    let spec = NodeSpec {
        domain: 0,
        namespace: "/".into(),
        name: "switch_bot".into(),
    };
    let node = Ros2Node::declare(session, Arc::new(Registry::shipped()), &spec, 0).unwrap();
    let delivered = Arc::new(Mutex::new(Vec::<Vec<u8>>::new()));
    let into = Arc::clone(&delivered);
    let service = ServiceSpec {
        name: NAME.into(),
        ty: set_bool(),
        request_field: Some("data".into()),
        response_field: None,
    };
    let server = node
        .service_server(service, move |bytes| into.lock().unwrap().push(bytes))
        .unwrap();
    (node, server, delivered)
}

/// A SetBool response (`success`, `message`) as the module's answer frame for call `id`.
fn answer(id: &[u8], kind: u8) -> Vec<u8> {
    let ty = TypeName::parse("std_srvs/srv/SetBool_Response").unwrap();
    let response = Value::Struct(vec![Value::Bool(true), Value::String("ok".into())]);
    let body = cdr::encode(&Registry::shipped(), &ty, &response).unwrap();
    [&id[..8], &[kind], &body[..]].concat()
}

#[test]
fn at_most_64_requests_wait_an_answer_frees_a_place_and_a_full_queue_is_said_once() {
    let session = session();
    let (_node, server, delivered) = switch_bot(&session);
    let count = || delivered.lock().unwrap().len();

    // 100 requests, nobody answers: 64 wait, 36 are refused.
    let calls: Vec<_> = (1..=100).map(|n| call(&session, &key(None), n)).collect();
    until("64 requests delivered", || count() == MAX_WAITING);
    let refused: Vec<String> = (calls.iter())
        .filter_map(|c| c.try_recv().ok().flatten())
        .map(|r| {
            r.result()
                .err()
                .unwrap()
                .payload()
                .try_to_string()
                .unwrap()
                .into_owned()
        })
        .collect();
    assert_eq!(refused.len(), 100 - MAX_WAITING, "{refused:#?}");
    for text in &refused {
        assert_eq!(text, "64 requests already wait for the service's answers");
    }
    assert_eq!(count(), MAX_WAITING);

    // The module answers the first: its caller gets the response, a place is free.
    let first = delivered.lock().unwrap()[0].clone();
    server.answer(&answer(&first, 0)).unwrap();
    let answered = calls.iter().find_map(|c| c.try_recv().ok().flatten());
    let sample = answered.expect("the first answer").into_result().unwrap();
    let echoed = Attachment::decode(&sample.attachment().unwrap().to_bytes()).unwrap();
    assert_eq!(echoed.gid, [7; 16]);
    let more = call(&session, &key(None), 101);
    until("the 65th request delivered", || count() == MAX_WAITING + 1);
    let again = call(&session, &key(None), 102);
    assert_eq!(
        error_of(&again).as_deref(),
        Some("64 requests already wait for the service's answers")
    );

    // The module's request queue was full: the caller is told, the warning is
    // `ROS 2 service `…`: ` (network.rs) and this, naming the service once.
    let last = delivered.lock().unwrap()[MAX_WAITING].clone();
    let why = server.answer(&answer(&last, 4)).unwrap_err();
    assert_eq!(
        why,
        "a request was not answered: the service's request queue is full"
    );
    assert_eq!(
        error_of(&more).as_deref(),
        Some("the service `/switch_bot/set_enabled` did not answer: the service's request queue is full")
    );
    assert!(server.answer(&answer(&last, 0)).is_err(), "answered once");
}

#[test]
fn a_call_under_another_hash_is_told_and_never_delivered_ours_reach_the_service() {
    let session = session();
    let (_node, server, delivered) = switch_bot(&session);
    let count = || delivered.lock().unwrap().len();

    let theirs = format!("RIHS01_{}", "5a".repeat(32));
    for target in [
        QueryTarget::AllComplete,
        QueryTarget::BestMatching,
        QueryTarget::All,
    ] {
        let wrong = call_to(&session, &key(Some(&theirs)), 1, target);
        let text = error_of(&wrong).unwrap();
        assert!(
            text.starts_with(&format!(
                "the ROS 2 service `{NAME}` refused the request: it was sent with another \
                 type hash, {theirs} (ours: RIHS01_"
            )),
            "{text}"
        );
        assert!(text.ends_with("give both sides the same one"), "{text}");
        assert!(wrong.recv().is_err(), "one reply only");
        assert_eq!(count(), 0, "never delivered");
    }
    // Ours, by every target: delivered once, and the other-hash listener says nothing.
    for (n, target) in [
        QueryTarget::AllComplete,
        QueryTarget::BestMatching,
        QueryTarget::All,
    ]
    .into_iter()
    .enumerate()
    {
        let ok = call_to(&session, &key(None), 10 + n as i64, target);
        until("our call delivered", || count() == n + 1);
        let id = delivered.lock().unwrap()[n].clone();
        server.answer(&answer(&id, 0)).unwrap();
        assert!(ok.recv().unwrap().result().is_ok());
        assert!(ok.recv().is_err(), "one reply only");
    }
}

#[test]
fn in_lockstep_every_waiting_request_reaches_the_next_instant() {
    let session = session();
    let node = ends::Ros2Node {
        part: "switch".into(),
        domain: 0,
        namespace: "/".into(),
        name: "switch_bot".into(),
        topics: Vec::new(),
        services: vec![ends::Ros2Service {
            id: 0,
            port: ("main/switch".into(), "set_enabled".into()),
            name: NAME.into(),
            service: "std_srvs/srv/SetBool".into(),
            request_field: Some("data".into()),
            response_field: None,
        }],
        clients: Vec::new(),
        interfaces: Vec::new(),
    };
    let inbox = Arc::new(Inbox::new(BTreeMap::new(), BTreeMap::new()));
    let open = Ros2Ends::open(&session, &[node], Delivery::new(inbox), true).unwrap();
    let calls: Vec<_> = (1..=MAX_WAITING as i64)
        .map(|n| call(&session, &key(None), n))
        .collect();
    // Taken at instants until all 64 arrived: none is dropped (each holds a place
    // among the 64 waiting, so dropping one would keep its place for ever).
    let mut frames: Vec<Frame> = Vec::new();
    until("64 requests at the instants", || {
        frames.extend(open.take_arrived());
        frames.len() >= MAX_WAITING
    });
    assert_eq!(frames.len(), MAX_WAITING);
    assert!(frames.iter().all(|f| f.link == ends::request_link(0)));
    for frame in &frames {
        let bytes = answer(&frame.bytes, 0);
        let reply = open.publish(Frame {
            link: ends::answer_link(0),
            bytes,
        });
        assert!(reply.is_ok());
    }
    for call in &calls {
        assert!(call.recv().unwrap().result().is_ok());
    }
}

/// A module's client in lockstep: every answer to its calls reaches the next instant
/// (they were kept 10 per instant: a module with more calls answered between two
/// instants lost the older answers, and those calls waited for ever).
#[test]
fn in_lockstep_every_answer_to_a_module_s_calls_reaches_the_next_instant() {
    let session = session();
    let response = answer(&[0; 8], 0)[9..].to_vec();
    let server_key = key(None);
    let _server = session
        .declare_queryable(key(None))
        .complete(true)
        .callback(move |query| {
            let _ = query.reply(server_key.clone(), response.clone()).wait();
        })
        .wait()
        .unwrap();
    let node = ends::Ros2Node {
        part: "asker".into(),
        domain: 0,
        namespace: "/".into(),
        name: "asker_bot".into(),
        topics: Vec::new(),
        services: Vec::new(),
        clients: vec![ends::Ros2Service {
            id: 0,
            port: ("main/ask".into(), "set_enabled".into()),
            name: NAME.into(),
            service: "std_srvs/srv/SetBool".into(),
            request_field: Some("data".into()),
            response_field: None,
        }],
        interfaces: Vec::new(),
    };
    let inbox = Arc::new(Inbox::new(BTreeMap::new(), BTreeMap::new()));
    let open = Ros2Ends::open(&session, &[node], Delivery::new(inbox), true).unwrap();
    const CALLS: u64 = 30;
    for id in 0..CALLS {
        let request = [&id.to_le_bytes()[..], &cdr::HEADER[..], &[1]].concat();
        let frame = Frame {
            link: ends::request_link(0),
            bytes: request,
        };
        assert!(open.publish(frame).is_ok());
    }
    let mut frames: Vec<Frame> = Vec::new();
    until("30 answers at the instants", || {
        frames.extend(open.take_arrived());
        frames.len() >= CALLS as usize
    });
    assert_eq!(frames.len(), CALLS as usize);
    let mut ids: Vec<u64> = (frames.iter())
        .map(|f| {
            assert_eq!((f.link, f.bytes[8]), (ends::answer_link(0), 0), "answered");
            u64::from_le_bytes(f.bytes[..8].try_into().unwrap())
        })
        .collect();
    ids.sort_unstable();
    assert_eq!(ids, (0..CALLS).collect::<Vec<_>>());
}
