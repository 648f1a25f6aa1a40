//! `<part shared-memory shared-memory-threshold shared-memory-pool>`: a part's shared
//! memory for links to parts on the same computer (docs/zenoh.md, "Shared memory").
//! Values that cannot work are M108 findings here, where they are read: a size that
//! does not parse, a threshold of zero, a pool outside 64 KiB..4 GiB, a threshold
//! larger than the pool (no value could ever use it).

use super::Resolver;
use crate::ir::{ElementId, SharedMemory};
use ferroc_diagnostics::source::Span;
use ferroc_syntax::Element;

const SIZE_HELP: &str = "write a size in bytes, KiB, MiB or GiB, e.g. \"64 MiB\"";

impl Resolver<'_, '_, '_> {
    /// The shared-memory settings of the part `id` (element `e`), checked.
    pub(super) fn part_shared_memory(&mut self, id: ElementId, e: &Element) {
        let mut settings = SharedMemory {
            enabled: e.value("shared-memory").map(|v| v == "on"),
            ..SharedMemory::default()
        };
        let threshold = self.size(e, "shared-memory-threshold");
        let pool = self.size(e, "shared-memory-pool");
        if let Some((bytes, span)) = pool {
            if !(SharedMemory::MIN_POOL..=SharedMemory::MAX_POOL).contains(&bytes) {
                self.invalid(
                    span,
                    &format!(
                        "a shared-memory pool of {} cannot work: it must hold at least one \
                         large value and fit in /dev/shm",
                        show(bytes)
                    ),
                    "give a pool from 64 KiB to 4 GiB, e.g. shared-memory-pool=\"64 MiB\"",
                );
            } else {
                settings.pool = Some(bytes);
            }
        }
        if let Some((bytes, span)) = threshold {
            let room = settings.pool.unwrap_or(SharedMemory::DEFAULT_POOL);
            self.threshold(bytes, span, room, &mut settings);
        }
        if settings != SharedMemory::default() {
            self.app.shared_memory.insert(id, settings);
        }
    }

    /// Checks `shared-memory-threshold` against zero and the pool of `room` bytes.
    fn threshold(&mut self, bytes: u64, span: Span, room: u64, settings: &mut SharedMemory) {
        if bytes == 0 {
            self.invalid(
                span,
                "a shared-memory threshold of 0 bytes would put even empty values in the pool",
                "write at least 1 byte; ferroc's default is \"4 KiB\"",
            );
        } else if bytes > room {
            self.invalid(
                span,
                &format!(
                    "the shared-memory threshold {} is larger than the part's pool ({}): no \
                     value could travel in shared memory",
                    show(bytes),
                    show(room)
                ),
                "lower shared-memory-threshold below the pool's size, or raise \
                 shared-memory-pool, or write shared-memory=\"off\"",
            );
        } else {
            settings.threshold = Some(bytes);
        }
    }

    /// The size attribute `name` of `e` in bytes, with its span; a finding when it is
    /// written but does not parse.
    fn size(&mut self, e: &Element, name: &str) -> Option<(u64, Span)> {
        let a = e.attr(name)?;
        match parse_size(a.value) {
            Some(bytes) => Some((bytes, a.value_span)),
            None => {
                let msg = format!("`{}` is not a size for `{name}`", a.value);
                self.invalid(a.value_span, &msg, SIZE_HELP);
                None
            }
        }
    }
}

/// `4096`, `4096 B`, `16 KiB`, `64 MiB`, `1 GiB` in bytes; `None` for anything else
/// (decimal units such as `MB` included: they are ambiguous, so the model says KiB/MiB).
fn parse_size(text: &str) -> Option<u64> {
    let t = text.trim();
    let split = t.find(|c: char| !c.is_ascii_digit()).unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let shift = match unit.trim() {
        "" | "B" => 0,
        "KiB" => 10,
        "MiB" => 20,
        "GiB" => 30,
        _ => return None,
    };
    let n: u64 = number.parse().ok()?;
    n.checked_mul(1 << shift)
}

/// `67108864` as `64 MiB` (whole GiB, MiB or KiB), other sizes in bytes.
fn show(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 30 && b % (1 << 30) == 0 => format!("{} GiB", b >> 30),
        b if b >= 1 << 20 && b % (1 << 20) == 0 => format!("{} MiB", b >> 20),
        b if b >= 1 << 10 && b % (1 << 10) == 0 => format!("{} KiB", b >> 10),
        b => format!("{b} bytes"),
    }
}

#[cfg(test)]
mod tests {
    use super::parse_size;

    #[test]
    fn sizes_in_bytes_and_binary_units() {
        assert_eq!(parse_size("4096"), Some(4096));
        assert_eq!(parse_size("4096 B"), Some(4096));
        assert_eq!(parse_size(" 16 KiB "), Some(16 << 10));
        assert_eq!(parse_size("64MiB"), Some(64 << 20));
        assert_eq!(parse_size("1 GiB"), Some(1 << 30));
        for bad in [
            "",
            "MiB",
            "64 MB",
            "1.5 MiB",
            "-1",
            "64 mib",
            "99999999999999999 GiB",
        ] {
            assert_eq!(parse_size(bad), None, "{bad}");
        }
    }
}
