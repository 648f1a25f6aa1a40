//! Reading a recording: every channel and message, also of a file whose writer was
//! killed (the messages up to the cut are read, and the cut is reported).
//!
//! The file is read front to back in pieces ([`mcap::sans_io::LinearReader`]), one
//! record at a time: memory follows the largest record (a chunk: 1 MiB in ferroc's
//! files, at most [`MAX_RECORD_BYTES`]) and what the caller keeps, not the file's
//! size. A caller that only counts (`ferroc log info`) or prints (`ferroc log cat`)
//! keeps nothing; the Player keeps the channels it replays.
//!
//! Checksums are verified where the file has them: each chunk's CRC before any of its
//! messages is handed out, and the data and summary sections' CRCs. A mismatch is an
//! error naming the chunk ([`Checksums::Verify`]); [`Checksums::Ignore`] reads such a
//! file anyway and lists what did not match in [`Recording::corrupt`]. A file that
//! ends with the MCAP magic was finished: a record in it that does not read is
//! corruption too, not a cut.

use mcap::records::Record;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use std::collections::{BTreeMap, HashMap};
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

/// The longest record read (a chunk, a message outside chunks): a longer one is
/// damage, not a reason to allocate.
pub const MAX_RECORD_BYTES: usize = 256 << 20;
/// What [`Recording::read`] keeps at most: the payloads of all messages.
pub const MAX_KEPT_BYTES: u64 = 2 << 30;

/// Whether checksums that do not match make the file an error.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Checksums {
    /// A mismatch is an error naming where it is.
    #[default]
    Verify,
    /// A mismatch is listed in [`Recording::corrupt`]; the data is read as it is.
    Ignore,
}

/// One channel of a recording and what it holds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ChannelSummary {
    pub id: u16,
    pub topic: String,
    pub message_encoding: String,
    /// The schema's name, encoding and text (empty without a schema).
    pub schema_name: String,
    pub schema_encoding: String,
    pub schema_data: Vec<u8>,
    pub metadata: BTreeMap<String, String>,
    /// Messages read, and the log times of the first and last (nanoseconds).
    pub count: u64,
    pub first: Option<u64>,
    pub last: Option<u64>,
}

impl ChannelSummary {
    /// The ferroc model type recorded (metadata `ferroc.type`, else the schema name).
    pub fn model_type(&self) -> &str {
        self.metadata
            .get(super::META_TYPE)
            .map_or(self.schema_name.as_str(), String::as_str)
    }
    /// Whether the channel holds the exact (postcard) form ferroc replays.
    pub fn is_exact(&self) -> bool {
        self.message_encoding == super::EXACT_ENCODING
    }
    /// Whether the channel holds ROS 2 messages (CDR with a `ros2msg` schema): a ROS-typed
    /// port's, or one a ROS 2 tool recorded.
    pub fn is_ros2(&self) -> bool {
        self.message_encoding == super::ros2::ROS2_ENCODING
            && self.schema_encoding == super::ros2::ROS2_SCHEMA_ENCODING
    }
}

/// One recorded message.
#[derive(Clone, Debug, PartialEq)]
pub struct Message {
    pub channel: u16,
    pub sequence: u32,
    pub log_time: u64,
    pub data: Vec<u8>,
}

/// A recording as read: its channels, the messages kept, and its state.
#[derive(Debug, Default)]
pub struct Recording {
    /// By channel id.
    pub channels: BTreeMap<u16, ChannelSummary>,
    /// The messages kept, in file order ([`Recording::read`] keeps all).
    pub messages: Vec<Message>,
    /// Messages read, kept or not.
    pub message_count: u64,
    /// Why reading stopped before the end of a complete file (a recording cut off
    /// by a crash: the messages before the cut are all here).
    pub damaged: Option<String>,
    /// Whether the file ends with a summary and footer (finished cleanly).
    pub finished: bool,
    /// What did not match its checksum (read with [`Checksums::Ignore`]).
    pub corrupt: Vec<String>,
    /// What the recording's metadata record `ferroc.run` says of the run.
    pub run: Run,
}

/// The metadata record `ferroc.run` of a recording (see the [module docs](super)).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Run {
    /// The run seed (`--seed`).
    pub seed: Option<u64>,
    /// The clock of the log times: `lockstep` (model time) or `wall`.
    pub clock: Option<String>,
    /// The log time of the run's start (nanoseconds since 1970): times from the
    /// start are log times minus this.
    pub start: Option<u64>,
}

/// What a reader is asked to keep of each message: `true` keeps it in
/// [`Recording::messages`].
pub type Keep<'a> = dyn FnMut(&ChannelSummary, &Message) -> bool + 'a;

/// [`Keep`] that is also told the run's metadata read so far (the writer puts it
/// before the first message).
pub type KeepRun<'a> = dyn FnMut(&Run, &ChannelSummary, &Message) -> bool + 'a;

impl Recording {
    /// Reads the recording at `path` with every message, checksums verified; an
    /// error if nothing can be read (not a file, not MCAP), if it is corrupted, or if
    /// its messages are larger than [`MAX_KEPT_BYTES`].
    pub fn read(path: &Path) -> Result<Recording, String> {
        let mut kept = 0u64;
        let mut over = false;
        let rec = Self::read_with(path, Checksums::Verify, &mut |_, m| {
            kept += m.data.len() as u64;
            over |= kept > MAX_KEPT_BYTES;
            !over
        })?;
        if over {
            return Err(format!(
                "`{}` holds more than {} GiB of messages: too many to keep in memory",
                path.display(),
                MAX_KEPT_BYTES >> 30
            ));
        }
        Ok(rec)
    }

    /// Reads the recording at `path`, handing every message to `keep` (which says
    /// whether to keep it); an error if nothing can be read (not a file, not MCAP) or,
    /// with [`Checksums::Verify`], if a checksum does not match.
    pub fn read_with(
        path: &Path,
        checksums: Checksums,
        keep: &mut Keep<'_>,
    ) -> Result<Recording, String> {
        Self::read_with_run(path, checksums, &mut |_, c, m| keep(c, m))
    }

    /// [`Self::read_with`] telling `keep` the run's metadata too.
    pub fn read_with_run(
        path: &Path,
        checksums: Checksums,
        keep: &mut KeepRun<'_>,
    ) -> Result<Recording, String> {
        let shown = path.display();
        let cannot = |e: std::io::Error| format!("cannot read `{shown}`: {e}");
        let meta = std::fs::metadata(path).map_err(cannot)?;
        if !meta.is_file() {
            return Err(format!("`{shown}` is not a regular file"));
        }
        let mut file = std::fs::File::open(path).map_err(cannot)?;
        let complete = ends_with_magic(&mut file).map_err(cannot)?;
        file.seek(SeekFrom::Start(0)).map_err(cannot)?;
        scan(&mut file, complete, checksums, keep).map_err(|e| format!("`{shown}` {e}"))
    }

    /// Reads a recording from its bytes (every message kept, checksums verified).
    pub fn parse(bytes: &[u8]) -> Result<Recording, String> {
        let complete = bytes.len() >= 2 * mcap::MAGIC.len() && bytes.ends_with(mcap::MAGIC);
        let mut src = bytes;
        scan(&mut src, complete, Checksums::Verify, &mut |_, _, _| true)
    }

    /// The exact channel of `topic`.
    pub fn exact_channel(&self, topic: &str) -> Option<&ChannelSummary> {
        self.channels
            .values()
            .find(|c| c.topic == topic && c.is_exact())
    }

    /// The ROS 2 channel of `topic` ([`ChannelSummary::is_ros2`]).
    pub fn ros2_channel(&self, topic: &str) -> Option<&ChannelSummary> {
        self.channels
            .values()
            .find(|c| c.topic == topic && c.is_ros2())
    }
}

/// Whether the file ends with the MCAP magic (its writer finished it).
fn ends_with_magic(file: &mut std::fs::File) -> std::io::Result<bool> {
    let len = file.seek(SeekFrom::End(0))?;
    let magic = mcap::MAGIC.len() as u64;
    if len < 2 * magic {
        return Ok(false);
    }
    file.seek(SeekFrom::End(-(magic as i64)))?;
    let mut tail = [0u8; 8];
    file.read_exact(&mut tail)?;
    Ok(tail[..] == *mcap::MAGIC)
}

/// How much is read from the file at once, whatever a record's length says.
const PIECE: usize = 1 << 20;

/// The reading state: what was found so far.
struct Scan<'k, 'a> {
    rec: Recording,
    schemas: HashMap<u16, (String, String, Vec<u8>)>,
    verify: bool,
    keep: &'k mut KeepRun<'a>,
    /// Chunks met so far (the one being read is number `chunks`).
    chunks: u64,
}

fn scan(
    src: &mut dyn Read,
    complete: bool,
    checksums: Checksums,
    keep: &mut KeepRun<'_>,
) -> Result<Recording, String> {
    let mut head = [0u8; 8];
    let got = read_full(src, &mut head).map_err(|e| format!("cannot be read: {e}"))?;
    if head[..got] != *mcap::MAGIC {
        return Err("is not an MCAP file (it does not start with the MCAP magic)".into());
    }
    let verify = checksums == Checksums::Verify;
    let options = LinearReaderOptions::default()
        .with_skip_end_magic(true)
        .with_emit_chunks(true)
        .with_validate_data_section_crc(verify)
        .with_validate_summary_section_crc(verify)
        .with_record_length_limit(MAX_RECORD_BYTES);
    let mut reader = LinearReader::new_with_options(options);
    // The magic read above goes in first: the data section's CRC covers it.
    reader.insert(head.len()).copy_from_slice(&head);
    reader.notify_read(head.len());
    let mut state = Scan {
        rec: Recording::default(),
        schemas: HashMap::new(),
        verify,
        keep,
        chunks: 0,
    };
    // Where the next record starts in the file.
    let mut offset = mcap::MAGIC.len() as u64;
    while let Some(event) = reader.next_event() {
        let problem = match event {
            Ok(LinearReadEvent::ReadRequest(need)) => {
                let piece = reader.insert(need.clamp(1, PIECE));
                let n = read_some(src, piece).map_err(|e| format!("cannot be read: {e}"))?;
                reader.notify_read(n);
                continue;
            }
            Ok(LinearReadEvent::Record { opcode, data }) => {
                let len = data.len() as u64;
                let done = state.record(opcode, data, offset);
                offset += 9 + len;
                match done {
                    Ok(()) => continue,
                    Err(Stop::Corrupt(what)) => Problem::Corrupt(what),
                    Err(Stop::Damaged(why)) => Problem::Damaged(why),
                    Err(Stop::Unsupported(why)) => return Err(why),
                }
            }
            Err(mcap::McapError::BadDataCrc { saved, calculated }) => Problem::Corrupt(format!(
                "the data section does not match its CRC (saved {saved:08x}, computed \
                 {calculated:08x}): a record outside the chunks was changed"
            )),
            Err(mcap::McapError::BadSummaryCrc { saved, calculated }) => Problem::Corrupt(format!(
                "the summary section does not match its CRC (saved {saved:08x}, computed \
                     {calculated:08x})"
            )),
            Err(e) => Problem::Damaged(format!("at byte {offset}: {e}")),
        };
        state.stop(problem, complete)?;
        break;
    }
    Ok(state.rec)
}

/// Why reading a record stopped the reading.
enum Stop {
    /// A checksum does not match (what, where).
    Corrupt(String),
    /// The record does not read.
    Damaged(String),
    /// The file is well formed but holds what ferroc does not read (compressed chunks):
    /// an error, whatever the checksums say.
    Unsupported(String),
}

/// What stopped the reading, as the file's state or an error.
enum Problem {
    Corrupt(String),
    Damaged(String),
}

impl Scan<'_, '_> {
    /// Ends the reading at `problem`: an error for corruption under
    /// [`Checksums::Verify`], else the recording's state says it.
    fn stop(&mut self, problem: Problem, complete: bool) -> Result<(), String> {
        let corrupt = match problem {
            Problem::Corrupt(what) => what,
            // A finished file does not end in the middle: it was changed.
            Problem::Damaged(why) if complete => format!(
                "the file was finished (it ends with the MCAP magic), but {why}: it was \
                 changed after it was written"
            ),
            Problem::Damaged(why) => {
                self.rec.damaged = Some(why);
                return Ok(());
            }
        };
        if self.verify {
            return Err(format!(
                "is corrupted: {corrupt}\n  help: the file changed after it was written (a \
                 bad disk, copy or transfer); record again, or read it anyway with \
                 `ferroc log info --ignore-checksums` (the Player's `checksums=\"ignore\"`)"
            ));
        }
        self.rec.corrupt.push(corrupt.clone());
        self.rec.damaged = Some(corrupt);
        Ok(())
    }

    /// Takes in one record of the file, starting at byte `offset`.
    fn record(&mut self, opcode: u8, data: &[u8], offset: u64) -> Result<(), Stop> {
        if opcode == 0 {
            return Err(Stop::Damaged(format!(
                "at byte {offset}: opcode 0x00 is no MCAP record"
            )));
        }
        let record = mcap::parse_record(opcode, data)
            .map_err(|e| Stop::Damaged(format!("at byte {offset}: {e}")))?;
        match record {
            Record::Chunk { header, data } => self.chunk(header, &data, offset),
            Record::Footer(_) => {
                self.rec.finished = true;
                Ok(())
            }
            other => self
                .inner(other)
                .map_err(|e| Stop::Damaged(format!("at byte {offset}: {e}"))),
        }
    }

    /// A chunk: its CRC checked before any of its records is taken in.
    fn chunk(
        &mut self,
        mut header: mcap::records::ChunkHeader,
        data: &[u8],
        offset: u64,
    ) -> Result<(), Stop> {
        self.chunks += 1;
        let which = format!("chunk {} (the record at byte {offset})", self.chunks);
        if !header.compression.is_empty() {
            return Err(Stop::Unsupported(format!(
                "holds chunks compressed with `{}` ({which}), which ferroc does not read: \
                 its recordings are uncompressed\n  help: write the file without chunk \
                 compression (the writer's compression `none`), or decompress it with an \
                 MCAP tool first",
                header.compression
            )));
        }
        if header.uncompressed_crc != 0 && header.compression.is_empty() {
            let computed = crc32fast::hash(data);
            if computed != header.uncompressed_crc {
                let what = format!(
                    "{which} does not match its CRC (saved {:08x}, computed {computed:08x})",
                    header.uncompressed_crc
                );
                if self.verify {
                    return Err(Stop::Corrupt(what));
                }
                self.rec.corrupt.push(what);
            }
            // Checked here, before its messages are handed out.
            header.uncompressed_crc = 0;
        }
        let records = mcap::read::ChunkReader::new(header, data)
            .map_err(|e| Stop::Damaged(format!("{which}: {e}")))?;
        for record in records {
            let record = record.map_err(|e| Stop::Damaged(format!("{which}: {e}")))?;
            self.inner(record)
                .map_err(|e| Stop::Damaged(format!("{which}: {e}")))?;
        }
        Ok(())
    }

    /// A record outside chunks or inside one: schemas, channels and messages count, and
    /// the run's metadata.
    fn inner(&mut self, record: Record<'_>) -> Result<(), String> {
        match record {
            Record::Schema { header, data } => {
                let schema = (header.name, header.encoding, data.into_owned());
                self.schemas.insert(header.id, schema);
            }
            Record::Metadata(m) if m.name == super::META_RUN => {
                self.rec.run = Run {
                    seed: m.metadata.get("seed").and_then(|s| s.parse().ok()),
                    clock: m.metadata.get("clock").cloned(),
                    start: m.metadata.get("start").and_then(|s| s.parse().ok()),
                };
            }
            Record::Channel(ch) if !self.rec.channels.contains_key(&ch.id) => {
                let summary = self.summary_of(ch);
                self.rec.channels.insert(summary.id, summary);
            }
            Record::Message { header, data } => {
                let Some(channel) = self.rec.channels.get_mut(&header.channel_id) else {
                    return Err(format!(
                        "a message of channel {} comes before the channel",
                        header.channel_id
                    ));
                };
                channel.count += 1;
                channel.first.get_or_insert(header.log_time);
                channel.last = Some(header.log_time);
                self.rec.message_count += 1;
                let message = Message {
                    channel: header.channel_id,
                    sequence: header.sequence,
                    log_time: header.log_time,
                    data: data.into_owned(),
                };
                if (self.keep)(&self.rec.run, channel, &message) {
                    self.rec.messages.push(message);
                }
            }
            _ => {}
        }
        Ok(())
    }

    fn summary_of(&self, ch: mcap::records::Channel) -> ChannelSummary {
        let (schema_name, schema_encoding, schema_data) =
            self.schemas.get(&ch.schema_id).cloned().unwrap_or_default();
        ChannelSummary {
            id: ch.id,
            topic: ch.topic,
            message_encoding: ch.message_encoding,
            schema_name,
            schema_encoding,
            schema_data,
            metadata: ch.metadata,
            ..ChannelSummary::default()
        }
    }
}

/// Reads into `buf` until it is full or the input ends; how much was read.
fn read_full(src: &mut dyn Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match read_some(src, &mut buf[got..])? {
            0 => break,
            n => got += n,
        }
    }
    Ok(got)
}

/// One read, retried when interrupted.
fn read_some(src: &mut dyn Read, buf: &mut [u8]) -> std::io::Result<usize> {
    loop {
        match src.read(buf) {
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            other => return other,
        }
    }
}
