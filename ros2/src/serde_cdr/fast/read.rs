//! The reading both fast readers share (`de.rs` along the tape, `trusted_read.rs`
//! without it): bytes at an offset, checked against the sample's end, and strings.

use super::Miss;

/// `N` bytes of `data` from `start`, the reader's offset `at` moved past them; one
/// bounds check.
#[inline(always)]
pub(super) fn read_at<const N: usize>(
    data: &[u8],
    at: &mut usize,
    start: usize,
) -> Result<[u8; N], Miss> {
    match data.get(start..).and_then(<[u8]>::first_chunk::<N>) {
        Some(bytes) => {
            *at = start + N;
            Ok(*bytes)
        }
        None => Err(Miss),
    }
}

/// The next `n` bytes of `data` from `at`, which moves past them.
#[inline(always)]
pub(super) fn take_at<'d>(data: &'d [u8], at: &mut usize, n: usize) -> Result<&'d [u8], Miss> {
    let bytes = data.get(*at..).and_then(|d| d.get(..n)).ok_or(Miss)?;
    *at += n;
    Ok(bytes)
}

/// A string's bytes after its length (the NUL counted): UTF-8, then the NUL.
#[inline(always)]
pub(super) fn text_of(bytes: &[u8]) -> Result<&str, Miss> {
    let (nul, text) = bytes.split_last().ok_or(Miss)?;
    if *nul != 0 {
        return Err(Miss);
    }
    std::str::from_utf8(text).map_err(|_| Miss)
}
