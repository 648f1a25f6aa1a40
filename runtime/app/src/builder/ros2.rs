//! A part's ROS 2 node (issue 29, docs/ros2.md): each published port gets a sending
//! end, each subscribed port a receiving end, both on the topic's link number
//! ([`ferroc_link::ros2`]). Values cross as the message's CDR, written straight from
//! the port's value and read straight into it (`Codec::ros2_encode`/`ros2_decode`, no
//! intermediate form, floats exact); the network (`ferroc_zenoh::ros2`) sends and
//! receives the samples with rmw_zenoh's keys and attachments.

use super::{BuildError, Builder, Conversion};
use ferroc_exec::Step;
use ferroc_link::ros2::{self, Ros2Node, Ros2Service, Ros2Topic, ServiceMessages};
use ferroc_link::{Frame, Receive};
use ferroc_module::{Codec, DynOut, ValueType};
use ferroc_ports::port::ConnectOptions;
use ferroc_ros2::serde_cdr::Shape;
use ferroc_ros2::Registry;
use std::sync::Arc;

impl Builder<'_> {
    /// Declares the ROS 2 node `node`: a sending end after the writer of every
    /// published port, a receiving end before the reader of every subscribed one. The
    /// network given at start declares the node and its topics.
    pub fn ros2_node(&mut self, node: Ros2Node) -> Result<(), BuildError> {
        let reg = ros2::node_registry(&node)
            .map_err(|why| BuildError::Connect(format!("ROS 2 node `{}`: {why}", node.name)))?;
        // Recordings see which ports are topics, and in which definitions.
        ferroc_link::ros2_wire::add_node(&node)
            .map_err(|why| BuildError::Connect(format!("ROS 2 node `{}`: {why}", node.name)))?;
        for topic in &node.topics {
            let port = (topic.port.0.as_str(), topic.port.1.as_str());
            if topic.publish {
                self.ros2_publish(topic, reg, port)?;
            } else {
                self.ros2_subscribe(topic, reg, port)?;
            }
        }
        for service in &node.services {
            self.ros2_serve(service, reg)?;
        }
        for client in &node.clients {
            self.ros2_call(client, reg)?;
        }
        self.remote.ros2.push(node);
        Ok(())
    }

    /// The end publishing every new value of `from` (module path, output) on the topic.
    fn ros2_publish(
        &mut self,
        topic: &Ros2Topic,
        reg: &'static Registry,
        from: (&str, &str),
    ) -> Result<(), BuildError> {
        let describe = format!("`{}/{}` → ROS 2 topic `{}`", from.0, from.1, topic.topic);
        let (value_type, codec) = self.ros2_type(topic, &describe)?;
        let shape = shape(topic, reg, &describe)?;
        let writer = self.module(from.0)?;
        let name = format!("ros2 {} out", ros2::link(topic.id));
        let (input, handle) = value_type.input(&name, None);
        let end = self.link_end(name, vec![("in".into(), handle)], vec![]);
        self.connect(
            from,
            (&end, "in"),
            Conversion::default(),
            ConnectOptions::default(),
        )?;
        let hub = Arc::clone(&self.hub);
        let (link, to) = (ros2::link(topic.id), Arc::<str>::from("ROS 2"));
        let frame_id = topic.frame_id.clone();
        let mut failed = false;
        let step = Step::new(describe.clone(), move || {
            if !input.changed() {
                return;
            }
            let mut bytes = Vec::new();
            match codec.ros2_encode_framed(&input, &shape, &frame_id, &mut bytes) {
                Ok(()) => hub.send(&to, Frame { link, bytes }),
                Err(why) if !std::mem::replace(&mut failed, true) => {
                    ferroc_ports::console::line(&format!("warning: {describe}: not sent: {why}"))
                }
                Err(_) => {}
            }
        });
        self.modules[writer].converters.push(step);
        Ok(())
    }

    /// The end publishing what arrives from the topic into `to` (module path, input).
    fn ros2_subscribe(
        &mut self,
        topic: &Ros2Topic,
        reg: &'static Registry,
        to: (&str, &str),
    ) -> Result<(), BuildError> {
        let describe = format!("ROS 2 topic `{}` → `{}/{}`", topic.topic, to.0, to.1);
        let (value_type, codec) = self.ros2_type(topic, &describe)?;
        let shape = shape(topic, reg, &describe)?;
        let name = ros2::subscriber_end(topic.id);
        let (out, handle) = value_type.output(&name);
        let end = self.link_end(name, vec![], vec![("out".into(), handle)]);
        self.connect(
            (&end, "out"),
            to,
            Conversion::default(),
            ConnectOptions::default(),
        )?;
        let end = Arc::new(CdrEnd {
            out,
            codec,
            shape,
            topic: topic.topic.clone(),
            describe: describe.clone(),
        });
        self.direct_end(ros2::link(topic.id), end, &describe)
    }

    /// The stand-in client calling the module's service for each request of the ROS 2
    /// service (as a call from another part does, its requests and answers as the CDR
    /// of the service's messages).
    fn ros2_serve(
        &mut self,
        service: &Ros2Service,
        reg: &'static Registry,
    ) -> Result<(), BuildError> {
        let at = (service.port.0.as_str(), service.port.1.as_str());
        let describe = format!("ROS 2 service `{}` → `{}/{}`", service.name, at.0, at.1);
        let m = self.module(at.0)?;
        let handle = super::find(&self.modules[m].services, at, "service")?;
        let ends = self.call_ends(handle.types(), &describe)?;
        let mut route = self.route(ros2::answer_link(service.id), "ROS 2");
        route.ros2 = Some(service_messages(service, reg, &describe)?);
        let (client, end) = ends.remote_client(format!("{} (ROS 2)", at.1), route);
        let handle = super::find(&self.modules[m].services, at, "service")?;
        client
            .connect(handle)
            .map_err(|e| BuildError::Connect(format!("{describe}: {e}")))?;
        self.direct_end(ros2::request_link(service.id), end, &describe)
    }

    /// The stand-in service the module's client calls: each call goes to the network as
    /// a request of the ROS 2 service (CDR), the answer comes back on the answer link.
    fn ros2_call(
        &mut self,
        client: &Ros2Service,
        reg: &'static Registry,
    ) -> Result<(), BuildError> {
        let at = (client.port.0.as_str(), client.port.1.as_str());
        let describe = format!("`{}/{}` → ROS 2 service `{}`", at.0, at.1, client.name);
        let m = self.module(at.0)?;
        let handle = super::find(&self.modules[m].clients, at, "client")?;
        let ends = self.call_ends(handle.types(), &describe)?;
        let mut route = self.route(ros2::request_link(client.id), "ROS 2");
        route.ros2 = Some(service_messages(client, reg, &describe)?);
        let (service, end) = ends.remote_service(format!("{} (ROS 2)", client.name), route);
        let handle = super::find(&self.modules[m].clients, at, "client")?;
        handle
            .connect(&service)
            .map_err(|e| BuildError::Connect(format!("{describe}: {e}")))?;
        self.direct_end(ros2::answer_link(client.id), end, &describe)
    }

    /// The value-table entry of a ROS 2 end's port type, which must have a serde form.
    fn ros2_type(
        &self,
        topic: &Ros2Topic,
        describe: &str,
    ) -> Result<(ValueType, Codec), BuildError> {
        let value_type = self
            .registry
            .values()
            .get(&topic.model_type)
            .ok_or_else(|| {
                BuildError::Connect(format!(
                    "{describe}: the type `{}` is not registered in this binary (its crate's \
                 register function should call `register_serde` for it)",
                    topic.model_type
                ))
            })?;
        let codec = *value_type.codec().ok_or_else(|| {
            BuildError::Connect(format!(
                "{describe}: values of `{}` have no serde form, which a ROS 2 message is \
                 made from: register it with `register_serde` (and mark it serde=\"true\" \
                 in its library manifest)",
                topic.model_type
            ))
        })?;
        Ok((*value_type, codec))
    }
}

/// The message (or field) of a topic end, from the node's definitions.
fn shape(
    topic: &Ros2Topic,
    reg: &'static Registry,
    describe: &str,
) -> Result<Shape<'static>, BuildError> {
    ros2::topic_shape(topic, reg).map_err(|why| BuildError::Connect(format!("{describe}: {why}")))
}

/// The request and response messages of a service end.
fn service_messages(
    service: &Ros2Service,
    reg: &'static Registry,
    describe: &str,
) -> Result<Arc<ServiceMessages>, BuildError> {
    ServiceMessages::new(service, reg)
        .map(Arc::new)
        .map_err(|why| BuildError::Connect(format!("{describe}: {why}")))
}

/// The receiving end of a subscribed topic: a sample's CDR (the message, of which the
/// port carries all or one field) decoded into the port. A sample that does not decode
/// (a foreign node's malformed one) is reported, throttled and naming the topic, and
/// dropped; the part keeps running.
struct CdrEnd {
    out: DynOut,
    codec: Codec,
    shape: Shape<'static>,
    topic: String,
    describe: String,
}

impl Receive for CdrEnd {
    fn receive(&self, bytes: &[u8]) -> Result<(), String> {
        if let Err(why) = self.codec.ros2_decode(&self.out, &self.shape, bytes) {
            ferroc_ports::console::report_as(
                &format!("ROS 2 topic `{}`: decode", self.topic),
                &format!(
                    "warning: a sample of the ROS 2 topic `{}` was dropped ({}): {why}",
                    self.topic, self.describe
                ),
            );
        }
        Ok(())
    }
}
