//! The stdio transport: LSP frames (`Content-Length` headers, a JSON body) read on one
//! thread and written on another, as `lsp-server`'s own stdio transport does — but a
//! frame that is not a JSON-RPC message does not end the connection: the reader
//! reports it (`window/logMessage`) and goes on with the next frame. A header larger
//! than a line limit or a body larger than [`MAX_BODY`] is skipped unread.

use crossbeam_channel::Sender;
use lsp_server::{Connection, Message, Notification};
use std::io::{BufRead, Read, Write};
use std::thread::{self, JoinHandle};

/// The largest message read: a 50 MB paste arrives as one `didChange` of that size,
/// with room for JSON's escapes; anything larger is skipped.
pub const MAX_BODY: usize = 256 << 20;
/// The longest header line kept (a real one is ~30 bytes).
const MAX_HEADER_LINE: usize = 4096;

/// The reader and writer threads; `join` waits for both (the writer ends when the
/// server drops its sender, the reader at the end of input).
pub struct IoThreads {
    reader: JoinHandle<()>,
    writer: JoinHandle<()>,
}

impl IoThreads {
    pub fn join(self) {
        let _ = self.writer.join();
        // The reader may be blocked in a read of a stdin that never closes; the
        // process ends after `exit` regardless.
        drop(self.reader);
    }
}

/// A connection over standard input and output.
pub fn stdio() -> (Connection, IoThreads) {
    let (to_server, receiver) = crossbeam_channel::bounded::<Message>(0);
    let (sender, from_server) = crossbeam_channel::unbounded::<Message>();
    let writer = thread::spawn(move || {
        let stdout = std::io::stdout();
        let mut out = stdout.lock();
        for msg in from_server {
            if msg.write(&mut out).is_err() {
                break; // the client is gone
            }
        }
        let _ = out.flush();
    });
    let reader = thread::spawn(move || {
        let stdin = std::io::stdin();
        read_frames(stdin.lock(), &to_server);
    });
    (
        Connection { sender, receiver },
        IoThreads { reader, writer },
    )
}

/// A connection over any reader and writer (tests drive the server through pipes).
pub fn over<R, W>(input: R, output: W) -> (Connection, IoThreads)
where
    R: Read + Send + 'static,
    W: Write + Send + 'static,
{
    let (to_server, receiver) = crossbeam_channel::bounded::<Message>(0);
    let (sender, from_server) = crossbeam_channel::unbounded::<Message>();
    let writer = thread::spawn(move || {
        let mut out = output;
        for msg in from_server {
            if msg.write(&mut out).is_err() {
                break;
            }
        }
        let _ = out.flush();
    });
    let reader = thread::spawn(move || {
        read_frames(std::io::BufReader::new(input), &to_server);
    });
    (
        Connection { sender, receiver },
        IoThreads { reader, writer },
    )
}

/// What the reader hands the server for a frame it could not read (the server tells
/// the client); not a method of the protocol.
pub const UNREADABLE: &str = "$/ferroc/unreadable";

/// Reads frames until the input ends or the server is gone; what cannot be read goes
/// to the server as an [`UNREADABLE`] notification, and reading goes on. (The reader
/// holds no sender to the client: the writer ends when the server drops its own.)
fn read_frames(mut input: impl BufRead, server: &Sender<Message>) {
    loop {
        let msg = match read_frame(&mut input) {
            Frame::End => return,
            Frame::Message(m) => m,
            Frame::Bad(why) => Message::Notification(Notification::new(
                UNREADABLE.into(),
                format!("ferroc lsp could not read a message: {why}"),
            )),
        };
        if server.send(msg).is_err() {
            return;
        }
    }
}

enum Frame {
    Message(Message),
    Bad(String),
    End,
}

fn read_frame(input: &mut impl BufRead) -> Frame {
    let mut length = None;
    let mut saw_header = false;
    loop {
        let line = match read_line(input) {
            Ok(Some(line)) => line,
            Ok(None) => return Frame::End,
            Err(why) => return Frame::Bad(why),
        };
        let line = line.trim_end_matches(['\r', '\n']);
        if line.is_empty() {
            if saw_header {
                break;
            }
            continue; // stray blank lines between frames
        }
        saw_header = true;
        if let Some((name, value)) = line.split_once(':') {
            if name.trim().eq_ignore_ascii_case("content-length") {
                length = value.trim().parse::<usize>().ok();
            }
        }
    }
    let Some(length) = length else {
        return Frame::Bad("a header without a valid Content-Length".into());
    };
    if length > MAX_BODY {
        let skipped = std::io::copy(&mut input.take(length as u64), &mut std::io::sink());
        return match skipped {
            Ok(_) => Frame::Bad(format!(
                "a message of {} MiB, over the limit of {} MiB (skipped)",
                length >> 20,
                MAX_BODY >> 20
            )),
            Err(_) => Frame::End,
        };
    }
    let mut body = vec![0u8; length];
    if input.read_exact(&mut body).is_err() {
        return Frame::End;
    }
    match serde_json::from_slice::<Message>(&body) {
        Ok(m) => Frame::Message(m),
        Err(e) => Frame::Bad(format!("not a JSON-RPC message ({e})")),
    }
}

/// One header line, at most [`MAX_HEADER_LINE`] bytes kept; `None` at the end of input.
fn read_line(input: &mut impl BufRead) -> Result<Option<String>, String> {
    let mut line = Vec::new();
    let n = input
        .by_ref()
        .take(MAX_HEADER_LINE as u64)
        .read_until(b'\n', &mut line)
        .map_err(|e| e.to_string())?;
    if n == 0 {
        return Ok(None);
    }
    if !line.ends_with(b"\n") && n == MAX_HEADER_LINE {
        // Skip the rest of an overlong line.
        let mut rest = Vec::new();
        let _ = input.read_until(b'\n', &mut rest);
        return Err("a header line longer than 4 KiB".into());
    }
    Ok(Some(String::from_utf8_lossy(&line).into_owned()))
}
