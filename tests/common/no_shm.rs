//! A program started where the computer gives no usable shared memory, as in a
//! container: in a mount namespace of its own (`unshare --mount`, private mounts, so
//! nothing changes outside it) whose `/dev/shm` is an empty read-only tmpfs, or whose
//! `/dev` has no `shm` at all (a small tmpfs moved over `/dev` holding only the
//! devices a program needs).

use std::path::Path;
use std::process::Command;

/// How `/dev/shm` is unusable.
#[derive(Clone, Copy, Debug)]
pub enum NoShm {
    /// An empty read-only tmpfs on `/dev/shm`.
    ReadOnly,
    /// No `/dev/shm` at all.
    Missing,
}

/// The shell script that makes the namespace's `/dev` and then runs `"$0" "$@"`.
fn script(how: NoShm) -> &'static str {
    match how {
        NoShm::ReadOnly => "mount -t tmpfs -o ro,size=64k tmpfs /dev/shm && exec \"$0\" \"$@\"",
        NoShm::Missing => {
            "set -e; d=$(mktemp -d); \
             mount -t tmpfs -o size=64k,mode=755 tmpfs \"$d\"; \
             for n in null zero full random urandom; do \
               touch \"$d/$n\"; mount --bind \"/dev/$n\" \"$d/$n\"; \
             done; \
             ln -s /proc/self/fd \"$d/fd\"; ln -s /proc/self/fd/0 \"$d/stdin\"; \
             ln -s /proc/self/fd/1 \"$d/stdout\"; ln -s /proc/self/fd/2 \"$d/stderr\"; \
             mount --move \"$d\" /dev; rmdir \"$d\"; \
             test ! -e /dev/shm; exec \"$0\" \"$@\""
        }
    }
}

/// The command that starts `program` without usable shared memory (`how`); `None`
/// (after a visible skip) where namespaces or mounts are refused (not root, no
/// CAP_SYS_ADMIN).
pub fn command(how: NoShm, program: &Path) -> Option<Command> {
    let unshare = ferroc_testkit::command("unshare")?;
    let probe = Command::new(&unshare)
        .args(["--mount", "sh", "-c", script(how), "true"])
        .output()
        .expect("unshare runs");
    if !probe.status.success() {
        ferroc_testkit::skip(&format!(
            "a mount namespace with {how:?} /dev/shm cannot be made here: {}",
            String::from_utf8_lossy(&probe.stderr).trim()
        ));
        return None;
    }
    let mut command = Command::new(unshare);
    command
        .args(["--mount", "sh", "-c", script(how)])
        .arg(program);
    Some(command)
}
