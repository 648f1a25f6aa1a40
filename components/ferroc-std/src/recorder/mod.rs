//! `ferroc_std.Recorder`: what `ferroc run --record FILE` adds to each thread
//! container, not a type models use (it is registered only for such runs, and has no
//! manifest entry). Every port group it is given is one recorded output: the group's
//! name is the output's path (`robot/laser/scan`), which becomes the topic. It runs
//! last in its container, so it sees every value the container's modules published
//! in the cycle; all recorders of a run write into one file.
//!
//! Which outputs get recorders is decided in one place for `ferroc run` and for the
//! programs `ferroc bundle` generates ([`select`], `select.rs`); a generated program
//! adds them with [`Recorders`] (`program.rs`).

mod program;
mod select;

pub use program::{Recordable, Recorders};
pub use select::{glob, select, Candidate, RecordedPort, RecorderPlan, RECORDER_TYPE};

use crate::logger::{record, recorded_inputs};
use crate::recording::{self, LogFile, SharedLog};
use ferroc_runtime::module::{Module, ModuleType, Parameter, Setup};
use std::path::PathBuf;
use std::time::Duration;

/// `ferroc_std.Recorder` (see the [module docs](self)).
pub struct Recorder {
    ports: Vec<crate::logger::Recorded>,
    path: PathBuf,
    log: Option<SharedLog>,
    failed: bool,
    exact: Vec<u8>,
    text: Vec<u8>,
}

impl ModuleType for Recorder {
    const NAME: &'static str = "ferroc_std.Recorder";
    const DOC: &'static str = "Records the outputs it is connected to (ferroc run --record)";
    fn create(m: &mut Setup<'_>) -> Self {
        let mut file: Parameter<String> = m.param("file").doc("the MCAP file").build();
        let path = recording::resolve_log_path(&PathBuf::from(file.value()));
        let groups = m.port_groups();
        let mut inputs = Vec::new();
        for g in groups {
            inputs.extend(m.flexible_inputs(g.name).build_dyn());
        }
        let mut ports = recorded_inputs(m, inputs);
        for port in &mut ports {
            // The topic is the recorded output's path, not the recorder's input.
            port.info.topic = port.input.name().to_owned();
            port.info.port = port.info.topic.clone();
            port.info.part = recording::part_of(&port.info.topic);
            port.info.unit = recording::unit_of(&port.info.topic);
        }
        if !m.path().is_empty() {
            recording::ros2::add_recorded(ports.iter().map(|p| p.info.port.as_str()));
        }
        Recorder {
            ports,
            path,
            log: None,
            failed: false,
            exact: Vec::new(),
            text: Vec::new(),
        }
    }
}

impl Module for Recorder {
    fn update(&mut self) {
        if self.failed || self.ports.is_empty() {
            return;
        }
        if self.log.is_none() {
            match LogFile::open_shared(&self.path, 1_000_000_000) {
                Ok(log) => self.log = Some(log),
                Err(e) => {
                    self.failed = true;
                    eprintln!("warning: ferroc run --record: {e}; nothing is recorded");
                    lost(&e);
                    return;
                }
            }
        }
        let Some(log) = &self.log else { return };
        if let Err(e) = record(
            log,
            &mut self.ports,
            Duration::ZERO,
            true,
            &mut self.exact,
            &mut self.text,
        ) {
            self.failed = true;
            self.log = None;
            eprintln!("warning: ferroc run --record: {e}; it records nothing more");
            lost(&e);
        }
    }
}

/// Reports the recording lost for the run's summary (once per file: every
/// recorder of a run writes the same one).
fn lost(why: &str) {
    let what = format!("--record: {why}; nothing was recorded after that");
    if !ferroc_runtime::module::data_losses().contains(&what) {
        ferroc_runtime::module::report_data_loss(what);
    }
}
