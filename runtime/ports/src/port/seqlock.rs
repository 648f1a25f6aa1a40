//! [`SeqCell`]: a port value for small `Copy` types, without reference counting.
//!
//! Three slots of atomic words, each with a sequence number (odd while being written),
//! and one `current` word naming the published slot: `seq << 3 | changed << 2 | index`.
//! The value is copied in and out word by word with relaxed atomics (so racing reads
//! are not data races) and validated with the sequence number, as in a seqlock; the
//! type must be [`NoUninit`] (no padding) so every word written is initialised.
//!
//! * **Writers** claim a slot other than the current one (CAS its even sequence to odd),
//!   re-check that it did not become current, copy the value, *then* make it current,
//!   and only then end the write (sequence back to even). So a slot is never claimed
//!   while current, and `current` never names a slot that another writer is filling:
//!   readers of the current value are not disturbed by writers (only, for one
//!   instruction, by the writer that is just publishing it).
//! * **Concurrent writers** (several outputs into one input, or several threads
//!   publishing on one output): if no other slot can be claimed, the write is dropped,
//!   as if it had been overwritten by the concurrent one ("last writer wins"). This
//!   needs three writers at once on one cell.
//! * **Readers** load `current`, check that the slot's sequence is even and is the one
//!   `current` names, copy the words, and re-check the sequence; otherwise retry.
//! * `current` never repeats (the sequence of a slot only grows), so it doubles as a
//!   version for conditional writes (initial push) and for blocking reads.

use std::marker::PhantomData;
use std::mem::{size_of, MaybeUninit};

use bytemuck::NoUninit;

use crate::sync::{fence, spin_loop, AtomicUsize, Ordering};

const SLOTS: usize = 3;
const INDEX: usize = 3;
const CHANGED: usize = 4;
const SEQ_SHIFT: u32 = 3;
const WORD: usize = size_of::<usize>();

pub(crate) struct SeqCell<T> {
    current: AtomicUsize,
    seqs: [AtomicUsize; SLOTS],
    words: Box<[AtomicUsize]>,
    _value: PhantomData<T>,
}

fn pack(seq: usize, changed: bool, index: usize) -> usize {
    (seq << SEQ_SHIFT) | if changed { CHANGED } else { 0 } | index
}

/// Does `current` name write `seq` of its slot? (`current` keeps the low bits of it.)
fn names(current: usize, seq: usize) -> bool {
    current >> SEQ_SHIFT == (seq << SEQ_SHIFT) >> SEQ_SHIFT
}

/// Claims a slot: even sequence → odd. A plain load may return an outdated sequence
/// (odd, or an older even one), so the CAS, which always sees the latest value, decides:
/// `None` only if the slot really is being written.
fn claim(seq: &AtomicUsize) -> Option<usize> {
    let mut s = seq.load(Ordering::Relaxed) & !1;
    loop {
        match seq.compare_exchange(s, s + 1, Ordering::Acquire, Ordering::Relaxed) {
            Ok(_) => return Some(s),
            Err(actual) if actual & 1 != 0 => return None,
            Err(actual) => s = actual,
        }
    }
}

impl<T: NoUninit> SeqCell<T> {
    const WORDS: usize = size_of::<T>().div_ceil(WORD);

    pub(crate) fn new(value: T) -> Self {
        let cell = SeqCell {
            current: AtomicUsize::new(pack(0, false, 0)),
            seqs: std::array::from_fn(|_| AtomicUsize::new(0)),
            words: (0..SLOTS * Self::WORDS)
                .map(|_| AtomicUsize::new(0))
                .collect(),
            _value: PhantomData,
        };
        cell.write_words(0, &value);
        cell
    }

    fn slot_words(&self, index: usize) -> &[AtomicUsize] {
        &self.words[index * Self::WORDS..(index + 1) * Self::WORDS]
    }

    fn write_words(&self, index: usize, value: &T) {
        let words = self.slot_words(index);
        let src = (value as *const T).cast::<u8>();
        let size = size_of::<T>();
        let full = size / WORD;
        for (i, word) in words[..full].iter().enumerate() {
            // SAFETY: bytes [i*WORD, (i+1)*WORD) lie inside `value` and are initialised
            // (`NoUninit`: no padding); unaligned reads are allowed.
            let w = unsafe { std::ptr::read_unaligned(src.add(i * WORD).cast::<usize>()) };
            word.store(w, Ordering::Relaxed);
        }
        if full < words.len() {
            let mut buf = [0u8; WORD];
            buf[..size - full * WORD].copy_from_slice(&bytemuck::bytes_of(value)[full * WORD..]);
            words[full].store(usize::from_ne_bytes(buf), Ordering::Relaxed);
        }
    }

    fn read_words(&self, index: usize) -> MaybeUninit<T> {
        let words = self.slot_words(index);
        let mut out = MaybeUninit::<T>::uninit();
        let dst = out.as_mut_ptr().cast::<u8>();
        let size = size_of::<T>();
        let full = size / WORD;
        for (i, word) in words[..full].iter().enumerate() {
            // SAFETY: bytes [i*WORD, (i+1)*WORD) lie inside `out`; unaligned writes are
            // allowed.
            unsafe {
                std::ptr::write_unaligned(
                    dst.add(i * WORD).cast::<usize>(),
                    word.load(Ordering::Relaxed),
                )
            };
        }
        if full < words.len() {
            let bytes = words[full].load(Ordering::Relaxed).to_ne_bytes();
            let tail = size - full * WORD;
            // SAFETY: the tail bytes [full*WORD, size) lie inside `out`.
            unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), dst.add(full * WORD), tail) };
        }
        out
    }

    /// Publishes `value` (marking it changed or not). False if the write was dropped
    /// because concurrent writers held every other slot.
    pub(crate) fn store(&self, value: &T, changed: bool) -> bool {
        self.write(value, changed, |current, word| {
            if changed {
                // A delivery to an input: SeqCst, ordered before the publisher's check
                // for blocked readers (see `queue::Signal`). A swap rather than a store:
                // the same instruction on x86, and loom models SeqCst stores loosely.
                current.swap(word, Ordering::SeqCst);
            } else {
                // An output's own value: Release is enough. Connect's initial push is
                // ordered with it through the reader-count RMW that follows in
                // `publish` (see `snapshot.rs`).
                current.store(word, Ordering::Release);
            }
            true
        })
    }

    /// Publishes `value` only if `current` is still `expected` (a version from
    /// [`Self::version`]); used by the initial push.
    pub(crate) fn replace_if(&self, expected: usize, value: &T) -> bool {
        self.write(value, true, |current, word| {
            current
                .compare_exchange(expected, word, Ordering::SeqCst, Ordering::SeqCst)
                .is_ok()
        })
    }

    fn write(
        &self,
        value: &T,
        changed: bool,
        flip: impl FnOnce(&AtomicUsize, usize) -> bool,
    ) -> bool {
        let current = self.current.load(Ordering::Acquire) & INDEX;
        for step in 1..SLOTS {
            let index = (current + step) % SLOTS;
            let seq = &self.seqs[index];
            let Some(s) = claim(seq) else { continue };
            if self.current.load(Ordering::Acquire) & INDEX == index {
                // It became current before our claim: leave it untouched.
                seq.store(s, Ordering::Release);
                continue;
            }
            // The odd sequence is visible before any word changes (Boehm's seqlock).
            fence(Ordering::Release);
            self.write_words(index, value);
            let flipped = flip(&self.current, pack(s + 2, changed, index));
            seq.store(s + 2, Ordering::Release);
            return flipped;
        }
        false
    }

    /// The current value and the version it belongs to.
    pub(crate) fn load(&self) -> (T, usize) {
        loop {
            let current = self.current.load(Ordering::Acquire);
            let index = current & INDEX;
            let seq = &self.seqs[index];
            let s1 = seq.load(Ordering::Acquire);
            if s1 & 1 == 0 && names(current, s1) {
                let value = self.read_words(index);
                fence(Ordering::Acquire);
                if seq.load(Ordering::Relaxed) == s1 {
                    // SAFETY: the sequence did not change while we copied, so the bytes
                    // are exactly those of the `T` written by one writer.
                    return (unsafe { value.assume_init() }, current);
                }
            }
            spin_loop();
        }
    }

    /// Opaque version: changes with every store and every change of the changed mark.
    pub(crate) fn version(&self) -> usize {
        self.current.load(Ordering::SeqCst)
    }

    /// Has anything been published since the initial value?
    pub(crate) fn is_initial(version: usize) -> bool {
        version >> SEQ_SHIFT == 0
    }

    pub(crate) fn has_changed(&self) -> bool {
        self.current.load(Ordering::SeqCst) & CHANGED != 0
    }

    pub(crate) fn take_changed(&self) -> bool {
        let mut cur = self.current.load(Ordering::SeqCst);
        loop {
            if cur & CHANGED == 0 {
                return false;
            }
            match self.current.compare_exchange_weak(
                cur,
                cur & !CHANGED,
                Ordering::SeqCst,
                Ordering::SeqCst,
            ) {
                Ok(_) => return true,
                Err(actual) => cur = actual,
            }
        }
    }
}
