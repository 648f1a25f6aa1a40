//! Which outputs lend their modules the network's buffers (`ferroc_module::lend`):
//! an output whose only readers are links to other parts does; one also read in its
//! own part does not (it lends plain memory). What the network sends is checked too:
//! the value in pieces around the lent buffer, exactly its postcard form.

use super::tests::add;
use super::*;
use ferroc_link::transport::{Connection, Delivery, Network, PartLinks};
use ferroc_link::{Frame, LinkSpec, Sharing};
use ferroc_module::lend::{LentBuffer, Piece};
use ferroc_module::{Bytes, In, Module, ModuleType, Out, Setup};
use std::sync::atomic::AtomicBool;
use std::sync::Mutex;

#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
struct Blob {
    name: String,
    data: Bytes,
}
ferroc_module::port_value!(Blob, "test.Blob", pooled);

/// Publishes a blob of 64 bytes in a buffer its output lends.
struct Lends {
    out: Out<Blob>,
}
impl Module for Lends {
    fn update(&mut self) {
        let out = &self.out;
        out.publish_with(|blob| {
            "blob".clone_into(&mut blob.name);
            blob.data = out.lend(64);
            blob.data.fill(9);
        });
    }
}
impl ModuleType for Lends {
    const NAME: &'static str = "test.Lends";
    fn create(m: &mut Setup<'_>) -> Self {
        Lends {
            out: m.output("out").build(),
        }
    }
}

/// Reads blobs in its own part.
struct Reads {
    input: In<Blob>,
}
impl Module for Reads {
    fn update(&mut self) {
        let _ = self.input.get();
    }
}
impl ModuleType for Reads {
    const NAME: &'static str = "test.Reads";
    fn create(m: &mut Setup<'_>) -> Self {
        Reads {
            input: m.input("in").build(),
        }
    }
}

/// A network that lends buffers and records what it was sent: per value, whether it
/// came in pieces with a lent buffer, and its bytes joined.
#[derive(Clone, Default)]
struct Lending(Arc<Mutex<Vec<Sent>>>);

/// Whether a value came with a lent buffer, and its bytes.
type Sent = (bool, Vec<u8>);

impl Network for Lending {
    fn open(&self, _: &PartLinks, _: Delivery, _: bool) -> Result<Box<dyn Connection>, String> {
        Ok(Box::new(self.clone()))
    }
}

impl Connection for Lending {
    fn send(&self, _to_part: &str, _frame: Frame) {}
    fn send_encoded(
        &self,
        _targets: &[(u32, Arc<str>)],
        encoder: &ferroc_module::Encoder<'_>,
    ) -> Result<(), String> {
        let sent = match encoder.pieces()? {
            Some(pieces) => {
                let lent = pieces.iter().any(|p| matches!(p, Piece::Lent(_)));
                (
                    lent,
                    pieces.iter().flat_map(Piece::bytes).copied().collect(),
                )
            }
            None => (false, encoder.to_vec()?),
        };
        self.0.lock().unwrap().push(sent);
        Ok(())
    }
    fn lend(&self, len: usize) -> Option<Box<dyn LentBuffer>> {
        Some(Box::new(vec![0u8; len]))
    }
    fn end_instant(&self, _: u64, _: Vec<(Arc<str>, Frame)>, _: &AtomicBool) -> Result<(), String> {
        Ok(())
    }
    fn wait_instant(&self, _: u64, _: &AtomicBool) -> Result<Vec<Frame>, String> {
        Ok(Vec::new())
    }
    fn close(&self) {}
}

/// Part `a`: `a/lends` linked to part `b`, and read by `a/reads` if `read_here`. What
/// the network was sent, once a few values went.
fn run(read_here: bool) -> Vec<Sent> {
    let mut registry = Registry::new();
    registry.register::<Lends>().register::<Reads>();
    registry.register_serde::<Blob>();
    let mut b = Builder::new(&registry);
    add(&mut b, "a/lends", "test.Lends", &[]);
    let mut steps = vec![("a/lends".to_string(), StepKind::Update)];
    if read_here {
        add(&mut b, "a/reads", "test.Reads", &[]);
        b.connect(
            ("a/lends", "out"),
            ("a/reads", "in"),
            Conversion::default(),
            Default::default(),
        )
        .unwrap();
        steps.push(("a/reads".to_string(), StepKind::Update));
    }
    b.add_thread(ThreadSpec {
        path: "a".into(),
        schedule: Schedule::Periodic(Duration::from_millis(2)),
        options: ThreadOptions::default(),
        steps,
    })
    .unwrap();
    let spec = LinkSpec {
        id: 0,
        from_part: "a",
        to_part: "b",
        model_type: "test.Blob",
        sharing: Sharing::default(),
        reliable: true,
        deadline: None,
    };
    b.link_out(&spec, ("a/lends", "out"), Conversion::default())
        .unwrap();
    let network = Lending::default();
    let options = StartOptions {
        network: Some(Arc::new(network.clone())),
        ..StartOptions::default()
    };
    let app = b.start_with(options).unwrap();
    let limit = std::time::Instant::now() + Duration::from_secs(30);
    while network.0.lock().unwrap().len() < 3 && std::time::Instant::now() < limit {
        std::thread::sleep(Duration::from_millis(5));
    }
    app.stop();
    let sent = network.0.lock().unwrap().clone();
    sent
}

fn expected() -> Vec<u8> {
    let blob = Blob {
        name: "blob".into(),
        data: vec![9; 64].into(),
    };
    postcard::to_stdvec(&blob).unwrap()
}

#[test]
fn an_output_read_only_by_links_lends_the_networks_buffers() {
    let sent = run(false);
    assert!(sent.len() >= 3, "{} values", sent.len());
    for (lent, bytes) in sent {
        assert!(lent, "sent without its lent buffer");
        assert_eq!(bytes, expected());
    }
}

#[test]
fn an_output_also_read_in_its_part_lends_plain_memory() {
    let sent = run(true);
    assert!(sent.len() >= 3, "{} values", sent.len());
    for (lent, bytes) in sent {
        assert!(
            !lent,
            "a reader in the part would hold the network's buffer"
        );
        assert_eq!(bytes, expected());
    }
}
