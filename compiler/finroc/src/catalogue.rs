//! The catalogue of FINROC component types: what a `(group, type)` pair creates.
//!
//! FINROC's files hold only what finstruct made; ports, types and units, and the
//! content a C++ constructor builds, are in the C++ sources. The catalogue states them
//! (`components/finroc/`, built in): module types as ferroc library manifests (one per
//! FINROC shared library; port names formed from the member names by port_name_builder's
//! rule), composite types in FINROC's own file format (`groups/*.xml`: interfaces, the
//! children and edges their constructors create, the group file they load).

use super::finstructable::Finstructable;
use super::text::finroc_port_name;
use ferroc_diagnostics::diagnostic::Diagnostics;
use ferroc_diagnostics::source::FileId;
use ferroc_syntax::{xml, Element as Xml};
use std::collections::HashMap;
use std::sync::OnceLock;

/// The built-in catalogue files: (name, text).
pub const FILES: &[(&str, &str)] = &[
    (
        "finroc_projects_crash_course.lib.xml",
        include_str!("../../../components/finroc/finroc_projects_crash_course.lib.xml"),
    ),
    (
        "finroc_projects_crash_course_control.lib.xml",
        include_str!("../../../components/finroc/finroc_projects_crash_course_control.lib.xml"),
    ),
    (
        "finroc_plugins_ib2c.lib.xml",
        include_str!("../../../components/finroc/finroc_plugins_ib2c.lib.xml"),
    ),
    (
        "finroc_projects_robprak_2024_2.lib.xml",
        include_str!("../../../components/finroc/finroc_projects_robprak_2024_2.lib.xml"),
    ),
    (
        "groups/finroc_projects_robprak_2024_2.xml",
        include_str!("../../../components/finroc/groups/finroc_projects_robprak_2024_2.xml"),
    ),
    (
        "finroc_projects_stereo_traversability_experiments_recognition.lib.xml",
        include_str!(
            "../../../components/finroc/finroc_projects_stereo_traversability_experiments_recognition.lib.xml"
        ),
    ),
    (
        "groups/finroc_projects_stereo_traversability_experiments.xml",
        include_str!(
            "../../../components/finroc/groups/finroc_projects_stereo_traversability_experiments.xml"
        ),
    ),
    (
        "groups/finroc_projects_rc_unimog_control.xml",
        include_str!("../../../components/finroc/groups/finroc_projects_rc_unimog_control.xml"),
    ),
    (
        "groups/finroc_projects_crash_course.xml",
        include_str!("../../../components/finroc/groups/finroc_projects_crash_course.xml"),
    ),
    (
        "groups/finroc_projects_crash_course_control.xml",
        include_str!("../../../components/finroc/groups/finroc_projects_crash_course_control.xml"),
    ),
    (
        "groups/finroc_plugins_structure.xml",
        include_str!("../../../components/finroc/groups/finroc_plugins_structure.xml"),
    ),
];

/// A port of a component type.
#[derive(Clone, Debug)]
pub struct Port {
    pub interface: String,
    /// FINROC's name (`Ir Distance Front`).
    pub name: String,
    /// The ferroc name (the C++ member: `ir_distance_front`).
    pub member: String,
    /// The rrlib type name (`double`, `rrlib.localization.Pose2D`).
    pub ty: String,
    pub unit: Option<String>,
    pub output: bool,
}

/// A component type.
#[derive(Clone, Debug)]
pub struct Component {
    pub library: String,
    pub name: String,
    pub composite: bool,
    pub interfaces: Vec<String>,
    pub ports: Vec<Port>,
    /// Ports also come from files or finstruct: an unlisted port is not known missing.
    pub open: bool,
    /// Static parameters (FINROC names) with their unit.
    pub params: Vec<(String, Option<String>)>,
    /// What the constructor of a composite builds (children, edges).
    pub content: Option<Finstructable>,
    /// The group file the constructor loads.
    pub xml_file: Option<String>,
}

impl Component {
    pub fn port(&self, interface: &str, name: &str) -> Option<&Port> {
        self.ports
            .iter()
            .find(|p| p.interface == interface && p.name == name)
    }

    pub fn param(&self, name: &str) -> Option<&(String, Option<String>)> {
        self.params.iter().find(|(n, _)| n == name)
    }
}

#[derive(Default)]
pub struct Catalogue {
    pub components: HashMap<(String, String), Component>,
    /// rrlib type name → ferroc type (`double` → `f64`, `rrlib.localization.Pose2D` →
    /// `finroc_projects_crash_course.Pose2D`), for writing ferroc models.
    pub ferroc_types: HashMap<String, String>,
}

impl Catalogue {
    pub fn get(&self, library: &str, ty: &str) -> Option<&Component> {
        self.components.get(&(library.to_string(), ty.to_string()))
    }

    /// A component type by its type name alone, when exactly one library registers it.
    pub fn by_type(&self, ty: &str) -> Option<&Component> {
        let mut found = self.components.values().filter(|c| c.name == ty);
        let first = found.next()?;
        found.next().is_none().then_some(first)
    }
}

/// The built-in catalogue, read once.
pub fn builtin() -> &'static Catalogue {
    static CATALOGUE: OnceLock<Catalogue> = OnceLock::new();
    CATALOGUE.get_or_init(|| {
        let mut c = Catalogue::default();
        for (name, text) in FILES {
            let Ok(root) = xml::parse(FileId(u32::MAX), text, 64) else {
                continue;
            };
            if name.ends_with(".lib.xml") {
                manifest(&root, &mut c);
            } else {
                groups(&root, &mut c);
            }
        }
        c
    })
}

/// FINROC's interface names for a base class.
pub fn interfaces_of(base: &str, thread: bool, ib2c: bool) -> Vec<String> {
    let mut v: Vec<&str> = match base {
        "SenseControlGroup" | "sense-control" => vec![
            "Sensor Input",
            "Sensor Output",
            "Controller Input",
            "Controller Output",
        ],
        _ => vec!["Input", "Output"],
    };
    v.push("Parameters");
    if thread {
        v.push("Profiling");
    }
    if ib2c {
        v.extend(["iB2C Input", "iB2C Output"]);
    }
    v.into_iter().map(str::to_string).collect()
}

/// A ferroc type name as rrlib names it.
fn rrlib_type(ty: &str, named: &HashMap<String, String>) -> String {
    match ty {
        "f64" => "double",
        "f32" => "float",
        "i8" => "int8",
        "i16" => "int16",
        "i32" => "int32",
        "i64" => "int64",
        "u8" => "uint8",
        "u16" => "uint16",
        "u32" => "uint32",
        "u64" => "uint64",
        "bool" => "bool",
        "string" => "String",
        other => {
            return named
                .get(other)
                .cloned()
                .unwrap_or_else(|| other.to_string())
        }
    }
    .to_string()
}

/// FINROC's name of a manifest port or parameter: the name its C++ constructor gives it
/// explicitly (`doc="FINROC: ZED Cam Image"`), else port_name_builder's from the member
/// name, which drops a prefix naming the port's kind (`si_us_front` of a sensor input →
/// `Us Front`).
fn finroc_name(p: &Xml, tag: &str) -> String {
    if let Some(explicit) = p.value("doc").and_then(|d| d.strip_prefix("FINROC: ")) {
        return explicit.to_string();
    }
    let member = p.value("name").unwrap_or_default();
    let prefixes: &[&str] = match tag {
        "sensor-in" => &["si_"],
        "sensor-out" => &["so_"],
        "controller-in" => &["ci_"],
        "controller-out" => &["co_"],
        "in" => &["in_"],
        "out" => &["out_"],
        "param" => &["par_"],
        _ => &[],
    };
    let stripped = prefixes
        .iter()
        .find_map(|x| member.strip_prefix(x).filter(|r| !r.is_empty()))
        .unwrap_or(member);
    finroc_port_name(stripped)
}

fn manifest(root: &Xml, c: &mut Catalogue) {
    let library = root.value("name").unwrap_or_default().to_string();
    let named = named_types(root, &library, c);
    for m in root.children_named("module-type") {
        let component = module_component(m, &library, &named, c);
        c.components.insert(
            (component.library.clone(), component.name.clone()),
            component,
        );
    }
}

/// Named types: `rust="finroc::rrlib::localization::tPose2D"` → `rrlib.localization.Pose2D`.
/// Registers each in the catalogue; returns ferroc's name → rrlib's name.
fn named_types(root: &Xml, library: &str, c: &mut Catalogue) -> HashMap<String, String> {
    let mut named = HashMap::new();
    for t in root.children_named("type") {
        let rust = t.value("rust").unwrap_or_default();
        let mut parts: Vec<String> = rust
            .split("::")
            .filter(|p| *p != "finroc")
            .map(str::to_string)
            .collect();
        if let Some(last) = parts.last_mut() {
            if last.starts_with('t') && last.len() > 1 {
                last.remove(0);
            }
        }
        let ferroc = format!("{library}.{}", t.value("name").unwrap_or_default());
        c.ferroc_types.insert(parts.join("."), ferroc.clone());
        named.insert(ferroc, parts.join("."));
    }
    named
}

/// The component a `<module-type>` of `library` declares: its ports (registering
/// their types) and parameters, and for a behaviour the iB2C ports.
fn module_component(
    m: &Xml,
    library: &str,
    named: &HashMap<String, String>,
    c: &mut Catalogue,
) -> Component {
    let kind = m.value("kind").unwrap_or("module");
    let behaviour = matches!(kind, "behaviour" | "fusion");
    let mut component = Component {
        library: library.to_string(),
        name: m.value("name").unwrap_or_default().to_string(),
        composite: false,
        interfaces: interfaces_of(kind, false, behaviour),
        ports: Vec::new(),
        open: false,
        params: Vec::new(),
        content: None,
        xml_file: None,
    };
    for p in &m.children {
        let (interface, output) = match p.name.as_str() {
            "in" => ("Input", false),
            "out" => ("Output", true),
            "sensor-in" => ("Sensor Input", false),
            "sensor-out" => ("Sensor Output", true),
            "controller-in" => ("Controller Input", false),
            "controller-out" => ("Controller Output", true),
            "param" => {
                component
                    .params
                    .push((finroc_name(p, "param"), p.value("unit").map(str::to_string)));
                continue;
            }
            _ => continue,
        };
        let ty = p.value("type").unwrap_or_default();
        c.ferroc_types
            .entry(rrlib_type(ty, named))
            .or_insert_with(|| ty.to_string());
        component.ports.push(Port {
            interface: interface.into(),
            name: finroc_name(p, &p.name),
            member: p.value("name").unwrap_or_default().to_string(),
            ty: rrlib_type(ty, named),
            unit: p.value("unit").map(str::to_string),
            output,
        });
    }
    if behaviour {
        add_ib2c_ports(&mut component);
    }
    component
}

/// The iB2C ports every behaviour has; inhibition ports are counted by a static
/// parameter, fusion channels too, so the component is open.
fn add_ib2c_ports(component: &mut Component) {
    for (i, n, t, o) in [
        (
            "iB2C Input",
            "Stimulation",
            "finroc.ib2c.Stimulation",
            false,
        ),
        ("iB2C Output", "Activity", "finroc.ib2c.Activity", true),
        (
            "iB2C Output",
            "Target Rating",
            "finroc.ib2c.TargetRating",
            true,
        ),
        ("iB2C Output", "Status", "finroc.ib2c.Status", true),
    ] {
        component.ports.push(Port {
            interface: i.into(),
            name: n.into(),
            member: super::text::ident_of(n),
            ty: t.into(),
            unit: None,
            output: o,
        });
    }
    component.open = true;
}

fn groups(root: &Xml, c: &mut Catalogue) {
    for g in root.children_named("Finstructable") {
        let flag = |a: &str| g.value(a) == Some("true");
        let base = g.value("base").unwrap_or("Group");
        let mut quiet = Diagnostics::default();
        let doc = super::read::read(FileId(u32::MAX), g, &mut quiet);
        let mut ports = Vec::new();
        for i in &doc.interfaces {
            for p in &i.ports {
                let unit = g
                    .children_named("interface")
                    .flat_map(|x| x.children_named("port"))
                    .find(|x| x.value("name") == Some(p.name.text.as_str()))
                    .and_then(|x| x.value("unit"))
                    .map(str::to_string);
                ports.push(Port {
                    interface: i.name.text.clone(),
                    name: p.name.text.clone(),
                    member: super::text::ident_of(&p.name.text),
                    ty: p.ty.as_ref().map(|t| t.text.clone()).unwrap_or_default(),
                    unit,
                    output: p.output,
                });
            }
        }
        if flag("thread") {
            ports.push(Port {
                interface: "Profiling".into(),
                name: "Execution Duration".into(),
                member: "execution_duration".into(),
                ty: "rrlib.time.Duration".into(),
                unit: None,
                output: true,
            });
        }
        let component = Component {
            library: g.value("library").unwrap_or_default().to_string(),
            name: g.value("type").unwrap_or_default().to_string(),
            composite: true,
            interfaces: interfaces_of(base, flag("thread"), flag("ib2c")),
            ports,
            open: flag("open"),
            params: vec![
                ("Manages Parameter Configuration".into(), None),
                ("XML file".into(), None),
            ],
            content: Some(doc),
            xml_file: g.value("xmlfile").map(str::to_string),
        };
        c.components.insert(
            (component.library.clone(), component.name.clone()),
            component,
        );
    }
}

#[cfg(test)]
#[path = "catalogue_tests.rs"]
mod tests;
