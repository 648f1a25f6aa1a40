//! dora node `sender`: `DORA_B4_COUNT` (+ warm-up) values of `DORA_B4_SIZE` bytes on
//! output `value`, one every `DORA_B4_GAP_US`, written straight into the sample dora
//! allocates (`send_output_raw`: shared memory from 4 KiB on, the zero-copy path
//! dora's documentation recommends), filled and stamped last.

use dora_b4::{env_number, fill_and_stamp, wait_until, warm_up};
use dora_node_api::{dora_core::config::DataId, DoraNode, MetadataParameters};
use std::time::{Duration, Instant};

fn main() {
    if let Err(e) = run() {
        eprintln!("dora_sender: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let size = env_number("DORA_B4_SIZE", 64)? as usize;
    let count = env_number("DORA_B4_COUNT", 10_000)?;
    let gap = Duration::from_micros(env_number("DORA_B4_GAP_US", 100)?);
    if size < 16 {
        return Err(format!(
            "DORA_B4_SIZE={size}: at least 16 bytes (stamp + sequence)"
        ));
    }
    let warm = warm_up()?;
    let (mut node, _events) = DoraNode::init_from_env().map_err(|e| e.to_string())?;
    let output = DataId::from("value".to_owned());
    // Let the receiver's subscription settle before the warm-up values.
    std::thread::sleep(Duration::from_millis(500));
    let mut next = Instant::now();
    for seq in 0..count + warm {
        wait_until(next);
        next += gap;
        node.send_output_raw(output.clone(), MetadataParameters::default(), size, |out| {
            fill_and_stamp(out, seq)
        })
        .map_err(|e| format!("send {seq}: {e}"))?;
    }
    // Give the last values time to arrive before the output closes.
    std::thread::sleep(Duration::from_millis(200));
    Ok(())
}
