//! Benchmark B4 across processes on dora-rs: one node (`dora_sender`) sends values of
//! `DORA_B4_SIZE` bytes to another (`dora_receiver`) through dora's daemon-managed
//! data plane, as ferroc's `b4-parts` (64 B) and `b4-large` (6.2 MB) do between two
//! part programs.
//!
//! The sender fills each value (the frame number in every byte), stamps its first 8
//! bytes with `CLOCK_MONOTONIC` as the last thing before sending and its next 8 with
//! the sequence number; the receiver takes `now - stamp` when dora hands it the
//! input. Both are processes on one machine, so the clock is shared. The settings
//! come from the environment the dataflow YAML gives each node (`run.sh` writes it).

use std::time::Duration;

/// Values sent before the measured ones and not counted (connections, pools,
/// caches): `DORA_B4_WARM_UP`, as many as ferroc's counterpart skips (b4-parts 500,
/// b4-large 20).
pub fn warm_up() -> Result<u64, String> {
    env_number("DORA_B4_WARM_UP", 20)
}

/// `CLOCK_MONOTONIC` in nanoseconds, the clock ferroc's benchmarks stamp with.
pub fn mono_ns() -> u64 {
    // std's Instant is CLOCK_MONOTONIC on Linux but opaque; read the clock directly.
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec for the duration of the call.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

/// A whole number from the environment, or `default` if unset.
pub fn env_number(name: &str, default: u64) -> Result<u64, String> {
    match std::env::var(name) {
        Ok(v) => v
            .parse()
            .map_err(|_| format!("{name}={v}: not a whole number")),
        Err(_) => Ok(default),
    }
}

/// Fills `data` with frame `seq`, stamps it last (sequence, then time).
pub fn fill_and_stamp(data: &mut [u8], seq: u64) {
    data.fill(seq as u8);
    data[8..16].copy_from_slice(&seq.to_le_bytes());
    data[..8].copy_from_slice(&mono_ns().to_le_bytes());
}

/// The stamp and sequence number of a received value.
pub fn read_stamp(data: &[u8]) -> Option<(u64, u64)> {
    let stamp = u64::from_le_bytes(data.get(..8)?.try_into().ok()?);
    let seq = u64::from_le_bytes(data.get(8..16)?.try_into().ok()?);
    Some((stamp, seq))
}

/// p50, p99 and max of latencies in nanoseconds, in microseconds.
pub fn percentiles(mut ns: Vec<u64>) -> (f64, f64, f64) {
    if ns.is_empty() {
        return (f64::NAN, f64::NAN, f64::NAN);
    }
    ns.sort_unstable();
    let at = |q: f64| ns[((ns.len() - 1) as f64 * q).round() as usize] as f64 / 1e3;
    (at(0.50), at(0.99), at(1.0))
}

/// Waits until `deadline`: sleeps while far from it, spins the last 100 µs, so a
/// 100 µs period is kept as ferroc's writer keeps it.
pub fn wait_until(deadline: std::time::Instant) {
    loop {
        let now = std::time::Instant::now();
        if now >= deadline {
            return;
        }
        let left = deadline - now;
        if left > Duration::from_micros(300) {
            std::thread::sleep(left - Duration::from_micros(200));
        } else {
            std::hint::spin_loop();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stamped_value_reads_back_its_sequence_and_a_recent_stamp() {
        let mut v = vec![0u8; 64];
        let before = mono_ns();
        fill_and_stamp(&mut v, 7);
        let (stamp, seq) = read_stamp(&v).unwrap();
        assert_eq!(seq, 7);
        assert!(stamp >= before && stamp <= mono_ns());
        assert!(v[16..].iter().all(|&b| b == 7));
    }

    #[test]
    fn a_value_shorter_than_the_stamp_is_refused() {
        assert_eq!(read_stamp(&[0u8; 15]), None);
    }

    #[test]
    fn percentiles_of_one_to_hundred_microseconds() {
        let ns: Vec<u64> = (1..=100).map(|i| i * 1000).collect();
        let (p50, p99, max) = percentiles(ns);
        assert_eq!((p50.round(), p99, max), (51.0, 99.0, 100.0));
    }
}
