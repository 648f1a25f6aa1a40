//! Where an edge end leads: the port it names, known missing, or not knowable here.
//!
//! A path is relative to the group the file describes (its *owner*): `Interface/Port`
//! is a port of the owner, `Element/…/Interface/Port` a port of an element the file
//! creates or that the owner's C++ constructor creates (catalogue). What a type offers
//! comes from the catalogue; a group instance's ports may also come from its group file.

use super::catalogue::{Catalogue, Component};
use super::checkout::Checkout;
use super::finstructable::{EdgeEnd, Element, Finstructable};
use std::path::Path;

/// What an end names, as far as the catalogue and the checkout tell.
#[derive(Clone, Debug)]
pub enum End {
    /// The port exists; its interface, type and unit when known.
    Port {
        interface: String,
        ty: Option<String>,
        unit: Option<String>,
    },
    /// Known not to exist, with why.
    Missing(String),
    /// Not knowable here, with why (for the "not checked" list).
    Unknown(String),
}

/// The component type of the group a file describes.
pub fn owner<'c>(
    doc: &Finstructable,
    path: &Path,
    catalogue: &'c Catalogue,
    checkout: &Checkout,
) -> Option<&'c Component> {
    let name = path.to_string_lossy().replace('\\', "/");
    if name.ends_with(".finroc") || doc.defaultname.is_some() {
        return catalogue.get(
            "finroc_plugins_structure",
            "ThreadContainer<SenseControlGroup>",
        );
    }
    if let Some(c) = catalogue_owner(doc, &name, catalogue, checkout) {
        return Some(c);
    }
    let tail_matches = |file: &str| {
        let file_name = file.rsplit('/').next().unwrap_or(file);
        name.ends_with(&format!("/{file}"))
            || name.ends_with(&format!("/{file_name}"))
            || name.ends_with(&format!("__{file_name}"))
            || name == file_name
    };
    // A group instance elsewhere in the checkout that loads this file (`XML file`).
    for g in &checkout.groups {
        for (_, e) in g.doc.all_elements() {
            let Some(xml) = e.xml_file() else { continue };
            if tail_matches(xml.value.text.trim()) {
                if let (Some(lib), Some(ty)) = (&e.group, &e.ty) {
                    return catalogue.get(&lib.text, &ty.text);
                }
            }
        }
    }
    None
}

/// The catalogue group type whose constructor loads the group file at `name`.
///
/// FINROC's key is the header's path in the FINROC tree (`__FILE__".xml"`:
/// `projects/robprak_2024_2/gMainControl.h.xml`). Where the file's place in the tree is
/// known (below `sources/cpp/`, or the checkout's one target prefix: `finroc_projects_x`
/// is `projects/x`), the type whose `xmlfile` is that path owns it. Elsewhere (a
/// repository cloned on its own, a flat folder of files) many projects have a
/// `gMainControl.h.xml`: the types whose file has this name are narrowed to those whose
/// constructor creates the most of the elements the file's edges name (at least one),
/// and one must remain; a file that names no element beyond its own is owned by the
/// one type with its name.
fn catalogue_owner<'c>(
    doc: &Finstructable,
    name: &str,
    catalogue: &'c Catalogue,
    checkout: &Checkout,
) -> Option<&'c Component> {
    let base = name.rsplit('/').next().unwrap_or(name);
    let base = base.rsplit("__").next().unwrap_or(base);
    let mut candidates: Vec<&Component> = catalogue
        .components
        .values()
        .filter(|c| {
            c.xml_file
                .as_deref()
                .is_some_and(|f| f.rsplit('/').next() == Some(base))
        })
        .collect();
    candidates.sort_by(|a, b| (&a.library, &a.name).cmp(&(&b.library, &b.name)));
    if let Some(place) = place_in_tree(name, checkout) {
        let known: Vec<&Component> = candidates
            .iter()
            .copied()
            .filter(|c| {
                let file = c.xml_file.as_deref().unwrap_or_default();
                place == file || place.ends_with(&format!("/{file}"))
            })
            .collect();
        return (known.len() == 1).then(|| known[0]);
    }
    let referenced: Vec<&str> = doc
        .edges
        .iter()
        .flat_map(|e| [&e.src, &e.dest])
        .filter(|end| end.scheme.is_none() && !end.absolute && end.segments.len() >= 3)
        .map(|end| end.segments[0].as_str())
        .filter(|first| !doc.elements.iter().any(|e| e.name.text == *first))
        .collect();
    if !referenced.is_empty() {
        // How many of the named elements each type's constructor creates; the types
        // that create the most (at least one) remain.
        let made = |c: &Component| {
            c.content.as_ref().map_or(0, |content| {
                let mut names: Vec<&str> = referenced
                    .iter()
                    .copied()
                    .filter(|r| content.elements.iter().any(|e| e.name.text == *r))
                    .collect();
                names.sort_unstable();
                names.dedup();
                names.len()
            })
        };
        let best = candidates.iter().map(|c| made(c)).max().unwrap_or(0);
        candidates.retain(|c| best > 0 && made(c) == best);
    }
    (candidates.len() == 1).then(|| candidates[0])
}

/// Where a file lies in the FINROC tree (`projects/x/gMain.h.xml`), when that is known.
fn place_in_tree(name: &str, checkout: &Checkout) -> Option<String> {
    if let Some((_, rest)) = name.rsplit_once("/sources/cpp/") {
        return Some(rest.to_string());
    }
    let mut prefixes: Vec<&String> = checkout.prefixes.iter().collect();
    prefixes.sort();
    prefixes.dedup();
    let [prefix] = prefixes.as_slice() else {
        return None;
    };
    let area = [
        ("finroc_projects_", "projects"),
        ("finroc_libraries_", "libraries"),
        ("finroc_plugins_", "plugins"),
        ("rrlib_", "rrlib"),
    ]
    .iter()
    .find_map(|(p, area)| prefix.strip_prefix(p).map(|x| format!("{area}/{x}")))?;
    let root = checkout.root.to_string_lossy().replace('\\', "/");
    let relative = name.strip_prefix(root.trim_end_matches('/'))?;
    Some(format!("{area}/{}", relative.trim_start_matches('/')))
}

/// `; did you mean `X`?` for the port of `ports` nearest to `port`, if one is near.
fn near<'p>(port: &str, ports: impl Iterator<Item = &'p super::catalogue::Port>) -> String {
    let names: Vec<&str> = ports.map(|p| p.name.as_str()).collect();
    ferroc_diagnostics::diagnostic::did_you_mean(port, names.iter().copied())
        .map(|n| format!("; did you mean `{n}`?"))
        .unwrap_or_default()
}

/// The context an end is resolved in.
pub struct Scope<'a> {
    pub doc: &'a Finstructable,
    pub owner: Option<&'a Component>,
    pub catalogue: &'a Catalogue,
    pub checkout: &'a Checkout,
}

impl Scope<'_> {
    pub fn resolve(&self, end: &EdgeEnd) -> End {
        if let Some(s) = &end.scheme {
            return End::Unknown(format!("`{s}:` ends are URI connectors to another runtime"));
        }
        if end.absolute {
            return End::Unknown(
                "absolute paths start at the runtime root, outside this file".into(),
            );
        }
        let segs = &end.segments;
        if segs.len() == 2 && self.owner_has_interface(&segs[0]) {
            return self.owner_port(&segs[0], &segs[1]);
        }
        match self.find_element(segs) {
            Ok((element, depth)) => self.element_port(element, &segs[depth..]),
            Err(end) => end,
        }
    }

    /// The element a path starts with and how many segments name it: elements the file
    /// creates, then those the owner's constructor creates. `Err` says why there is none.
    fn find_element(&self, segs: &[String]) -> Result<(&Element, usize), End> {
        let mut list: &[Element] = &self.doc.elements;
        let mut depth = 0;
        let mut element = None;
        while depth < segs.len() {
            match list.iter().find(|e| e.name.text == segs[depth]) {
                Some(e) => {
                    element = Some(e);
                    list = &e.children;
                    depth += 1;
                }
                None => break,
            }
        }
        if element.is_none() {
            if let Some(content) = self.owner.and_then(|o| o.content.as_ref()) {
                if let Some(e) = content.elements.iter().find(|e| e.name.text == segs[0]) {
                    element = Some(e);
                    depth = 1;
                }
            }
        }
        let Some(element) = element else {
            return Err(match self.owner {
                Some(o) if o.content.is_some() || o.open => End::Missing(format!(
                    "no element `{}` here: this file does not create one{}",
                    segs[0],
                    if o.content.as_ref().is_some_and(|c| !c.elements.is_empty()) {
                        format!(", nor does the constructor of `{}`", o.name)
                    } else {
                        String::new()
                    }
                )),
                _ => End::Unknown(format!(
                    "`{}` may be created by the group's C++ constructor, and the group's type is not in the catalogue",
                    segs[0]
                )),
            });
        };
        Ok((element, depth))
    }

    /// The port `rest` (`Interface/Port`) names below `element`, by its type in the
    /// catalogue (or the group's file).
    fn element_port(&self, element: &Element, rest: &[String]) -> End {
        let (Some(lib), Some(ty)) = (&element.group, &element.ty) else {
            return End::Unknown("the element has no type".into());
        };
        let Some(component) = self.catalogue.get(&lib.text, &ty.text) else {
            return End::Unknown(format!(
                "type `{}` of `{}` is not in the catalogue",
                ty.text, lib.text
            ));
        };
        if rest.len() != 2 {
            return if component.composite {
                End::Unknown("a path into a group's inner elements".into())
            } else {
                End::Missing(format!(
                    "`{}` is a module (`{}`): a port path below it is `Interface/Port`",
                    element.name.text, ty.text
                ))
            };
        }
        let (interface, port) = (&rest[0], &rest[1]);
        if !component.interfaces.iter().any(|i| i == interface) {
            if component.open && component.composite {
                if let Some(p) = self.group_file_port(element, component, interface, port) {
                    return p;
                }
            }
            return End::Missing(format!(
                "`{}` (`{}`) has no interface `{interface}`; it has {}",
                element.name.text,
                ty.text,
                component.interfaces.join(", ")
            ));
        }
        if let Some(p) = component.port(interface, port) {
            return End::Port {
                interface: interface.clone(),
                ty: Some(p.ty.clone()),
                unit: p.unit.clone(),
            };
        }
        if component.composite {
            if let Some(p) = self.group_file_port(element, component, interface, port) {
                return p;
            }
        }
        if component.open {
            return End::Unknown(format!("the ports of `{}` are made at run time", ty.text));
        }
        End::Missing(format!(
            "`{}` (`{}`) has no port `{port}` in `{interface}`{}",
            element.name.text,
            ty.text,
            near(
                port,
                component.ports.iter().filter(|p| &p.interface == interface)
            )
        ))
    }

    fn owner_has_interface(&self, name: &str) -> bool {
        self.doc.interfaces.iter().any(|i| i.name.text == name)
            || match self.owner {
                Some(o) => o.interfaces.iter().any(|i| i == name),
                None => super::catalogue::interfaces_of("SenseControlGroup", true, true)
                    .iter()
                    .chain(&["Input".to_string(), "Output".to_string()])
                    .any(|i| i == name),
            }
    }

    fn owner_port(&self, interface: &str, port: &str) -> End {
        if let Some(p) = self
            .doc
            .interfaces
            .iter()
            .filter(|i| i.name.text == interface)
            .flat_map(|i| &i.ports)
            .find(|p| p.name.text == port)
        {
            return End::Port {
                interface: interface.into(),
                ty: p.ty.as_ref().map(|t| t.text.clone()),
                unit: None,
            };
        }
        match self.owner {
            Some(o) => match o.port(interface, port) {
                Some(p) => End::Port {
                    interface: interface.into(),
                    ty: Some(p.ty.clone()),
                    unit: p.unit.clone(),
                },
                None if o.open && !self.doc.interfaces.iter().any(|i| i.name.text == interface) => {
                    End::Unknown(format!(
                        "the `{interface}` ports of `{}` are made by finstruct or C++",
                        o.name
                    ))
                }
                None => End::Missing(format!(
                    "this group has no port `{port}` in `{interface}`{}",
                    near(port, o.ports.iter().filter(|p| p.interface == interface))
                )),
            },
            None => End::Unknown("the group's type is not in the catalogue".into()),
        }
    }

    /// A port declared by the group file an instance loads (`XML file`, or the type's).
    fn group_file_port(
        &self,
        element: &Element,
        component: &Component,
        interface: &str,
        port: &str,
    ) -> Option<End> {
        let file = element
            .xml_file()
            .map(|p| p.value.text.trim().to_string())
            .or_else(|| component.xml_file.clone())?;
        let group = self.checkout.group_file(&file)?;
        let declared = group
            .doc
            .interfaces
            .iter()
            .find(|i| i.name.text == interface);
        Some(
            match declared.and_then(|d| d.ports.iter().find(|p| p.name.text == port)) {
                Some(p) => End::Port {
                    interface: interface.into(),
                    ty: p.ty.as_ref().map(|t| t.text.clone()),
                    unit: None,
                },
                None => End::Missing(format!(
                    "`{}` loads {}, which declares no port `{port}` in `{interface}`",
                    element.name.text,
                    group.path.display()
                )),
            },
        )
    }
}
