//! Reading one file's bytes safely: size limits judged on the bytes read, only regular
//! files (a FIFO or a device would block or never end), standard input read once, and
//! a file's root element without reading the rest.

use super::Limits;
use std::path::Path;

/// Reads a file as text, refusing what could exhaust memory or block: folders, files
/// over the size limit (judged on the bytes read, not only on the size the file system
/// reports: `/proc` files and growing files report less) and anything that is not a
/// regular file (a FIFO would block in `open` until a writer comes, a device such as
/// `/dev/zero` never ends). `Err` says why, in words for a diagnostic.
pub fn read_text(path: &Path, limits: &Limits) -> Result<String, String> {
    let meta = std::fs::metadata(path).map_err(|e| io_reason(&e))?;
    if meta.is_dir() {
        return Err("it is a directory".into());
    }
    if !meta.is_file() {
        return Err(not_regular(&meta));
    }
    if meta.len() > limits.max_file_bytes {
        return Err(over_limit(Some(meta.len()), limits));
    }
    let file = std::fs::File::open(path).map_err(|e| io_reason(&e))?;
    // The path may have been replaced since the check above: judge the opened file.
    let meta = file.metadata().map_err(|e| io_reason(&e))?;
    if !meta.is_file() {
        return Err(not_regular(&meta));
    }
    read_bounded_sized(file, limits, meta.len())
}

/// Reads `input` to its end, or fails once it holds more than the size limit.
pub fn read_bounded(input: impl std::io::Read, limits: &Limits) -> Result<String, String> {
    read_bounded_sized(input, limits, 0)
}

/// [`read_bounded`] into a buffer sized for the `expected` bytes a file's metadata
/// reports (plus one, to see the end without growing): a buffer grown by doubling
/// holds up to twice the file, and its copies stay resident.
fn read_bounded_sized(
    input: impl std::io::Read,
    limits: &Limits,
    expected: u64,
) -> Result<String, String> {
    use std::io::Read;
    let room = expected.min(limits.max_file_bytes).saturating_add(1);
    let mut bytes = Vec::with_capacity(usize::try_from(room).unwrap_or(0));
    input
        .take(limits.max_file_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| io_reason(&e))?;
    if bytes.len() as u64 > limits.max_file_bytes {
        // Reading stopped one byte past the limit: how much more there was is unknown.
        return Err(over_limit(None, limits));
    }
    String::from_utf8(bytes).map_err(|e| {
        format!(
            "it is not UTF-8 text (invalid byte at offset {})",
            e.utf8_error().valid_up_to()
        )
    })
}

/// Reads standard input to its end, within the size limit.
pub fn read_stdin(limits: &Limits) -> Result<String, String> {
    read_bounded(std::io::stdin().lock(), limits)
}

/// Whether `path` names standard input (`-` or `/dev/stdin`): a model may come from a
/// pipe, read once (a pipe cannot be read twice).
pub fn is_stdin(path: &Path) -> bool {
    path == Path::new("-") || path == Path::new("/dev/stdin")
}

/// Why a file of `len` bytes (`None`: more than the limit, how much more unknown) is
/// refused, in units that tell the sizes apart (a 100 KiB file over a 64 KiB limit is
/// not "0 MiB, over the limit of 0 MiB").
pub(crate) fn over_limit(len: Option<u64>, limits: &Limits) -> String {
    let limit = limits.max_file_bytes;
    match len {
        Some(len) => {
            let (it, max) = (size(len), size(limit));
            if it == max {
                format!("it is {len} bytes, over the limit of {limit} bytes")
            } else {
                format!("it is {it}, over the limit of {max}")
            }
        }
        None => format!("it is over the limit of {}", size(limit)),
    }
}

/// `n` bytes in the largest unit it reaches (bytes, KiB, MiB, GiB), with one decimal
/// unless that is 0.
fn size(n: u64) -> String {
    let units = [(1u64 << 30, "GiB"), (1 << 20, "MiB"), (1 << 10, "KiB")];
    for (unit, name) in units {
        if n >= unit {
            #[allow(clippy::cast_precision_loss)] // one decimal is shown
            let value = format!("{:.1}", n as f64 / unit as f64);
            let value = value.strip_suffix(".0").unwrap_or(&value);
            return format!("{value} {name}");
        }
    }
    format!("{n} bytes")
}

fn not_regular(meta: &std::fs::Metadata) -> String {
    #[cfg(unix)]
    let kind = {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            "a FIFO (named pipe)"
        } else if t.is_char_device() || t.is_block_device() {
            "a device"
        } else if t.is_socket() {
            "a socket"
        } else {
            "not a regular file"
        }
    };
    #[cfg(not(unix))]
    let kind = {
        let _ = meta;
        "not a regular file"
    };
    format!("it is {kind}; ferroc reads only regular files (a model may also come from standard input: `-`)")
}

/// The name of a file's first element, reading no further than that (at most 1 MiB);
/// `None` when the file cannot be read, is not a regular file (nothing that could
/// block or never end is opened) or holds no element there.
pub fn root_element(path: &Path) -> Option<String> {
    const LOOK_AT_MOST: u64 = 1 << 20;
    if !std::fs::metadata(path).ok()?.is_file() {
        return None;
    }
    let file = std::fs::File::open(path).ok()?;
    if !file.metadata().ok()?.is_file() {
        return None;
    }
    let input = std::io::BufReader::new(std::io::Read::take(file, LOOK_AT_MOST));
    root_element_of(input)
}

/// The name of the first element of XML text (see [`root_element`]).
pub fn root_element_of(input: impl std::io::BufRead) -> Option<String> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_reader(input);
    let mut buf = Vec::new();
    loop {
        match reader.read_event_into(&mut buf).ok()? {
            Event::Start(tag) | Event::Empty(tag) => {
                return Some(String::from_utf8_lossy(tag.name().into_inner()).into_owned())
            }
            Event::Eof => return None,
            _ => buf.clear(),
        }
    }
}

pub(super) fn io_reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".into(),
        std::io::ErrorKind::PermissionDenied => "permission denied".into(),
        _ => e.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limit(bytes: u64) -> Limits {
        Limits {
            max_file_bytes: bytes,
            ..Limits::default()
        }
    }

    /// Issue 27, item 17: a 100 KB edit file was "0 MiB, over the limit of 0 MiB".
    #[test]
    fn sizes_over_the_limit_are_told_apart() {
        assert_eq!(
            over_limit(Some(100_000), &limit(64 * 1024)),
            "it is 97.7 KiB, over the limit of 64 KiB"
        );
        assert_eq!(
            over_limit(Some(3 << 30), &limit(16 << 20)),
            "it is 3 GiB, over the limit of 16 MiB"
        );
        // Sizes that would read the same are given in bytes.
        assert_eq!(
            over_limit(Some(64 * 1024 + 1), &limit(64 * 1024)),
            "it is 65537 bytes, over the limit of 65536 bytes"
        );
        assert_eq!(size(1000), "1000 bytes");
        let e = read_bounded(&[b'x'; 2000][..], &limit(1024)).unwrap_err();
        assert_eq!(e, "it is over the limit of 1 KiB");
    }
}
