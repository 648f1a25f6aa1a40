//! The inside of one group: ten modules, four interface ports, 18 data connections
//! (paths relative to the group), the same for every [`GroupKind`]. The kinds that can
//! wait swap some `ferroc_std` modules for `b1` ones with the same port names, so the
//! data flow (and with it the schedule) does not depend on the kind.

use super::layout::GroupKind;
use super::Generator;

/// Parameter values of one group, varied per inline group like hand-tuned ones.
pub(super) struct GroupParams {
    gain: String,
    bias: String,
    label: String,
    /// `Logger` (to a file, at a period with a unit) or `Dump` in the group type.
    log_type: &'static str,
    log_params: Vec<String>,
    /// The block whose `map`/`pose` resources the group's lock slots are bound to.
    block: usize,
}

impl GroupParams {
    pub fn of_type() -> Self {
        GroupParams {
            gain: "1.0".into(),
            bias: "0.25".into(),
            label: "filter".into(),
            log_type: "Dump",
            log_params: vec!["<param name=\"label\">filter log</param>".into()],
            block: 0,
        }
    }

    pub fn inline(group: usize, block: usize) -> Self {
        const PERIODS: [&str; 4] = ["200ms", "0.5 s", "PT1S", "250000us"];
        GroupParams {
            gain: format!("0.{}", 1 + group % 9),
            bias: format!("{}.5", group % 13),
            label: format!("group {group}"),
            log_type: "Logger",
            log_params: vec![
                format!("<param name=\"file\">/var/log/ferroc/g{group}.log</param>"),
                format!(
                    "<param name=\"period\">{}</param>",
                    PERIODS[group % PERIODS.len()]
                ),
            ],
            block,
        }
    }
}

/// The `b1` module types a kind puts in place of `ferroc_std` ones: (module, type).
fn substitutes(kind: GroupKind) -> &'static [(&'static str, &'static str)] {
    match kind {
        GroupKind::Inline | GroupKind::Instance => &[],
        GroupKind::Inbox => &[("gain", "b1.Inbox")],
        GroupKind::Client => &[
            ("smooth", "b1.Planner"),
            ("drive", "b1.Tracker"),
            ("limit", "b1.Calibrated"),
            ("fallback", "b1.Calibration"),
        ],
        GroupKind::Locking => &[("limit", "b1.Estimator")],
        GroupKind::Server => &[("smooth", "b1.MapServer")],
    }
}

/// Modules whose lock slots `map` and `pose` are bound to the block's resources.
pub(super) fn binds_locks(kind: GroupKind, module: &str) -> bool {
    matches!(
        (kind, module),
        (GroupKind::Locking, "limit") | (GroupKind::Server, "smooth")
    )
}

/// Data connections inside every group.
pub(super) const WIRES: [(&str, &str); 18] = [
    ("in", "gain/input"),
    ("gain/output", "add/in/0"),
    ("bias/value", "add/in/1"),
    ("aux", "add/in/2"),
    ("add/out", "smooth/input"),
    ("smooth/output", "limit/input"),
    ("limit/output", "pick/in/0"),
    ("fallback/value", "pick/in/1"),
    ("gain/output", "pick/in/2"),
    ("pick/out", "drive/input"),
    ("pick/out", "log/in/0"),
    ("pick/index", "log/in/1"), // u32 → f64: lossless widening
    ("add/out", "log/in/2"),
    ("bias/value", "log/in/3"),
    ("smooth/output", "watch/in/0"),
    ("drive/output", "watch/in/1"),
    ("drive/output", "out"),
    ("limit/output", "level"),
];

impl Generator {
    pub(super) fn group_body(&mut self, i: usize, p: &GroupParams, kind: GroupKind) {
        for (name, dir) in [
            ("in", "in"),
            ("aux", "in"),
            ("out", "out"),
            ("level", "out"),
        ] {
            self.line(
                i,
                &format!("<port name=\"{name}\" dir=\"{dir}\" type=\"f64\"/>"),
            );
        }
        let param = |name: &str, value: &str| format!("<param name=\"{name}\">{value}</param>");
        let inputs =
            |count: usize| format!("<port name=\"in\" dir=\"in\" type=\"f64\" count=\"{count}\"/>");
        let modules: [(&str, &str, Vec<String>); 10] = [
            ("gain", "Scale", vec![param("factor", &p.gain)]),
            ("bias", "Constant", vec![param("value", &p.bias)]),
            ("add", "Sum", vec![inputs(3)]),
            ("smooth", "Scale", vec![param("factor", "0.9")]),
            ("limit", "Scale", vec![param("factor", "0.5")]),
            ("fallback", "Constant", vec![]),
            ("pick", "FlexiSelect", vec![inputs(3)]),
            (
                "log",
                p.log_type,
                [vec![inputs(4)], p.log_params.clone()].concat(),
            ),
            ("watch", "Dump", vec![inputs(2), param("label", &p.label)]),
            ("drive", "Scale", vec![param("factor", "2")]),
        ];
        let subs = substitutes(kind);
        for (name, ty, mut children) in modules {
            let ty = subs
                .iter()
                .find(|(m, _)| *m == name)
                .map_or_else(|| format!("ferroc_std.{ty}"), |(_, t)| t.to_string());
            if binds_locks(kind, name) {
                let b = p.block;
                children.push(format!("<bind lock=\"map\" resource=\"map{b}\"/>"));
                children.push(format!("<bind lock=\"pose\" resource=\"pose{b}\"/>"));
            }
            let open = format!("<module name=\"{name}\" type=\"{ty}\"");
            if children.is_empty() {
                self.line(i, &format!("{open}/>"));
            } else {
                self.line(i, &format!("{open}>"));
                for c in children {
                    self.line(i + 1, &c);
                }
                self.line(i, "</module>");
            }
        }
        for (from, to) in WIRES {
            self.line(i, &format!("<connect from=\"{from}\" to=\"{to}\"/>"));
        }
        if kind == GroupKind::Client {
            // The calibration service runs in the caller's thread: a call, no wait.
            self.line(i, "<connect from=\"limit/cal\" to=\"fallback/cal\"/>");
        }
    }
}
