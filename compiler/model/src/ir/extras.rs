//! The settings few `<connect>`s and module instances write, each record's behind one
//! box: inline, they made every connection and every element of a large model bigger
//! (B1: ~26 MiB of connections and ~9 MiB of elements at 100,000 modules).

use super::{Connection, ModuleInstance};
use ferroc_diagnostics::source::Span;

/// `sharing=`, `min-interval=`, `period=`, `reliability=`, `deadline=` of a `<connect>`:
/// how a connection behaves when it links two parts.
#[derive(Debug, Default)]
pub struct LinkSettings {
    pub sharing: Option<(String, Span)>,
    pub min_interval: Option<Span>,
    pub period: Option<Span>,
    /// The values of `min-interval=` and `period=`, in seconds.
    pub min_interval_seconds: Option<f64>,
    pub period_seconds: Option<f64>,
    pub reliability: Option<Span>,
    /// `reliability="reliable"` (true) or `"best-effort"` (false).
    pub reliable: Option<bool>,
    /// `deadline=`: the longest silence the reader accepts (span, seconds).
    pub deadline: Option<Span>,
    pub deadline_seconds: Option<f64>,
}

impl Connection {
    /// `sharing=` with the value's span.
    pub fn sharing(&self) -> Option<&(String, Span)> {
        self.link.as_ref()?.sharing.as_ref()
    }

    /// Span of the `min-interval=` value.
    pub fn min_interval(&self) -> Option<Span> {
        self.link.as_ref()?.min_interval
    }

    /// Span of the `period=` value.
    pub fn period(&self) -> Option<Span> {
        self.link.as_ref()?.period
    }

    /// `min-interval=` in seconds.
    pub fn min_interval_seconds(&self) -> Option<f64> {
        self.link.as_ref()?.min_interval_seconds
    }

    /// `period=` in seconds.
    pub fn period_seconds(&self) -> Option<f64> {
        self.link.as_ref()?.period_seconds
    }

    /// Span of the `reliability=` value.
    pub fn reliability(&self) -> Option<Span> {
        self.link.as_ref()?.reliability
    }

    /// `reliability="reliable"` (true) or `"best-effort"` (false).
    pub fn reliable(&self) -> Option<bool> {
        self.link.as_ref()?.reliable
    }

    /// Span of the `deadline=` value.
    pub fn deadline(&self) -> Option<Span> {
        self.link.as_ref()?.deadline
    }

    /// `deadline=` in seconds.
    pub fn deadline_seconds(&self) -> Option<f64> {
        self.link.as_ref()?.deadline_seconds
    }
}

/// The rarely written settings of a module instance (see [`ModuleInstance::extras`]).
#[derive(Debug, Default)]
pub struct ModuleExtras {
    /// `<bind lock resource>`: lock slot → application resource (span of `resource`).
    pub binds: Vec<(String, String, Span)>,
    /// `characteristic="true"` (span of the value): this behaviour is the characteristic
    /// behaviour of its nearest enclosing group, which makes that group an iB2C group.
    pub characteristic: Option<Span>,
    /// `budget="…"` on the instance: overrides the module type's budget (seconds, span).
    pub budget: Option<(f64, Span)>,
    /// `ib2c-violations` of the instance (`warn`, `clamp`, `stop`), if given.
    pub ib2c_violations: Option<String>,
    /// `<port name unit>` naming a port its type declares without a unit: the unit this
    /// instance gives it (index among the type's ports, unit), as a flexible port's
    /// `<port>` gives one (`ferroc_std.Constant`'s `value` in metres).
    pub port_units: Vec<(u32, ferroc_values::units::Unit)>,
}

impl ModuleInstance {
    /// `<bind lock resource>`s: lock slot → application resource (span of `resource`).
    pub fn binds(&self) -> &[(String, String, Span)] {
        self.extras.as_ref().map_or(&[], |x| &x.binds)
    }

    /// `characteristic="true"`, with the value's span.
    pub fn characteristic(&self) -> Option<Span> {
        self.extras.as_ref()?.characteristic
    }

    /// `budget="…"` on the instance (seconds, span).
    pub fn budget(&self) -> Option<(f64, Span)> {
        self.extras.as_ref()?.budget
    }

    /// `ib2c-violations` of the instance, if given.
    pub fn ib2c_violations(&self) -> Option<&str> {
        self.extras.as_ref()?.ib2c_violations.as_deref()
    }

    /// The unit the instance gives its type's port `port` (declared without one).
    pub fn port_unit(&self, port: u32) -> Option<&ferroc_values::units::Unit> {
        let extras = self.extras.as_ref()?;
        extras
            .port_units
            .iter()
            .find(|(p, _)| *p == port)
            .map(|(_, u)| u)
    }
}
