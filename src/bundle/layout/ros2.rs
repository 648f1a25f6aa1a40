//! The ROS 2 nodes of the parts (`<ros2>`): which part opens each, the library types
//! its topics carry, and the request and response types of its services and clients.

use ferroc_compiler::library::module_type::PortType;
use ferroc_compiler::plan::{PlannedModule, Ros2Node};
use ferroc_compiler::types::Type;

use super::super::text;
use super::Split;

impl<'p> Split<'_, 'p> {
    /// Each ROS 2 node into its part, which opens it; the services it offers are
    /// answered like calls from another part, so their request and response types are
    /// registered as calls (`register_call`).
    pub(super) fn place_ros2(&mut self, nodes: &'p [Ros2Node], modules: &'p [PlannedModule]) {
        for node in nodes {
            let Some(p) = self.parts.iter().position(|x| x.name == node.part) else {
                continue;
            };
            self.parts[p].ros2 = Some(node);
            for t in &node.topics {
                let Some((rust, library)) = self.topic_type(modules, &t.port) else {
                    continue; // a built-in type, registered with its serde form already
                };
                let part = &mut self.parts[p];
                part.use_library(&library);
                if !part.ros2_serde.contains(&rust) {
                    part.ros2_serde.push(rust);
                }
            }
            for s in node.services.iter().chain(&node.clients) {
                let Some(module) = modules.iter().find(|m| m.path == s.port.0) else {
                    continue; // the plan reported it
                };
                match self.service_types(module, &s.port.1) {
                    Some(pair) if !self.parts[p].call_types.contains(&pair) => {
                        self.parts[p].call_types.push(pair);
                    }
                    Some(_) => {}
                    None => self.problem(
                        module.span,
                        format!(
                            "the service or client `{}` of `{}` is a ROS 2 service end, but \
                             the generated code cannot name its request and response types: \
                             declare both in its manifest as Rust-named types",
                            s.port.1, s.port.0
                        ),
                    ),
                }
            }
        }
    }

    /// The Rust type and library of the library type of a ROS 2 topic's port (module
    /// path, port name); `None` for a built-in type.
    fn topic_type(
        &self,
        modules: &[PlannedModule],
        port: &(String, String),
    ) -> Option<(String, String)> {
        let module = modules.iter().find(|m| m.path == port.0)?;
        let (_, ty) = self.libs.module_type(&module.type_name)?;
        let decl = ty.ports.iter().find(|d| d.name == port.1)?;
        let PortType::Fixed(t @ Type::Named(id, _)) = &decl.ty else {
            return None;
        };
        let (rust, _) = super::super::fields::rust_type(self.libs, t)?;
        let library = &self.libs.get(self.libs.named_type(*id).library).name;
        text::is_rust_type(&rust).then(|| (rust, library.clone()))
    }

    /// The Rust request and response types of the service or client `name` of `module`.
    fn service_types(&self, module: &PlannedModule, name: &str) -> Option<(String, String)> {
        let (_, ty) = self.libs.module_type(&module.type_name)?;
        let services = ty.services.iter().map(|d| (&d.name, d.port, &d.response));
        let clients = ty.clients.iter().map(|d| (&d.name, d.port, &d.response));
        let (_, port, response) = services.chain(clients).find(|(n, _, _)| *n == name)?;
        let PortType::Fixed(request) = &ty.ports.get(port)?.ty else {
            return None;
        };
        let rust = |t: &Type| super::super::fields::rust_type(self.libs, t).map(|(r, _)| r);
        let pair = (rust(request)?, rust(response.as_ref()?)?);
        [&pair.0, &pair.1]
            .iter()
            .all(|t| text::is_rust_type(t))
            .then_some(pair)
    }
}
