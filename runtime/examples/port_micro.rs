//! Micro-measurement of the port core: nanoseconds per publish + get.
//!
//! `cargo run --release -p ferroc-runtime --example port_micro [iterations]`
//!
//! One thread, so this is the uncontended cost of the atomics (the B2 situation:
//! modules of one thread container talking through ports). Prints numbers only; the
//! benchmarks proper live in `bench/`.

use std::hint::black_box;
use std::time::Instant;

use ferroc_runtime::port::{
    connect, ConnectOptions, CopyInputPort, CopyOutputPort, InputPort, OutputPort,
};

type Matrix4 = [[f64; 4]; 4];

fn measure(label: &str, iterations: u64, mut step: impl FnMut(u64)) {
    for i in 0..iterations / 10 {
        step(i); // warm-up: pools grow to their steady size
    }
    let start = Instant::now();
    for i in 0..iterations {
        step(i);
    }
    let ns = start.elapsed().as_nanos() as f64 / iterations as f64;
    println!("{label:<58} {ns:>8.1} ns");
}

fn main() {
    let iterations: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(5_000_000);
    println!("{iterations} iterations each, one thread");

    let out = OutputPort::<Matrix4>::new("out");
    let inp = InputPort::<Matrix4>::new("in");
    connect(&out, &inp, ConnectOptions::default()).expect("fresh ports");
    measure(
        "OutputPort<Matrix4> publish_with + get, 1 input",
        iterations,
        |i| {
            out.publish_with(|m| m[0][0] = i as f64);
            black_box(inp.get()[0][0]);
        },
    );
    measure(
        "  get alone (PortRef taken and dropped)",
        iterations,
        |_| {
            black_box(inp.get()[0][0]);
        },
    );

    let lonely = OutputPort::<Matrix4>::new("lonely");
    measure(
        "OutputPort<Matrix4> publish_with, no input",
        iterations,
        |i| {
            lonely.publish_with(|m| m[0][0] = i as f64);
        },
    );

    let fan = OutputPort::<Matrix4>::new("fan");
    let inputs: Vec<_> = (0..15)
        .map(|i| InputPort::<Matrix4>::new(format!("in{i}")))
        .collect();
    for i in &inputs {
        connect(&fan, i, ConnectOptions::default()).expect("fresh ports");
    }
    measure(
        "OutputPort<Matrix4> publish_with + 15 gets, 15 inputs",
        iterations / 10,
        |i| {
            fan.publish_with(|m| m[0][0] = i as f64);
            for inp in &inputs {
                black_box(inp.get()[0][0]);
            }
        },
    );

    let cout = CopyOutputPort::<Matrix4>::new("cout");
    let cin = CopyInputPort::<Matrix4>::new("cin");
    connect(&cout, &cin, ConnectOptions::default()).expect("fresh ports");
    let mut m = Matrix4::default();
    measure(
        "CopyOutputPort<Matrix4> publish + get, 1 input",
        iterations,
        |i| {
            m[0][0] = i as f64;
            cout.publish(m);
            black_box(cin.get()[0][0]);
        },
    );

    let sout = CopyOutputPort::<u64>::new("sout");
    let sin = CopyInputPort::<u64>::new("sin");
    connect(&sout, &sin, ConnectOptions::default()).expect("fresh ports");
    measure(
        "CopyOutputPort<u64> publish + get, 1 input",
        iterations,
        |i| {
            sout.publish(i);
            black_box(sin.get());
        },
    );

    let mut a = Matrix4::default();
    let mut b = Matrix4::default();
    measure(
        "baseline: plain variable write + read (Matrix4)",
        iterations,
        |i| {
            a[0][0] = i as f64;
            b = black_box(a);
            black_box(b[0][0]);
        },
    );
}
