//! The two ends of a connection between parts (see [`ferroc_link`]): the sending end
//! runs after the writer in the writer's container, the receiving end feeds the reader
//! like any output. Both reuse [`Builder::connect`], so conversions, queues and
//! wakeups behave exactly as on a connection inside one part.

use super::{BuildError, Builder, Conversion, Instance};
use ferroc_exec::Step;
use ferroc_link::transport::{RemoteCall, Sending};
use ferroc_link::{calls, CallSpec, LinkSpec, Pace, Receiving, Sharing};
use ferroc_module::lend::{Lender, LentBuffer};
use ferroc_module::{Interface, Kind, Timestamp, ValueType};
use ferroc_ports::port::{ConnectOptions, InputHandle, OutputHandle};
use std::sync::{Arc, Mutex};

impl Builder<'_> {
    /// The sending end of the link `spec.id`: values of `from` (module path, output),
    /// converted by `conversion` into the reader's type `spec.model_type`, are sent to
    /// the part `spec.to_part` as `spec.sharing` says.
    pub fn link_out(
        &mut self,
        spec: &LinkSpec<'_>,
        from: (&str, &str),
        conversion: Conversion,
    ) -> Result<(), BuildError> {
        let describe = format!("`{}/{}` → part `{}`", from.0, from.1, spec.to_part);
        let value_type = self.link_type(spec, &describe)?;
        let codec = *value_type.codec().expect("link_type checked it");
        let writer = self.module(from.0)?;
        let target = (spec.id, Arc::<str>::from(spec.to_part));
        let key = Fanout::key(spec, from);
        // Only links that carry the output's values unchanged can share one encoding.
        let unchanged = conversion == Conversion::default();
        if unchanged {
            if let Some(fanout) = self.fanouts.iter().find(|f| f.key == key) {
                lock(&fanout.targets).push(target);
                self.remote.sending.insert(spec.id, sending(spec, from));
                return Ok(());
            }
        }
        let (input, handle) = value_type.input(&format!("link {} out", spec.id), None);
        let end = self.link_end(
            format!("link {} out", spec.id),
            vec![("in".into(), handle)],
            vec![],
        );
        self.connect(from, (&end, "in"), conversion, ConnectOptions::default())?;
        let targets: Targets = Arc::new(Mutex::new(vec![target]));
        if unchanged {
            let targets = Arc::clone(&targets);
            let lender = HubLender {
                hub: Arc::clone(&self.hub),
                targets: Arc::clone(&targets),
            };
            (self.lending.links).push((writer, from.1.to_owned(), Arc::new(lender)));
            self.fanouts.push(Fanout { key, targets });
        }
        let hub = Arc::clone(&self.hub);
        let mut pace = Pace::new(spec.sharing);
        let mut failed = false;
        // The links are all known once the application runs: copied out at the first
        // value, not locked for every one.
        let mut sent_to: Option<Vec<(u32, Arc<str>)>> = None;
        let step = Step::new(describe.clone(), move || {
            if !pace.send_at(input.changed(), Timestamp::now) {
                return;
            }
            // Encoded once, into the buffer it travels in (shared memory for a large
            // value to another part on this computer), for every link it goes on.
            let targets = sent_to.get_or_insert_with(|| lock(&targets).clone());
            let mut sent = Ok(());
            let encoded = codec.encode_with(&input, &mut |encoder| {
                sent = hub.send_encoded(targets, encoder);
            });
            match encoded.and(sent) {
                Ok(()) => {}
                Err(why) if !std::mem::replace(&mut failed, true) => {
                    ferroc_ports::console::line(&format!("warning: {describe}: not sent: {why}"))
                }
                Err(_) => {}
            }
        });
        self.modules[writer].converters.push(step);
        self.remote.sending.insert(spec.id, sending(spec, from));
        Ok(())
    }

    /// The receiving end of the link `spec.id`: values arriving from the part
    /// `spec.from_part` are published into `to` (module path, input) with `options`.
    pub fn link_in(
        &mut self,
        spec: &LinkSpec<'_>,
        to: (&str, &str),
        options: ConnectOptions,
    ) -> Result<(), BuildError> {
        let describe = format!("part `{}` → `{}/{}`", spec.from_part, to.0, to.1);
        let value_type = self.link_type(spec, &describe)?;
        let codec = *value_type.codec().expect("link_type checked it");
        if self.receiving.contains_key(&spec.id) {
            return Err(BuildError::Connect(format!(
                "{describe}: the link {} is received twice",
                spec.id
            )));
        }
        let (out, handle) = value_type.output(&format!("link {} in", spec.id));
        let end = self.link_end(
            format!("link {} in", spec.id),
            vec![],
            vec![("out".into(), handle)],
        );
        self.connect((&end, "out"), to, Conversion::default(), options)?;
        let receiving =
            Receiving::new(out, codec, describe, spec.from_part).with_deadline(spec.deadline);
        // The input shows the link's freshness (`In::age`, `In::is_stale`).
        let reader = self.module(to.0)?;
        let input = super::find(&self.modules[reader].inputs, to, "input")?;
        let _ = input.source().set(Arc::clone(&receiving.fresh));
        self.receiving.insert(spec.id, receiving);
        (self.remote.receiving).insert(spec.id, spec.from_part.to_owned());
        Ok(())
    }

    /// The value-table entry of a link's type, which must be able to cross.
    fn link_type(&self, spec: &LinkSpec<'_>, describe: &str) -> Result<ValueType, BuildError> {
        let value_type = self.registry.values().get(spec.model_type).ok_or_else(|| {
            BuildError::Connect(format!(
                "{describe}: the type `{}` is not registered in this binary (its crate's \
                 register function should call `register_serde` for it)",
                spec.model_type
            ))
        })?;
        if value_type.codec().is_none() {
            return Err(BuildError::Connect(format!(
                "{describe}: values of `{}` cannot cross between parts: register it with \
                 `register_serde` (and mark it serde=\"true\" in its library manifest)",
                spec.model_type
            )));
        }
        Ok(*value_type)
    }

    /// A port-only instance standing for one end of a link (no module, no thread).
    pub(super) fn link_end(
        &mut self,
        path: String,
        inputs: Vec<(String, InputHandle)>,
        outputs: Vec<(String, OutputHandle)>,
    ) -> String {
        self.index.insert(path.clone(), self.modules.len());
        self.modules.push(Instance {
            path: path.clone(),
            kind: Kind::Plain,
            module: None,
            interface: Interface {
                name: "link".into(),
                rust: String::new(),
                kind: Kind::Plain,
                doc: None,
                ports: Vec::new(),
                params: Vec::new(),
                flexible: Vec::new(),
                services: Vec::new(),
            },
            inputs,
            outputs,
            lenders: Vec::new(),
            params: Vec::new(),
            services: Vec::new(),
            clients: Vec::new(),
            locks: Vec::new(),
            converters: Vec::new(),
            thread: None,
            link_end: true,
        });
        path
    }
}

impl Builder<'_> {
    /// The client's end of the call `spec.id`: the client `client` (module path,
    /// client name) calls, through the network, the service of `spec.server_part` that
    /// the other end ([`Builder::call_in`]) names.
    pub fn call_out(
        &mut self,
        spec: &CallSpec<'_>,
        client: (&str, &str),
    ) -> Result<(), BuildError> {
        let m = self.module(client.0)?;
        let describe = format!("`{}/{}` → part `{}`", client.0, client.1, spec.server_part);
        let handle = super::find(&self.modules[m].clients, client, "client")?;
        let ends = self.call_ends(handle.types(), &describe)?;
        let route = self.route(calls::request_link(spec.id), spec.server_part);
        let (service, end) = ends.remote_service(format!("{} (remote)", client.1), route);
        let handle = super::find(&self.modules[m].clients, client, "client")?;
        handle
            .connect(&service)
            .map_err(|e| BuildError::Connect(format!("{describe}: {e}")))?;
        self.direct_end(calls::answer_link(spec.id), end, &describe)?;
        self.remote.calls_out.insert(spec.id, remote_call(spec));
        Ok(())
    }

    /// The service's end of the call `spec.id`: requests from the client in
    /// `spec.client_part` are executed by the service `service` (module path, name).
    pub fn call_in(
        &mut self,
        spec: &CallSpec<'_>,
        service: (&str, &str),
    ) -> Result<(), BuildError> {
        let m = self.module(service.0)?;
        let describe = format!(
            "part `{}` → `{}/{}`",
            spec.client_part, service.0, service.1
        );
        let handle = super::find(&self.modules[m].services, service, "service")?;
        let ends = self.call_ends(handle.types(), &describe)?;
        let route = self.route(calls::answer_link(spec.id), spec.client_part);
        let (client, end) = ends.remote_client(format!("{} (remote)", service.1), route);
        let handle = super::find(&self.modules[m].services, service, "service")?;
        client
            .connect(handle)
            .map_err(|e| BuildError::Connect(format!("{describe}: {e}")))?;
        self.direct_end(calls::request_link(spec.id), end, &describe)?;
        self.remote.calls_in.insert(spec.id, remote_call(spec));
        Ok(())
    }

    /// Whether the calls of this client (module path, client name) can cross between
    /// parts: their request and response types are registered with `register_call`.
    pub fn can_call_across(&self, client: (&str, &str)) -> bool {
        let Ok(m) = self.module(client.0) else {
            return false;
        };
        super::find(&self.modules[m].clients, client, "client")
            .is_ok_and(|c| self.registry.call_ends(c.types()).is_some())
    }

    pub(super) fn call_ends(
        &self,
        types: (&str, &str),
        describe: &str,
    ) -> Result<calls::CallEnds, BuildError> {
        self.registry.call_ends(types).ok_or_else(|| {
            BuildError::Connect(format!(
                "{describe}: calls with requests `{}` and responses `{}` cannot cross between \
                 parts: register them with `register_call::<{}, {}>()`",
                types.0, types.1, types.0, types.1
            ))
        })
    }

    pub(super) fn route(&self, link: u32, to_part: &str) -> calls::Route {
        calls::Route {
            hub: Arc::clone(&self.hub),
            link,
            to_part: Arc::from(to_part),
            ros2: None,
        }
    }

    /// Registers an end that handles its frames itself, refusing a link built twice.
    pub(super) fn direct_end(
        &mut self,
        link: u32,
        end: Arc<dyn ferroc_link::Receive>,
        describe: &str,
    ) -> Result<(), BuildError> {
        if self.direct_ends.insert(link, end).is_some() {
            return Err(BuildError::Connect(format!(
                "{describe}: this link is received twice"
            )));
        }
        Ok(())
    }
}

/// The sending end of links that carry the values of one output, unchanged, to other
/// parts: one step encodes each value once and sends it on all of them (one buffer of
/// the pool and one message for 15 reading parts, not 15).
/// Outputs that feed links to other parts unchanged, and outputs read in this part:
/// an output of the first kind and not the second lends its module the network's
/// buffers (`ferroc_module::lend`), given at start ([`Builder::give_lenders`]).
#[derive(Default)]
pub(super) struct Lending {
    /// (module, output, its lender).
    links: Vec<(usize, String, Arc<dyn Lender>)>,
    /// (module, output) with a reader in this part (a module, a converter).
    read_here: Vec<(usize, String)>,
}

impl Builder<'_> {
    /// Notes that the output `output` of module `writer` has a reader in this part,
    /// unless `reader` is the sending end of a link.
    pub(super) fn note_reader(&mut self, writer: usize, output: &str, reader: usize) {
        if !self.modules[reader].link_end {
            (self.lending.read_here).push((writer, output.to_owned()));
        }
    }

    /// Gives each output whose only readers are links to other parts its lender: its
    /// module's large values are then written straight into the network's buffers.
    /// An output also read here lends plain memory (its readers here would hold the
    /// pool's buffers).
    pub(super) fn give_lenders(&mut self) {
        for (writer, output, lender) in std::mem::take(&mut self.lending.links) {
            let read_here =
                (self.lending.read_here.iter()).any(|(w, o)| *w == writer && *o == output);
            let slot = self.modules[writer]
                .lenders
                .iter()
                .find(|(o, _)| *o == output);
            if let (false, Some((_, slot))) = (read_here, slot) {
                slot.set(lender);
            }
        }
    }
}

/// Lends an output the buffers of the network its links leave by.
struct HubLender {
    hub: Arc<ferroc_link::Hub>,
    targets: Targets,
}

impl Lender for HubLender {
    fn lend(&self, len: usize) -> Option<Box<dyn LentBuffer>> {
        self.hub.lend(&lock(&self.targets), len)
    }
}

pub(super) struct Fanout {
    key: FanoutKey,
    /// The links and their reading parts.
    targets: Targets,
}

/// The links a sending step sends on (link number, reading part); more join while the
/// application is built.
type Targets = Arc<Mutex<Vec<(u32, Arc<str>)>>>;

/// What links must share to be sent as one: the output, the type, when and how.
#[derive(PartialEq)]
struct FanoutKey {
    from: (String, String),
    model_type: String,
    sharing: Sharing,
    reliable: bool,
}

impl Fanout {
    fn key(spec: &LinkSpec<'_>, from: (&str, &str)) -> FanoutKey {
        FanoutKey {
            from: (from.0.to_owned(), from.1.to_owned()),
            model_type: spec.model_type.to_owned(),
            sharing: spec.sharing,
            reliable: spec.reliable,
        }
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

fn sending(spec: &LinkSpec<'_>, from: (&str, &str)) -> Sending {
    Sending {
        to_part: spec.to_part.to_owned(),
        topic: format!("{}/{}", from.0, from.1),
        model_type: spec.model_type.to_owned(),
        sharing: spec.sharing,
        reliable: spec.reliable,
    }
}

fn remote_call(spec: &CallSpec<'_>) -> RemoteCall {
    RemoteCall {
        client_part: spec.client_part.to_owned(),
        server_part: spec.server_part.to_owned(),
        service: spec.service.to_owned(),
    }
}
