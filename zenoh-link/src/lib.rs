//! ferroc's links between parts over Eclipse Zenoh.
//!
//! A generated program whose part is linked to others gives the runtime a [`Zenoh`]
//! network (`StartOptions::network`). When the part starts, it opens one Zenoh session
//! (peer mode, the addresses of the parts it is linked with as explicit endpoints,
//! multicast scouting off: [`config`]) and declares what its links need on the
//! documented keys ([`keys`], docs/zenoh.md):
//!
//! - running freely, a publisher per link it sends, a subscriber per part it receives
//!   from, a queryable per service it serves across parts and a `get` per call it
//!   makes ([`free`]);
//! - in lockstep, one message per instant for every part it sends to, carrying the
//!   frames of that instant ([`lockstep`]);
//! - for a part that is a ROS 2 node, the node's and its topics' liveliness tokens and
//!   samples on rmw_zenoh's keys, in CDR ([`ros2`], docs/ros2.md);
//! - values of at least 4 KB, in a bounded pool of shared memory that Zenoh hands to
//!   readers on the same computer without copying them through a socket ([`shm`]);
//! - always, a liveliness token, and a liveliness subscriber that notices parts that
//!   come and go ([`alive`]).
//!
//! The crate uses Zenoh's synchronous API (`.wait()`) from the runtime's threads; the
//! runtime itself depends on neither Zenoh nor tokio.

#![forbid(unsafe_code)]

pub mod alive;
pub mod config;
pub mod free;
pub mod keys;
pub mod lockstep;
pub mod ros2;
pub mod shm;
pub mod stats;

use ferroc_runtime::link::transport::{Addresses, Connection, Delivery, Network, PartLinks};
use ferroc_terminal::engine_error;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use zenoh::Wait;

pub use keys::Keys;

/// The Zenoh network of one part: its keys and its session's configuration.
pub struct Zenoh {
    keys: Keys,
    addresses: Addresses,
    config: config::PartConfig,
    /// Whether each session gets an id naming this process (the configuration file
    /// sets none): what tells a writer that a reader's process is gone
    /// ([`shm::process`]).
    own_id: bool,
    /// The shared-memory pool of the values this part sends, made when a connection
    /// that sends first opens and kept across reopenings (a restarted part).
    pool: Mutex<Option<Arc<shm::Pool>>>,
    /// How many values arrived in shared memory.
    received_shared: Arc<AtomicU64>,
    /// The computer gives no usable shared memory: sessions open without it (after
    /// one warning), and the part has no pool.
    no_shm: AtomicBool,
}

impl Zenoh {
    /// The network of the part `addresses.part` of the application `application`,
    /// configured from `config_file` (Zenoh's JSON5, `--zenoh-config`) if given. An
    /// error names the option to change.
    pub fn new(
        application: &str,
        addresses: Addresses,
        config_file: Option<&Path>,
    ) -> Result<Zenoh, String> {
        Zenoh::with_model(
            application,
            addresses,
            config_file,
            config::ModelShm::default(),
        )
    }

    /// [`Zenoh::new`] with the part's shared-memory settings from the model (`<part
    /// shared-memory…>`), which `config_file` overrides key by key.
    pub fn with_model(
        application: &str,
        addresses: Addresses,
        config_file: Option<&Path>,
        shm: config::ModelShm,
    ) -> Result<Zenoh, String> {
        let keys = Keys::new(application)?;
        keys.alive(&addresses.part)?;
        let config = config::PartConfig::new(&addresses, config_file, shm)?;
        let own_id = !config.names_an_id();
        Ok(Zenoh {
            keys,
            addresses,
            config,
            own_id,
            pool: Mutex::default(),
            received_shared: Arc::default(),
            no_shm: AtomicBool::new(false),
        })
    }

    /// The keys of the application.
    pub fn keys(&self) -> &Keys {
        &self.keys
    }

    /// The shared-memory settings of this part ([`shm::Settings`]).
    pub fn shm_settings(&self) -> shm::Settings {
        let mut settings = shm::Settings::of(self.config.every_part());
        settings.enabled &= !self.no_shm.load(Ordering::Relaxed);
        settings
    }

    /// What this part's shared memory did so far: its pool (not active before a
    /// connection that sends values opened) and the values received in shared memory.
    pub fn shm_use(&self) -> shm::Use {
        let pool = self.pool.lock().unwrap_or_else(|e| e.into_inner());
        let mut used = pool.as_ref().map(|p| p.usage()).unwrap_or_default();
        used.received_shared = self.received_shared.load(Ordering::Relaxed);
        used
    }

    /// How many buffers of `size` bytes this part's pool holds now
    /// ([`shm::Pool::room_for`]); `None` without a pool.
    pub fn shm_room_for(&self, size: usize) -> Option<usize> {
        let pool = self.pool.lock().unwrap_or_else(|e| e.into_inner());
        pool.as_ref().and_then(|p| p.room_for(size))
    }

    /// This part's pool, opened the first time it is asked for.
    fn shm_pool(&self) -> Arc<shm::Pool> {
        let mut pool = self.pool.lock().unwrap_or_else(|e| e.into_inner());
        Arc::clone(pool.get_or_insert_with(|| Arc::new(shm::Pool::open(self.shm_settings()))))
    }

    /// The configuration of this part's session when its links are `links`: it
    /// connects only to the parts it is linked with ([`config::connect`]).
    pub fn session_config(&self, links: &PartLinks) -> Result<zenoh::Config, String> {
        self.config.for_links(&self.addresses, links)
    }

    /// Opens this part's session for `links`: a listening address in use is an error
    /// that names `--listen`.
    fn session(&self, links: &PartLinks) -> Result<zenoh::Session, String> {
        let mut config = self.session_config(links)?;
        if self.own_id {
            let id = format!("\"{}\"", shm::process::session_id());
            config
                .insert_json5("id", &id)
                .map_err(|e| engine_error(&e))?;
        }
        // Where the computer cannot give shared memory, Zenoh would refuse to open the
        // session with it: off, after one warning for the part's life (docs/zenoh.md).
        shm::probe::off_where_unusable(&mut config, &self.no_shm, shm::probe::PARTS)?;
        zenoh::open(config).wait().map_err(|e| {
            let part = &self.addresses.part;
            let listen = &self.addresses.listen;
            let text = engine_error(&e);
            match text.strip_prefix("cannot listen on ") {
                Some(endpoint_and_reason) => format!(
                    "the part `{part}` cannot listen on {listen}: {}; choose another \
                     address with --listen ADDR and tell the other parts with \
                     --peer {part}=HOST:PORT",
                    endpoint_and_reason
                        .split_once(": ")
                        .map_or(endpoint_and_reason, |(_, reason)| reason)
                ),
                None => format!("the part `{part}` cannot open its Zenoh session: {text}"),
            }
        })
    }
}

impl Network for Zenoh {
    fn open(
        &self,
        links: &PartLinks,
        delivery: Delivery,
        lockstep: bool,
    ) -> Result<Box<dyn Connection>, String> {
        let part = self.addresses.part.clone();
        let mut links = links.clone();
        links.part = part.clone();
        let links = &links;
        let session = self.session(links)?;
        let for_ros2 = delivery.clone();
        let opened = if lockstep {
            lockstep::open(&session, &self.keys, &part, links)
                .map(|l| Box::new(l) as Box<dyn Connection>)
        } else {
            let pool = (!links.sending.is_empty()).then(|| self.shm_pool());
            let shm = free::Shm {
                pool,
                received: Arc::clone(&self.received_shared),
                enabled: self.shm_settings().enabled,
            };
            free::open(&session, &self.keys, &part, links, delivery, shm)
                .map(|l| Box::new(l) as Box<dyn Connection>)
        };
        // A part that is a ROS 2 node (a bundle's program) opens it on the same
        // session: its frames go to the node, the others to the parts (docs/ros2.md).
        let opened = opened.and_then(|conn| match links.ros2.is_empty() {
            true => Ok(conn),
            false => match ros2::network::Ros2Ends::open(&session, &links.ros2, for_ros2, lockstep)
            {
                Ok(ends) => Ok(Box::new(ros2::network::WithRos2::new(Some(conn), ends, None)) as _),
                Err(why) => {
                    conn.close();
                    Err(why)
                }
            },
        });
        if opened.is_err() {
            let _ = session.close().wait();
        }
        opened
    }
}
