//! `crash_course.EnableSwitch`: permission to drive as a service of the shape ROS 2's
//! `std_srvs/srv/SetBool` has (request `bool data`; response `bool success`, `string
//! message`), so a part can offer it as a ROS 2 service (docs/ros2.md). Each step
//! answers the waiting requests and publishes whether driving is enabled.

use ferroc_runtime::module::{Module, ModuleType, Out, Setup};
use ferroc_runtime::service::ServicePort;

/// A service's answer: done or not, and why (`std_srvs/srv/SetBool`'s response fields).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Ack {
    pub success: bool,
    pub message: String,
}

ferroc_runtime::port_value!(Ack, "crash_course.Ack", pooled);

/// Enables or disables driving on request; publishes the state every step.
pub struct EnableSwitch {
    set_enabled: ServicePort<bool, Ack>,
    enable: Out<bool>,
    enabled: bool,
}

impl ModuleType for EnableSwitch {
    const NAME: &'static str = "crash_course.EnableSwitch";
    const DOC: &'static str = "Enables or disables driving on request (SetBool's shape)";

    fn create(m: &mut Setup<'_>) -> Self {
        EnableSwitch {
            set_enabled: m
                .service("set_enabled")
                .doc("true enables driving, false disables it")
                .build(),
            enable: m.output("enable").doc("whether driving is enabled").build(),
            enabled: true,
        }
    }
}

impl Module for EnableSwitch {
    fn update(&mut self) {
        let enabled = &mut self.enabled;
        self.set_enabled.serve_pending(|on| {
            let message = if on == *enabled {
                "unchanged"
            } else if on {
                "enabled"
            } else {
                "disabled"
            };
            *enabled = on;
            Ack {
                success: true,
                message: message.into(),
            }
        });
        self.enable.publish(self.enabled);
    }
}
