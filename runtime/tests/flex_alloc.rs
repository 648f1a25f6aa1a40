//! The cycle path of type-erased ports allocates nothing once warm: reading numbers,
//! publishing from `f64`, forwarding copy and pooled values, and formatting into a
//! reused buffer (what `ferroc_std`'s `Sum`, `FlexiSelect` and `Dump` do every cycle).
//!
//! A counting global allocator, counted per thread so parallel tests do not interfere.

use ferroc_runtime::builder::Registry;
use ferroc_runtime::module::{DynIn, DynOut, ValueTable};
use ferroc_runtime::port::ConnectOptions;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

// SAFETY: forwards to the system allocator; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as ours.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as ours.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as ours.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> u64 {
    ALLOCATIONS.with(Cell::get)
}

fn wire(t: &ValueTable, ty: &str) -> (DynOut, DynIn) {
    let vt = t.get(ty).unwrap();
    let (out, oh) = vt.output("out");
    let (inp, ih) = vt.input("in", None);
    oh.connect(&ih, ConnectOptions::default()).unwrap();
    (out, inp)
}

/// Allocations made by `cycle` on its 101st to 1100th run.
fn steady(mut cycle: impl FnMut()) -> u64 {
    for _ in 0..100 {
        cycle();
    }
    let before = allocations();
    for _ in 0..1000 {
        cycle();
    }
    allocations() - before
}

#[test]
fn numbers_forwarding_and_text_do_not_allocate_once_warm() {
    let registry = Registry::new();
    let t = registry.values();
    let mut line = String::new();

    // Sum: read as f64, publish from f64.
    let (src, a) = wire(t, "u32");
    let (sum, probe) = wire(t, "u32");
    let mut x = 0.0;
    let n = steady(|| {
        x += 1.0;
        src.publish_f64(x);
        sum.publish_f64(a.get_f64().unwrap_or(0.0) + 1.0);
        line.clear();
        probe.write_human(&mut line);
        probe.write_json(&mut line);
    });
    assert_eq!(n, 0, "copy numbers allocated");

    // FlexiSelect over a pooled type: a Vec forwarded into recycled buffers.
    let (src, mid) = wire(t, "[f64]");
    let (fwd, end) = wire(t, "[f64]");
    let feed = src.typed::<Vec<f64>>().unwrap();
    let n = steady(|| {
        feed.publish_with(|v| {
            v.clear();
            v.extend_from_slice(&[1.0, 2.0, 3.0]);
        });
        assert!(fwd.forward(&mid));
        line.clear();
        end.write_human(&mut line);
    });
    assert_eq!(n, 0, "pooled forwarding allocated");
    assert_eq!(line, "[1.0, 2.0, 3.0]");

    // Dump of a timestamp and a string.
    let (src, ts) = wire(t, "timestamp");
    src.typed::<ferroc_runtime::module::Timestamp>()
        .unwrap()
        .publish(ferroc_runtime::module::Timestamp::now());
    let (words, text) = wire(t, "string");
    words
        .typed::<String>()
        .unwrap()
        .publish("with \"quotes\" and \\ to escape".into());
    let n = steady(|| {
        line.clear();
        ts.write_human(&mut line);
        ts.write_json(&mut line);
        text.write_human(&mut line);
        text.write_json(&mut line);
    });
    assert_eq!(n, 0, "formatting allocated: {line}");
}
