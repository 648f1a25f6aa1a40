//! Errors of the libraries ferroc runs on (Zenoh, the operating system) said in plain
//! words before a user sees them. Zenoh's errors end with the place in its source they
//! were made (` at /root/.cargo/registry/src/…/orchestrator.rs:388.`) and wrap I/O
//! errors as Rust `Debug` text (`Os { code: 98, kind: AddrInUse, message: "Address
//! already in use" }`); neither helps a user, and a path into a registry reads as a
//! crash. [`engine_error`] keeps what does help: the message, an address, the
//! operating system's reason.

use std::fmt::Display;

/// `error` in plain words: without source locations (`at FILE.rs:LINE.`), with I/O
/// errors as their message (`address already in use`) and with Zenoh's common messages
/// said as a user would (`Unable to connect to any of [tcp/127.0.0.1:1]. Timeout!` →
/// `nothing answered at tcp/127.0.0.1:1`). Callers say what failed and what to do
/// around it: `cannot reach ADDR (…); is the program running?`.
pub fn engine_error(error: &dyn Display) -> String {
    let text = error.to_string();
    let text = without_source_locations(&text);
    let text = without_os_error_numbers(&text);
    let text = text.replace(" - Caused by ", ": ");
    let text = io_messages(&text);
    let text = zenoh_phrases(&text);
    let text = text
        .trim()
        .trim_end_matches(['.', '!', ':', ' '])
        .to_owned();
    if text.is_empty() {
        "no reason given".to_owned()
    } else {
        text
    }
}

/// Removes every ` at SOMETHING.rs:LINE` (keeping a bracket that closes after it).
fn without_source_locations(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(" at ") {
        let after = &rest[at + 4..];
        let end = after.find(char::is_whitespace).unwrap_or(after.len());
        let word = &after[..end];
        let bare = word.trim_end_matches(['.', ',', ';', ']', ')']);
        if is_source_location(bare.trim_end_matches(['.', ',', ';'])) {
            out.push_str(&rest[..at]);
            out.extend(
                word[bare.len()..]
                    .chars()
                    .filter(|c| matches!(c, ']' | ')')),
            );
            rest = &after[end..];
        } else {
            out.push_str(&rest[..at + 4]);
            rest = after;
        }
    }
    out.push_str(rest);
    out
}

/// Removes ` (os error N)`: the reason's words say it.
fn without_os_error_numbers(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(" (os error ") {
        let after = &rest[at + 11..];
        match after.find(')') {
            Some(end) if after[..end].bytes().all(|b| b.is_ascii_digit()) => {
                out.push_str(&rest[..at]);
                rest = &after[end + 1..];
            }
            _ => {
                out.push_str(&rest[..at + 11]);
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// `…/file.rs:123` (or `file.rs:123:4`).
fn is_source_location(word: &str) -> bool {
    let mut parts = word.rsplitn(3, ':');
    let (Some(last), Some(before)) = (parts.next(), parts.next()) else {
        return false;
    };
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    match parts.next() {
        Some(file) if digits(before) => digits(last) && file.ends_with(".rs"),
        _ => digits(last) && before.ends_with(".rs"),
    }
}

/// `Os { code: 98, kind: AddrInUse, message: "Address already in use" }` and
/// `Custom { kind: …, error: "…" }` (`std::io::Error`'s `Debug`) as their message,
/// starting in lower case.
fn io_messages(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    loop {
        let start = [rest.find("Os { "), rest.find("Custom { ")]
            .into_iter()
            .flatten()
            .min();
        let Some(start) = start else { break };
        let Some(len) = rest[start..].find(" }") else {
            break;
        };
        let dump = &rest[start..start + len];
        let message = ["message: \"", "error: \""]
            .iter()
            .find_map(|k| dump.find(k).map(|i| &dump[i + k.len()..]))
            .map(|m| m.trim_end_matches('"'));
        out.push_str(&rest[..start]);
        match message {
            Some(m) => out.push_str(&lower_first(m)),
            None => out.push_str(dump),
        }
        rest = &rest[start + len + 2..];
    }
    out.push_str(rest);
    out
}

fn lower_first(text: &str) -> String {
    let mut c = text.chars();
    match c.next() {
        Some(first) => first.to_lowercase().chain(c).collect(),
        None => String::new(),
    }
}

/// Zenoh's messages for what goes wrong most often, reworded.
fn zenoh_phrases(text: &str) -> String {
    const UNABLE: &str = "Unable to connect to any of ";
    const LISTENER: &str = "Can not create a new TCP listener bound to ";
    if let Some(at) = text.find(UNABLE) {
        let list = &text[at + UNABLE.len()..];
        let peers = list.strip_prefix('[').map_or(list, |l| &l[..closing(l)]);
        let peers = peers
            .replace('"', "")
            .replace("Single(", "")
            .replace(')', "");
        return format!("{}nothing answered at {peers}", &text[..at]);
    }
    if let Some(at) = text.find(LISTENER) {
        let rest = &text[at + LISTENER.len()..];
        if let Some((endpoint, reason)) = rest.split_once(": ") {
            return format!(
                "{}cannot listen on {endpoint}: {}",
                &text[..at],
                lower_first(bare_reason(reason))
            );
        }
    }
    text.to_owned()
}

/// Where the bracket opened before `text` closes (IPv6 addresses hold brackets too).
fn closing(text: &str) -> usize {
    let mut depth = 0usize;
    for (i, c) in text.char_indices() {
        match c {
            '[' => depth += 1,
            ']' if depth == 0 => return i,
            ']' => depth -= 1,
            _ => {}
        }
    }
    text.len()
}

/// `[127.0.0.1:5: Address already in use]` → `Address already in use`: the reason
/// without the brackets and the address said already.
fn bare_reason(reason: &str) -> &str {
    let reason = reason.trim().trim_start_matches('[');
    let reason = reason.strip_suffix(']').unwrap_or(reason).trim();
    match reason.split_once(": ") {
        Some((address, rest)) if !address.contains(' ') => rest,
        _ => reason,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zenoh_source_paths_and_debug_dumps_are_gone_and_the_reason_stays() {
        let timeout = "Unable to connect to any of [Single(tcp/127.0.0.1:47901)]. Timeout! at \
            /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/zenoh-1.10.2/src/net/runtime/orchestrator.rs:388.";
        assert_eq!(
            engine_error(&timeout),
            "nothing answered at tcp/127.0.0.1:47901"
        );
        let in_use = "Can not create a new TCP listener bound to tcp/127.0.0.1:52527: \
            [127.0.0.1:52527: Address already in use (os error 98) at /root/.cargo/registry/src/\
            index.crates.io-1949cf8c6b5b557f/zenoh-link-commons-1.10.2/src/tcp.rs:61.] at \
            /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/zenoh-link-tcp-1.10.2/src/unicast.rs:338.";
        assert_eq!(
            engine_error(&in_use),
            "cannot listen on tcp/127.0.0.1:52527: address already in use"
        );
        let dump = "bind: Os { code: 98, kind: AddrInUse, message: \"Address already in use\" }";
        assert_eq!(engine_error(&dump), "bind: address already in use");
        let peers = "Unable to connect to any of [Single(tcp/127.0.0.1:1), Single(tcp/[::1]:2)]! ";
        assert_eq!(
            engine_error(&peers),
            "nothing answered at tcp/127.0.0.1:1, tcp/[::1]:2"
        );
        let caused = "outer at a/b.rs:1:2. - Caused by inner at c/d.rs:3.";
        assert_eq!(engine_error(&caused), "outer: inner");
    }

    #[test]
    fn plain_errors_stay_as_they_are() {
        for text in [
            "connection refused",
            "meet me at noon",
            "the file at models/x.xml:3 is bad",
        ] {
            assert_eq!(engine_error(&text), text);
        }
        assert_eq!(engine_error(&""), "no reason given");
    }
}
