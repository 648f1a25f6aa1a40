//! What the model says about ROS 2 (`<ros2>` in a part, `<ros2-external>`; docs/ros2.md):
//! the nodes, their topic and service ends with the ports behind them, as written. The
//! checks of area R (`checks/src/ros2/`) judge them; names are validated and expanded
//! there with `ferroc_ros2::names`, so a bad name is one finding, not a missing node.

use super::{ElementId, Endpoint};
use ferroc_diagnostics::source::{FileId, Span};
use hashbrown::HashSet;

/// Every ROS 2 node of the model and every external one it declares.
#[derive(Debug, Default)]
pub struct Ros2 {
    pub nodes: Vec<Ros2Node>,
    /// The ports a `<publish>`, `<subscribe>`, `<service>` or `<client>` names: they are
    /// connected to ROS 2, so "not connected" findings (T109, T110) pass them over.
    pub ports: HashSet<Endpoint>,
    /// The team packages `<ros2-interfaces>` adds, in model order.
    pub interfaces: Vec<Ros2Interfaces>,
}

impl Ros2 {
    /// Whether a port is published, subscribed, offered or called as a ROS 2 end.
    pub fn binds(&self, ep: Endpoint) -> bool {
        self.ports.contains(&ep)
    }
}

/// A text attribute with the span of its value.
pub type Spanned<T> = (T, Span);

/// A `<ros2>` (a part as a node) or a `<ros2-external>`.
#[derive(Debug)]
pub struct Ros2Node {
    /// The part; `None` for an external node.
    pub part: Option<ElementId>,
    /// The element's tag.
    pub span: Span,
    pub name: Spanned<String>,
    pub namespace: Option<Spanned<String>>,
    /// `domain=`, default 0.
    pub domain: u32,
    pub topics: Vec<Ros2Topic>,
    pub services: Vec<Ros2Service>,
}

impl Ros2Node {
    /// The namespace in force: the one written, else `/`.
    pub fn namespace(&self) -> &str {
        self.namespace.as_ref().map_or("/", |(n, _)| n)
    }

    /// Whether this is a node outside the model.
    pub fn is_external(&self) -> bool {
        self.part.is_none()
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TopicDirection {
    Publish,
    Subscribe,
}

/// A `<publish>` or `<subscribe>`.
#[derive(Debug)]
pub struct Ros2Topic {
    pub direction: TopicDirection,
    /// The element's tag.
    pub span: Span,
    /// The port behind it (model nodes only; `None` when the path did not resolve or
    /// the node is external).
    pub port: Option<Spanned<Endpoint>>,
    pub topic: Spanned<String>,
    /// The message type as written (`geometry_msgs/msg/Twist`).
    pub ty: Spanned<String>,
    /// `field="linear.x"`: the port carries this field of the message.
    pub field: Option<Spanned<String>>,
    /// `reliability=` written: `true` for `best-effort` (ROS 2's default is reliable).
    pub best_effort: Option<Spanned<bool>>,
    /// `durability=` written: `true` for `transient-local` (the default is volatile).
    pub transient_local: Option<Spanned<bool>>,
    pub depth: Option<Spanned<u32>>,
    /// `frame-id=` (published ends): the `header.frame_id` of a type its library maps
    /// to a message with a header (`ferroc_std.Image`).
    pub frame_id: Option<Spanned<String>>,
}

impl Ros2Topic {
    pub fn is_best_effort(&self) -> bool {
        self.best_effort.as_ref().is_some_and(|(b, _)| *b)
    }

    pub fn is_transient_local(&self) -> bool {
        self.transient_local.as_ref().is_some_and(|(t, _)| *t)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ServiceRole {
    Server,
    Client,
}

impl ServiceRole {
    /// The response type the module type declares for its service (server) or client
    /// `name`; `None` where it declares none or it did not resolve (reported).
    pub fn response<'m>(
        self,
        mt: &'m crate::library::ModuleType,
        name: &str,
    ) -> Option<&'m ferroc_values::types::Type> {
        match self {
            ServiceRole::Server => (mt.services.iter().find(|d| d.name == name))?
                .response
                .as_ref(),
            ServiceRole::Client => (mt.clients.iter().find(|d| d.name == name))?
                .response
                .as_ref(),
        }
    }
}

/// A `<service>` or `<client>` of a `<ros2>`.
#[derive(Debug)]
pub struct Ros2Service {
    pub role: ServiceRole,
    pub span: Span,
    pub port: Option<Spanned<Endpoint>>,
    pub name: Spanned<String>,
    pub ty: Spanned<String>,
}

/// A `<ros2-interfaces>`: a team's package and the definition files read from its
/// folder (into the model's sources, so findings point into them). Parsing and
/// judging them is R109's (`checks/src/ros2/`).
#[derive(Debug)]
pub struct Ros2Interfaces {
    /// The element's tag.
    pub span: Span,
    pub package: Spanned<String>,
    pub path: Spanned<String>,
    /// The files read (`msg/*.msg`, `srv/*.srv`, sorted by name), or why the folder
    /// could not be read (`None`: refused and reported already, as outside the model's
    /// folder).
    pub files: Result<Vec<Ros2InterfaceFile>, Option<String>>,
    /// Files of the folder that could not be read, each with why.
    pub unreadable: Vec<String>,
}

/// One definition file of a team's package.
#[derive(Debug, Clone)]
pub struct Ros2InterfaceFile {
    /// `msg` or `srv`.
    pub kind: &'static str,
    /// The type's name: the file's stem.
    pub name: String,
    pub file: FileId,
    /// Its text (also in the sources): what the plan hands the runtime.
    pub text: String,
}
