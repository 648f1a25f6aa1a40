//! `ferroc log info FILE` and `ferroc log cat FILE --channel TOPIC`: what an MCAP
//! recording holds (ferroc's, or any other), also one cut off by a crash.

use ferroc_std::recording::{ChannelSummary, Checksums, Message, Recording, Run};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct LogArgs {
    #[command(subcommand)]
    command: LogCommand,
}

#[derive(clap::Subcommand)]
enum LogCommand {
    /// The channels of a recording: topic, encoding, type, unit, part, messages, time span
    Info {
        /// The MCAP file
        file: PathBuf,
        /// Read a file whose checksums do not match anyway, and say where
        #[arg(long)]
        ignore_checksums: bool,
        #[command(flatten)]
        time: TimeArgs,
    },
    /// The messages of one topic, one line each: the time in seconds from the run's
    /// start (model time in lockstep), then the value (the JSON form, or a ROS 2
    /// channel's messages as JSON; --exact: the exact channel's bytes in hex)
    Cat {
        /// The MCAP file
        file: PathBuf,
        /// The topic (a recorded port's path, or a ROS 2 topic: `/cmd_vel`)
        #[arg(long, value_name = "TOPIC")]
        channel: String,
        /// Print the exact (postcard) payloads instead of the JSON form
        #[arg(long)]
        exact: bool,
        /// Print the messages of chunks whose checksums do not match too
        #[arg(long)]
        ignore_checksums: bool,
        #[command(flatten)]
        time: TimeArgs,
    },
}

#[derive(clap::Args, Clone, Copy)]
struct TimeArgs {
    /// Print log times as recorded (seconds since 1970; in lockstep model time counts
    /// from 2000-01-01) instead of from the run's start
    #[arg(long)]
    absolute_time: bool,
}

pub fn run(args: LogArgs) -> ExitCode {
    let mut out = std::io::stdout().lock();
    let result = match &args.command {
        LogCommand::Info {
            file,
            ignore_checksums,
            time,
        } => Recording::read_with(file, checksums(*ignore_checksums), &mut |_, _| false)
            .map(|rec| info(&mut out, file, &rec, *time)),
        LogCommand::Cat {
            file,
            channel,
            exact,
            ignore_checksums,
            time,
        } => cat(
            &mut out,
            file,
            channel,
            *exact,
            checksums(*ignore_checksums),
            *time,
        ),
    };
    let written = match result {
        Ok(written) => written,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    match written.and_then(|()| out.flush()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: cannot write the output: {e}");
            ExitCode::from(2)
        }
    }
}

fn checksums(ignore: bool) -> Checksums {
    if ignore {
        Checksums::Ignore
    } else {
        Checksums::Verify
    }
}

/// Text of the recording on one line of the output: control characters (a topic
/// named `\x1b[2J`, a bell) and line breaks escaped, never sent to the terminal.
fn shown(text: &str) -> String {
    ferroc_terminal::escape_controls(text).replace('\n', "\\u{a}")
}

fn seconds(nanos: u64) -> String {
    format!("{}.{:09}", nanos / 1_000_000_000, nanos % 1_000_000_000)
}

/// How log times are shown: from the run's start (the recording's `ferroc.run`
/// metadata says where it lies), or as recorded.
#[derive(Clone, Copy)]
struct Times {
    start: Option<u64>,
}

impl Times {
    fn of(run: &Run, args: TimeArgs) -> Self {
        Times {
            start: run.start.filter(|_| !args.absolute_time),
        }
    }

    /// `log_time` in seconds as shown (a time before the start with a `-`).
    fn show(self, log_time: u64) -> String {
        match self.start {
            Some(start) if log_time < start => format!("-{}", seconds(start - log_time)),
            Some(start) => seconds(log_time - start),
            None => seconds(log_time),
        }
    }

    /// What the times of `rec` are, for `log info`.
    fn describe(self, run: &Run) -> String {
        let clock = run.clock.as_deref().unwrap_or("");
        match (self.start, clock) {
            (Some(_), "lockstep") => {
                "time: model time (lockstep) from the run's start; --absolute-time for log times"
                    .into()
            }
            (Some(start), _) => format!(
                "time: seconds from the start of the recording ({}); --absolute-time for log times",
                ferroc_runtime::module::Timestamp {
                    nanos: i64::try_from(start).unwrap_or(i64::MAX)
                }
            ),
            (None, "lockstep") => {
                "time: log time, seconds since 1970 (model time counts from 2000-01-01)".into()
            }
            (None, _) => "time: log time, seconds since 1970".into(),
        }
    }
}

fn info(
    out: &mut impl Write,
    file: &std::path::Path,
    rec: &Recording,
    time: TimeArgs,
) -> std::io::Result<()> {
    let times = Times::of(&rec.run, time);
    let state = match (&rec.damaged, rec.finished) {
        _ if !rec.corrupt.is_empty() => format!(
            "corrupted: {}; read anyway (--ignore-checksums)",
            rec.corrupt.join("; ")
        ),
        (Some(why), _) => format!("cut off ({why}); the messages before the cut are counted"),
        (None, true) => "finished".to_owned(),
        (None, false) => "not finished (no summary): still being written, or stopped hard".into(),
    };
    writeln!(
        out,
        "{}: {}",
        shown(&file.display().to_string()),
        shown(&state)
    )?;
    if let Some(seed) = rec.run.seed {
        writeln!(out, "run seed {seed} (repeat the run with --seed {seed})")?;
    }
    writeln!(
        out,
        "{} message(s) in {} channel(s)",
        rec.message_count,
        rec.channels.len()
    )?;
    let first = rec.channels.values().filter_map(|c| c.first).min();
    let last = rec.channels.values().filter_map(|c| c.last).max();
    writeln!(out, "{}", times.describe(&rec.run))?;
    if let (Some(a), Some(b)) = (first, last) {
        writeln!(
            out,
            "messages from {} to {} s ({} s)",
            times.show(a),
            times.show(b),
            seconds(b - a)
        )?;
    }
    for c in rec.channels.values() {
        writeln!(out, "{}", channel_line(c))?;
    }
    Ok(())
}

fn channel_line(c: &ChannelSummary) -> String {
    let labelled = |key: &str, label: &str| match c.metadata.get(key) {
        Some(v) if !v.is_empty() => format!("  {label} {}", shown(v)),
        _ => String::new(),
    };
    format!(
        "  {:>3}  {}  [{}]  type {}{}{}  {} message(s)",
        c.id,
        shown(&c.topic),
        shown(&c.message_encoding),
        shown(c.model_type()),
        labelled(ferroc_std::recording::META_UNIT, "unit"),
        labelled(ferroc_std::recording::META_PART, "part"),
        c.count
    )
}

/// Prints the messages of `topic` as the file is read (nothing is kept); an error if
/// the file cannot be read, has no such channel, or (unless ignored) a checksum does
/// not match: the messages of a chunk are printed only after its CRC matched.
fn cat(
    out: &mut impl Write,
    file: &std::path::Path,
    topic: &str,
    exact: bool,
    checksums: Checksums,
    time: TimeArgs,
) -> Result<std::io::Result<()>, String> {
    let pick = |c: &ChannelSummary| {
        c.topic == topic
            && (if exact {
                c.is_exact()
            } else {
                c.message_encoding == "json" || c.is_ros2()
            })
    };
    let mut picked = None;
    let mut written = Ok(());
    let mut decoder = None;
    // `ferroc.run` comes before the first chunk (where the writer puts it): the start
    // is known when the first message is printed.
    let rec = Recording::read_with_run(file, checksums, &mut |run, c, m| {
        if written.is_ok() && pick(c) && picked.is_none_or(|id| id == c.id) {
            picked = Some(c.id);
            let decoded = c.is_ros2().then(|| ros2_json(&mut decoder, c, m));
            written = message_line(out, m, exact, decoded.as_deref(), Times::of(run, time));
        }
        false
    })?;
    if picked.is_none() && !rec.channels.values().any(pick) {
        let topics: std::collections::BTreeSet<String> =
            rec.channels.values().map(|c| shown(&c.topic)).collect();
        return Err(format!(
            "no {} channel `{}` in the recording\n  help: its topics are: {}",
            if exact { "exact" } else { "JSON or ROS 2" },
            shown(topic),
            topics.into_iter().collect::<Vec<_>>().join(", ")
        ));
    }
    Ok(written)
}

/// A ROS 2 channel's message as JSON, decoded with the definitions of the channel's
/// schema (`decoder` made at the first message); what does not decode says why.
fn ros2_json(
    decoder: &mut Option<Result<ferroc_ros2::mcap_schema::Decoder, String>>,
    c: &ChannelSummary,
    m: &Message,
) -> String {
    let decoder = decoder.get_or_insert_with(|| {
        let text = String::from_utf8_lossy(&c.schema_data);
        ferroc_ros2::mcap_schema::Decoder::new(&c.schema_name, &text)
    });
    match decoder.as_ref().map(|d| d.json(&m.data)) {
        Ok(Ok(json)) => json.to_string(),
        Ok(Err(why)) => format!("(this message does not decode: {why})"),
        Err(why) => format!("(the channel's schema does not read: {why})"),
    }
}

fn message_line(
    out: &mut impl Write,
    m: &Message,
    exact: bool,
    decoded: Option<&str>,
    times: Times,
) -> std::io::Result<()> {
    write!(out, "{} ", times.show(m.log_time))?;
    if let Some(text) = decoded {
        write!(out, "{}", text.escape_debug())?;
    } else if exact {
        for b in &m.data {
            write!(out, "{b:02x}")?;
        }
    } else {
        // Recorded text is printed escaped: control bytes never reach the terminal.
        let text = String::from_utf8_lossy(&m.data);
        write!(out, "{}", text.escape_debug())?;
    }
    writeln!(out)
}
