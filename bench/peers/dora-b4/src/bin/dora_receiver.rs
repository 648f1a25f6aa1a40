//! dora node `receiver`: takes `now - stamp` of every value on input `value` after the
//! warm-up; when the sender's output closes (or `DORA_B4_COUNT` were seen) writes one
//! line `p50_us p99_us max_us n lost` to the file `DORA_B4_OUT`.

use dora_b4::{env_number, mono_ns, percentiles, read_stamp, warm_up};
use dora_node_api::{DoraNode, Event};

fn main() {
    if let Err(e) = run() {
        eprintln!("dora_receiver: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let count = env_number("DORA_B4_COUNT", 10_000)?;
    let out = std::env::var("DORA_B4_OUT").map_err(|_| "DORA_B4_OUT is not set".to_string())?;
    let warm = warm_up()?;
    let (_node, mut events) = DoraNode::init_from_env().map_err(|e| e.to_string())?;
    let mut seen = Vec::with_capacity(count as usize);
    while let Some(event) = events.recv() {
        match event {
            Event::Input { data, .. } => {
                let now = mono_ns();
                let bytes: &[u8] = (&data).try_into().map_err(|e| format!("{e}"))?;
                let (stamp, seq) = read_stamp(bytes).ok_or("a value shorter than its stamp")?;
                if seq >= warm {
                    seen.push(now.saturating_sub(stamp));
                }
                if seen.len() as u64 >= count {
                    break;
                }
            }
            Event::InputClosed { .. } | Event::Stop(_) => break,
            _ => {}
        }
    }
    let n = seen.len() as u64;
    let (p50, p99, max) = percentiles(seen);
    let line = format!("{p50:.2} {p99:.2} {max:.2} {n} {}\n", count - n.min(count));
    std::fs::write(&out, line).map_err(|e| format!("{out}: {e}"))
}
