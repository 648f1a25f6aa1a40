//! Data a module was meant to keep and lost (a recording cut short by a full disk):
//! reported here by the module as it happens, named in the run's summary at the end,
//! and the run's exit code says so (`supervise`). Process-wide, like the run itself.

use std::sync::{Mutex, PoisonError};

static LOST: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// Records that `what` was lost, in plain words naming what and why (one line,
/// e.g. "the recording `run.mcap` stopped: the disk is full"). Reported once per
/// loss: a module calls it when the loss begins, not for every value after.
pub fn report_data_loss(what: impl Into<String>) {
    LOST.lock()
        .unwrap_or_else(PoisonError::into_inner)
        .push(what.into());
}

/// What was reported lost so far, in order.
pub fn data_losses() -> Vec<String> {
    LOST.lock().unwrap_or_else(PoisonError::into_inner).clone()
}
