//! The fast paths of the serde codec (`serde_cdr`'s compiled plan, arrays of a
//! primitive aligned once and read from their bytes taken whole, field names checked
//! once per type): the same bytes as the dynamic codec where alignment is tricky
//! (an empty array writes no padding, an 8-byte array after an odd offset does), type
//! errors inside an array naming the element, a field-name check that still refuses a
//! wrong type after a right one was seen, and hostile lengths refused before anything
//! large is allocated (a counting allocator watches every allocation of this test
//! program).
use ferroc_ros2::def::TypeName;
use ferroc_ros2::serde_cdr::{self, Shape};
use ferroc_ros2::{cdr, Registry, Value};
use proptest::prelude::*;
use serde::{Deserialize, Serialize};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, remembering the largest allocation of each thread (the
/// tests run side by side) since it was last reset.
struct Counting;

thread_local! {
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

fn note(size: usize) {
    // `try_with`: nothing to note while the thread's locals are being torn down.
    let _ = LARGEST.try_with(|l| l.set(l.get().max(size)));
}

/// The largest allocation of this thread since the last call.
fn largest() -> usize {
    LARGEST.with(|l| l.replace(0))
}

// SAFETY: every call is passed on unchanged to the system allocator; only a size is
// noted (in a const-initialised thread local, which does not allocate).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        // SAFETY: the caller's contract for `alloc` is the system allocator's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System.alloc` with this layout (above).
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(new_size);
        // SAFETY: as for `dealloc`; the caller's contract for `realloc` is the system's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

const ARRAYS: &str = "\
bool[] flags
int8 odd
float64[] wide
uint16[3] shorts
int64[<=4] longs
uint8[] bytes
float32[] ranges
";

fn registry() -> Registry {
    let mut reg = Registry::shipped();
    reg.add_text("fast_test", "msg", "Arrays", ARRAYS, "Arrays.msg")
        .unwrap();
    reg
}

fn ty(name: &str) -> TypeName {
    TypeName::parse(name).unwrap()
}

#[derive(Serialize, Deserialize, Debug, PartialEq, Clone, Default)]
struct Arrays {
    flags: Vec<bool>,
    odd: i8,
    wide: Vec<f64>,
    shorts: [u16; 3],
    longs: Vec<i64>,
    bytes: Vec<u8>,
    ranges: Vec<f32>,
}

impl Arrays {
    fn dynamic(&self) -> Value {
        let list = |v: Vec<Value>| Value::Array(v);
        Value::Struct(vec![
            list(self.flags.iter().map(|b| Value::Bool(*b)).collect()),
            Value::I8(self.odd),
            list(self.wide.iter().map(|x| Value::F64(*x)).collect()),
            list(self.shorts.iter().map(|x| Value::U16(*x)).collect()),
            list(self.longs.iter().map(|x| Value::I64(*x)).collect()),
            Value::Bytes(self.bytes.clone()),
            list(self.ranges.iter().map(|x| Value::F32(*x)).collect()),
        ])
    }
}

fn arrays(flags: usize, wide: usize, longs: usize, bytes: usize) -> Arrays {
    Arrays {
        flags: (0..flags).map(|i| i % 3 == 0).collect(),
        odd: -7,
        wide: (0..wide).map(|i| i as f64 * -0.5).collect(),
        shorts: [1, 0xfffe, 3],
        longs: (0..longs as i64).map(|i| i64::MIN + i).collect(),
        bytes: (0..bytes).map(|i| i as u8).collect(),
        ranges: vec![f32::INFINITY, 0.25],
    }
}

#[test]
fn arrays_of_every_width_are_the_dynamic_codec_s_bytes_empty_or_not() {
    let reg = registry();
    let t = ty("fast_test/msg/Arrays");
    let shape = Shape::new(&reg, &t, None).unwrap();
    // An odd number of flags puts `odd` and the float64s off their alignment; empty
    // arrays must write no padding at all.
    for (flags, wide, longs, bytes) in [(0, 0, 0, 0), (1, 1, 1, 1), (3, 5, 4, 7), (2, 0, 4, 0)] {
        let value = arrays(flags, wide, longs, bytes);
        let ours = serde_cdr::encode(&shape, &value).unwrap();
        let dynamic = cdr::encode(&reg, &t, &value.dynamic()).unwrap();
        assert_eq!(ours, dynamic, "{flags} {wide} {longs} {bytes}");
        let back: Arrays = serde_cdr::from_cdr(&shape, &ours).unwrap();
        assert_eq!(back, value);
    }
}

#[test]
fn a_wrong_element_type_in_an_array_names_the_element() {
    let reg = registry();
    let scan = Shape::new(&reg, &ty("sensor_msgs/msg/LaserScan"), Some("ranges")).unwrap();
    let e = serde_cdr::encode(&scan, &vec![1.0f64, 2.0]).unwrap_err();
    assert_eq!(e.path, "ranges[0]", "{e}");
    assert!(
        e.message.contains("float64") && e.message.contains("float32"),
        "{e}"
    );
    let bytes = serde_cdr::encode(&scan, &vec![1.0f32, 2.0]).unwrap();
    let e = serde_cdr::from_cdr::<Vec<i32>>(&scan, &bytes).unwrap_err();
    assert_eq!(e.path, "ranges[0]", "{e}");
    // The same array read as what it is: no error.
    let back: Vec<f32> = serde_cdr::from_cdr(&scan, &bytes).unwrap();
    assert_eq!(back, [1.0, 2.0]);

    let t = ty("fast_test/msg/Arrays");
    let shape = Shape::new(&reg, &t, None).unwrap();
    let mut sample = serde_cdr::encode(&shape, &arrays(3, 0, 0, 0)).unwrap();
    sample[4 + 4 + 1] = 2; // the second flag: neither 0 nor 1
    let e = serde_cdr::from_cdr::<Arrays>(&shape, &sample).unwrap_err();
    assert_eq!(e.path, "flags[1]", "{e}");
    assert!(e.message.contains("bool"), "{e}");
}

#[derive(Serialize, Deserialize, Default)]
struct Vector3 {
    x: f64,
    y: f64,
    z: f64,
}

#[derive(Serialize, Deserialize, Default)]
struct Moved {
    a: f64,
    b: f64,
    c: f64,
}

#[derive(Serialize, Deserialize, Default)]
struct Swapped {
    y: f64,
    x: f64,
    z: f64,
}

#[test]
fn field_names_are_still_checked_after_a_type_that_fits() {
    let reg = registry();
    let shape = Shape::new(&reg, &ty("geometry_msgs/msg/Vector3"), None).unwrap();
    for _ in 0..3 {
        let bytes = serde_cdr::encode(&shape, &Vector3::default()).unwrap();
        assert!(serde_cdr::from_cdr::<Vector3>(&shape, &bytes).is_ok());
        let e = serde_cdr::encode(&shape, &Moved::default()).unwrap_err();
        assert!(e.message.contains("`a`"), "{e}");
        let e = serde_cdr::encode(&shape, &Swapped::default()).unwrap_err();
        assert!(e.message.contains("`y`"), "{e}");
        assert!(serde_cdr::from_cdr::<Moved>(&shape, &bytes).is_err());
        assert!(serde_cdr::from_cdr::<Swapped>(&shape, &bytes).is_err());
    }
}

/// An `Arrays` sample whose `ranges` claims `len` elements, followed by 64 zero bytes.
fn arrays_claiming(len: u32) -> Vec<u8> {
    let reg = registry();
    let shape = Shape::new(&reg, &ty("fast_test/msg/Arrays"), None).unwrap();
    let empty = Arrays {
        ranges: Vec::new(),
        ..arrays(0, 0, 0, 0)
    };
    let mut sample = serde_cdr::encode(&shape, &empty).unwrap();
    // `ranges`' length: the last 4 bytes of a sample whose arrays are all empty.
    let at = sample.len() - 4;
    sample[at..].copy_from_slice(&len.to_le_bytes());
    sample.extend_from_slice(&[0; 64]);
    sample
}

#[test]
fn a_length_larger_than_the_sample_is_refused_before_allocating() {
    let reg = registry();
    let shape = Shape::new(&reg, &ty("fast_test/msg/Arrays"), None).unwrap();
    for len in [17, 1 << 20, u32::MAX / 4, u32::MAX] {
        let sample = arrays_claiming(len);
        largest();
        let e = serde_cdr::from_cdr::<Arrays>(&shape, &sample).unwrap_err();
        let largest = largest();
        assert_eq!(e.path, "ranges", "{len}: {e}");
        assert!(largest < 4096, "{len}: {largest} bytes allocated");
        // The fast path alone (tried first above) refuses it as cheaply.
        assert!(serde_cdr::from_cdr_fast::<Arrays>(&shape, &sample).is_none());
        assert!(self::largest() < 4096, "{len}: the fast path allocated");
        // So does the trusted reader (what reads a type found to mirror the message).
        assert!(serde_cdr::from_cdr_trusted::<Arrays>(&shape, &sample).is_none());
        assert!(
            self::largest() < 4096,
            "{len}: the trusted reader allocated"
        );
    }
    // The silent case: a length the sample holds is read (by the fast path too).
    let back: Arrays = serde_cdr::from_cdr(&shape, &arrays_claiming(16)).unwrap();
    assert_eq!(back.ranges, [0.0; 16]);
    let fast: Arrays = serde_cdr::from_cdr_fast(&shape, &arrays_claiming(16)).unwrap();
    assert_eq!(fast, back);
    let trusted: Arrays = serde_cdr::from_cdr_trusted(&shape, &arrays_claiming(16)).unwrap();
    assert_eq!(trusted, back);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_bytes_into_the_array_paths_never_panic_nor_allocate_much(
        bytes in proptest::collection::vec(any::<u8>(), 0..400),
    ) {
        let reg = registry();
        let shape = Shape::new(&reg, &ty("fast_test/msg/Arrays"), None).unwrap();
        let mut sample = vec![0, 1, 0, 0];
        sample.extend(bytes);
        largest();
        let read = serde_cdr::from_cdr::<Arrays>(&shape, &sample).ok();
        prop_assert!(largest() < 64 * 1024);
        // The fast path alone: no panic, no large allocation, and what it reads is
        // what the plan path reads.
        let fast = serde_cdr::from_cdr_fast::<Arrays>(&shape, &sample);
        prop_assert!(largest() < 64 * 1024);
        if fast.is_some() {
            prop_assert_eq!(&fast, &read);
        }
        // The trusted reader alone: the same.
        let trusted = serde_cdr::from_cdr_trusted::<Arrays>(&shape, &sample);
        prop_assert!(largest() < 64 * 1024);
        if trusted.is_some() {
            prop_assert_eq!(trusted, read);
        }
    }
}
