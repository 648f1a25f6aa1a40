//! Writing a command's report to standard output without losing it silently.
//!
//! `println!` panics when standard output is a closed pipe or a full disk (exit 101),
//! and ignoring the error exits 0 with the report lost. Here: a reader that closed the
//! pipe (`ferroc explain --list | head -1`) ends the output quietly, as `head` users
//! expect, and the command's exit code stands; any other failure (`> /dev/full`) is an
//! error with exit code 2.

use std::io::Write;
use std::process::ExitCode;

/// Writes `text` to standard output and flushes it. `Err` carries exit code 2 after
/// saying why on standard error.
pub fn stdout(text: &[u8]) -> Result<(), ExitCode> {
    write(text).map(|_| ())
}

/// Whether what was written has a reader.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Written {
    /// Written and flushed.
    Read,
    /// The reader closed the pipe: nothing more need be written (a command that goes
    /// on writing, `ferroc inspect --watch`, stops).
    ReaderGone,
}

/// [`stdout`], saying whether the reader is still there.
pub fn write(text: &[u8]) -> Result<Written, ExitCode> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text).and_then(|()| out.flush()) {
        Ok(()) => Ok(Written::Read),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(Written::ReaderGone),
        Err(e) => {
            eprintln!("error: cannot write to standard output: {e}");
            Err(ExitCode::from(2))
        }
    }
}

/// [`stdout`], then `code` if it succeeded.
pub fn stdout_then(text: &[u8], code: ExitCode) -> ExitCode {
    match stdout(text) {
        Ok(()) => code,
        Err(failed) => failed,
    }
}
