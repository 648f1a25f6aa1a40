//! Recordings in MCAP (<https://mcap.dev>): what `ferroc_std.Logger` and the recorder
//! of `ferroc run --record` write, what `ferroc_std.Player` and `ferroc log` read.
//!
//! Every recorded port has two channels on the same topic (the port's path):
//!
//! - the **exact** one, message encoding `postcard` (the encoding of links between
//!   parts): floats, NaN and infinities replay bit for bit; its schema (encoding
//!   `ferroc-type`) names the model type and holds the Rust type's name;
//! - the **display** one, message encoding `json` with a JSON Schema, which Foxglove
//!   and other MCAP tools show. JSON has no NaN or infinity: serde_json writes them as
//!   `null`, so the schema allows `null` wherever a float may be; the exact channel
//!   keeps the real value.
//!
//! A recorded output the model publishes as a ROS 2 topic has a third channel, on the
//! topic (`/cmd_vel`), with message encoding `cdr` and a `ros2msg` schema, which ROS 2
//! tools and Foxglove read as ROS data ([`ros2`]).
//!
//! Channel metadata names the part, the port path, the model type, the unit of the
//! values (`ferroc.unit`, as the model writes it: `m/s`; empty when the port has none)
//! and which of the two forms the channel holds. A metadata record `ferroc.run` holds
//! the clock the log times come from (`clock`: `lockstep`, model time, or `wall`), the
//! log time of the run's start (`start`, nanoseconds since 1970: in lockstep
//! 2000-01-01, where model time 0 lies; on the wall clock when the recording was
//! created) and the run seed (`seed`), with which the run can be repeated (`--seed`).
//! Log time and publish time are `Timestamp::now()`: model time in lockstep, so a
//! lockstep recording is the same file every run; `ferroc log` shows times from
//! `start`.
//!
//! The file stays readable while it is written: messages go into chunks that are
//! written out and flushed at least once per `flush` interval of (model) time, so a
//! crash or a kill loses at most the chunk under way; on a clean stop the summary and
//! footer are written too.
//!
//! Relative log paths are resolved against the log folder ([`set_log_dir`]; `ferroc
//! run --log-dir`, else the environment variable `FERROC_LOG_DIR`, else the working
//! directory). A model (or an edit of a running one) writes only inside the log folder
//! ([`check_in_log_dir`]): an absolute path must lead there. Only the command line
//! (`--record FILE`) names a file anywhere.
//!
//! Nothing but a recording of ours is replaced: a log file that exists, is not empty
//! and is not an MCAP file whose header names the library `ferroc` is refused
//! ([`check_overwrite`]) unless `--force` said otherwise ([`set_overwrite`]).

mod context;
mod file;
mod read;
pub mod ros2;
mod schema;

pub use context::{
    check_in_log_dir, check_overwrite, is_ferroc_recording, log_dir, part_of, resolve_log_path,
    run_seed, set_log_dir, set_overwrite, set_parts, set_run_seed, set_units, unit_of, LIBRARY,
};
pub use file::{ChannelId, ChannelInfo, LogFile, SharedLog};
pub use read::{
    ChannelSummary, Checksums, Keep, KeepRun, Message, Recording, Run, MAX_KEPT_BYTES,
    MAX_RECORD_BYTES,
};
pub use schema::json_schema;

/// Message encoding of the exact channels.
pub const EXACT_ENCODING: &str = "postcard";
/// Schema encoding of the exact channels: the schema names a ferroc model type.
pub const TYPE_SCHEMA_ENCODING: &str = "ferroc-type";
/// Metadata keys of every channel.
pub const META_PART: &str = "ferroc.part";
pub const META_PORT: &str = "ferroc.port";
pub const META_TYPE: &str = "ferroc.type";
pub const META_FORM: &str = "ferroc.form";
pub const META_UNIT: &str = "ferroc.unit";
/// The name of the file's metadata record about the run (`clock`, `start`, and `seed`:
/// the run seed, when the program told it with [`set_run_seed`]).
pub const META_RUN: &str = "ferroc.run";
