//! Copying a small port value in 16-byte pieces, so the optimiser keeps it in registers.
//!
//! A module's step typically reads a value, changes a part of it and publishes it
//! (`let mut m = input.get(); m[0][0] += x; output.publish(m)`). Copied with a plain
//! assignment, a 128-byte value is one aggregate to the optimiser: it splits off the
//! element the step changes and leaves the rest in a slot on the stack, so every value
//! crosses the stack on its way from the input's cell to the output's, and each stage
//! of a chain of modules waits for two store-to-load forwards instead of one (measured
//! in b2). Copied in 16-byte pieces, the local variable becomes vector registers:
//! loaded from one cell, stored into the other. The pieces are written out, not looped
//! over: the optimiser turns a copy loop back into one `memcpy`.

use std::mem::size_of;

/// Copies `*src` to `*dst` (the two may not overlap).
///
/// # Safety
/// `src` is valid for reads and `dst` for writes of one `T`; every byte of `T` is
/// initialised (`T: NoUninit`), so reading it in pieces reads no padding. Pointers
/// inside `T` would lose their provenance, but port values are `Send + Sync`, which
/// raw pointers are not.
#[inline(always)]
pub(crate) unsafe fn copy<T: bytemuck::NoUninit>(src: *const T, dst: *mut T) {
    #[cfg(target_arch = "x86_64")]
    if size_of::<T>() <= 16 * PIECES {
        // SAFETY: caller's contract.
        unsafe { copy_pieces(src.cast::<u8>(), dst.cast::<u8>(), size_of::<T>()) };
        return;
    }
    // SAFETY: caller's contract.
    unsafe { std::ptr::copy_nonoverlapping(src, dst, 1) };
}

/// Values of up to this many 16-byte pieces are copied in pieces, larger ones with
/// one `memcpy`.
#[cfg(target_arch = "x86_64")]
const PIECES: usize = 16;

/// `size` bytes from `src` to `dst` in straight-line 16-, 8-, 4-, 2- and 1-byte pieces
/// (`size` is a constant after inlining, so every test below folds away).
///
/// # Safety
///
/// `src` must be valid for reads and `dst` for writes of `size` bytes, and the two
/// ranges must not overlap (as for [`copy`]).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn copy_pieces(src: *const u8, dst: *mut u8, size: usize) {
    use std::arch::x86_64::{__m128i, _mm_loadu_si128, _mm_storeu_si128};
    macro_rules! pieces {
        ($($k:literal)*) => {$(
            if ($k + 1) * 16 <= size {
                // SAFETY: in bounds of the value; unaligned loads and stores.
                unsafe {
                    let piece = _mm_loadu_si128(src.add($k * 16).cast::<__m128i>());
                    _mm_storeu_si128(dst.add($k * 16).cast::<__m128i>(), piece);
                }
            }
        )*};
    }
    pieces!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15);
    let mut at = size / 16 * 16;
    macro_rules! tail {
        ($($ty:ty)*) => {$(
            if size - at >= size_of::<$ty>() {
                // SAFETY: in bounds of the value; unaligned.
                unsafe {
                    let piece = src.add(at).cast::<$ty>().read_unaligned();
                    dst.add(at).cast::<$ty>().write_unaligned(piece);
                }
                at += size_of::<$ty>();
            }
        )*};
    }
    tail!(u64 u32 u16 u8);
    debug_assert_eq!(at, size);
}

#[cfg(test)]
mod tests {
    use super::copy;

    /// Copies a `[u8; N]` sitting between guard bytes and checks every byte arrived and
    /// nothing around the destination was touched (sizes around each piece width).
    macro_rules! round_trip {
        ($($n:literal)*) => {$({
            const N: usize = $n;
            let src: [u8; N] = std::array::from_fn(|i| (i as u8).wrapping_mul(31).wrapping_add(7));
            // Destination at an odd offset: the pieces are unaligned accesses.
            let mut buffer = vec![0xAAu8; N + 33];
            let dst = buffer[17..].as_mut_ptr().cast::<[u8; N]>();
            // SAFETY: `dst` has room for N bytes; `[u8; N]` has no padding.
            unsafe { copy(&src, dst) };
            assert_eq!(&buffer[17..17 + N], &src[..], "size {N}");
            assert!(buffer[..17].iter().all(|b| *b == 0xAA), "size {N}: wrote before");
            assert!(buffer[17 + N..].iter().all(|b| *b == 0xAA), "size {N}: wrote after");
        })*};
    }

    #[test]
    fn values_of_every_shape_arrive_whole_and_nothing_around_them_changes() {
        // Up to 256 bytes in pieces (bytemuck knows arrays of these lengths); past
        // that, one memcpy.
        round_trip!(1 2 3 7 8 15 16 17 31 32 48 64 128 256 512 4096);
    }

    #[test]
    fn a_matrix_of_floats_copies_exactly() {
        let m: [[f64; 4]; 4] =
            std::array::from_fn(|i| std::array::from_fn(|j| (i * 4 + j) as f64 + 0.5));
        let mut out = [[0.0f64; 4]; 4];
        // SAFETY: two distinct matrices.
        unsafe { copy(&m, &mut out) };
        assert_eq!(m, out);
    }
}
