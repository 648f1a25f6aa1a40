//! ROS 2 interface definitions as data: what a `.msg` or `.srv` file says, with the place
//! of each field so that later findings can point at it.
use std::fmt;

/// The full name of a type: `package/msg/Name` or `package/srv/Name`.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct TypeName {
    pub package: String,
    /// `msg` or `srv` (the request, response and event messages of a service live in `srv`).
    pub kind: String,
    pub name: String,
}

impl TypeName {
    pub fn new(package: &str, kind: &str, name: &str) -> Self {
        TypeName {
            package: package.to_string(),
            kind: kind.to_string(),
            name: name.to_string(),
        }
    }

    /// Parses `pkg/msg/Name` (or `pkg/srv/Name`).
    pub fn parse(full: &str) -> Option<Self> {
        let mut it = full.split('/');
        let (p, k, n) = (it.next()?, it.next()?, it.next()?);
        (it.next().is_none() && !p.is_empty() && !n.is_empty() && (k == "msg" || k == "srv"))
            .then(|| TypeName::new(p, k, n))
    }

    /// The name DDS (and so rmw_zenoh's keys) uses: `geometry_msgs::msg::dds_::Twist_`.
    pub fn dds_name(&self) -> String {
        format!("{}::{}::dds_::{}_", self.package, self.kind, self.name)
    }
}

impl fmt::Display for TypeName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}/{}", self.package, self.kind, self.name)
    }
}

/// A primitive type of the `.msg` language.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Primitive {
    Bool,
    /// `byte` (IDL `octet`).
    Byte,
    /// `char` (IDL `uint8`, as rosidl maps it).
    Char,
    Float32,
    Float64,
    Int8,
    UInt8,
    Int16,
    UInt16,
    Int32,
    UInt32,
    Int64,
    UInt64,
}

impl Primitive {
    /// The `.msg` spelling.
    pub fn from_msg(s: &str) -> Option<Self> {
        use Primitive::*;
        Some(match s {
            "bool" => Bool,
            "byte" => Byte,
            "char" => Char,
            "float32" => Float32,
            "float64" => Float64,
            "int8" => Int8,
            "uint8" => UInt8,
            "int16" => Int16,
            "uint16" => UInt16,
            "int32" => Int32,
            "uint32" => UInt32,
            "int64" => Int64,
            "uint64" => UInt64,
            _ => return None,
        })
    }

    /// Size in bytes on the wire (and CDR alignment).
    pub fn size(self) -> usize {
        use Primitive::*;
        match self {
            Bool | Byte | Char | Int8 | UInt8 => 1,
            Int16 | UInt16 => 2,
            Float32 | Int32 | UInt32 => 4,
            Float64 | Int64 | UInt64 => 8,
        }
    }

    /// The `.msg` spelling.
    pub fn msg_name(self) -> &'static str {
        use Primitive::*;
        match self {
            Bool => "bool",
            Byte => "byte",
            Char => "char",
            Float32 => "float32",
            Float64 => "float64",
            Int8 => "int8",
            UInt8 => "uint8",
            Int16 => "int16",
            UInt16 => "uint16",
            Int32 => "int32",
            UInt32 => "uint32",
            Int64 => "int64",
            UInt64 => "uint64",
        }
    }
}

/// The element type of a field (before any array).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum BaseType {
    Primitive(Primitive),
    /// `string` or `string<=N`.
    String {
        bound: Option<u32>,
    },
    /// `wstring` or `wstring<=N` (parsed and hashed; CDR refuses it).
    WString {
        bound: Option<u32>,
    },
    /// A nested message, resolved to its full name while parsing.
    Nested(TypeName),
}

/// Whether a field is one value or an array, and of what size.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Arity {
    Single,
    /// `T[N]`.
    Fixed(u32),
    /// `T[<=N]`.
    Bounded(u32),
    /// `T[]`.
    Unbounded,
}

/// A field's type.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct FieldType {
    pub base: BaseType,
    pub arity: Arity,
}

/// Where something is in its file (1-based line and column).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Place {
    pub line: usize,
    pub col: usize,
}

/// A field of a message.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    pub name: String,
    pub ty: FieldType,
    /// The default value's text as written (validated against the type).
    pub default: Option<String>,
    /// The comments written on and above the field.
    pub comment: String,
    /// The unit a comment names in brackets (`# [m/s]`), as rosidl reads it.
    pub unit: Option<String>,
    /// Where the field's type starts.
    pub place: Place,
}

/// A constant (`uint8 OK=0`).
#[derive(Debug, Clone, PartialEq)]
pub struct Constant {
    pub name: String,
    pub ty: BaseType,
    /// The value's text as written (validated against the type).
    pub value: String,
    pub place: Place,
}

/// A message type: its fields in order and its constants.
#[derive(Debug, Clone, PartialEq)]
pub struct Message {
    pub name: TypeName,
    pub fields: Vec<Field>,
    pub constants: Vec<Constant>,
    /// The file it was read from (for messages).
    pub file: String,
}

/// A service type: its request and response messages (`Name_Request`, `Name_Response`).
#[derive(Debug, Clone, PartialEq)]
pub struct Service {
    pub name: TypeName,
    pub request: Message,
    pub response: Message,
    pub file: String,
}

impl Service {
    /// `pkg/srv/Name_Event`: the event message rosidl derives for every service.
    pub fn event_name(&self) -> TypeName {
        TypeName::new(
            &self.name.package,
            "srv",
            &format!("{}_Event", self.name.name),
        )
    }
}

/// The member rosidl adds to a structure without fields (IDL forbids empty structures);
/// it is hashed and sent on the wire as a `uint8`.
pub const EMPTY_STRUCT_MEMBER: &str = "structure_needs_at_least_one_member";
