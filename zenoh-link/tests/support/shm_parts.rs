//! The two parts of the shared-memory tests (tests/shm.rs): a camera part sending
//! `ferroc_std.Image`s whose bytes all say which frame they are, and a viewer part,
//! in this process or as the reader program (the test binary started again).

use crate::support::{free_port, model_ms, note};
use ferroc_runtime::builder::{
    Builder, ModuleSpec, Registry, RunningApp, Schedule, StartOptions, StepKind, ThreadSpec,
};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::link::transport::Addresses;
use ferroc_runtime::link::{LinkSpec, Sharing};
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup, Value};
use ferroc_runtime::port::ConnectOptions;
use ferroc_std::Image;
use ferroc_zenoh::Zenoh;
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// 64 B, 64 KB, 1 MB and a 1080p RGB frame (6.2 MB).
pub const SIZES: [usize; 4] = [64, 64 * 1024, 1 << 20, 1920 * 1080 * 3];

/// Every cycle, the next frame: `size` bytes (0: the sizes of [`SIZES`] in turn), the
/// frame number in the first 8, every other byte the frame number's low byte.
pub struct Camera {
    out: Out<Image>,
    size: Parameter<f64>,
    /// 1: the pixels go into a buffer the output lends (`Out::lend`).
    lend: Parameter<f64>,
    seq: u64,
}
impl Module for Camera {
    fn update(&mut self) {
        self.seq += 1;
        let seq = self.seq;
        let size = match self.size.get() as usize {
            0 => SIZES[(seq % 4) as usize],
            n => n,
        };
        let (out, lend) = (&self.out, self.lend.get() == 1.0);
        out.publish_with(|img| {
            img.width = size as u32;
            img.height = 1;
            img.encoding = "mono8".into();
            img.step = size as u32;
            if lend {
                out.lend_in(&mut img.data, size);
            } else {
                img.data.to_mut().resize(size, 0);
            }
            let data: &mut [u8] = &mut img.data;
            data.fill(seq as u8);
            data[..8].copy_from_slice(&seq.to_le_bytes());
        });
    }
}
impl ModuleType for Camera {
    const NAME: &'static str = "test.Camera";
    fn create(m: &mut Setup<'_>) -> Self {
        Camera {
            out: m.output("out").build(),
            size: m.param("size").default(0.0).build(),
            lend: m.param("lend").default(0.0).build(),
            seq: 0,
        }
    }
}

/// Checks every frame it reads and says `seen SEQ SIZE ok|bad`: on standard output in
/// the reader program, in the record of `tag` in this process. With `hold` > 0 it keeps
/// its last `hold` frames (where they arrived) and checks them all again every step,
/// saying `held N ok|bad`: a frame reused under it would show. With `hold` < 0 it keeps
/// its first `-hold` frames instead, for as long as it runs.
pub struct Viewer {
    input: In<Image>,
    tag: Parameter<f64>,
    hold: Parameter<f64>,
    held: Vec<Image>,
}

/// A camera frame's number and whether its bytes all say it (`None`: no frame yet).
fn frame(img: &Image) -> Option<(u64, bool)> {
    let seq = img
        .data
        .first_chunk::<8>()
        .map(|b| u64::from_le_bytes(*b))?;
    let block = [seq as u8; 4096];
    let intact = img.data[8..].chunks(4096).all(|c| c == &block[..c.len()])
        && img.width as usize == img.data.len()
        && img.check().is_ok();
    Some((seq, intact))
}

impl Viewer {
    fn check_held(&mut self, img: &Image) {
        let (hold, first) = (self.hold.get().abs() as usize, self.hold.get() < 0.0);
        if hold == 0 {
            return;
        }
        match (self.held.len() == hold, first) {
            (true, true) => {}
            (true, false) => {
                self.held.remove(0);
                self.held.push(img.clone());
            }
            (false, _) => self.held.push(img.clone()),
        }
        let intact = self.held.iter().all(|h| frame(h).is_some_and(|(_, ok)| ok));
        let word = if intact { "ok" } else { "bad" };
        println!("held {} {word}", self.held.len());
    }
}

impl Module for Viewer {
    fn update(&mut self) {
        if !self.input.changed() {
            return;
        }
        let img = self.input.get();
        let Some((seq, intact)) = frame(&img) else {
            return; // the default value before the first frame
        };
        self.check_held(&img);
        let line = format!(
            "seen {seq} {} {}",
            img.data.len(),
            if intact { "ok" } else { "bad" }
        );
        let tag = self.tag.get();
        if tag == 0.0 {
            // Where its pixels are: still in the buffer they arrived in, or copied.
            let place = if img.data.is_shared() {
                "in-place"
            } else {
                "owned"
            };
            println!("{line} {place}");
        } else {
            note(tag, format!("{line} at {} ms", model_ms()));
        }
    }
}
impl ModuleType for Viewer {
    const NAME: &'static str = "test.Viewer";
    fn create(m: &mut Setup<'_>) -> Self {
        Viewer {
            input: m.input("in").build(),
            tag: m.param("tag").default(0.0).build(),
            hold: m.param("hold").default(0.0).build(),
            held: Vec::new(),
        }
    }
}

pub fn registry() -> Registry {
    let mut r = Registry::new();
    r.register::<Camera>().register::<Viewer>();
    ferroc_std::register(&mut r);
    r
}

pub fn link(reliable: bool) -> LinkSpec<'static> {
    LinkSpec {
        id: 0,
        from_part: "cam",
        to_part: "view",
        model_type: "ferroc_std.Image",
        sharing: Sharing::OnChange {
            min_interval: Duration::ZERO,
        },
        reliable,
        deadline: None,
    }
}

/// The part `part` (`cam`: a camera every `ms`; `view`: a viewer every `ms`).
pub fn part<'r>(
    registry: &'r Registry,
    part: &str,
    ms: u64,
    params: &[(String, Value)],
) -> Builder<'r> {
    let mut b = Builder::new(registry);
    let path = add_part(&mut b, part, ms, params);
    if part == "cam" {
        b.link_out(&link(true), (path, "out"), Default::default())
    } else {
        b.link_in(&link(true), (path, "in"), ConnectOptions::default())
    }
    .unwrap();
    b
}

/// The module and thread of the part `part` ([`part`] without its link), added to `b`;
/// the module's path.
pub fn add_part(
    b: &mut Builder<'_>,
    part: &str,
    ms: u64,
    params: &[(String, Value)],
) -> &'static str {
    let (path, type_name) = match part {
        "cam" => ("cam/camera", "test.Camera"),
        _ => ("view/viewer", "test.Viewer"),
    };
    b.add_module(ModuleSpec {
        path,
        type_name,
        params,
        queues: &[],
        ports: &[],
        violations: Default::default(),
    })
    .unwrap();
    b.add_thread(ThreadSpec {
        path: part.into(),
        schedule: Schedule::Periodic(Duration::from_millis(ms)),
        options: ThreadOptions::default(),
        steps: vec![(path.into(), StepKind::Update)],
    })
    .unwrap();
    path
}

/// The Zenoh network of `part` of the application `app`, configured by `config`.
pub fn zenoh(
    app: &str,
    part: &str,
    peers: &BTreeMap<String, String>,
    config: Option<&PathBuf>,
) -> Arc<Zenoh> {
    let addresses = Addresses {
        part: part.into(),
        listen: peers[part].clone(),
        peers: peers.clone(),
    };
    Arc::new(Zenoh::new(app, addresses, config.map(PathBuf::as_path)).unwrap())
}

pub fn peers() -> BTreeMap<String, String> {
    [
        ("cam".to_string(), free_port()),
        ("view".to_string(), free_port()),
    ]
    .into()
}

/// A `--zenoh-config` file holding `text`.
pub fn config_file(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ferroc-shm-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The camera part running freely, a frame every `ms` of `size` bytes (0: all sizes).
pub fn camera(registry: &Registry, zenoh: &Arc<Zenoh>, ms: u64, size: usize) -> RunningApp {
    camera_with(registry, zenoh, ms, size, false)
}

/// [`camera`], its pixels in buffers its output lends if `lend`.
pub fn camera_with(
    registry: &Registry,
    zenoh: &Arc<Zenoh>,
    ms: u64,
    size: usize,
    lend: bool,
) -> RunningApp {
    let params = [
        ("size".to_string(), Value::Float(size as f64)),
        ("lend".to_string(), Value::Float(f64::from(u8::from(lend)))),
    ];
    let options = StartOptions {
        network: Some(Arc::clone(zenoh) as _),
        ..StartOptions::default()
    };
    part(registry, "cam", ms, &params)
        .start_with(options)
        .unwrap()
}

/// The reader program: this binary's `reader_program`, whose lines land in `lines`.
pub struct Reader {
    child: Child,
    lines: Arc<Mutex<Vec<String>>>,
}

impl Reader {
    pub fn start(app: &str, peers: &BTreeMap<String, String>) -> Reader {
        Reader::start_with(app, &peers["cam"], &peers["view"], 0, 5)
    }

    /// A reader listening on `listen`, connecting to the camera at `cam`, keeping its
    /// last `hold` frames (its first `-hold` if negative: [`Viewer`]), stepping every
    /// `ms`.
    pub fn start_with(app: &str, cam: &str, listen: &str, hold: i64, ms: u64) -> Reader {
        let mut child = Command::new(std::env::current_exe().unwrap())
            .args(["reader_program", "--exact", "--ignored", "--nocapture"])
            .env(
                "FERROC_SHM_READER",
                format!("{app} {cam} {listen} {hold} {ms}"),
            )
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let lines: Arc<Mutex<Vec<String>>> = Arc::default();
        let (stdout, into) = (child.stdout.take().unwrap(), Arc::clone(&lines));
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                into.lock().unwrap().push(line);
            }
        });
        Reader { child, lines }
    }

    /// The frames seen so far: (size, intact).
    pub fn seen(&self) -> Vec<(usize, bool)> {
        let lines = self.lines.lock().unwrap();
        (lines.iter())
            .filter_map(|l| {
                let mut w = l.strip_prefix("seen ")?.split(' ').skip(1);
                Some((w.next()?.parse().ok()?, w.next()? == "ok"))
            })
            .collect()
    }

    /// The sizes of the frames seen read in place (their pixels in the buffer they
    /// arrived in) and of those seen copied.
    pub fn places(&self) -> (Vec<usize>, Vec<usize>) {
        let lines = self.lines.lock().unwrap();
        let mut places = (Vec::new(), Vec::new());
        for l in lines.iter().filter_map(|l| l.strip_prefix("seen ")) {
            let w: Vec<&str> = l.split(' ').collect();
            let Some(size) = w.get(1).and_then(|s| s.parse().ok()) else {
                continue;
            };
            match w.get(3) {
                Some(&"in-place") => places.0.push(size),
                _ => places.1.push(size),
            }
        }
        places
    }

    /// The checks of the frames it keeps so far: whether each found them all intact.
    pub fn held_checks(&self) -> Vec<bool> {
        let lines = self.lines.lock().unwrap();
        (lines.iter())
            .filter_map(|l| Some(l.strip_prefix("held ")?.ends_with(" ok")))
            .collect()
    }

    /// The latest count of values that arrived in shared memory.
    pub fn received_shared(&self) -> u64 {
        let lines = self.lines.lock().unwrap();
        (lines.iter().rev())
            .find_map(|l| l.strip_prefix("received_shared ")?.parse().ok())
            .unwrap_or(0)
    }

    /// Sends the program the signal `name` (`STOP`, `CONT`), with the shell's own
    /// `kill` and the program's process id only.
    pub fn signal(&self, name: &str) {
        let command = format!("kill -s {name} {}", self.child.id());
        let status = Command::new("sh").args(["-c", &command]).status().unwrap();
        assert!(status.success(), "{command}");
    }

    /// Ends the program as a crash would: SIGKILL.
    pub fn kill(mut self) {
        self.child.kill().unwrap();
        self.child.wait().unwrap();
    }
}

impl Drop for Reader {
    fn drop(&mut self) {
        drop(self.child.stdin.take()); // the program ends when its input closes
        let _ = self.child.wait();
    }
}

/// The words of a helper program's spec in the environment variable `var` ("APP
/// CAM_ADDR VIEW_ADDR …") and the two parts' addresses they name; `None` when the
/// variable is not set (the program was not started by a test).
pub fn program_spec(var: &str) -> Option<(Vec<String>, BTreeMap<String, String>)> {
    let spec = std::env::var(var).ok()?;
    let words: Vec<String> = spec.split(' ').map(str::to_string).collect();
    let peers = [
        ("cam".to_string(), words[1].clone()),
        ("view".to_string(), words[2].clone()),
    ]
    .into();
    Some((words, peers))
}

/// The reader program of tests/shm.rs (started by them; does nothing otherwise):
/// the `view` part of `FERROC_SHM_READER` = "APP CAM_ADDR VIEW_ADDR HOLD MS" (its
/// viewer keeping HOLD frames, stepping every MS), until its standard input closes.
pub fn reader_program() {
    let Some((words, peers)) = program_spec("FERROC_SHM_READER") else {
        return;
    };
    let registry = registry();
    let zenoh = zenoh(&words[0], "view", &peers, None);
    let options = StartOptions {
        network: Some(Arc::clone(&zenoh) as _),
        ..StartOptions::default()
    };
    let number = |i: usize| words.get(i).and_then(|w| w.parse::<i64>().ok());
    let (hold, ms) = (number(3).unwrap_or(0), number(4).unwrap_or(5).max(1) as u64);
    let params = [("hold".to_string(), Value::Float(hold as f64))];
    let app = part(&registry, "view", ms, &params)
        .start_with(options)
        .unwrap();
    let (tx, rx) = std::sync::mpsc::channel::<()>();
    std::thread::spawn(move || {
        let _ = std::io::stdin().read_to_end(&mut Vec::new());
        let _ = tx.send(());
    });
    while rx.recv_timeout(Duration::from_millis(100)).is_err() {
        println!("received_shared {}", zenoh.shm_use().received_shared);
        let _ = std::io::stdout().flush();
    }
    app.stop();
}
