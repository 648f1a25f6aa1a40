//! An array of a primitive as both fast writers write it (`ser.rs`, `trusted.rs`): room
//! for all its elements made once, zeroed, when it begins (aligned already: every
//! element is as wide as the alignment it needs), each element then written into the
//! slice left. The buffer's length and capacity are not touched per element, so the
//! slice's pointer and length stay in registers while a derived `Serialize` visits the
//! elements one by one (with `extend_from_slice` per element, the buffer's fields were
//! loaded and stored again for each).

use super::Miss;
use crate::def::Primitive;

/// The elements not yet written of an array of `elem`.
pub(super) struct Packed<'a> {
    out: &'a mut [u8],
    elem: Primitive,
}

impl<'a> Packed<'a> {
    /// `len` elements of `elem` at the end of `buf`.
    #[inline(always)]
    pub fn new(buf: &'a mut Vec<u8>, elem: Primitive, len: usize) -> Result<Self, Miss> {
        let start = buf.len();
        // `len` is at most the sequence's bound or the array's length, and is what
        // the value in memory says it holds (a length that is not the number of
        // elements visited is a miss at the end; the writer's caller starts over).
        let size = len.checked_mul(elem.size()).ok_or(Miss)?;
        buf.resize(start.checked_add(size).ok_or(Miss)?, 0);
        Ok(Packed {
            out: &mut buf[start..],
            elem,
        })
    }

    /// The next element, `bytes` of a `p`: a miss if the array is not of `p` or is full.
    #[inline(always)]
    pub fn fill<const N: usize>(&mut self, p: Primitive, bytes: [u8; N]) -> Result<(), Miss> {
        if self.elem != p {
            return Err(Miss);
        }
        let (head, rest) = std::mem::take(&mut self.out)
            .split_first_chunk_mut::<N>()
            .ok_or(Miss)?;
        *head = bytes;
        self.out = rest;
        Ok(())
    }

    /// Whether every element was written.
    #[inline(always)]
    pub fn full(&self) -> bool {
        self.out.is_empty()
    }
}
