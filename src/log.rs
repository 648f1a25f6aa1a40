//! `ferroc log info FILE` and `ferroc log cat FILE --channel TOPIC`: what an MCAP
//! recording holds (ferroc's, or any other), also one cut off by a crash.

use ferroc_std::recording::{ChannelSummary, Recording};
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
    /// The channels of a recording: topic, encoding, type, part, messages, time span
    Info {
        /// The MCAP file
        file: PathBuf,
    },
    /// The messages of one topic, one line each: log time in seconds, then the value
    /// (the JSON form; --exact: the exact channel's bytes in hex)
    Cat {
        /// The MCAP file
        file: PathBuf,
        /// The topic (a recorded port's path)
        #[arg(long, value_name = "TOPIC")]
        channel: String,
        /// Print the exact (postcard) payloads instead of the JSON form
        #[arg(long)]
        exact: bool,
    },
}

pub fn run(args: LogArgs) -> ExitCode {
    let file = match &args.command {
        LogCommand::Info { file } | LogCommand::Cat { file, .. } => file,
    };
    let rec = match Recording::read(file) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let mut out = std::io::stdout().lock();
    let written = match &args.command {
        LogCommand::Info { file } => info(&mut out, file, &rec),
        LogCommand::Cat { channel, exact, .. } => match cat(&mut out, &rec, channel, *exact) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
        },
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

fn seconds(nanos: u64) -> String {
    format!("{}.{:09}", nanos / 1_000_000_000, nanos % 1_000_000_000)
}

fn info(out: &mut impl Write, file: &std::path::Path, rec: &Recording) -> std::io::Result<()> {
    let state = match (&rec.damaged, rec.finished) {
        (Some(why), _) => format!("cut off ({why}); the messages before the cut are counted"),
        (None, true) => "finished".to_owned(),
        (None, false) => "not finished (no summary): still being written, or stopped hard".into(),
    };
    writeln!(out, "{}: {state}", file.display())?;
    if let Some(seed) = rec.seed {
        writeln!(out, "run seed {seed} (repeat the run with --seed {seed})")?;
    }
    writeln!(
        out,
        "{} message(s) in {} channel(s)",
        rec.messages.len(),
        rec.channels.len()
    )?;
    let first = rec.channels.values().filter_map(|c| c.first).min();
    let last = rec.channels.values().filter_map(|c| c.last).max();
    if let (Some(a), Some(b)) = (first, last) {
        writeln!(
            out,
            "log time {} .. {} s ({} s)",
            seconds(a),
            seconds(b),
            seconds(b - a)
        )?;
    }
    for c in rec.channels.values() {
        writeln!(out, "{}", channel_line(c))?;
    }
    Ok(())
}

fn channel_line(c: &ChannelSummary) -> String {
    let part = c.metadata.get("ferroc.part").map_or("", String::as_str);
    format!(
        "  {:>3}  {}  [{}]  type {}{}  {} message(s)",
        c.id,
        c.topic,
        c.message_encoding,
        c.model_type(),
        if part.is_empty() {
            String::new()
        } else {
            format!("  part {part}")
        },
        c.count
    )
}

fn cat(
    out: &mut impl Write,
    rec: &Recording,
    topic: &str,
    exact: bool,
) -> Result<std::io::Result<()>, String> {
    let pick = |c: &&ChannelSummary| {
        c.topic == topic
            && (if exact {
                c.is_exact()
            } else {
                c.message_encoding == "json"
            })
    };
    let Some(channel) = rec.channels.values().find(pick) else {
        let topics: std::collections::BTreeSet<&str> =
            rec.channels.values().map(|c| c.topic.as_str()).collect();
        return Err(format!(
            "no {} channel `{topic}` in the recording\n  help: its topics are: {}",
            if exact { "exact" } else { "JSON" },
            topics.into_iter().collect::<Vec<_>>().join(", ")
        ));
    };
    let write = |out: &mut dyn Write| -> std::io::Result<()> {
        for m in rec.messages.iter().filter(|m| m.channel == channel.id) {
            write!(out, "{} ", seconds(m.log_time))?;
            if exact {
                for b in &m.data {
                    write!(out, "{b:02x}")?;
                }
            } else {
                // Recorded text is printed escaped: control bytes never reach the terminal.
                let text = String::from_utf8_lossy(&m.data);
                write!(out, "{}", text.escape_debug())?;
            }
            writeln!(out)?;
        }
        Ok(())
    };
    Ok(write(out))
}
