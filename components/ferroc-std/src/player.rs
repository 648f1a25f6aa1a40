//! `ferroc_std.Player`: replays recorded channels (of a `Logger` or of `ferroc run
//! --record`) on instance-declared outputs, so a recorded sensor stream can replace
//! the live module that produced it.
//!
//! `channels` names the recorded topic of each output, in order (`out/0` plays the
//! first). When the instance is created, before anything runs, the recording is read
//! and checked: every topic must have an exact (postcard) channel there, recorded
//! with the output's model type; otherwise the instance is refused with what the file
//! has. A recording cut off by a crash is replayed up to the cut, with a warning.
//!
//! `mode`: `recorded` replays at the recorded timing (a message is published in the
//! first step at or after its log time, counted from the first step and the first
//! recorded message), `rate` the same timing sped up by `rate`, `step` one message
//! per channel and step (as fast as the schedule runs). In lockstep a recording made
//! in lockstep is replayed bit for bit at the same model instants.

use crate::recording::{self, Recording};
use ferroc_runtime::module::{DynOut, Module, ModuleType, Parameter, Setup, Wire};
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
        match load(m, &path, outputs, &topics) {
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
) -> Result<Vec<Replayed>, String> {
    if topics.len() != outputs.len() {
        return Err(format!(
            "parameter `channels` names {} topic(s) for {} output(s); name one recorded \
             topic per output, comma-separated",
            topics.len(),
            outputs.len()
        ));
    }
    let rec = Recording::read(path)?;
    if let Some(why) = &rec.damaged {
        eprintln!(
            "warning: ferroc_std.Player `{}`: the recording `{}` is cut off ({why}); \
             it replays the {} messages before the cut",
            m.path(),
            path.display(),
            rec.messages.len()
        );
    }
    let types: Vec<(String, &str)> = m
        .port_groups()
        .iter()
        .flat_map(|g| g.port_names().into_iter().map(move |n| (n, g.model_type)))
        .collect();
    let mut replayed = Vec::with_capacity(outputs.len());
    for (out, topic) in outputs.into_iter().zip(topics) {
        let Some(channel) = rec.exact_channel(topic) else {
            let known: Vec<&str> = rec
                .channels
                .values()
                .filter(|c| c.is_exact())
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
        if channel.model_type() != ty {
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
        let messages = rec
            .messages
            .iter()
            .filter(|msg| msg.channel == channel.id)
            .map(|msg| (msg.log_time, msg.data.clone()))
            .collect();
        replayed.push(Replayed {
            out,
            wire,
            topic: topic.clone(),
            messages,
            warned: false,
        });
    }
    Ok(replayed)
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
            while let Some((t, _)) = o.messages.front() {
                if due.is_some_and(|due| *t > due) {
                    break;
                }
                let Some((_, bytes)) = o.messages.pop_front() else {
                    break;
                };
                if let Err(e) = o.wire.decode(&o.out, &bytes) {
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
