//! Service calls between parts: a client in one part calling a service in another.
//!
//! In the client's part a stand-in service (a [`ServicePort`] the client connects to
//! as to any service) sends each request as a frame; in the service's part a stand-in
//! client (a [`ClientPort`]) makes the call asynchronously and sends the answer, or the
//! error, back. Both sides are woken by the service machinery's own notifiers (a
//! request queued, an answer ready), so no extra thread polls. A call travels on two
//! link numbers above every data link: one for requests, one for answers.
//!
//! Request and response types cross encoded like values (postcard); they are
//! registered in pairs with `Registry::register_call` (`ferroc_app::builder`). A
//! service offered as a ROS 2 service has the same stand-in client, with requests and
//! answers as the CDR of the service's messages (`Route::ros2`), which the network
//! sends as they are (docs/ros2.md).

use super::{Frame, Hub, Receive};
use ferroc_ports::port::{Notifier, Notify};
use ferroc_ports::service::{CallError, ClientHandle, ClientPort, PendingResponse, ServiceHandle};
use ferroc_ports::service::{Responder, ServicePort};
use ferroc_ros2::serde_cdr;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, Weak};

/// Data links are numbered below this; call `k` uses the two numbers after
/// `CALL_LINKS + 2k`.
pub(crate) const CALL_LINKS: u32 = 1 << 31;

/// The link number of call `id`'s requests.
#[doc(hidden)]
pub fn request_link(id: u32) -> u32 {
    CALL_LINKS.saturating_add(id.saturating_mul(2))
}

/// The link number of call `id`'s answers.
#[doc(hidden)]
pub fn answer_link(id: u32) -> u32 {
    request_link(id).saturating_add(1)
}

/// Where an end sends its frames.
#[doc(hidden)]
pub struct Route {
    pub hub: Arc<Hub>,
    pub link: u32,
    pub to_part: Arc<str>,
    /// Requests and answers as the CDR of a ROS 2 service's messages, else postcard.
    pub ros2: Option<Arc<super::ros2::ServiceMessages>>,
}

impl Route {
    fn send(&self, id: u64, head: Option<u8>, body: &[u8]) {
        let mut bytes = Vec::with_capacity(9 + body.len());
        bytes.extend_from_slice(&id.to_le_bytes());
        bytes.extend(head);
        bytes.extend_from_slice(body);
        let frame = Frame {
            link: self.link,
            bytes,
        };
        self.hub.send(&self.to_part, frame);
    }
}

/// How to make the two ends of a call across parts (the stand-ins for a remote
/// service or client) for one pair of request and response types.
#[derive(Clone, Copy)]
pub struct CallEnds {
    remote_service: fn(String, Route) -> (ServiceHandle, Arc<dyn Receive>),
    remote_client: fn(String, Route) -> (ClientHandle, Arc<dyn Receive>),
}

impl CallEnds {
    #[doc(hidden)]
    pub fn of<Req, Resp>() -> Self
    where
        Req: Serialize + DeserializeOwned + Send + 'static,
        Resp: Serialize + DeserializeOwned + Send + 'static,
    {
        CallEnds {
            remote_service: remote_service::<Req, Resp>,
            remote_client: remote_client::<Req, Resp>,
        }
    }

    /// A service standing for one in another part (connect the local client to it).
    #[doc(hidden)]
    pub fn remote_service(&self, name: String, route: Route) -> (ServiceHandle, Arc<dyn Receive>) {
        (self.remote_service)(name, route)
    }

    /// A client standing for one in another part (connect it to the local service).
    #[doc(hidden)]
    pub fn remote_client(&self, name: String, route: Route) -> (ClientHandle, Arc<dyn Receive>) {
        (self.remote_client)(name, route)
    }
}

/// Calls a notifier target without keeping it alive (the port holding the notifier is
/// owned by the target: a strong reference would be a cycle).
struct WeakNotify<T>(Weak<T>);

impl<T: Notify> Notify for WeakNotify<T> {
    fn notify(&self) {
        if let Some(target) = self.0.upgrade() {
            target.notify();
        }
    }
}

/// `value` (a request, else an answer) as the route carries it.
fn encode<T: Serialize>(route: &Route, value: &T, request: bool) -> Result<Vec<u8>, String> {
    match &route.ros2 {
        Some(m) => serde_cdr::encode(m.of(request), value).map_err(|e| e.to_string()),
        None => postcard::to_stdvec(value).map_err(|e| e.to_string()),
    }
}

/// A value (a request, else an answer) as the route carries it.
fn decode<T: DeserializeOwned>(route: &Route, bytes: &[u8], request: bool) -> Result<T, String> {
    match &route.ros2 {
        Some(m) => serde_cdr::from_cdr(m.of(request), bytes).map_err(|e| e.to_string()),
        None => postcard::from_bytes(bytes).map_err(|e| e.to_string()),
    }
}

fn split_id(bytes: &[u8]) -> Result<(u64, &[u8]), String> {
    let (id, rest) = bytes
        .split_first_chunk::<8>()
        .ok_or("a call message shorter than its number")?;
    Ok((u64::from_le_bytes(*id), rest))
}

const ANSWERED: u8 = 0;

pub(crate) fn error_code(e: CallError) -> u8 {
    match e {
        CallError::NotConnected => 1,
        CallError::Timeout => 2,
        CallError::QueueFull => 4,
        CallError::ServerPanicked => 5,
        _ => 3,
    }
}

/// The call error a failed answer's code stands for (what [`error_code`] wrote).
pub fn error_of(code: u8) -> CallError {
    match code {
        1 => CallError::NotConnected,
        2 => CallError::Timeout,
        4 => CallError::QueueFull,
        5 => CallError::ServerPanicked,
        _ => CallError::Disconnected,
    }
}

/// In the client's part: takes the requests the client queues and sends them.
struct RemoteService<Req, Resp> {
    port: ServicePort<Req, Resp>,
    route: Route,
    next: AtomicU64,
    waiting: Mutex<HashMap<u64, Responder<Resp>>>,
}

fn remote_service<Req, Resp>(name: String, route: Route) -> (ServiceHandle, Arc<dyn Receive>)
where
    Req: Serialize + DeserializeOwned + Send + 'static,
    Resp: Serialize + DeserializeOwned + Send + 'static,
{
    let remote = Arc::new(RemoteService {
        port: ServicePort::<Req, Resp>::new(name),
        route,
        next: AtomicU64::new(0),
        waiting: Mutex::default(),
    });
    let notifier: Notifier = Arc::new(WeakNotify(Arc::downgrade(&remote)));
    let _ = remote.port.set_notifier(notifier);
    (remote.port.handle(), remote)
}

impl<Req, Resp> Notify for RemoteService<Req, Resp>
where
    Req: Serialize + Send + 'static,
    Resp: Send + 'static,
{
    fn notify(&self) {
        while let Some(request) = self.port.take_request() {
            let (request, responder) = request.into_parts();
            let Ok(body) = encode(&self.route, &request, true) else {
                responder.fail(CallError::Disconnected);
                continue;
            };
            let id = self.next.fetch_add(1, Ordering::Relaxed);
            lock(&self.waiting).insert(id, responder);
            self.route.send(id, None, &body);
        }
    }
}

impl<Req, Resp> Receive for RemoteService<Req, Resp>
where
    Req: Send + 'static,
    Resp: DeserializeOwned + Send + 'static,
{
    fn receive(&self, bytes: &[u8]) -> Result<(), String> {
        let (id, rest) = split_id(bytes)?;
        let (&head, body) = rest.split_first().ok_or("an answer without its kind")?;
        let responder = lock(&self.waiting)
            .remove(&id)
            .ok_or_else(|| format!("an answer to call {id}, which is not waiting"))?;
        if head != ANSWERED {
            responder.fail(error_of(head));
            return Ok(());
        }
        match decode::<Resp>(&self.route, body, false) {
            Ok(response) => {
                responder.respond(response);
                Ok(())
            }
            Err(e) => {
                responder.fail(CallError::Disconnected);
                Err(format!("an answer that does not decode: {e}"))
            }
        }
    }
}

/// In the service's part: calls the service for each request that arrives and sends
/// the answers back.
struct RemoteClient<Req, Resp> {
    port: ClientPort<Req, Resp>,
    route: Route,
    calls: Mutex<Vec<(u64, PendingResponse<Resp>)>>,
}

fn remote_client<Req, Resp>(name: String, route: Route) -> (ClientHandle, Arc<dyn Receive>)
where
    Req: Serialize + DeserializeOwned + Send + 'static,
    Resp: Serialize + DeserializeOwned + Send + 'static,
{
    let remote = Arc::new(RemoteClient {
        port: ClientPort::<Req, Resp>::new(name),
        route,
        calls: Mutex::default(),
    });
    let notifier: Notifier = Arc::new(WeakNotify(Arc::downgrade(&remote)));
    let _ = remote.port.set_notifier(notifier);
    (remote.port.handle(), remote)
}

impl<Req, Resp: Serialize> RemoteClient<Req, Resp> {
    /// Sends the answers that are ready, in the order the calls came.
    fn answer_ready(&self) {
        let mut calls = lock(&self.calls);
        let (ready, waiting): (Vec<_>, Vec<_>) = std::mem::take(&mut *calls)
            .into_iter()
            .partition(|(_, p)| p.is_ready());
        *calls = waiting;
        drop(calls);
        for (id, pending) in ready {
            match pending.try_take() {
                Ok(Ok(response)) => match encode(&self.route, &response, false) {
                    Ok(body) => self.route.send(id, Some(ANSWERED), &body),
                    Err(_) => self
                        .route
                        .send(id, Some(error_code(CallError::Disconnected)), &[]),
                },
                Ok(Err(e)) => self.route.send(id, Some(error_code(e)), &[]),
                Err(pending) => lock(&self.calls).push((id, pending)),
            }
        }
    }
}

impl<Req, Resp> Notify for RemoteClient<Req, Resp>
where
    Req: Send + 'static,
    Resp: Serialize + Send + 'static,
{
    fn notify(&self) {
        self.answer_ready();
    }
}

impl<Req, Resp> Receive for RemoteClient<Req, Resp>
where
    Req: DeserializeOwned + Send + 'static,
    Resp: Serialize + Send + 'static,
{
    fn receive(&self, bytes: &[u8]) -> Result<(), String> {
        let (id, body) = split_id(bytes)?;
        let request = match decode::<Req>(&self.route, body, true) {
            Ok(r) => r,
            Err(e) => {
                self.route
                    .send(id, Some(error_code(CallError::Disconnected)), &[]);
                return Err(format!("a request that does not decode: {e}"));
            }
        };
        match self.port.call_async(request) {
            Ok(pending) => lock(&self.calls).push((id, pending)),
            Err(e) => self.route.send(id, Some(error_code(e)), &[]),
        }
        self.answer_ready();
        Ok(())
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}
