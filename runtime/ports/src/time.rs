//! [`Timestamp`]: the port value of the model type `timestamp`.
//!
//! A wall-clock instant as signed nanoseconds since the Unix epoch, in one `i64` so it
//! takes the seqlock (copy) path like any number: a clock publishes one every cycle and
//! must not allocate or count references for it. `i64` nanoseconds cover the years
//! 1678 to 2262, which is enough for robots.

use std::cell::Cell;
use std::fmt;
use std::time::{Duration, SystemTime, UNIX_EPOCH};

/// A wall-clock instant (model type `timestamp`): nanoseconds since 1970-01-01 UTC.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    PartialOrd,
    Ord,
    Hash,
    bytemuck::NoUninit,
    serde::Serialize,
    serde::Deserialize,
)]
#[repr(C)]
pub struct Timestamp {
    /// Nanoseconds since the Unix epoch (negative: before it).
    pub nanos: i64,
}

impl Timestamp {
    /// The current time: the wall clock, or on a thread that runs the application in
    /// simulated time (lockstep) the model time, counted from [`Self::LOCKSTEP_EPOCH`].
    /// Modules that read the time through here run the same way in every lockstep run.
    #[inline]
    pub fn now() -> Self {
        match MODEL_TIME.with(Cell::get) {
            Some(since_start) => Timestamp {
                nanos: Self::LOCKSTEP_EPOCH.nanos.saturating_add(since_start),
            },
            None => Self::from_system_time(SystemTime::now()),
        }
    }

    /// Model time since the start when this thread runs the application in lockstep
    /// (what [`Self::now`] returns minus [`Self::LOCKSTEP_EPOCH`]); `None` when it
    /// runs on the wall clock. Recordings note which of the two their times are.
    #[inline]
    pub fn model_time() -> Option<Duration> {
        MODEL_TIME
            .with(Cell::get)
            .map(|n| Duration::from_nanos(n.max(0).unsigned_abs()))
    }

    /// Where model time starts in a lockstep run: 2000-01-01T00:00:00Z.
    pub const LOCKSTEP_EPOCH: Timestamp = Timestamp {
        nanos: 946_684_800_000_000_000,
    };

    /// Converts a `SystemTime`, saturating at the `i64` range.
    #[inline]
    pub fn from_system_time(t: SystemTime) -> Self {
        let nanos = match t.duration_since(UNIX_EPOCH) {
            Ok(d) => i64::try_from(d.as_nanos()).unwrap_or(i64::MAX),
            Err(e) => i64::try_from(e.duration().as_nanos()).map_or(i64::MIN, |n| -n),
        };
        Timestamp { nanos }
    }

    /// The instant as a `SystemTime`.
    pub fn to_system_time(self) -> SystemTime {
        let magnitude = Duration::from_nanos(self.nanos.unsigned_abs());
        if self.nanos >= 0 {
            UNIX_EPOCH + magnitude
        } else {
            UNIX_EPOCH - magnitude
        }
    }
}

thread_local! {
    /// Nanoseconds of model time since the start, on a thread running in lockstep.
    static MODEL_TIME: Cell<Option<i64>> = const { Cell::new(None) };
}

/// Makes [`Timestamp::now`] on this thread return model time (`Some`: time since the
/// start) or the wall clock again (`None`).
pub fn set_model_time(since_start: Option<std::time::Duration>) {
    let nanos = since_start.map(|d| i64::try_from(d.as_nanos()).unwrap_or(i64::MAX));
    MODEL_TIME.with(|t| t.set(nanos));
}

/// RFC 3339 in UTC with microseconds: `2026-12-01T16:10:20.123456Z`. Written without
/// allocating, so formatting into a reused buffer stays allocation-free.
impl fmt::Display for Timestamp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let secs = self.nanos.div_euclid(1_000_000_000);
        let micros = self.nanos.rem_euclid(1_000_000_000) / 1_000;
        let (days, of_day) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
        let (y, m, d) = civil_from_days(days);
        write!(
            f,
            "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}.{micros:06}Z",
            of_day / 3600,
            of_day % 3600 / 60,
            of_day % 60
        )
    }
}

/// The proleptic Gregorian date of a day count since 1970-01-01 (Howard Hinnant's
/// `civil_from_days`, which is exact for every `i64` day count we can reach here).
fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097); // [0, 146096]
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365; // [0, 399]
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100); // [0, 365]
    let mp = (5 * doy + 2) / 153; // [0, 11]
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32; // [1, 31]
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32; // [1, 12]
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_as_rfc3339_utc() {
        assert_eq!(
            Timestamp { nanos: 0 }.to_string(),
            "1970-01-01T00:00:00.000000Z"
        );
        // 2000-02-29 (a leap day of a century leap year) 12:34:56.789012345
        let t = Timestamp {
            nanos: 951_827_696_789_012_345,
        };
        assert_eq!(t.to_string(), "2000-02-29T12:34:56.789012Z");
        // Before the epoch: one nanosecond earlier is the last microsecond of 1969.
        assert_eq!(
            Timestamp { nanos: -1 }.to_string(),
            "1969-12-31T23:59:59.999999Z"
        );
        // The extremes format without overflow.
        assert!(Timestamp { nanos: i64::MAX }
            .to_string()
            .starts_with("2262-04-11T"));
        assert!(Timestamp { nanos: i64::MIN }
            .to_string()
            .starts_with("1677-09-21T"));
    }

    #[test]
    fn round_trips_system_time() {
        let t = Timestamp::now();
        assert!(t.nanos > 1_700_000_000_000_000_000, "{t}");
        assert_eq!(Timestamp::from_system_time(t.to_system_time()), t);
        let before = Timestamp { nanos: -5 };
        assert_eq!(Timestamp::from_system_time(before.to_system_time()), before);
    }

    #[test]
    fn model_time_is_told_only_on_a_lockstep_thread() {
        assert_eq!(Timestamp::model_time(), None);
        set_model_time(Some(Duration::from_millis(4440)));
        assert_eq!(Timestamp::model_time(), Some(Duration::from_millis(4440)));
        assert_eq!(
            Timestamp::now().nanos,
            Timestamp::LOCKSTEP_EPOCH.nanos + 4_440_000_000
        );
        set_model_time(None);
        assert_eq!(Timestamp::model_time(), None);
    }
}
