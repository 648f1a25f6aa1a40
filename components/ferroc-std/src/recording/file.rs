//! One MCAP file being written, shared by every module recording into it (two
//! loggers naming the same file, the recorders of `ferroc run --record`, one per
//! thread container): they take turns through a mutex, each message one lock.

use super::ros2::{Ros2Form, META_ROS2_FIELD, ROS2_ENCODING, ROS2_FORM, ROS2_SCHEMA_ENCODING};
use super::TYPE_SCHEMA_ENCODING;
use super::{
    json_schema, EXACT_ENCODING, META_FORM, META_PART, META_PORT, META_RUN, META_TYPE, META_UNIT,
};
use mcap::records::MessageHeader;
use mcap::{WriteOptions, Writer};
use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::{BufWriter, Seek};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError, Weak};

/// A log file shared by the modules writing into it.
pub type SharedLog = Arc<Mutex<LogFile>>;

/// Files open for writing, by absolute path: a second module naming a file joins the
/// recording instead of truncating it.
static OPEN: Mutex<Vec<(PathBuf, Weak<Mutex<LogFile>>)>> = Mutex::new(Vec::new());

/// Chunks are closed at this size even between flushes.
const CHUNK_SIZE: u64 = 1 << 20;

/// What a channel records: the topic and the metadata naming its source.
#[derive(Clone, Debug, Default)]
pub struct ChannelInfo {
    /// The topic: the recorded port's path (`robot/laser/scan`).
    pub topic: String,
    /// The part holding the recorded port (empty if unknown).
    pub part: String,
    /// The path of the port whose values are recorded.
    pub port: String,
    /// Its model type (`f64`, `rescue.Pose2D`).
    pub model_type: String,
    /// The Rust type behind it.
    pub rust: String,
    /// The unit of the values (`m/s`), as the model writes it; empty without one.
    pub unit: String,
}

/// The two channels of one recorded port and its message counter.
struct Channels {
    info: ChannelInfo,
    exact: u16,
    /// The channel on the port's ROS 2 topic ([`super::ros2`]), if it is one.
    ros2: Option<u16>,
    /// Added at the first message: a library type's JSON Schema is read off its
    /// first value.
    json: Option<u16>,
    sequence: u32,
}

/// An MCAP file being written (see the [module docs](super)).
pub struct LogFile {
    path: PathBuf,
    writer: Option<Writer<BufWriter<File>>>,
    channels: Vec<Channels>,
    by_topic: HashMap<String, usize>,
    /// Chunks are written out at least this often (log-time nanoseconds).
    flush_every: u64,
    last_flush: Option<u64>,
    /// The first error; after it nothing more is written.
    failed: bool,
}

/// A channel of a [`LogFile`] (index of its port).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChannelId(usize);

fn mcap_error(path: &Path, e: impl Into<WriteError>) -> String {
    format!(
        "cannot write the recording `{}`: {}",
        path.display(),
        e.into().0
    )
}

/// Why a write failed, in plain words: the operating system's reason where there is
/// one (a full disk, a missing permission), not the MCAP library's wrapper of it.
struct WriteError(String);

impl From<std::io::Error> for WriteError {
    fn from(e: std::io::Error) -> Self {
        use std::io::ErrorKind;
        WriteError(match e.kind() {
            ErrorKind::StorageFull => "the disk is full (no space left on the device)".into(),
            ErrorKind::QuotaExceeded => "the disk quota is used up".into(),
            ErrorKind::PermissionDenied => format!("permission denied ({e})"),
            ErrorKind::ReadOnlyFilesystem => "the file system is read-only".into(),
            _ => e.to_string(),
        })
    }
}

impl From<mcap::McapError> for WriteError {
    fn from(e: mcap::McapError) -> Self {
        match e {
            mcap::McapError::Io(io) => io.into(),
            other => WriteError(other.to_string()),
        }
    }
}

impl From<serde_json::Error> for WriteError {
    fn from(e: serde_json::Error) -> Self {
        WriteError(e.to_string())
    }
}

impl LogFile {
    /// The recording at `path` (already resolved, see
    /// [`resolve_log_path`](super::resolve_log_path)): joined if a module of this
    /// process writes it already, else created (its folders too; an existing
    /// recording of ours or empty file is replaced, anything else refused without
    /// `--force`: [`check_overwrite`](super::check_overwrite)). `flush_every`: how often chunks are written out, in nanoseconds.
    pub fn open_shared(path: &Path, flush_every: u64) -> Result<SharedLog, String> {
        let key = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
        let mut open = OPEN.lock().unwrap_or_else(PoisonError::into_inner);
        open.retain(|(_, w)| w.strong_count() > 0);
        if let Some(log) = open
            .iter()
            .find(|(p, _)| *p == key)
            .and_then(|(_, w)| w.upgrade())
        {
            let mut file = log.lock().unwrap_or_else(PoisonError::into_inner);
            file.flush_every = file.flush_every.min(flush_every);
            drop(file);
            return Ok(log);
        }
        let log = Arc::new(Mutex::new(LogFile::create(&key, flush_every)?));
        open.push((key, Arc::downgrade(&log)));
        Ok(log)
    }

    fn create(path: &Path, flush_every: u64) -> Result<LogFile, String> {
        if let Some(folder) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(folder).map_err(|e| mcap_error(path, e))?;
        }
        // Opened without truncating: only a recording of ours (or an empty file) is
        // replaced, unless `--force` said otherwise.
        let mut file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)
            .map_err(|e| mcap_error(path, e))?;
        super::context::check_replaceable(path, &mut file)?;
        file.set_len(0).map_err(|e| mcap_error(path, e))?;
        file.seek(std::io::SeekFrom::Start(0))
            .map_err(|e| mcap_error(path, e))?;
        let options = WriteOptions::new()
            .compression(None)
            .chunk_size(Some(CHUNK_SIZE))
            .library(super::LIBRARY)
            .profile("");
        let mut writer = options
            .create(BufWriter::new(file))
            .map_err(|e| mcap_error(path, e))?;
        writer
            .write_metadata(&run_metadata())
            .map_err(|e| mcap_error(path, e))?;
        // The header on disk at once: the file is an MCAP file from the start.
        writer.flush().map_err(|e| mcap_error(path, e))?;
        Ok(LogFile {
            path: path.to_path_buf(),
            writer: Some(writer),
            channels: Vec::new(),
            by_topic: HashMap::new(),
            flush_every,
            last_flush: None,
            failed: false,
        })
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The channel of `info.topic`, added with its exact form's schema if new.
    pub fn channel(&mut self, info: &ChannelInfo) -> Result<ChannelId, String> {
        if let Some(&k) = self.by_topic.get(&info.topic) {
            return Ok(ChannelId(k));
        }
        let path = self.path.clone();
        let writer = self.writer_mut()?;
        let schema = writer
            .add_schema(&info.model_type, TYPE_SCHEMA_ENCODING, info.rust.as_bytes())
            .map_err(|e| mcap_error(&path, e))?;
        let exact = writer
            .add_channel(
                schema,
                &info.topic,
                EXACT_ENCODING,
                &metadata(info, "exact"),
            )
            .map_err(|e| mcap_error(&path, e))?;
        let k = self.channels.len();
        self.channels.push(Channels {
            info: info.clone(),
            exact,
            ros2: None,
            json: None,
            sequence: 0,
        });
        self.by_topic.insert(info.topic.clone(), k);
        Ok(ChannelId(k))
    }

    /// Adds the channel on the ROS 2 topic of `channel`'s port (see [`super::ros2`]);
    /// nothing if it has one.
    pub fn add_ros2(&mut self, channel: ChannelId, form: &Ros2Form) -> Result<(), String> {
        let path = self.path.clone();
        let Some(info) = self.channels.get(channel.0).map(|c| c.info.clone()) else {
            return Err(format!("no channel {channel:?}"));
        };
        if self.channels[channel.0].ros2.is_some() {
            return Ok(());
        }
        let writer = self.writer_mut()?;
        let schema = writer
            .add_schema(&form.message, ROS2_SCHEMA_ENCODING, form.schema.as_bytes())
            .map_err(|e| mcap_error(&path, e))?;
        let mut meta = metadata(&info, ROS2_FORM);
        if let Some(field) = &form.field {
            meta.insert(META_ROS2_FIELD.to_owned(), field.clone());
        }
        let id = writer
            .add_channel(schema, &form.topic, ROS2_ENCODING, &meta)
            .map_err(|e| mcap_error(&path, e))?;
        self.channels[channel.0].ros2 = Some(id);
        Ok(())
    }

    fn writer_mut(&mut self) -> Result<&mut Writer<BufWriter<File>>, String> {
        match &mut self.writer {
            Some(w) if !self.failed => Ok(w),
            _ => Err(format!(
                "the recording `{}` is closed after an error",
                self.path.display()
            )),
        }
    }

    /// Whether an error stopped the recording.
    pub fn failed(&self) -> bool {
        self.failed
    }

    /// Writes one value of `channel` at `log_time` (nanoseconds): `exact` (postcard)
    /// and, if given, `json`. The first error is returned and closes the recording;
    /// later calls do nothing.
    pub fn write(
        &mut self,
        channel: ChannelId,
        log_time: u64,
        exact: &[u8],
        json: Option<&[u8]>,
    ) -> Result<(), String> {
        self.write_forms(channel, log_time, exact, json, None)
    }

    /// [`Self::write`], and `cdr` on the port's ROS 2 channel ([`Self::add_ros2`]).
    pub fn write_forms(
        &mut self,
        channel: ChannelId,
        log_time: u64,
        exact: &[u8],
        json: Option<&[u8]>,
        cdr: Option<&[u8]>,
    ) -> Result<(), String> {
        if self.failed {
            return Ok(());
        }
        let result = self.write_inner(channel, log_time, exact, json, cdr);
        if result.is_err() {
            self.failed = true;
            // Closed quietly: what could be written was, and one message said why.
            self.writer = None;
        }
        result
    }

    fn write_inner(
        &mut self,
        channel: ChannelId,
        log_time: u64,
        exact: &[u8],
        json: Option<&[u8]>,
        cdr: Option<&[u8]>,
    ) -> Result<(), String> {
        let path = self.path.clone();
        let Some(ch) = self.channels.get(channel.0) else {
            return Err(format!("no channel {channel:?}"));
        };
        let (exact_id, json_id, ros2_id, sequence) = (ch.exact, ch.json, ch.ros2, ch.sequence);
        let json_id = match (json, json_id) {
            (Some(bytes), None) => Some(self.add_json_channel(channel.0, bytes)?),
            (_, id) => id,
        };
        let writer = self.writer_mut()?;
        let header = |channel_id| MessageHeader {
            channel_id,
            sequence,
            log_time,
            publish_time: log_time,
        };
        writer
            .write_to_known_channel(&header(exact_id), exact)
            .map_err(|e| mcap_error(&path, e))?;
        for (id, bytes) in [(json_id, json), (ros2_id, cdr)] {
            if let (Some(id), Some(bytes)) = (id, bytes) {
                writer
                    .write_to_known_channel(&header(id), bytes)
                    .map_err(|e| mcap_error(&path, e))?;
            }
        }
        if let Some(ch) = self.channels.get_mut(channel.0) {
            ch.sequence = sequence.wrapping_add(1);
        }
        let due = self
            .last_flush
            .is_none_or(|last| log_time.saturating_sub(last) >= self.flush_every);
        if due {
            self.last_flush = Some(log_time);
            self.writer_mut()?
                .flush()
                .map_err(|e| mcap_error(&path, e))?;
        }
        Ok(())
    }

    fn add_json_channel(&mut self, k: usize, first: &[u8]) -> Result<u16, String> {
        let path = self.path.clone();
        let info = self.channels[k].info.clone();
        let value: serde_json::Value =
            serde_json::from_slice(first).map_err(|e| mcap_error(&path, e))?;
        let schema = json_schema(&info.model_type, &value);
        let schema_text = serde_json::to_vec(&schema).map_err(|e| mcap_error(&path, e))?;
        let writer = self.writer_mut()?;
        let schema = writer
            .add_schema(&info.model_type, "jsonschema", &schema_text)
            .map_err(|e| mcap_error(&path, e))?;
        let id = writer
            .add_channel(schema, &info.topic, "json", &metadata(&info, "json"))
            .map_err(|e| mcap_error(&path, e))?;
        self.channels[k].json = Some(id);
        Ok(id)
    }

    /// Writes the summary and footer and closes the file (also done when the last
    /// module holding it is dropped).
    pub fn finish(&mut self) -> Result<(), String> {
        let Some(mut writer) = self.writer.take() else {
            return Ok(());
        };
        let path = self.path.clone();
        writer.finish().map_err(|e| mcap_error(&path, e))?;
        let file = writer
            .into_inner()
            .into_inner()
            .map_err(|e| mcap_error(&path, e.into_error()))?;
        file.sync_all().map_err(|e| mcap_error(&path, e))
    }
}

impl Drop for LogFile {
    fn drop(&mut self) {
        if let Err(e) = self.finish() {
            eprintln!("warning: {e}");
        }
    }
}

fn metadata(info: &ChannelInfo, form: &str) -> BTreeMap<String, String> {
    BTreeMap::from([
        (META_PART.to_owned(), info.part.clone()),
        (META_PORT.to_owned(), info.port.clone()),
        (META_TYPE.to_owned(), info.model_type.clone()),
        (META_UNIT.to_owned(), info.unit.clone()),
        (META_FORM.to_owned(), form.to_owned()),
    ])
}

/// The record `ferroc.run` (see the [module docs](super)): which clock the log times
/// come from and where the run started on it, the run seed if told. A recording is
/// created in a module's step, so this thread's clock is the run's.
fn run_metadata() -> mcap::records::Metadata {
    use ferroc_runtime::module::Timestamp;
    let (clock, start) = match Timestamp::model_time() {
        Some(_) => ("lockstep", Timestamp::LOCKSTEP_EPOCH),
        None => ("wall", Timestamp::now()),
    };
    let mut metadata = BTreeMap::from([
        ("clock".to_owned(), clock.to_owned()),
        ("start".to_owned(), start.nanos.to_string()),
    ]);
    if let Some(seed) = super::run_seed() {
        metadata.insert("seed".to_owned(), seed.to_string());
    }
    mcap::records::Metadata {
        name: META_RUN.to_owned(),
        metadata,
    }
}
