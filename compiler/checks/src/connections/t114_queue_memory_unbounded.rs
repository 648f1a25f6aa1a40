//! T114 `queue-memory-unbounded`: A queue's values have no size bound, or its values
//! together may take more memory than a run should reserve for one queue.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_model::library::LibrarySet;
use ferroc_values::types::Type;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T114",
    name: "queue-memory-unbounded",
    severity: Severity::Warning,
    summary: "A queue holds values of unbounded size, or more bytes than one queue should.",
    explanation: "`queue=\"N\"` bounds how many values wait at an input, not how many bytes: a
queue of strings, sequences (`[f64]`) or library types that hold them grows with
whatever its writer sends — a queue of 100 values of 20,000-element vectors holds 16 MB,
and a slow reader with a large queue lets a run take gigabytes. A queue of fixed-size
values (numbers, arrays `f64[N]`, library types whose declared fields are all of fixed
size) reserves at most N times their size; above 256 MiB for one queue that is reported
too. A library type that declares no fields and is not `copy=\"true\"` may hold heap
data: its size is not known to the checker, and a queue of it is reported as unbounded.

Bad:
    <connect from=\"robot/main/lidar/scan\" to=\"robot/slow/mapper/scan\" queue=\"1000\"/>
    <!-- scan is [f64]: 1000 scans of any length -->

Fix: queue fewer values (a reader that keeps up needs a few), send a fixed-size type
(`f64[720]`), or, when the sizes are bounded by the writer, say so with
<allow code=\"T114\" reason=\"…\">.",
    fixtures: "compiler/checks/src/connections/t114_queue_memory_unbounded",
};

/// Bytes one queue may reserve before it is reported (the size limit of a model file).
pub const MAX_QUEUE_BYTES: u64 = 256 << 20;

/// The most bytes a value of `ty` takes, `None` when nothing bounds it.
pub fn max_size(libraries: &LibrarySet, ty: &Type) -> Option<u64> {
    max_size_at(libraries, ty, 0)
}

/// [`max_size`] with the depth of library types followed (a type holding itself
/// through fields cannot be bounded; the depth keeps that finite).
fn max_size_at(libraries: &LibrarySet, ty: &Type, depth: usize) -> Option<u64> {
    match ty {
        Type::Bool => Some(1),
        Type::Int { bits, .. } | Type::Float { bits } => Some(u64::from(*bits).div_ceil(8)),
        Type::Meta(_) => Some(8),
        Type::Duration | Type::Timestamp => Some(16),
        Type::Array(element, n) => {
            max_size_at(libraries, element, depth)?.checked_mul(u64::from(*n))
        }
        Type::String | Type::Seq(_) => None,
        Type::Named(id, _) => {
            let named = libraries.named_type(*id);
            if depth > 16 || (named.fields.is_empty() && !named.copy) {
                return None;
            }
            // A copy type has no heap data; without declared fields its size is not
            // known here, but it is small (it is copied by value).
            named.fields.iter().try_fold(0u64, |sum, (_, field, _)| {
                sum.checked_add(max_size_at(libraries, field, depth + 1)?)
            })
        }
    }
}

/// What the bytes of a number are called in a message.
fn bytes(n: u64) -> String {
    match n {
        n if n >= 1 << 30 => format!("{:.1} GiB", n as f64 / f64::from(1u32 << 30)),
        n if n >= 1 << 20 => format!("{:.1} MiB", n as f64 / f64::from(1u32 << 20)),
        n => format!("{n} bytes"),
    }
}

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (c, _, to) in ctx.connections_with_ends() {
        let Some(capacity) = c.queue else {
            continue;
        };
        let label = format!("`{}` takes `{}`", to.name, to.ty);
        let d = match max_size(ctx.libraries, to.ty) {
            None => Diagnostic::new(
                &CHECK,
                c.span,
                format!(
                    "`{}` queues up to {capacity} values of `{}`, whose size has no bound: the queue's memory has none",
                    super::describe(ctx, c),
                    to.ty
                ),
            )
            .label("a count of values, not of bytes")
            .secondary(to.span, label)
            .help("queue fewer values, or send a fixed-size type (an array `T[N]`); if the writer bounds the sizes, say so with <allow code=\"T114\" reason=\"…\">"),
            Some(size) => {
                let total = size.saturating_mul(u64::from(capacity));
                if total <= MAX_QUEUE_BYTES {
                    continue;
                }
                Diagnostic::new(
                    &CHECK,
                    c.span,
                    format!(
                        "`{}` queues up to {capacity} values of `{}` ({} each): {} for one queue, over {}",
                        super::describe(ctx, c),
                        to.ty,
                        bytes(size),
                        bytes(total),
                        bytes(MAX_QUEUE_BYTES)
                    ),
                )
                .label("this queue may hold that much")
                .secondary(to.span, label)
                .help(format!(
                    "queue at most {} values of this type",
                    (MAX_QUEUE_BYTES / size.max(1)).max(1)
                ))
            }
        };
        out.push(d);
    }
}
