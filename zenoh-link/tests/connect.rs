//! Who connects to whom, on real sockets: three programs in a star (part `a` sends a
//! link to `b` and one to `c`) deliver, and the TCP connections the kernel shows are
//! exactly one from each reader to `a`: nobody connects to `b` or `c`, so `b` and `c`
//! are not connected to each other (no gossip mesh) and `a` opens nothing itself (of a
//! linked pair only the later name connects). docs/zenoh.md "Who connects to whom".

mod support;

use ferroc_runtime::builder::{
    Builder, Conversion, ModuleSpec, Registry, Schedule, StepKind, ThreadSpec,
};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::link::LinkSpec;
use ferroc_runtime::module::Value;
use ferroc_runtime::port::ConnectOptions;
use std::collections::BTreeMap;
use std::time::Duration;
use support::*;

const A_TO_C: LinkSpec<'static> = LinkSpec {
    id: 1,
    to_part: "c",
    ..A_TO_B
};

/// Part `part` of the star: `a` an echo sending to both, `b` and `c` a probe each.
fn star<'r>(registry: &'r Registry, part: &str, tag: f64) -> Builder<'r> {
    let mut b = Builder::new(registry);
    let (path, type_name) = match part {
        "a" => ("a/echo".to_string(), "test.Echo"),
        _ => (format!("{part}/probe"), "test.Probe"),
    };
    let params = [("tag".to_string(), Value::Float(tag))];
    b.add_module(ModuleSpec {
        path: &path,
        type_name,
        params: &params,
        queues: &[],
        ports: &[],
        violations: Default::default(),
    })
    .unwrap();
    b.add_thread(ThreadSpec {
        path: part.into(),
        schedule: Schedule::Periodic(Duration::from_millis(10)),
        options: ThreadOptions::default(),
        steps: vec![(path.clone(), StepKind::Update)],
    })
    .unwrap();
    match part {
        "a" => {
            for spec in [A_TO_B, A_TO_C] {
                (b.link_out(&spec, (&path, "out"), Conversion::default())).unwrap();
            }
        }
        "b" => b
            .link_in(&A_TO_B, (&path, "in"), ConnectOptions::default())
            .unwrap(),
        _ => b
            .link_in(&A_TO_C, (&path, "in"), ConnectOptions::default())
            .unwrap(),
    }
    b
}

/// The established IPv4 TCP connections of this machine: (local port, remote port).
fn established() -> Vec<(u16, u16)> {
    let text = std::fs::read_to_string("/proc/net/tcp").unwrap_or_default();
    let port = |field: &str| {
        let hex = field.rsplit_once(':').map_or("", |(_, p)| p);
        u16::from_str_radix(hex, 16).ok()
    };
    text.lines()
        .skip(1)
        .filter_map(|line| {
            let fields: Vec<&str> = line.split_whitespace().collect();
            // sl, local_address, rem_address, st (01 = ESTABLISHED)
            if fields.get(3) != Some(&"01") {
                return None;
            }
            Some((port(fields.get(1)?)?, port(fields.get(2)?)?))
        })
        .collect()
}

fn port_of(address: &str) -> u16 {
    address.rsplit_once(':').unwrap().1.parse().unwrap()
}

#[test]
fn in_a_star_each_reader_connects_to_the_writer_and_to_nobody_else() {
    if !std::path::Path::new("/proc/net/tcp").exists() {
        eprintln!("skipped: no /proc/net/tcp to read the connections from");
        return;
    }
    let registry = registry();
    let peers: BTreeMap<String, String> = ["a", "b", "c"]
        .iter()
        .map(|p| (p.to_string(), free_port()))
        .collect();
    let start = |part: &str, tag: f64| {
        let options = over_zenoh(free(1_000_000), "connect", part, &peers);
        star(&registry, part, tag).start_with(options).unwrap()
    };
    // The readers first: they connect to `a` before it listens (Zenoh retries).
    let (b, c) = (start("b", 411.0), start("c", 412.0));
    let a = start("a", 410.0);
    let wait = Duration::from_secs(20);
    for tag in [411, 412] {
        assert!(
            eventually(wait, || record(tag)
                .last()
                .is_some_and(|l| l.starts_with("fresh"))),
            "part {tag} receives: {:?}",
            record(tag)
        );
    }
    let [pa, pb, pc] = ["a", "b", "c"].map(|p| port_of(&peers[p]));
    let to = |port: u16| established().iter().filter(|(_, r)| *r == port).count();
    assert!(
        eventually(wait, || to(pa) == 2),
        "one connection from each reader to `a`: {:?}",
        established()
    );
    assert_eq!(
        (to(pb), to(pc)),
        (0, 0),
        "nobody connects to a reader: {:?}",
        established()
    );
    for part in [a, b, c] {
        part.stop();
    }
}
