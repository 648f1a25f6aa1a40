//! `ferroc_std.Player`: replays recorded channels (of a `Logger` or of `ferroc run
//! --record`) on instance-declared outputs, so a recorded sensor stream can replace
//! the live module that produced it.
//!
//! `channels` names the recorded topic of each output, in order (`out/0` plays the
//! first). When the instance is created, before anything runs, the recording is read
//! and checked: every topic must have an exact (postcard) channel there, recorded
//! with the output's model type, or a ROS 2 channel (CDR with a `ros2msg` schema: a
//! ROS-typed port's, or one a ROS 2 tool recorded), read with the definitions its
//! schema holds: each message is checked against the message then (one that does not
//! decode is skipped, said once) and read straight into the output's value when it is
//! replayed (`Codec::ros2_decode`), in any program; otherwise the instance is refused
//! with what the file has. A recording cut off by a crash is replayed up to the cut, with a warning. A
//! recording whose checksums do not match (it changed after it was written) is refused
//! naming the chunk, unless `checksums` is `ignore`. Only the replayed channels'
//! messages are kept in memory.
//!
//! `mode`: `recorded` replays at the recorded timing (a message is published in the
//! first step at or after its log time, counted from the first step and the first
//! recorded message), `rate` the same timing sped up by `rate`, `step` one message
//! per channel and step (as fast as the schedule runs). In lockstep a recording made
//! in lockstep is replayed bit for bit at the same model instants.
//!
//! `timestamps`: `recorded` replays values as they were; `now` shifts every value of
//! model type `timestamp` (also `timestamp[N]` and `[timestamp]`) by how much later it
//! is replayed than it was recorded (the step's time minus the message's log time), so
//! a recorded stamp is as old, relative to now, as it was relative to its recording.
//! Timestamps inside library types are opaque bytes to the player and stay as they were.

use crate::recording::{self, Recording};
use ferroc_runtime::module::{DynOut, Module, ModuleType, Parameter, Setup, Timestamp, Wire};
use std::collections::VecDeque;
use std::path::PathBuf;

/// `ferroc_std.Player`: replays a recording on its outputs.
pub struct Player {
    outputs: Vec<Replayed>,
    mode: Mode,
    rate: f64,
    /// Log time of the first replayed message and model time of the first step.
    origin: Option<(u64, u64)>,
    ended: bool,
    /// `timestamps=now`.
    shift: bool,
}

#[derive(Clone, Copy, PartialEq)]
enum Mode {
    Recorded,
    Rate,
    Step,
}

struct Replayed {
    out: DynOut,
    wire: Wire,
    topic: String,
    messages: VecDeque<(u64, Vec<u8>)>,
    /// A message did not decode: reported once.
    warned: bool,
    /// How its values hold timestamps (`None`: not a timestamp type).
    stamps: Option<Stamps>,
    /// The messages are a ROS 2 channel's CDR, read with its definitions, not postcard.
    ros2: Option<recording::ros2::Ros2Channel>,
}

/// The shape of a timestamp output's values, in postcard: one stamp, `N` stamps in a
/// row (an array), or a length and the stamps (a sequence).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Stamps {
    One,
    Array(usize),
    Seq,
}

impl Stamps {
    fn of(model_type: &str) -> Option<Stamps> {
        if model_type == "timestamp" {
            return Some(Stamps::One);
        }
        if model_type == "[timestamp]" {
            return Some(Stamps::Seq);
        }
        let n = model_type.strip_prefix("timestamp[")?.strip_suffix(']')?;
        n.parse().ok().map(Stamps::Array)
    }

    /// `bytes` with every stamp moved by `by` nanoseconds (saturating); `None` if they
    /// are not values of this shape.
    fn shift(self, bytes: &[u8], by: i64) -> Option<Vec<u8>> {
        let moved = |t: Timestamp| Timestamp {
            nanos: t.nanos.saturating_add(by),
        };
        match self {
            Stamps::One => {
                let t: Timestamp = postcard::from_bytes(bytes).ok()?;
                postcard::to_stdvec(&moved(t)).ok()
            }
            Stamps::Seq => {
                let ts: Vec<Timestamp> = postcard::from_bytes(bytes).ok()?;
                postcard::to_stdvec(&ts.into_iter().map(moved).collect::<Vec<_>>()).ok()
            }
            Stamps::Array(n) => {
                let (mut rest, mut out) = (bytes, Vec::with_capacity(bytes.len()));
                for _ in 0..n {
                    let (t, tail): (Timestamp, _) = postcard::take_from_bytes(rest).ok()?;
                    out.extend(postcard::to_stdvec(&moved(t)).ok()?);
                    rest = tail;
                }
                rest.is_empty().then_some(out)
            }
        }
    }
}

impl ModuleType for Player {
    const NAME: &'static str = "ferroc_std.Player";
    const DOC: &'static str = "Replays recorded channels of an MCAP file on its outputs";
    fn create(m: &mut Setup<'_>) -> Self {
        let outputs = m.flexible_outputs("out").min_count(1).build_dyn_outputs();
        let mut file: Parameter<String> = m
            .param("file")
            .doc("the MCAP recording; relative paths lie under the log folder (--log-dir)")
            .build();
        let mut channels: Parameter<String> = m
            .param("channels")
            .doc("the recorded topic of each output, comma-separated, in order")
            .build();
        let mut mode: Parameter<String> = m
            .param("mode")
            .default("recorded".to_owned())
            .choices(&["recorded", "rate", "step"])
            .doc("recorded timing, sped up by `rate`, or one message per step")
            .build();
        let mut rate: Parameter<f64> = m
            .param("rate")
            .default(1.0)
            .range(0.001, 1000.0)
            .doc("speed factor of mode `rate`")
            .build();
        let mut timestamps: Parameter<String> = m
            .param("timestamps")
            .default("recorded".to_owned())
            .choices(&["recorded", "now"])
            .doc("replay timestamp values as recorded, or shifted by how much later they are replayed")
            .build();
        let mut checksums: Parameter<String> = m
            .param("checksums")
            .default("verify".to_owned())
            .choices(&["verify", "ignore"])
            .doc("refuse a recording whose checksums do not match (verify), or replay it anyway (ignore)")
            .build();
        let checksums = if checksums.value() == "ignore" {
            recording::Checksums::Ignore
        } else {
            recording::Checksums::Verify
        };
        let mode = match mode.value().as_str() {
            "rate" => Mode::Rate,
            "step" => Mode::Step,
            _ => Mode::Recorded,
        };
        let mut player = Player {
            outputs: Vec::new(),
            mode,
            rate: rate.get(),
            origin: None,
            ended: false,
            shift: timestamps.value() == "now",
        };
        // The registry learning the interface: no recording to read.
        if m.path().is_empty() {
            return player;
        }
        let path = recording::resolve_log_path(&PathBuf::from(file.value()));
        let topics: Vec<String> = channels
            .value()
            .split(',')
            .map(|t| t.trim().to_owned())
            .filter(|t| !t.is_empty())
            .collect();
        match load(m, &path, outputs, &topics, checksums) {
            Ok(replayed) => player.outputs = replayed,
            Err(why) => m.problem(why),
        }
        player
    }
}

/// Reads the recording and pairs each output with its channel's messages.
fn load(
    m: &Setup<'_>,
    path: &std::path::Path,
    outputs: Vec<DynOut>,
    topics: &[String],
    checksums: recording::Checksums,
) -> Result<Vec<Replayed>, String> {
    if topics.len() != outputs.len() {
        return Err(format!(
            "parameter `channels` names {} topic(s) for {} output(s); name one recorded \
             topic per output, comma-separated",
            topics.len(),
            outputs.len()
        ));
    }
    let mut rec = read_replayed(m, path, topics, checksums)?;
    let types: Vec<(String, &str)> = m
        .port_groups()
        .iter()
        .flat_map(|g| g.port_names().into_iter().map(move |n| (n, g.model_type)))
        .collect();
    let mut replayed = Vec::with_capacity(outputs.len());
    let mut by_channel: std::collections::HashMap<u16, VecDeque<(u64, Vec<u8>)>> =
        std::collections::HashMap::new();
    for msg in std::mem::take(&mut rec.messages) {
        (by_channel.entry(msg.channel).or_default()).push_back((msg.log_time, msg.data));
    }
    for (k, (out, topic)) in outputs.into_iter().zip(topics).enumerate() {
        let Some(channel) = rec.exact_channel(topic).or_else(|| rec.ros2_channel(topic)) else {
            let known: Vec<&str> = rec
                .channels
                .values()
                .filter(|c| c.is_exact() || c.is_ros2())
                .map(|c| c.topic.as_str())
                .collect();
            return Err(format!(
                "output `{}`: the recording `{}` has no channel `{topic}`\n  help: its \
                 channels are: {}",
                out.name(),
                path.display(),
                if known.is_empty() {
                    "none".to_owned()
                } else {
                    known.join(", ")
                }
            ));
        };
        let ty = types
            .iter()
            .find(|(n, _)| n == out.name())
            .map_or("", |(_, t)| *t);
        // A ROS 2 channel another program recorded names no ferroc type: its messages
        // become the output's values by their fields' names.
        let foreign = channel.is_ros2() && !channel.metadata.contains_key(recording::META_TYPE);
        if channel.model_type() != ty && !foreign {
            return Err(format!(
                "output `{}` has type `{ty}`, but the channel `{topic}` of `{}` was recorded \
                 as `{}`\n  help: declare the output with type=\"{}\" or pick another channel",
                out.name(),
                path.display(),
                channel.model_type(),
                channel.model_type()
            ));
        }
        let Some(wire) = m.value_type_of(ty).and_then(|v| v.wire()).copied() else {
            return Err(format!(
                "output `{}`: values of `{ty}` cannot be replayed: its library registers the \
                 type without serde",
                out.name()
            ));
        };
        // Moved out of the recording; copied only for a topic two outputs replay.
        let rest = topics[k + 1..].iter().any(|t| t == topic);
        let messages = if rest {
            by_channel.get(&channel.id).cloned()
        } else {
            by_channel.remove(&channel.id)
        }
        .unwrap_or_default();
        let (messages, ros2) = if channel.is_ros2() {
            let (messages, read) = from_cdr(m, path, channel, messages)?;
            (messages, Some(read))
        } else {
            (messages, None)
        };
        replayed.push(Replayed {
            out,
            wire,
            topic: topic.clone(),
            messages,
            warned: false,
            stamps: Stamps::of(ty).filter(|_| ros2.is_none()),
            ros2,
        });
    }
    Ok(replayed)
}

/// A channel's messages to replay: (log time, bytes).
type Queue = VecDeque<(u64, Vec<u8>)>;

/// The reader of the ROS 2 channel `channel` (the definitions its schema holds) and
/// its messages, each checked against the message: one that does not read is left out,
/// said once with how many were. An error if the schema does not read.
fn from_cdr(
    m: &Setup<'_>,
    path: &std::path::Path,
    channel: &recording::ChannelSummary,
    messages: Queue,
) -> Result<(Queue, recording::ros2::Ros2Channel), String> {
    use recording::ros2::Ros2Channel;
    let read = Ros2Channel::of(channel).map_err(|why| {
        let exact = (channel.metadata.get(recording::META_PORT))
            .map(|p| format!("\n  help: replay the port's exact channel `{p}`"))
            .unwrap_or_default();
        format!("{why}{exact}")
    })?;
    // Without definitions in the file, the program's may be known only at the first
    // step: its messages are checked as they are replayed.
    if read.of_program() {
        return Ok((messages, read));
    }
    let shape = read.shape()?;
    let (mut out, mut bad) = (VecDeque::with_capacity(messages.len()), None);
    let mut skipped = 0usize;
    for (time, cdr) in messages {
        match Ros2Channel::check(&shape, &cdr) {
            Ok(()) => out.push_back((time, cdr)),
            Err(why) => {
                skipped += 1;
                bad.get_or_insert(why);
            }
        }
    }
    drop(shape);
    if let Some(why) = bad {
        eprintln!(
            "warning: ferroc_std.Player `{}`: {skipped} message(s) of the ROS 2 channel `{}` \
             of `{}` do not decode ({why}); they are skipped",
            m.path(),
            channel.topic,
            path.display()
        );
    }
    Ok((out, read))
}

/// Reads the channels of `topics` from the recording at `path` (the others are only
/// counted), saying on standard error what is corrupted (with `checksums=ignore`) or
/// cut off.
fn read_replayed(
    m: &Setup<'_>,
    path: &std::path::Path,
    topics: &[String],
    checksums: recording::Checksums,
) -> Result<Recording, String> {
    // Only the replayed channels' messages are kept, and only up to a bound.
    let mut kept = 0u64;
    let rec = Recording::read_with(path, checksums, &mut |c, msg| {
        let replayed = (c.is_exact() || c.is_ros2()) && topics.contains(&c.topic);
        if replayed {
            kept += msg.data.len() as u64;
        }
        replayed && kept <= recording::MAX_KEPT_BYTES
    })?;
    if kept > recording::MAX_KEPT_BYTES {
        return Err(format!(
            "the channels to replay of `{}` hold more than {} GiB: too many to keep in memory",
            path.display(),
            recording::MAX_KEPT_BYTES >> 30
        ));
    }
    for what in &rec.corrupt {
        eprintln!(
            "warning: ferroc_std.Player `{}`: the recording `{}` is corrupted ({what}); it \
             replays it anyway (checksums=\"ignore\")",
            m.path(),
            path.display()
        );
    }
    if let Some(why) = rec.damaged.as_ref().filter(|_| rec.corrupt.is_empty()) {
        eprintln!(
            "warning: ferroc_std.Player `{}`: the recording `{}` is cut off ({why}); \
             it replays the {} messages before the cut",
            m.path(),
            path.display(),
            rec.messages.len()
        );
    }
    Ok(rec)
}

impl Module for Player {
    fn update(&mut self) {
        if self.ended {
            return;
        }
        let now = crate::logger::log_time();
        let first = self
            .outputs
            .iter()
            .filter_map(|o| o.messages.front().map(|(t, _)| *t))
            .min();
        let Some(first) = first else {
            self.ended = true;
            return;
        };
        let (t0, start) = *self.origin.get_or_insert((first, now));
        let elapsed = now.saturating_sub(start);
        let due = match self.mode {
            Mode::Recorded => Some(t0.saturating_add(elapsed)),
            Mode::Rate => Some(t0.saturating_add((elapsed as f64 * self.rate) as u64)),
            Mode::Step => None,
        };
        for o in &mut self.outputs {
            let shape = match o.ros2.as_ref().map(|r| r.shape()).transpose() {
                Ok(shape) => shape,
                Err(e) => {
                    // A channel without definitions whose message this program does not
                    // define either: said once, nothing of it replayed.
                    eprintln!(
                        "warning: ferroc_std.Player: the ROS 2 channel `{}` is not replayed: {e}",
                        o.topic
                    );
                    o.messages.clear();
                    continue;
                }
            };
            while let Some((t, _)) = o.messages.front() {
                if due.is_some_and(|due| *t > due) {
                    break;
                }
                let Some((logged, mut bytes)) = o.messages.pop_front() else {
                    break;
                };
                if let Some(stamps) = o.stamps.filter(|_| self.shift) {
                    let by = i64::try_from(now)
                        .unwrap_or(i64::MAX)
                        .saturating_sub(i64::try_from(logged).unwrap_or(i64::MAX));
                    // Bytes that are no stamps are left for `decode` to report.
                    if let Some(shifted) = stamps.shift(&bytes, by) {
                        bytes = shifted;
                    }
                }
                let published = if let Some(shape) = &shape {
                    recording::ros2::Ros2Channel::publish(&o.wire, &o.out, shape, &bytes)
                } else {
                    o.wire.decode(&o.out, &bytes)
                };
                if let Err(e) = published {
                    if !o.warned {
                        o.warned = true;
                        eprintln!(
                            "warning: ferroc_std.Player: a message of `{}` does not decode \
                             ({e}); such messages are skipped",
                            o.topic
                        );
                    }
                }
                if due.is_none() {
                    break;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stamps(nanos: &[i64]) -> Vec<Timestamp> {
        nanos.iter().map(|&nanos| Timestamp { nanos }).collect()
    }

    #[test]
    fn stamps_of_every_shape_move_by_the_delay() {
        assert_eq!(Stamps::of("timestamp"), Some(Stamps::One));
        assert_eq!(Stamps::of("timestamp[3]"), Some(Stamps::Array(3)));
        assert_eq!(Stamps::of("[timestamp]"), Some(Stamps::Seq));
        assert_eq!(Stamps::of("f64"), None);
        assert_eq!(Stamps::of("lib.Stamped"), None);
        let one = postcard::to_stdvec(&Timestamp { nanos: 5 }).unwrap();
        let moved = Stamps::One.shift(&one, 1_000).unwrap();
        assert_eq!(
            postcard::from_bytes::<Timestamp>(&moved).unwrap().nanos,
            1_005
        );
        let seq = postcard::to_stdvec(&stamps(&[1, -2, i64::MAX])).unwrap();
        let moved = Stamps::Seq.shift(&seq, 10).unwrap();
        let back: Vec<Timestamp> = postcard::from_bytes(&moved).unwrap();
        assert_eq!(back, stamps(&[11, 8, i64::MAX]), "saturates");
        let array: [Timestamp; 2] = [Timestamp { nanos: 1 }, Timestamp { nanos: 2 }];
        let bytes = postcard::to_stdvec(&array).unwrap();
        let moved = Stamps::Array(2).shift(&bytes, -1).unwrap();
        let back: [Timestamp; 2] = postcard::from_bytes(&moved).unwrap();
        assert_eq!(back.map(|t| t.nanos), [0, 1]);
        // Not values of the shape: left alone (decode reports them).
        assert_eq!(Stamps::Array(3).shift(&bytes, 1), None);
        assert_eq!(Stamps::One.shift(&[], 1), None);
    }
}
