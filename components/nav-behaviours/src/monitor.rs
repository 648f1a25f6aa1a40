//! `nav_behaviours.NavMonitor`: what the user watches, as text at a human rate.

use crate::simulation::step_seconds;
use crate::Pose2D;
use ferroc_runtime::console;
use ferroc_runtime::module::{In, MetaType, Module, ModuleType, Parameter, Setup};

/// Prints pose, activities and the fused command every `print_every` cycles, and the
/// arrival at the goal once.
pub struct NavMonitor {
    pose: In<Pose2D>,
    goal: In<f64>,
    wall: In<f64>,
    avoid: In<f64>,
    emergency: In<f64>,
    arrived: In<f64>,
    linear: In<f64>,
    angular: In<f64>,
    print_every: Parameter<u32>,
    cycle: u64,
    has_arrived: bool,
}

impl ModuleType for NavMonitor {
    const NAME: &'static str = "nav_behaviours.NavMonitor";
    const DOC: &'static str = "Prints pose, activities and the fused command now and then";

    fn create(m: &mut Setup<'_>) -> Self {
        let mut activity = |name: &str| m.input(name).meta(MetaType::Activity).build();
        NavMonitor {
            goal: activity("goal_activity"),
            wall: activity("wall_activity"),
            avoid: activity("avoid_activity"),
            emergency: activity("emergency"),
            arrived: activity("arrived"),
            pose: m.input("pose").build(),
            linear: m.input("linear").unit("m/s").build(),
            angular: m.input("angular").unit("rad/s").build(),
            print_every: m
                .param("print_every")
                .range(1.0, 100000.0)
                .default(25)
                .doc("cycles between two status lines")
                .build(),
            cycle: 0,
            has_arrived: false,
        }
    }
}

impl Module for NavMonitor {
    fn update(&mut self) {
        self.cycle += 1;
        let t = self.cycle as f64 * step_seconds();
        let p = self.pose.get();
        if !self.has_arrived && self.arrived.get() > 0.5 {
            self.has_arrived = true;
            console::line(&format!(
                "[nav] t={t:5.1} s goal reached at x={:+.2} m y={:+.2} m",
                p.x, p.y
            ));
        }
        if self.cycle % u64::from(self.print_every.get().max(1)) != 0 {
            return;
        }
        console::line(&format!(
            "[nav] t={t:5.1} s x={:+.2} y={:+.2} heading={:>4.0}° | activity goal {:.2} wall {:.2} avoid {:.2} (emergency {:.2}) | fused linear {:+.2} m/s angular {:+.2} rad/s",
            p.x,
            p.y,
            p.theta.to_degrees(),
            self.goal.get(),
            self.wall.get(),
            self.avoid.get(),
            self.emergency.get(),
            self.linear.get(),
            self.angular.get()
        ));
    }
}
