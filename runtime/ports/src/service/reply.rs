//! The way back: a one-shot reply slot shared by one caller and whoever answers.
//!
//! Every call that is queued gets its own [`Slot`]. The server side holds it through a
//! [`Responder`], the caller through a [`PendingResponse`] (or, for a blocking call, on
//! its stack). The slot is a mutex around a small state plus a condition variable:
//! a blocking caller sleeps on the condvar (no spinning), and the responder fills the
//! state and wakes it. A mutex is fine here: the critical sections are a few
//! instructions, at most two threads ever touch one slot, and services are not the
//! zero-copy data path.
//!
//! The one rule that makes calls unable to hang on a vanished server: a [`Responder`]
//! always answers. Dropping it unanswered (the request was withdrawn, the server was
//! dropped with the request still queued, or the code holding it gave up) completes
//! the slot with [`CallError::Disconnected`]; dropping it while its thread unwinds from
//! a panic completes it with [`CallError::ServerPanicked`].

use std::fmt;
use std::time::{Duration, Instant};

use super::CallError;
use crate::port::Notifier;
use crate::sync::{lock, Arc, Condvar, Mutex};

enum State<Resp> {
    Waiting,
    Done(Result<Resp, CallError>),
    Taken,
}

pub(crate) struct Slot<Resp> {
    state: Mutex<State<Resp>>,
    cv: Condvar,
    /// The calling client's notifier (asynchronous calls only): lets a data-triggered
    /// container that made the call wake up for the answer.
    notifier: Option<Notifier>,
}

impl<Resp> Slot<Resp> {
    pub(crate) fn new(notifier: Option<Notifier>) -> Arc<Self> {
        Arc::new(Slot {
            state: Mutex::new(State::Waiting),
            cv: Condvar::new(),
            notifier,
        })
    }

    fn done(result: Result<Resp, CallError>) -> Arc<Self> {
        Arc::new(Slot {
            state: Mutex::new(State::Done(result)),
            cv: Condvar::new(),
            notifier: None,
        })
    }

    /// Stores the result (the first one wins) and wakes the caller. The notifier runs
    /// after the lock is released: it is user code.
    fn complete(&self, result: Result<Resp, CallError>) {
        let mut state = lock(&self.state);
        if !matches!(*state, State::Waiting) {
            return;
        }
        *state = State::Done(result);
        self.cv.notify_all();
        drop(state);
        if let Some(n) = &self.notifier {
            n.notify();
        }
    }

    fn is_ready(&self) -> bool {
        matches!(*lock(&self.state), State::Done(_))
    }

    fn try_take(&self) -> Option<Result<Resp, CallError>> {
        let mut state = lock(&self.state);
        take_done(&mut state)
    }

    /// Sleeps until the result is in (`None` deadline: however long that takes) and
    /// takes it; `None` if the deadline passed first.
    pub(crate) fn wait(&self, deadline: Option<Instant>) -> Option<Result<Resp, CallError>> {
        let mut state = lock(&self.state);
        loop {
            if let Some(result) = take_done(&mut state) {
                return Some(result);
            }
            state = match deadline {
                None => self.cv.wait(state).unwrap_or_else(|e| e.into_inner()),
                Some(deadline) => {
                    let now = Instant::now();
                    if now >= deadline {
                        return None;
                    }
                    match self.cv.wait_timeout(state, deadline - now) {
                        Ok((g, _)) => g,
                        Err(e) => e.into_inner().0,
                    }
                }
            };
        }
    }
}

fn take_done<Resp>(state: &mut State<Resp>) -> Option<Result<Resp, CallError>> {
    match std::mem::replace(state, State::Taken) {
        State::Done(result) => Some(result),
        other => {
            *state = other;
            None
        }
    }
}

/// The right (and duty) to answer one call.
///
/// Obtained from [`Request::into_parts`](super::Request::into_parts) when a service
/// answers later than in the step that took the request (an action that takes several
/// cycles, say). It may be moved to another thread. If it is dropped without
/// [`respond`](Self::respond), the caller gets [`CallError::Disconnected`] — or
/// [`CallError::ServerPanicked`] if it is dropped by a panic, which also stops the
/// service (see [`ServicePort`](super::ServicePort)) — so a caller never waits for an
/// answer that cannot come.
pub struct Responder<Resp> {
    slot: Option<Arc<Slot<Resp>>>,
    /// Set once the responder left the queue for user code: stops the service if that
    /// code panics while holding it.
    on_panic: Option<Box<dyn FnOnce() + Send>>,
}

impl<Resp> Responder<Resp> {
    pub(crate) fn new(slot: Arc<Slot<Resp>>) -> Self {
        Responder {
            slot: Some(slot),
            on_panic: None,
        }
    }

    pub(crate) fn handed_out(mut self, on_panic: Box<dyn FnOnce() + Send>) -> Self {
        self.on_panic = Some(on_panic);
        self
    }

    /// Answers the call. If the caller stopped waiting (timed out, or dropped its
    /// [`PendingResponse`]), the response is dropped.
    pub fn respond(mut self, response: Resp) {
        self.finish(Ok(response));
    }

    #[doc(hidden)]
    pub fn fail(mut self, error: CallError) {
        self.finish(Err(error));
    }

    fn finish(&mut self, result: Result<Resp, CallError>) {
        self.on_panic = None;
        if let Some(slot) = self.slot.take() {
            slot.complete(result);
        }
    }
}

impl<Resp> Drop for Responder<Resp> {
    fn drop(&mut self) {
        let Some(slot) = self.slot.take() else { return };
        match self.on_panic.take() {
            Some(stop_service) if std::thread::panicking() => {
                slot.complete(Err(CallError::ServerPanicked));
                stop_service();
            }
            _ => slot.complete(Err(CallError::Disconnected)),
        }
    }
}

impl<Resp> fmt::Debug for Responder<Resp> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Responder").finish_non_exhaustive()
    }
}

/// The answer to an asynchronous call, once it is in.
///
/// Returned by [`ClientPort::call_async`](super::ClientPort::call_async). Poll it with
/// [`try_take`](Self::try_take) from a step (a client's notifier, see
/// [`ClientPort::set_notifier`](super::ClientPort::set_notifier), can wake a
/// data-triggered container when it arrives), or wait with [`wait`](Self::wait) /
/// [`wait_timeout`](Self::wait_timeout). The methods that end the call take `self`:
/// a result can only be taken once, and nothing can wait on a taken result.
///
/// Dropping it abandons the answer, not the request: a request the server has
/// accepted is executed all the same.
pub struct PendingResponse<Resp> {
    slot: Arc<Slot<Resp>>,
}

impl<Resp> PendingResponse<Resp> {
    pub(crate) fn queued(slot: Arc<Slot<Resp>>) -> Self {
        PendingResponse { slot }
    }

    /// An already answered call (the service ran inline in the caller's thread).
    pub(crate) fn ready(result: Result<Resp, CallError>) -> Self {
        PendingResponse {
            slot: Slot::done(result),
        }
    }

    /// Whether the answer (or an error) is in; [`try_take`](Self::try_take) would
    /// return it.
    pub fn is_ready(&self) -> bool {
        self.slot.is_ready()
    }

    /// The result if it is in, without waiting; otherwise the handle back, to poll
    /// again later.
    pub fn try_take(self) -> Result<Result<Resp, CallError>, Self> {
        self.slot.try_take().ok_or(self)
    }

    /// Waits for the result (without a time limit: see
    /// [`ClientPort::call`](super::ClientPort::call) for when that can be forever).
    pub fn wait(self) -> Result<Resp, CallError> {
        // Some(_) is the only possible outcome without a deadline.
        self.slot.wait(None).unwrap_or(Err(CallError::Disconnected))
    }

    /// Waits at most `timeout` for the result; on timeout the handle comes back (drop
    /// it to give up, or keep waiting later).
    pub fn wait_timeout(self, timeout: Duration) -> Result<Result<Resp, CallError>, Self> {
        let deadline = Instant::now().checked_add(timeout);
        self.slot.wait(deadline).ok_or(self)
    }
}

impl<Resp> fmt::Debug for PendingResponse<Resp> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("PendingResponse")
            .field("ready", &self.is_ready())
            .finish()
    }
}
