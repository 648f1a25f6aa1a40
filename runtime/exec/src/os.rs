//! Placing the current thread: real-time priority and CPU affinity, where the operating
//! system allows it. Refusals come back as plain-language warnings, never as failures:
//! a robot that cannot get real-time priority on a developer laptop should still run.

use super::ThreadOptions;

/// A placement the operating system refused.
#[derive(Clone, Debug, PartialEq)]
pub struct Refusal {
    /// What was asked for.
    pub asked: Placement,
    /// The operating system's answer.
    pub why: String,
}

/// A placement request of [`ThreadOptions`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    /// Real-time priority.
    Priority(i32),
    /// Pinning to a CPU.
    Cpu(usize),
}

impl Refusal {
    /// The refusal as a warning about one thread.
    pub fn line(&self) -> String {
        match self.asked {
            Placement::Priority(p) => format!(
                "real-time priority {p} refused ({}); running with normal priority ({PRIORITY_HELP})",
                self.why
            ),
            Placement::Cpu(c) => format!(
                "pinning to CPU {c} refused ({}); the thread may run on any CPU",
                self.why
            ),
        }
    }
}

const PRIORITY_HELP: &str = "grant CAP_SYS_NICE or an rtprio limit in /etc/security/limits.conf";

/// The refusals of several containers (path, refusal) as warnings: one line per kind of
/// request and answer, naming every container it concerns, so that an application of
/// seven containers on a machine without real-time rights gives one line, not seven.
pub fn summarise(refusals: &[(String, Refusal)]) -> Vec<String> {
    /// Refusals of one kind of request for one reason: (priority?, reason, members).
    type Group<'a> = (bool, &'a str, Vec<(&'a str, &'a Refusal)>);
    let mut groups: Vec<Group<'_>> = Vec::new();
    for (path, r) in refusals {
        let priority = matches!(r.asked, Placement::Priority(_));
        match groups
            .iter_mut()
            .find(|(p, why, _)| *p == priority && *why == r.why)
        {
            Some((_, _, members)) => members.push((path, r)),
            None => groups.push((priority, &r.why, vec![(path, r)])),
        }
    }
    groups
        .into_iter()
        .map(|(priority, why, members)| {
            if let [(path, r)] = members[..] {
                return format!("thread container `{path}`: {}", r.line());
            }
            let list: Vec<String> = members
                .iter()
                .map(|(path, r)| match r.asked {
                    Placement::Priority(v) => format!("`{path}` {v}"),
                    Placement::Cpu(v) => format!("`{path}` CPU {v}"),
                })
                .collect();
            if priority {
                format!(
                    "real-time priority refused for {} thread containers ({why}): {}; they run \
                     with normal priority ({PRIORITY_HELP})",
                    members.len(),
                    list.join(", ")
                )
            } else {
                format!(
                    "pinning refused for {} thread containers ({why}): {}; they may run on any CPU",
                    members.len(),
                    list.join(", ")
                )
            }
        })
        .collect()
}

/// Applies `options` to the calling thread; returns what was refused.
pub(crate) fn place_current_thread(options: &ThreadOptions) -> Vec<Refusal> {
    let mut refused = Vec::new();
    if let Some(priority) = options.priority {
        if let Err(e) = ferroc_ports::thread::set_priority(priority) {
            refused.push(Refusal {
                asked: Placement::Priority(priority),
                why: e.to_string(),
            });
        }
    }
    if let Some(cpu) = options.cpu {
        if let Err(e) = ferroc_ports::thread::set_affinity(cpu) {
            refused.push(Refusal {
                asked: Placement::Cpu(cpu),
                why: e.to_string(),
            });
        }
    }
    refused
}

/// Pins the calling thread to `cpu` (what [`ThreadOptions::cpu`](super::ThreadOptions)
/// does for a container; also for helper threads such as benchmark drivers).
pub fn pin_current_thread(cpu: usize) -> std::io::Result<()> {
    ferroc_ports::thread::set_affinity(cpu)
}
