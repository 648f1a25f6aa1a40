//! `crash_course.EnableSwitch`: permission to drive as a service of the shape ROS 2's
//! `std_srvs/srv/SetBool` has (request `bool data`; response `bool success`, `string
//! message`), so a part can offer it as a ROS 2 service (docs/ros2.md). Each step
//! answers the waiting requests and publishes whether driving is enabled.
//! `crash_course.EnableAsk` is the client side: it calls such a service.

use ferroc_runtime::module::{Module, ModuleType, Out, Setup};
use ferroc_runtime::service::{ClientPort, PendingResponse, ServicePort};

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

/// Asks its client to enable and disable driving in turn, one call at a time, and
/// publishes the message of each answer (a failed call publishes nothing).
pub struct EnableAsk {
    set_enabled: ClientPort<bool, Ack>,
    message: Out<String>,
    pending: Option<PendingResponse<Ack>>,
    next: bool,
}

impl ModuleType for EnableAsk {
    const NAME: &'static str = "crash_course.EnableAsk";
    const DOC: &'static str = "Asks to disable and enable driving in turn; publishes the answers";

    fn create(m: &mut Setup<'_>) -> Self {
        EnableAsk {
            set_enabled: m
                .client("set_enabled")
                .doc("asynchronous, one call at a time")
                .build(),
            message: m
                .output("message")
                .doc("the message of each answer")
                .build(),
            pending: None,
            next: false,
        }
    }
}

impl Module for EnableAsk {
    fn update(&mut self) {
        if let Some(pending) = self.pending.take() {
            match pending.try_take() {
                Ok(Ok(answer)) => self.message.publish(answer.message),
                Ok(Err(_)) => {}
                Err(pending) => self.pending = Some(pending),
            }
        }
        if self.pending.is_none() {
            self.pending = self.set_enabled.call_async(self.next).ok();
            self.next = !self.next;
        }
    }
}
