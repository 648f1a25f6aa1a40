//! `ferroc_std.Logger`: records its inputs into an MCAP file (`recording/` describes
//! the file: an exact postcard channel and a JSON display channel per port, log time =
//! model time, readable while written, finished on stop).
//!
//! With `period` 0 every input is recorded each time a new value arrives; with a
//! period, the latest value of every input that has one is recorded once per period
//! (sampling, whether or not it changed). Types registered without
//! serde cannot be recorded: the instance is refused when created.
//!
//! The path is checked when the module is created, without touching the file system
//! beyond reading metadata (creation must stay free of side effects): an empty path,
//! control characters, `..` components, a folder that is not one, or something that
//! exists but is not a regular file (a folder, a device, a symbolic link) are refused
//! with an error naming the module. A relative path lies under the log folder
//! (`ferroc run --log-dir`, else `FERROC_LOG_DIR`, else the working directory), and an
//! absolute one must lead there too: a model (or an edit) never writes elsewhere. An
//! existing file that is not a recording of ours is refused unless `--force` (see
//! [`recording`](crate::recording)). The file is created at the first step, whether or
//! not a value has arrived (its folders too; a recording of ours is replaced), so a run
//! always leaves its recording; if that or a later write fails, the logger reports it
//! once, stops logging rather than stopping the application, and the run's summary
//! names the lost recording (exit code 3).

use crate::recording::ros2::Ros2Form;
use crate::recording::{self, ChannelInfo, LogFile, SharedLog};
use ferroc_runtime::module::{DynIn, Module, ModuleType, Parameter, Setup, Timestamp, Wire};
use std::path::{Component, Path, PathBuf};
use std::sync::PoisonError;
use std::time::Duration;

/// `ferroc_std.Logger`: records its inputs into an MCAP file.
pub struct Logger {
    /// The module's path (named when its recording is lost).
    module: String,
    ports: Vec<Recorded>,
    path: PathBuf,
    period: Parameter<Duration>,
    flush: Duration,
    json: bool,
    log: Option<SharedLog>,
    /// Opening or writing failed once: reported, nothing more is written.
    failed: bool,
    exact: Vec<u8>,
    text: Vec<u8>,
}

/// One recorded input.
pub(crate) struct Recorded {
    pub(crate) input: DynIn,
    pub(crate) wire: Wire,
    pub(crate) info: ChannelInfo,
    channel: Option<recording::ChannelId>,
    /// The port's ROS 2 topic, if it is published or subscribed as one and writes
    /// the topic's channel (found when its channel is added: the nodes are declared by
    /// then).
    ros2: Option<Ros2Form>,
    /// A value that did not fit its ROS 2 message was reported.
    ros2_warned: bool,
    /// The CDR of the latest value (its buffer kept between values).
    cdr: Vec<u8>,
    /// A value arrived that is not recorded yet.
    pending: bool,
    /// A value has arrived (sampling records nothing before).
    seen: bool,
    /// Log time from which the next value may be recorded.
    next: Option<u64>,
}

impl Recorded {
    /// Records `input` (its value type's `wire`) on the topic `topic`.
    pub(crate) fn new(input: DynIn, wire: Wire, info: ChannelInfo) -> Self {
        Recorded {
            input,
            wire,
            info,
            channel: None,
            ros2: None,
            ros2_warned: false,
            cdr: Vec::new(),
            pending: false,
            seen: false,
            next: None,
        }
    }
}

impl ModuleType for Logger {
    const NAME: &'static str = "ferroc_std.Logger";
    const DOC: &'static str = "Records its inputs into an MCAP file";
    fn create(m: &mut Setup<'_>) -> Self {
        let inputs = m.flexible_inputs("in").min_count(1).build_dyn();
        let mut file: Parameter<String> = m
            .param("file")
            .doc("the MCAP file; relative paths lie under the log folder (--log-dir)")
            .build();
        let period = m
            .param("period")
            .default(Duration::ZERO)
            .range(0.0, 3600.0)
            .doc("record the latest values once per period (0: every new value)")
            .build();
        let mut flush: Parameter<Duration> = m
            .param("flush")
            .default(Duration::from_secs(1))
            .range(0.001, 3600.0)
            .doc("recorded data reaches the file at least this often")
            .build();
        let mut json: Parameter<bool> = m
            .param("json")
            .default(true)
            .doc("also record a JSON form of every value, for display tools")
            .build();
        let raw = PathBuf::from(file.value());
        let path = recording::resolve_log_path(&raw);
        let ports = recorded_inputs(m, inputs);
        if !m.path().is_empty() {
            recording::ros2::add_recorded(ports.iter().map(|p| p.info.port.as_str()));
        }
        // The registry learning the interface gives no path: nothing to check then.
        // The path as written first (empty, `..`), then where it leads.
        if !m.path().is_empty() {
            let checked = check_log_path(&raw)
                .and_then(|()| check_log_path(&path))
                .and_then(|()| recording::check_in_log_dir(&raw))
                .and_then(|()| recording::check_overwrite(&path));
            if let Err(why) = checked {
                m.problem(format!("parameter `file`: {why}"));
            }
        }
        Logger {
            module: m.path().to_owned(),
            ports,
            path,
            period,
            flush: flush.get(),
            json: json.get(),
            log: None,
            failed: false,
            exact: Vec::new(),
            text: Vec::new(),
        }
    }
}

/// The recorded form of every input of `m` (refusing types without serde).
pub(crate) fn recorded_inputs(m: &mut Setup<'_>, inputs: Vec<DynIn>) -> Vec<Recorded> {
    let module = m.path().to_owned();
    let part = recording::part_of(&module);
    let mut ports = Vec::with_capacity(inputs.len());
    let types: Vec<(String, String)> = m
        .port_groups()
        .iter()
        .flat_map(|g| {
            g.port_names()
                .into_iter()
                .map(|n| (n, g.model_type.to_owned()))
        })
        .collect();
    for input in inputs {
        let Some(model_type) = types
            .iter()
            .find(|(n, _)| n == input.name())
            .map(|(_, t)| t.clone())
        else {
            continue;
        };
        let Some(vt) = m.value_type_of(&model_type).copied() else {
            continue;
        };
        let Some(wire) = vt.wire().copied() else {
            m.problem(format!(
                "port `{}`: values of `{model_type}` cannot be recorded: its library registers \
                 the type without serde (register it with `register_serde` and mark it \
                 serde=\"true\" in its manifest)",
                input.name()
            ));
            continue;
        };
        let port = format!("{module}/{}", input.name());
        let info = ChannelInfo {
            topic: port.clone(),
            part: part.clone(),
            unit: recording::unit_of(&port),
            port,
            model_type,
            rust: vt.rust().to_owned(),
        };
        ports.push(Recorded::new(input, wire, info));
    }
    ports
}

/// Whether `path` may name a log file: see the [module docs](self).
pub fn check_log_path(path: &Path) -> Result<(), String> {
    let text = path.to_string_lossy();
    if text.trim().is_empty() {
        return Err("the path of the log file is empty".into());
    }
    if text.chars().any(char::is_control) {
        return Err(format!("the path {text:?} contains control characters"));
    }
    if path.components().any(|c| c == Component::ParentDir) {
        return Err(format!(
            "the path `{text}` climbs out of a folder with `..`: name the file directly"
        ));
    }
    if text.ends_with('/') || path.file_name().is_none() {
        return Err(format!("the path `{text}` names a folder, not a file"));
    }
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    // A missing folder is created at the first write; an existing non-folder is wrong.
    if let Some(not_folder) = folder
        .ancestors()
        .find(|a| a.exists())
        .filter(|a| !a.is_dir())
    {
        return Err(format!(
            "`{}` in the path of the log file is not a folder",
            not_folder.display()
        ));
    }
    match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_file() => Ok(()),
        Ok(meta) => Err(format!(
            "`{text}` exists and is not a regular file but {}",
            if meta.file_type().is_symlink() {
                "a symbolic link"
            } else if meta.is_dir() {
                "a folder"
            } else {
                "a special file"
            }
        )),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(format!("`{text}` cannot be inspected: {e}")),
    }
}

/// The log time of now: `Timestamp::now` (model time in lockstep) in nanoseconds.
pub(crate) fn log_time() -> u64 {
    u64::try_from(Timestamp::now().nanos).unwrap_or(0)
}

/// Writes the due values of `ports` into `log`; `period` throttles each port.
/// An error is returned once (the file then takes nothing more).
pub(crate) fn record(
    log: &SharedLog,
    ports: &mut [Recorded],
    period: Duration,
    json: bool,
    exact: &mut Vec<u8>,
    text: &mut Vec<u8>,
) -> Result<(), String> {
    let period = u64::try_from(period.as_nanos()).unwrap_or(u64::MAX);
    record_with(log, ports, log_time(), period, json, exact, text)
}

/// [`record`] at log time `now`, every new value (the benchmark's entry).
#[cfg(test)]
fn record_at(
    log: &SharedLog,
    ports: &mut [Recorded],
    now: u64,
    json: bool,
    exact: &mut Vec<u8>,
    text: &mut Vec<u8>,
) -> Result<(), String> {
    record_with(log, ports, now, 0, json, exact, text)
}

fn record_with(
    log: &SharedLog,
    ports: &mut [Recorded],
    now: u64,
    period: u64,
    json: bool,
    exact: &mut Vec<u8>,
    text: &mut Vec<u8>,
) -> Result<(), String> {
    for port in ports.iter_mut() {
        if port.input.changed() {
            port.pending = true;
        }
        port.seen |= port.pending;
        if period == 0 && !port.pending {
            continue;
        }
        // Due from a quarter period before the deadline: a thread container of the
        // same period starts each cycle a little late or early (a strict comparison
        // would skip every other value), and one of half the period must not record
        // twice per period. Deadlines advance by whole periods; after a long stall the
        // schedule restarts instead of catching up.
        if !port.seen
            || port
                .next
                .is_some_and(|next| now.saturating_add(period / 4) < next)
        {
            continue;
        }
        port.pending = false;
        port.next = Some(match port.next {
            Some(next) if now < next.saturating_add(period) => next.saturating_add(period),
            _ => now.saturating_add(period),
        });
        port.wire.encode(&port.input, exact)?;
        let mut file = log.lock().unwrap_or_else(PoisonError::into_inner);
        let channel = match port.channel {
            Some(c) => c,
            None => add_channel(&mut file, port)?,
        };
        if json {
            port.wire.json(&port.input, text)?;
        }
        let cdr = cdr_of(port).then_some(port.cdr.as_slice());
        let json = json.then_some(text.as_slice());
        file.write_forms(channel, now, exact, json, cdr)?;
    }
    Ok(())
}

/// The channels of `port`, its ROS 2 channel too if the program publishes it as a topic
/// (a message that cannot be had is said once; the port is recorded without it).
fn add_channel(file: &mut LogFile, port: &mut Recorded) -> Result<recording::ChannelId, String> {
    let c = file.channel(&port.info)?;
    port.channel = Some(c);
    match Ros2Form::of_port(&port.info.port) {
        Ok(Some(form)) => {
            file.add_ros2(c, &form)?;
            port.ros2 = Some(form);
        }
        Ok(None) => {}
        Err(why) => eprintln!("warning: {why}"),
    }
    Ok(c)
}

/// Whether `port` is written on its ROS 2 topic and its latest value is in `port.cdr`
/// (a value that does not fit the message is said once per port and left out there).
fn cdr_of(port: &mut Recorded) -> bool {
    let Some(form) = port.ros2.as_ref() else {
        return false;
    };
    match form.encode(&port.wire, &port.input, &mut port.cdr) {
        Ok(()) => true,
        Err(why) => {
            if !std::mem::replace(&mut port.ros2_warned, true) {
                eprintln!(
                    "warning: a value of `{}` is not recorded on the ROS 2 topic `{}`: {why}; \
                     such values are left out there",
                    port.info.port, form.topic
                );
            }
            false
        }
    }
}

impl Module for Logger {
    fn update(&mut self) {
        if self.failed {
            return;
        }
        // The file is created at the first step, before any value: a run that stops
        // before its inputs receive anything leaves an empty recording (valid MCAP),
        // not no file.
        if self.log.is_none() {
            let flush = u64::try_from(self.flush.as_nanos()).unwrap_or(u64::MAX);
            match LogFile::open_shared(&self.path, flush) {
                Ok(log) => self.log = Some(log),
                Err(e) => return self.fail(&e),
            }
        }
        let Some(log) = &self.log else { return };
        let period = self.period.get();
        if let Err(e) = record(
            log,
            &mut self.ports,
            period,
            self.json,
            &mut self.exact,
            &mut self.text,
        ) {
            self.fail(&e);
        }
    }
}

impl Logger {
    fn fail(&mut self, why: &str) {
        self.failed = true;
        self.log = None;
        eprintln!("warning: ferroc_std.Logger: {why}; it records nothing more");
        ferroc_runtime::module::report_data_loss(format!(
            "ferroc_std.Logger `{}`: {why}; nothing was recorded after that",
            self.module
        ));
    }
}

#[cfg(test)]
mod tests;
