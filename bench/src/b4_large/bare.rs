//! The bare Zenoh writer of b4-large's `zenoh-shm` and `zenoh-net` variants: what
//! ferroc's link is measured against, with nothing of ferroc but the session set-up.

use super::{config_of, fill, gap, KEY, LINK};
use crate::b4_parts::addresses;
use ferroc_runtime::link::transport::{PartLinks, Sending};
use ferroc_zenoh::config::{ModelShm, PartConfig};
use std::path::Path;
use std::time::Instant;
use zenoh::shm::{BlockOn, GarbageCollect, ShmProviderBuilder};
use zenoh::Wait;

/// A bare Zenoh session of the part `part` (`writer` or `reader`): ferroc's
/// configuration of the same part, who connects to whom included (the writer
/// connects, the reader only listens), as b3-parts' bare programs have it.
pub(super) fn session(
    part: &str,
    (writer, reader): (&str, &str),
    file: Option<&Path>,
) -> Result<zenoh::Session, String> {
    let addresses = addresses(part, writer, reader);
    let config = PartConfig::new(&addresses, file, ModelShm::default())?;
    let mut links = PartLinks {
        part: part.into(),
        ..PartLinks::default()
    };
    if part == "writer" {
        let sending = Sending {
            to_part: LINK.to_part.into(),
            topic: "writer/camera/out".into(),
            model_type: LINK.model_type.into(),
            sharing: LINK.sharing,
            reliable: LINK.reliable,
        };
        links.sending.insert(LINK.id, sending);
    } else {
        links.receiving.insert(LINK.id, LINK.from_part.into());
    }
    let config = config.for_links(&addresses, &links)?;
    zenoh::open(config).wait().map_err(|e| e.to_string())
}

/// A bare writer: puts a filled, stamped value of `size` bytes every `gap` until
/// `done`, in shared memory of its own provider (`zenoh-shm`) or as a `Vec`.
pub(super) fn writer(
    variant: &str,
    (writer, reader): (&str, &str),
    size: usize,
    done: &mut dyn FnMut() -> Result<bool, String>,
) -> Result<(), String> {
    let config = config_of(variant)?;
    let s = session("writer", (writer, reader), config.as_deref())?;
    let publisher = s
        .declare_publisher(KEY)
        .congestion_control(zenoh::qos::CongestionControl::Block)
        .wait()
        .map_err(|e| e.to_string())?;
    let provider = match variant {
        "zenoh-shm" => Some(
            ShmProviderBuilder::default_backend(ferroc_zenoh::shm::POOL_SIZE)
                .wait()
                .map_err(|e| e.to_string())?,
        ),
        _ => None,
    };
    let mut next = Instant::now();
    let mut seq = 0u64;
    while !done()? {
        // Sleeps to the next value as ferroc's periodic writer container does (it
        // polled every 200 µs before: a writer process that never slept long).
        std::thread::sleep(next.saturating_duration_since(Instant::now()));
        next += gap(size);
        seq += 1;
        let put = match &provider {
            Some(p) => {
                let mut buf = p
                    .alloc(size)
                    .with_policy::<BlockOn<GarbageCollect>>()
                    .wait()
                    .map_err(|e| e.to_string())?;
                fill(&mut buf[..], seq);
                publisher.put(buf).wait()
            }
            None => {
                let mut v = vec![0u8; size];
                fill(&mut v, seq);
                publisher.put(v).wait()
            }
        };
        put.map_err(|e| e.to_string())?;
    }
    Ok(())
}
