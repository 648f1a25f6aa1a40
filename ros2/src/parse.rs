//! The `.msg` and `.srv` text format, as rosidl reads it (rosidl_adapter's parser): one
//! field (`TYPE NAME [DEFAULT]`) or constant (`TYPE NAME=VALUE`) a line, `#` comments,
//! and in a service one `---` line between request and response.
//!
//! Names are resolved while parsing: `pkg/Type` and `pkg/msg/Type` name another
//! package's message, a bare `Type` one of the same package (`Header` is std_msgs', as in
//! rosidl). Whether the named type exists, and whether nested types form a cycle, is the
//! [`Registry`](crate::Registry)'s question, since it needs every package.
use crate::def::{
    Arity, BaseType, Constant, Field, FieldType, Message, Place, Primitive, Service, TypeName,
};
use crate::error::DefinitionError;

/// The primitive types, for help texts.
const PRIMITIVES: &str =
    "bool, byte, char, float32, float64, int8, uint8, int16, uint16, int32, uint32, int64, \
     uint64, string, wstring";

/// Parses a `.msg` file's text: the message `package/msg/name`. `file` names it in errors.
pub fn parse_message(
    text: &str,
    package: &str,
    name: &str,
    file: &str,
) -> Result<Message, DefinitionError> {
    check_type_names(package, name, file)?;
    let lines: Vec<(usize, &str)> = text.lines().enumerate().map(|(i, l)| (i + 1, l)).collect();
    parse_body(&lines, TypeName::new(package, "msg", name), file)
}

/// Parses a `.srv` file's text: the service `package/srv/name`, its request and response
/// messages `name_Request` and `name_Response`.
pub fn parse_service(
    text: &str,
    package: &str,
    name: &str,
    file: &str,
) -> Result<Service, DefinitionError> {
    check_type_names(package, name, file)?;
    let lines: Vec<(usize, &str)> = text.lines().enumerate().map(|(i, l)| (i + 1, l)).collect();
    let separators: Vec<usize> = lines
        .iter()
        .enumerate()
        .filter(|(_, (_, l))| l.trim_end() == "---")
        .map(|(i, _)| i)
        .collect();
    let at = match separators.as_slice() {
        [one] => *one,
        [] => {
            return Err(DefinitionError::new(
                file,
                lines.len().max(1),
                1,
                "a service definition needs a `---` line between request and response".into(),
                "write the request's fields, then a line `---`, then the response's fields",
            ))
        }
        [_, second, ..] => {
            return Err(DefinitionError::new(
                file,
                lines[*second].0,
                1,
                "a service definition has one `---` line; this is a second one".into(),
                "keep one `---` between request and response (actions, with two, are not \
                 supported)",
            ))
        }
    };
    let service = TypeName::new(package, "srv", name);
    let request = parse_body(
        &lines[..at],
        TypeName::new(package, "srv", &format!("{name}_Request")),
        file,
    )?;
    let response = parse_body(
        &lines[at + 1..],
        TypeName::new(package, "srv", &format!("{name}_Response")),
        file,
    )?;
    Ok(Service {
        name: service,
        request,
        response,
        file: file.to_string(),
    })
}

/// The package's and the type's own names follow ROS 2's rules.
fn check_type_names(package: &str, name: &str, file: &str) -> Result<(), DefinitionError> {
    if !valid_package_name(package) {
        return Err(DefinitionError::new(
            file,
            1,
            1,
            format!("`{package}` is not a valid ROS 2 package name"),
            "a package name is lower case letters, digits and single underscores, starting \
             with a letter (rename the package's folder)",
        ));
    }
    if !valid_type_name(name) {
        return Err(DefinitionError::new(
            file,
            1,
            1,
            format!("`{name}` is not a valid ROS 2 type name"),
            "a type name starts with a capital letter and has only letters and digits \
             (rename the file)",
        ));
    }
    Ok(())
}

/// `^[a-z][a-z0-9_]*$` without `__` or a trailing `_` (rosidl's package and field names).
fn valid_package_name(s: &str) -> bool {
    let mut chars = s.chars();
    chars.next().is_some_and(|c| c.is_ascii_lowercase())
        && chars.all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
        && !s.contains("__")
        && !s.ends_with('_')
}

/// `^[A-Z][A-Za-z0-9]*$`.
fn valid_type_name(s: &str) -> bool {
    let mut chars = s.chars();
    chars.next().is_some_and(|c| c.is_ascii_uppercase()) && chars.all(|c| c.is_ascii_alphanumeric())
}

/// `^[A-Z]([A-Z0-9_]?[A-Z0-9]+)*$`: upper case, single underscores, none at the end.
fn valid_constant_name(s: &str) -> bool {
    let mut chars = s.chars();
    chars.next().is_some_and(|c| c.is_ascii_uppercase())
        && chars.all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
        && !s.contains("__")
        && !s.ends_with('_')
}

/// One message body: lines (with their 1-based numbers) of fields and constants.
fn parse_body(
    lines: &[(usize, &str)],
    name: TypeName,
    file: &str,
) -> Result<Message, DefinitionError> {
    let mut message = Message {
        name,
        fields: Vec::new(),
        constants: Vec::new(),
        file: file.to_string(),
    };
    let mut pending = String::new();
    // Comments above the first blank line describe the file, not the first field.
    let mut header = true;
    for &(number, line) in lines {
        let (code, comment) = match line.find('#') {
            Some(i) => (&line[..i], Some(&line[i + 1..])),
            None => (line, None),
        };
        if code.trim().is_empty() {
            match comment {
                Some(c) if !header => {
                    pending.push_str(c.trim());
                    pending.push('\n');
                }
                Some(_) => {}
                None => {
                    header = false;
                    pending.clear();
                }
            }
            continue;
        }
        header = false;
        let mut text = std::mem::take(&mut pending);
        if let Some(c) = comment {
            text.push_str(c.trim());
        }
        parse_line(&mut message, code, number, text.trim_end().to_string())?;
    }
    Ok(message)
}

/// One line with code: a field or a constant.
fn parse_line(
    message: &mut Message,
    code: &str,
    number: usize,
    comment: String,
) -> Result<(), DefinitionError> {
    let file = message.file.clone();
    let indent = code.len() - code.trim_start().len();
    let code = code.trim();
    let col = |byte: usize| code[..byte].chars().count() + indent + 1;
    let err = |byte: usize, msg: String, help: &str| {
        DefinitionError::new(&file, number, col(byte), msg, help)
    };
    let type_end = code.find(char::is_whitespace).ok_or_else(|| {
        err(
            0,
            format!("`{code}` is a type without a name"),
            "a field is written `TYPE NAME` (e.g. `float64 x`), a constant `TYPE NAME=VALUE`",
        )
    })?;
    let type_text = &code[..type_end];
    let rest_start = type_end + (code[type_end..].len() - code[type_end..].trim_start().len());
    let rest = &code[rest_start..];
    let place = Place {
        line: number,
        col: col(0),
    };
    let ty =
        parse_type(type_text, &message.name.package).map_err(|(msg, help)| err(0, msg, &help))?;
    if let Some(eq) = rest.find('=') {
        let name = rest[..eq].trim_end();
        let value = rest[eq + 1..].trim();
        if !valid_constant_name(name) {
            return Err(err(
                rest_start,
                format!("`{name}` is not a valid constant name"),
                "a constant's name is upper case letters, digits and single underscores \
                 (e.g. `MAX_SPEED`)",
            ));
        }
        let base = match (&ty.base, ty.arity) {
            (BaseType::Primitive(_) | BaseType::String { .. }, Arity::Single) => ty.base,
            _ => {
                return Err(err(
                    0,
                    format!("constant `{name}` has type `{type_text}`; a constant is a primitive or a string"),
                    "give the constant a primitive type (e.g. `uint8`) or `string`",
                ))
            }
        };
        let value_at =
            rest_start + eq + 1 + (rest[eq + 1..].len() - rest[eq + 1..].trim_start().len());
        check_value(&base, Arity::Single, value)
            .map_err(|m| err(value_at, m, "write a value of the constant's type"))?;
        message.constants.push(Constant {
            name: name.to_string(),
            ty: base,
            value: value.to_string(),
            place,
        });
        return Ok(());
    }
    let name_end = rest.find(char::is_whitespace).unwrap_or(rest.len());
    let name = &rest[..name_end];
    if !valid_package_name(name) {
        return Err(err(
            rest_start,
            format!("`{name}` is not a valid field name"),
            "a field's name is lower case letters, digits and single underscores, starting \
             with a letter (e.g. `angular_velocity`)",
        ));
    }
    if message.fields.iter().any(|f| f.name == name) {
        return Err(err(
            rest_start,
            format!("field `{name}` is defined twice"),
            "give each field its own name",
        ));
    }
    let default = rest[name_end..].trim();
    let default = if default.is_empty() {
        None
    } else {
        if matches!(ty.base, BaseType::Nested(_)) {
            return Err(err(
                rest_start + name_end,
                format!("field `{name}` of a message type cannot have a default value"),
                "remove the default; only primitive and string fields have defaults",
            ));
        }
        let at =
            rest_start + name_end + (rest[name_end..].len() - rest[name_end..].trim_start().len());
        check_value(&ty.base, ty.arity, default)
            .map_err(|m| err(at, m, "write a default of the field's type"))?;
        Some(default.to_string())
    };
    message.fields.push(Field {
        name: name.to_string(),
        ty,
        default,
        unit: unit_of(&comment),
        comment,
        place,
    });
    Ok(())
}

/// A type as written: `float64`, `string<=10`, `Point[]`, `geometry_msgs/Pose[<=5]`, …
fn parse_type(text: &str, package: &str) -> Result<FieldType, (String, String)> {
    let (base_text, arity) = match text.find('[') {
        Some(open) => {
            let inner = text[open + 1..].strip_suffix(']').ok_or_else(|| {
                (
                    format!("`{text}`: an array type ends with `]`"),
                    "write `T[]`, `T[N]` or `T[<=N]`".to_string(),
                )
            })?;
            let arity = if inner.is_empty() {
                Arity::Unbounded
            } else if let Some(n) = inner.strip_prefix("<=") {
                Arity::Bounded(parse_bound(n, text)?)
            } else {
                Arity::Fixed(parse_bound(inner, text)?)
            };
            (&text[..open], arity)
        }
        None => (text, Arity::Single),
    };
    let base = parse_base(base_text, package)?;
    Ok(FieldType { base, arity })
}

/// The size of an array or the bound of a string: a positive integer.
fn parse_bound(n: &str, text: &str) -> Result<u32, (String, String)> {
    n.parse::<u32>().ok().filter(|n| *n > 0).ok_or_else(|| {
        (
            format!("`{text}`: `{n}` is not a size (a positive whole number)"),
            "write the size as digits, e.g. `float64[3]` or `string<=16`".to_string(),
        )
    })
}

/// The element type, resolving a message name against the file's package.
fn parse_base(text: &str, package: &str) -> Result<BaseType, (String, String)> {
    if let Some(p) = Primitive::from_msg(text) {
        return Ok(BaseType::Primitive(p));
    }
    for (word, wide) in [("string", false), ("wstring", true)] {
        if let Some(rest) = text.strip_prefix(word) {
            let bound = match rest {
                "" => None,
                _ => match rest.strip_prefix("<=") {
                    Some(n) => Some(parse_bound(n, text)?),
                    None => continue,
                },
            };
            return Ok(if wide {
                BaseType::WString { bound }
            } else {
                BaseType::String { bound }
            });
        }
    }
    if text == "time" || text == "duration" {
        return Err((
            format!("`{text}` is a ROS 1 type"),
            "use `builtin_interfaces/Time` or `builtin_interfaces/Duration`".to_string(),
        ));
    }
    let parts: Vec<&str> = text.split('/').collect();
    let name = match parts.as_slice() {
        [name] if *name == "Header" => TypeName::new("std_msgs", "msg", "Header"),
        [name] => TypeName::new(package, "msg", name),
        [pkg, name] => TypeName::new(pkg, "msg", name),
        [pkg, "msg", name] => TypeName::new(pkg, "msg", name),
        _ => return Err(unknown(text)),
    };
    if !valid_package_name(&name.package) || !valid_type_name(&name.name) {
        return Err(unknown(text));
    }
    Ok(BaseType::Nested(name))
}

/// A type that is neither primitive nor a message name.
fn unknown(text: &str) -> (String, String) {
    (
        format!("unknown type `{text}`: not a primitive type and not a message type's name"),
        format!(
            "the primitive types are {PRIMITIVES}; a message type is `Name` (same package) or \
             `package/Name`"
        ),
    )
}

/// The unit in a comment, as rosidl reads it: exactly one `[...]` without a comma.
fn unit_of(comment: &str) -> Option<String> {
    let mut found = Vec::new();
    let mut rest = comment;
    while let Some(open) = rest.find('[') {
        let after = &rest[open + 1..];
        match after.find(']') {
            Some(close) => {
                let inner = &after[..close];
                if !inner.is_empty() && !inner.contains(',') && !inner.contains('[') {
                    found.push(inner.trim().to_string());
                }
                rest = &after[close + 1..];
            }
            None => break,
        }
    }
    (found.len() == 1).then(|| found.remove(0))
}

/// Checks a default or constant value's text against its type.
fn check_value(base: &BaseType, arity: Arity, text: &str) -> Result<(), String> {
    if arity != Arity::Single {
        let inner = text
            .strip_prefix('[')
            .and_then(|t| t.strip_suffix(']'))
            .ok_or_else(|| format!("`{text}`: an array's default is written `[a, b, c]`"))?;
        let items = split_items(inner);
        match arity {
            Arity::Fixed(n) if items.len() != n as usize => {
                return Err(format!(
                    "`{text}` has {} values; the array has {n}",
                    items.len()
                ))
            }
            Arity::Bounded(n) if items.len() > n as usize => {
                return Err(format!(
                    "`{text}` has {} values; the array holds at most {n}",
                    items.len()
                ))
            }
            _ => {}
        }
        return items
            .iter()
            .try_for_each(|item| check_value(base, Arity::Single, item));
    }
    let bad = || format!("`{text}` is not a value of type `{}`", base_name(base));
    match base {
        BaseType::Primitive(p) => check_primitive(*p, text).ok_or_else(bad),
        BaseType::String { bound } | BaseType::WString { bound } => {
            let s = unquote(text);
            match bound {
                Some(b) if s.chars().count() > *b as usize => {
                    Err(format!("`{text}` is longer than the string's bound of {b}"))
                }
                _ => Ok(()),
            }
        }
        BaseType::Nested(_) => Err(bad()),
    }
}

fn base_name(base: &BaseType) -> String {
    match base {
        BaseType::Primitive(p) => p.msg_name().to_string(),
        BaseType::String { .. } => "string".into(),
        BaseType::WString { .. } => "wstring".into(),
        BaseType::Nested(n) => n.to_string(),
    }
}

fn check_primitive(p: Primitive, text: &str) -> Option<()> {
    use Primitive::*;
    let int = |lo: i128, hi: i128| {
        text.parse::<i128>()
            .ok()
            .filter(|v| (lo..=hi).contains(v))
            .map(|_| ())
    };
    match p {
        Bool => matches!(
            text.to_ascii_lowercase().as_str(),
            "true" | "false" | "1" | "0"
        )
        .then_some(()),
        Float32 | Float64 => text.parse::<f64>().ok().map(|_| ()),
        Int8 => int(i8::MIN.into(), i8::MAX.into()),
        Byte | Char | UInt8 => int(0, u8::MAX.into()),
        Int16 => int(i16::MIN.into(), i16::MAX.into()),
        UInt16 => int(0, u16::MAX.into()),
        Int32 => int(i32::MIN.into(), i32::MAX.into()),
        UInt32 => int(0, u32::MAX.into()),
        Int64 => int(i64::MIN.into(), i64::MAX.into()),
        UInt64 => int(0, u64::MAX.into()),
    }
}

/// A string value without its quotes (`"a"`, `'a'` or bare `a`).
fn unquote(text: &str) -> &str {
    for q in ['"', '\''] {
        if let Some(inner) = text.strip_prefix(q).and_then(|t| t.strip_suffix(q)) {
            return inner;
        }
    }
    text
}

/// The items of an array literal, split at commas outside quotes.
fn split_items(inner: &str) -> Vec<&str> {
    if inner.trim().is_empty() {
        return Vec::new();
    }
    let mut items = Vec::new();
    let mut quote = None;
    let mut start = 0;
    for (i, c) in inner.char_indices() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, ',') => {
                items.push(inner[start..i].trim());
                start = i + 1;
            }
            _ => {}
        }
    }
    items.push(inner[start..].trim());
    items
}
