//! Whether the process behind a Zenoh session is gone, for the buffers it may hold
//! (reclaim.rs). A transport that closes says only that a session went silent: a
//! process stopped for longer than the lease, or starved on a loaded machine, loses
//! its transport and comes back, still holding what it read in place. So a ferroc
//! part names its session after its process: its Zenoh id holds its process id and
//! its PID namespace, and a writer on the same computer asks the system whether that
//! process still exists. A session that is not named so (another Zenoh program, a
//! part in a container with its own PID namespace, a system without `/proc`) never
//! counts as gone: its buffers stay, as they did before. Nor does any session while
//! `/proc` hides other users' processes (`hidepid`): there a missing process may be
//! one this process may not see.

use std::collections::BTreeSet;
use std::sync::atomic::{AtomicU64, Ordering};

/// The first two hex digits of a session id that names its process.
const MARK: &str = "f3";

/// A new Zenoh session id for a part of this process: the mark, the process id and
/// PID namespace (8 hex digits each) and 14 digits that differ per session.
pub fn session_id() -> String {
    id_for(std::process::id())
}

/// A session id naming the process `pid` of this PID namespace.
pub(crate) fn id_for(pid: u32) -> String {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let seed = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64);
    let nonce = (seed ^ NEXT.fetch_add(1, Ordering::Relaxed).rotate_left(40)) & ((1 << 56) - 1);
    let ns = pid_namespace().unwrap_or(0);
    format!("{MARK}{pid:08x}{ns:08x}{nonce:014x}")
}

/// Whether the session `zid` (as Zenoh writes it) names a process of this computer's
/// PID namespace that no longer exists (or is a zombie: its memory is released). A
/// process found gone stays gone (its session id holds a nonce no later process has),
/// so that answer is remembered: the ledger asks about the same dead reader at every
/// send until its buffers are back.
pub fn gone(zid: &str) -> bool {
    static GONE: std::sync::Mutex<BTreeSet<String>> = std::sync::Mutex::new(BTreeSet::new());
    let known = |g: &BTreeSet<String>| g.contains(zid);
    if known(&GONE.lock().unwrap_or_else(|e| e.into_inner())) {
        return true;
    }
    let gone = looked_up(zid);
    if gone {
        (GONE.lock().unwrap_or_else(|e| e.into_inner())).insert(zid.to_owned());
    }
    gone
}

/// [`gone`], asking the system.
fn looked_up(zid: &str) -> bool {
    let Some(rest) = zid.strip_prefix(MARK).filter(|_| zid.len() == 32) else {
        return false;
    };
    let hex = |s: &str| u32::from_str_radix(s, 16).ok();
    let (Some(pid), Some(ns)) = (hex(&rest[..8]), hex(&rest[8..16])) else {
        return false;
    };
    if pid_namespace() != Some(ns) || ns == 0 || proc_hides_processes() {
        return false;
    }
    match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
        // The state follows the command's closing parenthesis.
        Ok(stat) => stat
            .rsplit_once(')')
            .is_some_and(|(_, s)| matches!(s.trim_start().chars().next(), Some('Z' | 'X'))),
        Err(e) => e.kind() == std::io::ErrorKind::NotFound,
    }
}

/// Whether `/proc` is mounted so that it hides processes (`hidepid=1|2`,
/// `invisible`, `noaccess`, `subset=pid` aside): a process it does not show may live.
/// Also true when the mounts cannot be read.
fn proc_hides_processes() -> bool {
    let Ok(mounts) = std::fs::read_to_string("/proc/self/mountinfo") else {
        return true;
    };
    let proc = mounts
        .lines()
        .find(|l| l.split(' ').nth(4) == Some("/proc"));
    proc.is_none_or(|line| {
        let options = line.rsplit(' ').next().unwrap_or("");
        options.split(',').any(|o| {
            matches!(
                o,
                "hidepid=1" | "hidepid=2" | "hidepid=invisible" | "hidepid=noaccess"
            )
        })
    })
}

/// This process's PID namespace (the low 32 bits of its inode), if the system says.
#[cfg(target_os = "linux")]
fn pid_namespace() -> Option<u32> {
    use std::os::unix::fs::MetadataExt;
    let ino = std::fs::metadata("/proc/self/ns/pid").ok()?.ino();
    Some(ino as u32)
}

#[cfg(not(target_os = "linux"))]
fn pid_namespace() -> Option<u32> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::str::FromStr;

    #[test]
    fn a_session_named_after_a_live_process_is_not_gone_and_after_a_dead_one_is() {
        let id = session_id();
        assert_ne!(id, session_id(), "one per session");
        let zid = zenoh::session::ZenohId::from_str(&id).unwrap();
        assert_eq!(zid.to_string(), id, "Zenoh writes it back as it was");
        assert!(!gone(&id), "this process lives");
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        let dead = id_for(pid);
        assert!(gone(&dead), "{dead}");
        // Not named after a process, or in another namespace: never gone.
        assert!(!gone("1f2e3d4c5b6a79881f2e3d4c5b6a7988"));
        let elsewhere = format!("{}00000001{}", &dead[..10], &dead[18..]);
        assert!(!gone(&elsewhere));
        assert!(
            !proc_hides_processes(),
            "this machine's /proc shows every process"
        );
    }
}
