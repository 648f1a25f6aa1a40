//! D110 `same-thread-queue-read`: A blocking read of a queue whose only writers run later in the reader's own thread container.
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "D110",
    name: "same-thread-queue-read",
    severity: Severity::Error,
    summary: "A blocking read of a queue whose only writers run later in the reader's own thread container.",
    explanation: "Modules of one thread container run one after another in a static order. A module
that blocks reading a queue fed only by modules of its own container that are
scheduled after it waits for them, and they never run: the container hangs. A writer
scheduled earlier puts the item in first (clean), unless it may skip its write (then
the container hangs the first time it skips: a warning).

Bad (r is scheduled before w because r feeds w):
    <connect from=\"robot/main/w/out\" to=\"robot/main/r/in\" queue=\"2\"/>
    <connect from=\"robot/main/r/out\" to=\"robot/main/w/in\"/>

Fix: run the writer before the reader (or in another thread container), or add
initial=\"1\" to the <connect>.",
    fixtures: "compiler/checks/src/deadlocks/d110_same_thread_queue_read",
};
