//! R109 `invalid-ros2-interfaces`: a team's ROS 2 package (`<ros2-interfaces>`) cannot
//! be read as ROS 2 reads it.

use super::team::{refused, Refused};
use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_model::ir::Ros2Interfaces;

pub static CHECK: CheckInfo = CheckInfo {
    code: "R109",
    name: "invalid-ros2-interfaces",
    severity: Severity::Error,
    summary: "A team's ROS 2 message package cannot be read: no such folder, a definition ROS 2 refuses, or a shipped package's name.",
    explanation: "`<ros2-interfaces package=\"my_robot_msgs\" path=\"interfaces/my_robot_msgs\"/>` adds a
team's package beside the shipped ones: `path=` (relative to the model file) is the
package's folder, holding `msg/*.msg` and `srv/*.srv` as a ROS 2 package does. Its
types are then usable in `type=` and hashed (RIHS01) as ROS 2 hashes them. ROS 2's
code generators refuse the same package at build time; ferroc says so before the run:
a folder that does not exist or holds no definitions, a definition with a syntax error
(at its file:line:col), a nested type that no package defines, nested types that form a
cycle, a package named like a shipped one (`std_msgs`: a team cannot redefine it), the
same package twice.

Bad:
    <ros2-interfaces package=\"geometry_msgs\" path=\"interfaces/geometry_msgs\"/>

Fix: give the team's package its own name (`my_robot_msgs`), with the folder it is in.",
    fixtures: "compiler/checks/src/ros2/r109_invalid_ros2_interfaces",
};

const FOLDER_HELP: &str = "`path=` is the package's folder, relative to this model file, holding `msg/*.msg` and `srv/*.srv` as a ROS 2 package does";

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    if ctx.app.ros2.interfaces.is_empty() {
        return;
    }
    for (i, interfaces) in ctx.app.ros2.interfaces.iter().enumerate() {
        package(ctx, i, interfaces, out);
    }
    for (span, e) in &ctx.ros2_team().errors {
        out.push(
            Diagnostic::new(&CHECK, *span, e.message.clone())
                .label("ROS 2 refuses this")
                .help(e.help.clone()),
        );
    }
}

/// What is wrong with the package as a whole: its name, its folder, its files.
fn package(ctx: &PassContext<'_>, index: usize, i: &Ros2Interfaces, out: &mut Diagnostics) {
    let (name, name_span) = (&i.package.0, i.package.1);
    match refused(ctx.app, index) {
        Some(Refused::Shipped) => out.push(
            Diagnostic::new(&CHECK, name_span, format!("package `{name}` is one ferroc ships"))
                .label("a shipped package")
                .help("a team package cannot redefine a shipped one: give yours its own name (`my_robot_msgs`); the shipped packages are listed in docs/ros2.md"),
        ),
        Some(Refused::Twice(first)) => out.push(
            Diagnostic::new(&CHECK, name_span, format!("package `{name}` is added twice"))
                .label("again")
                .secondary(first, "first added here")
                .help("add each package once: remove this <ros2-interfaces>"),
        ),
        None => {}
    }
    let (path, path_span) = (&i.path.0, i.path.1);
    match &i.files {
        Err(None) => {} // refused and reported while reading (M113)
        Err(Some(why)) => out.push(
            Diagnostic::new(
                &CHECK,
                path_span,
                format!("cannot read the package folder `{path}`: {why}"),
            )
            .label("no such package folder")
            .help(FOLDER_HELP),
        ),
        Ok(files) if files.is_empty() && i.unreadable.is_empty() => out.push(
            Diagnostic::new(
                &CHECK,
                path_span,
                format!("`{path}` holds no `msg/*.msg` or `srv/*.srv` files"),
            )
            .label("no definitions")
            .help(FOLDER_HELP),
        ),
        Ok(_) => {}
    }
    // One finding for them all (findings at one place are one finding).
    if !i.unreadable.is_empty() {
        out.push(
            Diagnostic::new(
                &CHECK,
                path_span,
                format!(
                    "definitions of `{name}` cannot be read: {}",
                    i.unreadable.join("; ")
                ),
            )
            .label("in this package")
            .help("keep the package's definitions as readable UTF-8 files inside its folder"),
        );
    }
}
