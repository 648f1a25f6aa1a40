//! `<ros2>` in a part and `<ros2-external>`: read into [`Ros2`](crate::ir::Ros2). Port
//! paths resolve relative to the part, as a `<connect>` written in the part does; what
//! the values mean (names, types, QoS pairs) is judged by the checks of area R.

use super::Resolver;
use crate::ir::*;
use crate::load::Confined;
use ferroc_syntax::Element;
use std::path::Path;

/// A team package with more definition files than this is refused (the largest shipped
/// package, sensor_msgs, has 27).
const MAX_FILES: usize = 1000;

/// A definition file larger than this is refused (as `ferroc_ros2::Registry` refuses
/// one; the largest shipped one is under 8 KiB).
const MAX_FILE_BYTES: usize = 1 << 20;

impl Resolver<'_, '_, '_> {
    /// `<ros2>` children of the part `part`.
    pub(super) fn part_ros2(&mut self, part: ElementId, e: &Element) {
        for r in e.children_named("ros2") {
            if let Some(node) = self.ros2_node(Some(part), r) {
                self.app.ros2.nodes.push(node);
            }
        }
    }

    /// `<ros2-external>` children of the application.
    pub(super) fn external_ros2(&mut self, root: &Element) {
        for r in root.children_named("ros2-external") {
            if let Some(node) = self.ros2_node(None, r) {
                self.app.ros2.nodes.push(node);
            }
        }
    }

    /// `<ros2-interfaces>` children of the application: each package's definition
    /// files read into the model's sources (R109 parses and judges them).
    pub(super) fn ros2_interfaces(&mut self, root: &Element) {
        for e in root.children_named("ros2-interfaces") {
            let (Some(package), Some(path)) = (text(e, "package"), text(e, "path")) else {
                continue; // M104 reported the missing attribute
            };
            let mut unreadable = Vec::new();
            let files = match self.loader.confine(path.1.file, &path.0) {
                Ok(folder) if folder.is_dir() => {
                    Ok(self.definition_files(&folder, &mut unreadable))
                }
                Ok(_) => Err(Some("it is not a folder".to_string())),
                Err(Confined::Outside) => {
                    self.loader
                        .report_outside(path.1, &path.0, "message packages");
                    Err(None)
                }
                Err(Confined::Unreadable(why)) => Err(Some(why)),
            };
            self.app.ros2.interfaces.push(Ros2Interfaces {
                span: e.name_span,
                package,
                path,
                files,
                unreadable,
            });
        }
    }

    /// The `msg/*.msg` and `srv/*.srv` files of `folder`, read into the sources.
    fn definition_files(
        &mut self,
        folder: &Path,
        unreadable: &mut Vec<String>,
    ) -> Vec<Ros2InterfaceFile> {
        let mut files = Vec::new();
        for kind in ["msg", "srv"] {
            let Ok(entries) = std::fs::read_dir(folder.join(kind)) else {
                continue;
            };
            let mut paths: Vec<_> = entries.filter_map(Result::ok).map(|e| e.path()).collect();
            paths.retain(|p| p.extension().is_some_and(|x| x == kind) && p.is_file());
            paths.sort();
            for path in paths {
                let shown = format!(
                    "{kind}/{}",
                    path.file_name().unwrap_or_default().to_string_lossy()
                );
                if files.len() == MAX_FILES {
                    unreadable.push(format!(
                        "{shown} and the rest: a package has at most {MAX_FILES} definition files"
                    ));
                    break;
                }
                let Some(name) = path
                    .file_stem()
                    .and_then(|s| s.to_str())
                    .map(str::to_string)
                else {
                    unreadable.push(format!("{shown}: the file name is not UTF-8"));
                    continue;
                };
                // A link out of the package's folder is not followed (as includes'
                // are not out of the model's folder).
                if !path
                    .canonicalize()
                    .is_ok_and(|real| real.starts_with(folder))
                {
                    unreadable.push(format!("{shown}: it leads outside the package's folder"));
                    continue;
                }
                let file = match self.loader.sources.find(&path) {
                    Some(id) => id,
                    None => match self.loader.options.read(&path) {
                        Ok(text) => {
                            let display = self.loader.display_name(&path);
                            self.loader.sources.add(display, path.clone(), text)
                        }
                        Err(why) => {
                            unreadable.push(format!("{shown}: {why}"));
                            continue;
                        }
                    },
                };
                let text = self.loader.sources.get(file).text.clone();
                if text.len() > MAX_FILE_BYTES {
                    unreadable.push(format!(
                        "{shown}: {} bytes, more than a definition may have ({MAX_FILE_BYTES})",
                        text.len()
                    ));
                    continue;
                }
                files.push(Ros2InterfaceFile {
                    kind,
                    name,
                    file,
                    text,
                });
            }
        }
        files
    }

    /// A node and its ends; `None` without `node=` (M104 reported it).
    fn ros2_node(&mut self, part: Option<ElementId>, r: &Element) -> Option<Ros2Node> {
        let mut node = Ros2Node {
            part,
            span: r.name_span,
            name: text(r, "node")?,
            namespace: text(r, "namespace"),
            domain: r.value("domain").and_then(|d| d.parse().ok()).unwrap_or(0),
            topics: Vec::new(),
            services: Vec::new(),
        };
        for c in &r.children {
            let direction = match c.name.as_str() {
                "publish" => TopicDirection::Publish,
                "subscribe" => TopicDirection::Subscribe,
                "service" | "client" => {
                    let role = if c.name == "service" {
                        ServiceRole::Server
                    } else {
                        ServiceRole::Client
                    };
                    let port = self.ros2_port(part, c);
                    if let (Some(name), Some(ty)) = (text(c, "name"), text(c, "type")) {
                        node.services.push(Ros2Service {
                            role,
                            span: c.name_span,
                            port,
                            name,
                            ty,
                        });
                    }
                    continue;
                }
                _ => continue,
            };
            let port = self.ros2_port(part, c);
            let (Some(topic), Some(ty)) = (text(c, "topic"), text(c, "type")) else {
                continue; // M104 reported the missing attribute
            };
            node.topics.push(Ros2Topic {
                direction,
                span: c.name_span,
                port,
                topic,
                ty,
                field: text(c, "field"),
                best_effort: c
                    .attr("reliability")
                    .map(|a| (a.value == "best-effort", a.value_span)),
                transient_local: c
                    .attr("durability")
                    .map(|a| (a.value == "transient-local", a.value_span)),
                depth: c
                    .attr("depth")
                    .and_then(|a| Some((a.value.trim().parse().ok()?, a.value_span))),
                frame_id: text(c, "frame-id"),
            });
        }
        Some(node)
    }

    /// The port a `port=` names, relative to the part (reported when it does not resolve).
    fn ros2_port(&mut self, part: Option<ElementId>, c: &Element) -> Option<Spanned<Endpoint>> {
        let part = part?;
        let a = c.attr("port")?;
        let (endpoint, _) = self.resolve_path(part, a.value, a.value_span)?;
        self.app.ros2.ports.insert(endpoint);
        Some((endpoint, a.value_span))
    }
}

fn text(e: &Element, name: &str) -> Option<Spanned<String>> {
    e.attr(name).map(|a| (a.value.to_string(), a.value_span))
}
