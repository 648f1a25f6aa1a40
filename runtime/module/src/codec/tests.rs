//! [`Codec::encode_with`]: a lent value and a small one are walked once, and what the
//! network gets from the [`Encoder`] is exactly the postcard form, however it asks.

use super::*;
use crate::bytes::Bytes;
use crate::value_table::{DebugText, ValueTable};
use crate::DynIn;
use ferroc_ports::port::ConnectOptions;
use serde::ser::SerializeStruct;
use serde::{Deserialize, Serializer};
use std::cell::Cell;

thread_local! {
    /// How often a [`Counted`] was serialised on this thread.
    static WALKS: Cell<usize> = const { Cell::new(0) };
}

/// A value with a name and a block of bytes, counting its walks.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
struct Counted {
    name: String,
    data: Bytes,
}
crate::port_value!(Counted, "test.Counted", pooled);

impl Serialize for Counted {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        WALKS.with(|w| w.set(w.get() + 1));
        let mut fields = s.serialize_struct("Counted", 2)?;
        fields.serialize_field("name", &self.name)?;
        fields.serialize_field("data", &self.data)?;
        fields.end()
    }
}

/// `value` published on a fresh wire; its input, and the codec.
fn published(value: Counted) -> (DynIn, Codec) {
    let mut table = ValueTable::default();
    table.insert_serde::<Counted, DebugText>();
    let vt = table.get("test.Counted").unwrap();
    let (out, oh) = vt.output("out");
    let (input, ih) = vt.input("in", None);
    oh.connect(&ih, ConnectOptions::default()).unwrap();
    out.typed::<Counted>().unwrap().publish(value);
    (input, *vt.codec().unwrap())
}

/// What `ask` got from the encoder of `value`, and how many walks it took.
fn encoded<R>(value: Counted, ask: impl Fn(&Encoder<'_>) -> R) -> (R, usize) {
    let (input, codec) = published(value);
    let before = WALKS.with(Cell::get);
    let mut got = None;
    codec
        .encode_with(&input, &mut |e| got = Some(ask(e)))
        .unwrap();
    (got.unwrap(), WALKS.with(Cell::get) - before)
}

fn lent(len: usize) -> Counted {
    let mut data = Bytes::lent(Box::new(vec![0u8; len]));
    data.fill(7);
    assert!(data.is_lent());
    Counted {
        name: "cam".into(),
        data,
    }
}

fn joined(pieces: &[Piece]) -> Vec<u8> {
    pieces.iter().flat_map(Piece::bytes).copied().collect()
}

#[test]
fn a_lent_value_is_walked_once_into_its_pieces() {
    let whole = postcard::to_stdvec(&lent(10_000)).unwrap();
    let ((len, pieces), walks) = encoded(lent(10_000), |e| (e.len(), e.pieces().unwrap()));
    let pieces = pieces.expect("a lent value comes in pieces");
    assert!(matches!(
        pieces.as_slice(),
        [Piece::Encoded(_), Piece::Lent(_)]
    ));
    assert_eq!((len, joined(&pieces)), (whole.len(), whole));
    assert_eq!(walks, 1, "one pass: the size and the pieces");
    // Asked again (a network that sends twice), the encoder walks the value again.
    let ((first, second), walks) = encoded(lent(64), |e| (e.pieces(), e.pieces()));
    let (first, second) = (first.unwrap().unwrap(), second.unwrap().unwrap());
    assert_eq!(joined(&first), joined(&second));
    assert_eq!(walks, 2);
}

#[test]
fn a_small_value_is_walked_once_into_its_bytes() {
    let small = Counted {
        name: "small".into(),
        data: vec![1, 2, 3].into(),
    };
    let whole = postcard::to_stdvec(&small).unwrap();
    let ((vec, pieces), walks) = encoded(small.clone(), |e| (e.to_vec(), e.pieces()));
    assert_eq!(vec.unwrap(), whole);
    assert!(pieces.unwrap().is_none(), "no lent buffer: no pieces");
    assert_eq!(walks, 1, "one pass: the size and the bytes");
    // Written into a buffer of its size, twice: the kept bytes both times.
    let (written, walks) = encoded(small, |e| {
        let mut a = vec![0; e.len()];
        let mut b = vec![0; e.len()];
        e.write(&mut a).unwrap();
        e.write(&mut b).unwrap();
        assert!(e.write(&mut [0; 1]).is_err(), "the wrong size is refused");
        (a, b)
    });
    assert_eq!(written, (whole.clone(), whole));
    assert_eq!(walks, 1);
}

#[test]
fn a_large_value_of_its_own_bytes_is_written_where_it_goes() {
    // Not lent and larger than what one pass keeps: sized first, written after.
    let large = Counted {
        name: "frame".into(),
        data: vec![5; crate::lend::KEPT + 1].into(),
    };
    let whole = postcard::to_stdvec(&large).unwrap();
    let ((pieces, written), walks) = encoded(large, |e| {
        let mut buffer = vec![0; e.len()];
        e.write(&mut buffer).unwrap();
        (e.pieces().unwrap(), buffer)
    });
    assert!(pieces.is_none());
    assert_eq!(written, whole);
    assert_eq!(walks, 2, "the size pass, then the write");
}

#[test]
fn a_lent_value_with_a_large_block_of_its_own_is_split_by_a_second_pass() {
    // A block of its own beyond what one pass keeps, before the lent one.
    let mut value = lent(5000);
    value.name = "n".repeat(crate::lend::KEPT + 1);
    let whole = postcard::to_stdvec(&value).unwrap();
    let (pieces, walks) = encoded(value, |e| e.pieces().unwrap().unwrap());
    assert_eq!(joined(&pieces), whole);
    assert!(pieces.iter().any(|p| matches!(p, Piece::Lent(_))));
    assert_eq!(walks, 2);
}
