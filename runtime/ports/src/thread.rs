//! The two operating-system calls that place the calling thread: real-time priority
//! and CPU affinity. They are the only `unsafe` of the runtime outside the port core,
//! kept here so that every crate above the ports forbids `unsafe`. Refusals come back
//! as `io::Error`s; `ferroc_exec` turns them into warnings.

/// Gives the calling thread real-time priority `priority` (`SCHED_FIFO`).
#[cfg(target_os = "linux")]
pub fn set_priority(priority: i32) -> std::io::Result<()> {
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

/// Pins the calling thread to `cpu`.
#[cfg(target_os = "linux")]
pub fn set_affinity(cpu: usize) -> std::io::Result<()> {
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

/// Real-time priority: not supported here.
#[cfg(not(target_os = "linux"))]
pub fn set_priority(_: i32) -> std::io::Result<()> {
    Err(std::io::Error::new(
        std::io::ErrorKind::Unsupported,
        "not supported on this operating system",
    ))
}

/// CPU affinity: not supported here.
#[cfg(not(target_os = "linux"))]
pub fn set_affinity(_: usize) -> std::io::Result<()> {
    Err(std::io::Error::new(
        std::io::ErrorKind::Unsupported,
        "not supported on this operating system",
    ))
}
