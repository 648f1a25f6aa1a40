//! `ferroc-bench cdr` built on its own: the same source (bench/src/cdr.rs), with only
//! what it needs (this crate, serde, postcard), so that its release build is quick
//! where the whole ferroc-bench (Zenoh, the compiler) takes long on a loaded machine.
//!
//! `cargo run --release -p ferroc-ros2 --example cdr_bench -- [--messages N] [--rounds R]`

#[allow(dead_code)]
#[path = "../../bench/src/options.rs"]
mod options;

#[path = "../../bench/src/cdr.rs"]
mod cdr;

fn main() -> std::process::ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    std::process::ExitCode::from(cdr::run(&args))
}
