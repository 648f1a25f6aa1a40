//! Placing the current thread: real-time priority and CPU affinity, where the operating
//! system allows it. Refusals come back as plain-language warnings, never as failures:
//! a robot that cannot get real-time priority on a developer laptop should still run.

use super::ThreadOptions;

/// Applies `options` to the calling thread; returns one warning per refused request.
pub(crate) fn place_current_thread(options: &ThreadOptions) -> Vec<String> {
    let mut warnings = Vec::new();
    if let Some(priority) = options.priority {
        if let Err(e) = set_priority(priority) {
            warnings.push(format!(
                "real-time priority {priority} refused ({e}); running with normal priority \
                 (grant CAP_SYS_NICE or an rtprio limit in /etc/security/limits.conf)"
            ));
        }
    }
    if let Some(cpu) = options.cpu {
        if let Err(e) = set_affinity(cpu) {
            warnings.push(format!(
                "pinning to CPU {cpu} refused ({e}); the thread may run on any CPU"
            ));
        }
    }
    warnings
}

#[cfg(target_os = "linux")]
fn set_priority(priority: i32) -> std::io::Result<()> {
    let param = libc::sched_param {
        sched_priority: priority,
    };
    // SAFETY: plain system call on the calling thread with a valid, initialised param.
    let rc = unsafe { libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_FIFO, &param) };
    if rc == 0 {
        Ok(())
    } else {
        Err(std::io::Error::from_raw_os_error(rc))
    }
}

/// Pins the calling thread to `cpu` (what [`ThreadOptions::cpu`](super::ThreadOptions)
/// does for a container; also for helper threads such as benchmark drivers).
pub fn pin_current_thread(cpu: usize) -> std::io::Result<()> {
    set_affinity(cpu)
}

#[cfg(target_os = "linux")]
fn set_affinity(cpu: usize) -> std::io::Result<()> {
    if cpu >= libc::CPU_SETSIZE as usize {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "no such CPU",
        ));
    }
    // SAFETY: cpu_set_t is plain data; zeroed is its empty set; CPU_SET is bounds-checked
    // above; the call affects only the calling thread.
    let rc = unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set)
    };
    if rc == 0 {
        Ok(())
    } else {
        Err(std::io::Error::last_os_error())
    }
}

#[cfg(not(target_os = "linux"))]
fn set_priority(_: i32) -> std::io::Result<()> {
    Err(std::io::Error::new(
        std::io::ErrorKind::Unsupported,
        "not supported on this operating system",
    ))
}

#[cfg(not(target_os = "linux"))]
fn set_affinity(_: usize) -> std::io::Result<()> {
    Err(std::io::Error::new(
        std::io::ErrorKind::Unsupported,
        "not supported on this operating system",
    ))
}
