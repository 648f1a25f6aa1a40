//! A module's service offered as a ROS 2 service, and a module's client calling one, on
//! rmw_zenoh's wire (docs/ros2.md). A service:
//! the liveliness token `SS` and a queryable on the service's key
//! (`<domain>/<name>/<pkg>::srv::dds_::<Name>_/<RIHS01 of the service type>`), as
//! rmw_zenoh's `ServiceData` declares them (rmw_service_data.cpp).
//!
//! A query is a request: its payload the `Name_Request` message in CDR, its attachment
//! the client's (sequence number, time, GID). The request goes to the module's service
//! as its CDR (the stand-in client of `ferroc_link::calls` decodes it into the
//! service's request type); the answer comes back as the `Name_Response` CDR the
//! stand-in wrote from the module's answer and is replied on the service's key with the
//! attachment
//! rmw_zenoh's server writes: the request's sequence number, the reply's time and the
//! client's GID, by which the client matches it. A request that does not decode is
//! reported (throttled, naming the service) and answered with an error reply; at most
//! [`MAX_WAITING`] requests wait for their answers at once (more are refused), so a
//! flood of requests cannot grow the part's memory. A call under another type hash is
//! reported and answered with an error reply ([`super::service_hash`]).
//!
//! A client (`SC` token, rmw_zenoh's `ClientData`, rmw_client_data.cpp) sends each call
//! of the module's client as a query on the service's key with the request's CDR and
//! the client's attachment (its sequence number from 1, the time, its GID); the first
//! reply's CDR is the answer. A reply that does not decode, an error reply, or none
//! within 10 s answers the call as failed or timed out. A server announcing another
//! type hash is reported ([`super::service_hash`]).

use super::service_hash::{other_hash_calls, other_hash_servers};
use super::{token, Ros2Node, TopicSpec};
use ferroc_ros2::def::TypeName;
use ferroc_ros2::rmw_zenoh::{self, Attachment, EntityKind, Qos};
use ferroc_ros2::{cdr, Registry};
use ferroc_runtime::console;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicI64, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, SystemTime, UNIX_EPOCH};
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Subscriber;
use zenoh::query::{Query, Queryable};
use zenoh::{Session, Wait};

/// Requests waiting for the module's answer at once, at most.
pub const MAX_WAITING: usize = 64;

/// A service end: the fully qualified service name, the service type and the one field
/// of the request and of the response a single value fills (`None`: all of it).
#[derive(Clone, Debug, PartialEq)]
pub struct ServiceSpec {
    pub name: String,
    pub ty: TypeName,
    pub request_field: Option<String>,
    pub response_field: Option<String>,
}

impl ServiceSpec {
    /// `pkg/srv/Name_Request` or `pkg/srv/Name_Response`.
    fn message(&self, suffix: &str) -> TypeName {
        let name = format!("{}_{suffix}", self.ty.name);
        TypeName::new(&self.ty.package, &self.ty.kind, &name)
    }
}

/// A ROS 2 service server; dropping it ends it.
pub struct Ros2Server {
    shared: Arc<Shared>,
    _queryable: Queryable<()>,
    _other_hashes: Queryable<()>,
    _token: LivelinessToken,
}

/// What the queryable's callback and the answers share.
struct Shared {
    registry: Arc<Registry>,
    spec: ServiceSpec,
    key: String,
    next: AtomicU64,
    waiting: Mutex<HashMap<u64, (Query, Attachment)>>,
}

impl Ros2Node {
    /// A server of `spec` (its token `SS` and a queryable on the service key) handing
    /// each request, as the call number followed by the request's CDR (checked against
    /// the request message), to `deliver`.
    pub fn service_server(
        &self,
        spec: ServiceSpec,
        deliver: impl Fn(Vec<u8>) + Send + Sync + 'static,
    ) -> Result<Ros2Server, String> {
        // rmw_zenoh's services announce rclcpp's default service QoS: reliable,
        // volatile, keep last 10, which is a topic's default too.
        let as_topic = TopicSpec {
            topic: spec.name.clone(),
            ty: spec.ty.clone(),
            qos: Qos::default(),
            field: None,
        };
        let (key, live, _) = self.keys(&as_topic, EntityKind::ServiceServer)?;
        let token = token(&self.session, &live, &spec.name)?;
        let other_hashes = other_hash_calls(&self.session, &key, &spec.name, &spec.ty)?;
        let shared = Arc::new(Shared {
            registry: Arc::clone(&self.registry),
            spec,
            key: key.clone(),
            next: AtomicU64::new(0),
            waiting: Mutex::default(),
        });
        let on_query = Arc::clone(&shared);
        let queryable = self
            .session
            .declare_queryable(key)
            .complete(true)
            .callback(move |query| on_query.request(query, &deliver))
            .wait()
            .map_err(|e| format!("cannot offer the ROS 2 service `{}`: {e}", shared.spec.name))?;
        Ok(Ros2Server {
            shared,
            _queryable: queryable,
            _other_hashes: other_hashes,
            _token: token,
        })
    }
}

impl Ros2Server {
    /// Replies to the request an answer frame names (call number, kind, the response's
    /// CDR). An answer nobody waits for, or one that does not fit the response
    /// message, is an error (its text without the service's name, which the caller's
    /// report puts first).
    pub fn answer(&self, bytes: &[u8]) -> Result<(), String> {
        self.shared.answer(bytes)
    }

    /// The service.
    pub fn spec(&self) -> &ServiceSpec {
        &self.shared.spec
    }
}

impl Shared {
    /// A request arrived: kept for its answer and handed to the module, or refused.
    fn request(&self, query: Query, deliver: &dyn Fn(Vec<u8>)) {
        let decoded = self.decode(&query);
        let mut waiting = lock(&self.waiting);
        let refused = match decoded {
            Err(why) => why,
            Ok(_) if waiting.len() >= MAX_WAITING => {
                format!("{MAX_WAITING} requests already wait for the service's answers")
            }
            Ok((attachment, request)) => {
                let id = self.next.fetch_add(1, Ordering::Relaxed);
                waiting.insert(id, (query, attachment));
                drop(waiting);
                let mut bytes = id.to_le_bytes().to_vec();
                bytes.extend_from_slice(&request);
                deliver(bytes);
                return;
            }
        };
        drop(waiting);
        console::report_as(
            &format!("ROS 2 service `{}`: refused", self.spec.name),
            &format!(
                "warning: a request to the ROS 2 service `{}` was refused: {refused}",
                self.spec.name
            ),
        );
        let _ = query.reply_err(refused).wait();
    }

    /// The request's attachment and its CDR.
    fn decode(&self, query: &Query) -> Result<(Attachment, Vec<u8>), String> {
        let attachment = query.attachment().map(|a| a.to_bytes());
        let payload = query.payload().map(|p| p.to_bytes());
        read_request(
            &self.registry,
            &self.spec,
            attachment.as_deref(),
            payload.as_deref(),
        )
    }

    fn answer(&self, bytes: &[u8]) -> Result<(), String> {
        let name = &self.spec.name;
        let (id, rest) = bytes
            .split_first_chunk::<8>()
            .ok_or("an answer shorter than its number")?;
        let id = u64::from_le_bytes(*id);
        let (&kind, body) = rest.split_first().ok_or("an answer without its kind")?;
        let Some((query, asked)) = lock(&self.waiting).remove(&id) else {
            return Err("an answer to a request nobody waits for".into());
        };
        if kind != 0 {
            let error = ferroc_runtime::link::calls::error_of(kind);
            let _ = query
                .reply_err(format!("the service `{name}` did not answer: {error}"))
                .wait();
            return Err(not_answered(&error));
        }
        let response = match self.encode(body) {
            Ok(response) => response,
            Err(why) => {
                let _ = query.reply_err(why.clone()).wait();
                return Err(format!("an answer was not sent: {why}"));
            }
        };
        let attachment = Attachment {
            sequence_number: asked.sequence_number,
            source_timestamp: now_ns(),
            gid: asked.gid,
        };
        query
            .reply(self.key.clone(), response)
            .attachment(attachment.encode().to_vec())
            .wait()
            .map_err(|e| format!("an answer was not sent: {e}"))
    }

    /// The answer's CDR, checked against the response message.
    fn encode(&self, body: &[u8]) -> Result<Vec<u8>, String> {
        check(&self.registry, &self.spec, "Response", body)?;
        Ok(body.to_vec())
    }
}

/// What the part reports (after the service's name) when the module's service did not
/// answer a request: `error` says why.
pub(super) fn not_answered(error: &dyn std::fmt::Display) -> String {
    format!("a request was not answered: {error}")
}

/// A request as the module's service reads it: the client's attachment checked, the
/// request message's CDR checked (so a malformed request is refused here, naming the
/// service, and never waits for an answer).
fn read_request(
    registry: &Registry,
    spec: &ServiceSpec,
    attachment: Option<&[u8]>,
    payload: Option<&[u8]>,
) -> Result<(Attachment, Vec<u8>), String> {
    let attachment =
        attachment.ok_or("it has no attachment (rmw_zenoh's clients send one with each)")?;
    let attachment = Attachment::decode(attachment).map_err(|e| e.0)?;
    let payload = payload.ok_or("it has no request message")?;
    check(registry, spec, "Request", payload)?;
    Ok((attachment, payload.to_vec()))
}

/// Whether `bytes` is a CDR sample of the service's `Request` or `Response` message
/// (`which`). Calls are few: the dynamic decoder checks them whole, so a malformed one
/// is reported here, naming the service.
fn check(registry: &Registry, spec: &ServiceSpec, which: &str, bytes: &[u8]) -> Result<(), String> {
    let ty = spec.message(which);
    cdr::decode(registry, &ty, bytes)
        .map(|_| ())
        .map_err(|e| e.to_string())
}

fn now_ns() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as i64)
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// A ROS 2 service client for a module's client; dropping it ends it.
pub struct Ros2Caller {
    shared: Arc<CallerShared>,
    _other_servers: Subscriber<()>,
    _token: LivelinessToken,
}

/// What the calls in flight share.
struct CallerShared {
    registry: Arc<Registry>,
    spec: ServiceSpec,
    session: Session,
    key: String,
    /// The client's GID, which the server echoes in its reply.
    gid: [u8; 16],
    sequence: AtomicI64,
    deliver: Box<dyn Fn(Vec<u8>) + Send + Sync>,
}

impl Ros2Node {
    /// A client of `spec` (its token `SC`): each call ([`Ros2Caller::call`]) is a query
    /// on the service's key; its answer (call number, kind, the response's JSON, as
    /// `ferroc_link::calls` reads answers: the response's CDR) goes to `deliver`.
    pub fn service_client(
        &self,
        spec: ServiceSpec,
        deliver: impl Fn(Vec<u8>) + Send + Sync + 'static,
    ) -> Result<Ros2Caller, String> {
        let as_topic = TopicSpec {
            topic: spec.name.clone(),
            ty: spec.ty.clone(),
            qos: Qos::default(),
            field: None,
        };
        let (key, live, _) = self.keys(&as_topic, EntityKind::ServiceClient)?;
        let token = token(&self.session, &live, &spec.name)?;
        let ours = key.rsplit('/').next().unwrap_or_default();
        let other_servers =
            other_hash_servers(&self.session, self.info.domain, &spec.name, &spec.ty, ours)?;
        Ok(Ros2Caller {
            shared: Arc::new(CallerShared {
                registry: Arc::clone(&self.registry),
                spec,
                session: self.session.clone(),
                key,
                gid: rmw_zenoh::gid_of(&live),
                sequence: AtomicI64::new(0),
                deliver: Box::new(deliver),
            }),
            _other_servers: other_servers,
            _token: token,
        })
    }
}

/// How long a call waits for the server's reply.
const CALL_TIMEOUT: Duration = Duration::from_secs(10);

/// The kinds of an answer, as `ferroc_link::calls` reads them.
const ANSWERED: u8 = 0;
const TIMED_OUT: u8 = 2;
const FAILED: u8 = 3;

impl Ros2Caller {
    /// Sends a request frame of the module's client (call number, the request's CDR)
    /// as a query with rmw_zenoh's attachment. A request that does not fit the request
    /// message is answered at once as failed, and an error naming the service.
    pub fn call(&self, bytes: &[u8]) -> Result<(), String> {
        let shared = &self.shared;
        let (id, body) = bytes
            .split_first_chunk::<8>()
            .ok_or("a request shorter than its number")?;
        let id = u64::from_le_bytes(*id);
        let request = match shared.encode(body) {
            Ok(request) => request,
            Err(why) => {
                shared.answer(id, FAILED, &[]);
                return Err(format!("a request was not sent: {why}"));
            }
        };
        let attachment = Attachment {
            sequence_number: shared.sequence.fetch_add(1, Ordering::Relaxed) + 1,
            source_timestamp: now_ns(),
            gid: shared.gid,
        };
        let pending = Pending {
            shared: Arc::clone(shared),
            id,
            answered: AtomicBool::new(false),
        };
        shared
            .session
            .get(shared.key.clone())
            .payload(request)
            .attachment(attachment.encode().to_vec())
            .timeout(CALL_TIMEOUT)
            .callback(move |reply| pending.reply(reply))
            .wait()
            .map_err(|e| format!("a request was not sent: {e}"))
    }

    /// The service.
    pub fn spec(&self) -> &ServiceSpec {
        &self.shared.spec
    }
}

impl CallerShared {
    /// The request's CDR, checked against the request message.
    fn encode(&self, body: &[u8]) -> Result<Vec<u8>, String> {
        check(&self.registry, &self.spec, "Request", body)?;
        Ok(body.to_vec())
    }

    /// A reply's CDR, checked against the response message.
    fn decode(&self, payload: &[u8]) -> Result<Vec<u8>, String> {
        check(&self.registry, &self.spec, "Response", payload)?;
        Ok(payload.to_vec())
    }

    fn answer(&self, id: u64, kind: u8, body: &[u8]) {
        let mut bytes = id.to_le_bytes().to_vec();
        bytes.push(kind);
        bytes.extend_from_slice(body);
        (self.deliver)(bytes);
    }
}

/// A call in flight: answered by its first reply, else, when the query ends without
/// one (no server, or none in time), as timed out.
struct Pending {
    shared: Arc<CallerShared>,
    id: u64,
    answered: AtomicBool,
}

impl Pending {
    fn reply(&self, reply: zenoh::query::Reply) {
        if self.answered.swap(true, Ordering::Relaxed) {
            return;
        }
        let shared = &self.shared;
        let decoded = match reply.result() {
            Ok(sample) => shared.decode(&sample.payload().to_bytes()),
            Err(e) => Err(format!(
                "the server refused the request: {}",
                String::from_utf8_lossy(&e.payload().to_bytes())
            )),
        };
        match decoded {
            Ok(response) => shared.answer(self.id, ANSWERED, &response),
            Err(why) => {
                shared.answer(self.id, FAILED, &[]);
                console::report_as(
                    &format!("ROS 2 service `{}`: reply", shared.spec.name),
                    &format!(
                        "warning: a reply of the ROS 2 service `{}` was dropped: {why}",
                        shared.spec.name
                    ),
                );
            }
        }
    }
}

impl Drop for Pending {
    fn drop(&mut self) {
        if !self.answered.swap(true, Ordering::Relaxed) {
            self.shared.answer(self.id, TIMED_OUT, &[]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ferroc_ros2::Value;

    fn set_bool() -> ServiceSpec {
        ServiceSpec {
            name: "/switch_bot/set_enabled".into(),
            ty: TypeName::parse("std_srvs/srv/SetBool").unwrap(),
            request_field: Some("data".into()),
            response_field: None,
        }
    }

    #[test]
    fn a_bad_request_is_an_error_naming_what_is_wrong_never_a_panic() {
        let reg = Registry::shipped();
        let spec = set_bool();
        let asked = Attachment {
            sequence_number: 7,
            source_timestamp: 0,
            gid: [9; 16],
        }
        .encode();
        // SetBool_Request { data: true }: the encapsulation header, then one byte.
        let request = [&cdr::HEADER[..], &[1]].concat();
        let (attachment, cdr) = read_request(&reg, &spec, Some(&asked), Some(&request)).unwrap();
        assert_eq!((attachment.sequence_number, cdr), (7, request.clone()));
        let short = read_request(&reg, &spec, Some(&asked[..20]), Some(&request)).unwrap_err();
        assert!(short.contains("attachment has 20 bytes"), "{short}");
        let none = read_request(&reg, &spec, None, Some(&request)).unwrap_err();
        assert!(none.contains("no attachment"), "{none}");
        let empty = read_request(&reg, &spec, Some(&asked), None).unwrap_err();
        assert!(empty.contains("no request"), "{empty}");
        for n in 0..request.len() {
            assert!(read_request(&reg, &spec, Some(&asked), Some(&request[..n])).is_err());
        }
        let not_bool = [&cdr::HEADER[..], &[7]].concat();
        let e = read_request(&reg, &spec, Some(&asked), Some(&not_bool)).unwrap_err();
        assert!(e.contains("bool"), "{e}");
    }

    #[test]
    fn an_answer_must_be_the_response_message() {
        let reg = Registry::shipped();
        let spec = set_bool();
        let ty = spec.message("Response");
        let answer = Value::Struct(vec![Value::Bool(true), Value::String("disabled".into())]);
        let bytes = cdr::encode(&reg, &ty, &answer).unwrap();
        assert!(check(&reg, &spec, "Response", &bytes).is_ok());
        assert!(check(&reg, &spec, "Response", &bytes[..5]).is_err());
        assert!(
            check(&reg, &spec, "Request", &bytes).is_err(),
            "another message"
        );
    }
}
