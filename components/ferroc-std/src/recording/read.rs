//! Reading a recording: every channel and message, also of a file whose writer was
//! killed (the messages up to the cut are read, and the cut is reported).

use mcap::read::{MessageStream, Options, Summary};
use std::collections::BTreeMap;
use std::io::Read;
use std::path::Path;

/// Recordings larger than this are refused (they are read into memory whole).
pub const MAX_RECORDING_BYTES: u64 = 2 << 30;

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
}

/// One recorded message.
#[derive(Clone, Debug, PartialEq)]
pub struct Message {
    pub channel: u16,
    pub sequence: u32,
    pub log_time: u64,
    pub data: Vec<u8>,
}

/// A recording read into memory.
#[derive(Debug, Default)]
pub struct Recording {
    /// By channel id.
    pub channels: BTreeMap<u16, ChannelSummary>,
    /// In file order.
    pub messages: Vec<Message>,
    /// Why reading stopped before the end of a complete file (a recording cut off
    /// by a crash: the messages before the cut are all here).
    pub damaged: Option<String>,
    /// Whether the file ends with a summary and footer (finished cleanly).
    pub finished: bool,
    /// The run seed the recording's metadata `ferroc.run` names (`--seed`).
    pub seed: Option<u64>,
}

impl Recording {
    /// Reads the recording at `path`; an error only if nothing can be read (not a
    /// file, not MCAP, too large).
    pub fn read(path: &Path) -> Result<Recording, String> {
        let shown = path.display();
        let meta = std::fs::metadata(path).map_err(|e| format!("cannot read `{shown}`: {e}"))?;
        if !meta.is_file() {
            return Err(format!("`{shown}` is not a regular file"));
        }
        let mut bytes = Vec::new();
        std::fs::File::open(path)
            .and_then(|f| f.take(MAX_RECORDING_BYTES + 1).read_to_end(&mut bytes))
            .map_err(|e| format!("cannot read `{shown}`: {e}"))?;
        if bytes.len() as u64 > MAX_RECORDING_BYTES {
            return Err(format!(
                "`{shown}` is larger than {} GiB; ferroc reads recordings into memory",
                MAX_RECORDING_BYTES >> 30
            ));
        }
        Self::parse(&bytes).map_err(|e| format!("`{shown}` {e}"))
    }

    /// Reads a recording from its bytes.
    pub fn parse(bytes: &[u8]) -> Result<Recording, String> {
        if !bytes.starts_with(mcap::MAGIC) {
            return Err("is not an MCAP file (it does not start with the MCAP magic)".into());
        }
        let mut rec = Recording {
            seed: run_seed(bytes),
            ..Recording::default()
        };
        let stream = MessageStream::new_with_options(bytes, Options::IgnoreEndMagic.into())
            .map_err(|e| format!("is not a readable MCAP file: {e}"))?;
        for item in stream {
            match item {
                Ok(m) => {
                    let ch = rec
                        .channels
                        .entry(m.channel.id)
                        .or_insert_with(|| summary_of(&m.channel));
                    ch.count += 1;
                    ch.first.get_or_insert(m.log_time);
                    ch.last = Some(m.log_time);
                    rec.messages.push(Message {
                        channel: m.channel.id,
                        sequence: m.sequence,
                        log_time: m.log_time,
                        data: m.data.into_owned(),
                    });
                }
                Err(e) => {
                    rec.damaged = Some(e.to_string());
                    break;
                }
            }
        }
        // Channels without messages are only in the summary of a finished file.
        if let Ok(Some(summary)) = Summary::read(bytes) {
            rec.finished = true;
            for (id, ch) in &summary.channels {
                rec.channels.entry(*id).or_insert_with(|| summary_of(ch));
            }
        }
        Ok(rec)
    }

    /// The exact channel of `topic`.
    pub fn exact_channel(&self, topic: &str) -> Option<&ChannelSummary> {
        self.channels
            .values()
            .find(|c| c.topic == topic && c.is_exact())
    }
}

/// The seed of the `ferroc.run` metadata record, which ferroc writes right after the
/// header: only the records before the first chunk or message are looked at.
fn run_seed(bytes: &[u8]) -> Option<u64> {
    use mcap::records::Record;
    let records = mcap::read::LinearReader::new_with_options(bytes, Options::IgnoreEndMagic.into());
    for record in records.ok()? {
        match record.ok()? {
            Record::Metadata(m) if m.name == super::META_RUN => {
                return m.metadata.get("seed")?.parse().ok();
            }
            Record::Header(_) | Record::Metadata(_) => {}
            _ => return None,
        }
    }
    None
}

fn summary_of(ch: &mcap::Channel<'_>) -> ChannelSummary {
    let (schema_name, schema_encoding, schema_data) = match &ch.schema {
        Some(s) => (s.name.clone(), s.encoding.clone(), s.data.to_vec()),
        None => Default::default(),
    };
    ChannelSummary {
        id: ch.id,
        topic: ch.topic.clone(),
        message_encoding: ch.message_encoding.clone(),
        schema_name,
        schema_encoding,
        schema_data,
        metadata: ch.metadata.clone(),
        ..ChannelSummary::default()
    }
}
