//! D103 `lock-order-inversion`: Two threads take the same locks in opposite orders.
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "D103",
    name: "lock-order-inversion",
    severity: Severity::Error,
    summary: "Two threads take the same locks in opposite orders.",
    explanation: "Thread 1 holds lock A and waits for lock B while thread 2 holds B and waits for A: both
wait forever. ferroc reports such a cycle when the modules run on distinct thread
containers and hold no common guard (a shared thread or an outer lock serialises them:
then it is only a note, D117).

Bad (m1 and m2 in different thread containers):
    <module-type name=\"M1\" ...><activity><lock slot=\"a\"/><lock slot=\"b\"/></activity></module-type>
    <module-type name=\"M2\" ...><activity><lock slot=\"b\"/><lock slot=\"a\"/></activity></module-type>

Fix: take the locks in the same order everywhere (declare it with <locks order=\"a b\"/>),
or give one lock step a timeout.",
    fixtures: "compiler/checks/src/deadlocks/d103_lock_order_inversion",
};
