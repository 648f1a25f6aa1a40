//! The service blocks of `ferroc_std`: `ScaleService` answers calls, `Ask` makes them.
//! Together they are the smallest client/service pair a model can wire, inside one part
//! or between parts (where the call travels over the network).

use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup};
use ferroc_runtime::service::{ClientPort, PendingResponse, ServicePort};

/// `ferroc_std.ScaleService`: answers each call with factor · request, in its step.
pub struct ScaleService {
    scale: ServicePort<f64, f64>,
    factor: Parameter<f64>,
}

impl ModuleType for ScaleService {
    const NAME: &'static str = "ferroc_std.ScaleService";
    const DOC: &'static str = "Answers calls with factor times the request";
    fn create(m: &mut Setup<'_>) -> Self {
        ScaleService {
            scale: m.service("scale").doc("factor · request").build(),
            factor: m.param("factor").default(1.0).build(),
        }
    }
}

impl Module for ScaleService {
    fn update(&mut self) {
        let factor = self.factor.get();
        self.scale.serve_pending(|x| x * factor);
    }
}

/// `ferroc_std.Ask`: calls `ask` with its input without waiting, one call at a time,
/// and publishes each answer when it arrives (a failed call publishes nothing).
pub struct Ask {
    input: In<f64>,
    ask: ClientPort<f64, f64>,
    answer: Out<f64>,
    pending: Option<PendingResponse<f64>>,
}

impl ModuleType for Ask {
    const NAME: &'static str = "ferroc_std.Ask";
    const DOC: &'static str = "Calls a service with its input and publishes the answers";
    fn create(m: &mut Setup<'_>) -> Self {
        Ask {
            input: m.input("input").required().build(),
            ask: m
                .client("ask")
                .doc("asynchronous, one call at a time")
                .build(),
            answer: m.output("answer").build(),
            pending: None,
        }
    }
}

impl Module for Ask {
    fn update(&mut self) {
        if let Some(pending) = self.pending.take() {
            match pending.try_take() {
                Ok(Ok(answer)) => self.answer.publish(answer),
                Ok(Err(_)) => {}
                Err(pending) => self.pending = Some(pending),
            }
        }
        if self.pending.is_none() {
            self.pending = self.ask.call_async(self.input.get()).ok();
        }
    }
}
