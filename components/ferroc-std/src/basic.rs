//! The plain modules of `ferroc_std`: sources, arithmetic and the iB2C converters.

use ferroc_runtime::module::{In, MetaType, Module, ModuleType, Out, Parameter, Setup};

/// `ferroc_std.Constant`: publishes its parameter every cycle.
pub struct Constant {
    value_out: Out<f64>,
    value: Parameter<f64>,
}

impl ModuleType for Constant {
    const NAME: &'static str = "ferroc_std.Constant";
    const DOC: &'static str = "Publishes the value of its parameter every cycle";
    fn create(m: &mut Setup<'_>) -> Self {
        Constant {
            value_out: m.output("value").build(),
            value: m
                .param("value")
                .default(0.0)
                .doc("the number to publish")
                .build(),
        }
    }
}

impl Module for Constant {
    fn update(&mut self) {
        self.value_out.publish(self.value.get());
    }
}

/// `ferroc_std.Scale`: output = factor · input.
pub struct Scale {
    input: In<f64>,
    output: Out<f64>,
    factor: Parameter<f64>,
}

impl ModuleType for Scale {
    const NAME: &'static str = "ferroc_std.Scale";
    const DOC: &'static str = "Multiplies its input by a constant factor";
    fn create(m: &mut Setup<'_>) -> Self {
        Scale {
            input: m.input("input").required().build(),
            output: m.output("output").build(),
            factor: m.param("factor").default(1.0).build(),
        }
    }
}

impl Module for Scale {
    fn update(&mut self) {
        let factor = self.factor.get();
        self.output.publish(self.input.get() * factor);
    }
}

/// The activity of `value` on the line through (`min`, 0) and (`max`, 1), clamped into
/// [0, 1]; `min > max` maps falling values onto rising activity. With `min == max` it
/// is a step: 1 from `max` on. NaN gives 0.
pub fn number_to_activity(value: f64, min: f64, max: f64) -> f64 {
    if value.is_nan() {
        return 0.0;
    }
    if min == max {
        return if value >= max { 1.0 } else { 0.0 };
    }
    let a = (value - min) / (max - min);
    if a.is_nan() {
        0.0 // infinite bounds
    } else {
        a.clamp(0.0, 1.0)
    }
}

/// `ferroc_std.NumberToActivity`: maps a number linearly onto an activity in [0, 1].
pub struct NumberToActivity {
    value: In<f64>,
    activity: Out<f64>,
    min: Parameter<f64>,
    max: Parameter<f64>,
}

impl ModuleType for NumberToActivity {
    const NAME: &'static str = "ferroc_std.NumberToActivity";
    const DOC: &'static str = "Maps a number linearly onto an iB2C activity in [0, 1]";
    fn create(m: &mut Setup<'_>) -> Self {
        NumberToActivity {
            value: m.input("value").build(),
            activity: m.output("activity").meta(MetaType::Activity).build(),
            min: m
                .param("min")
                .default(0.0)
                .doc("value mapped to activity 0")
                .build(),
            max: m
                .param("max")
                .default(1.0)
                .doc("value mapped to activity 1")
                .build(),
        }
    }
}

impl Module for NumberToActivity {
    fn update(&mut self) {
        let (min, max) = (self.min.get(), self.max.get());
        self.activity
            .publish(number_to_activity(self.value.get(), min, max));
    }
}

/// `ferroc_std.ConstantActivity`: publishes a constant activity.
pub struct ConstantActivity {
    activity: Out<f64>,
    value: Parameter<f64>,
}

impl ModuleType for ConstantActivity {
    const NAME: &'static str = "ferroc_std.ConstantActivity";
    const DOC: &'static str = "Publishes a constant iB2C activity in [0, 1]";
    fn create(m: &mut Setup<'_>) -> Self {
        ConstantActivity {
            activity: m.output("activity").meta(MetaType::Activity).build(),
            value: m
                .param("value")
                .meta(MetaType::Activity)
                .default(1.0)
                .doc("the activity to publish")
                .build(),
        }
    }
}

impl Module for ConstantActivity {
    fn update(&mut self) {
        self.activity.publish(self.value.get());
    }
}

#[cfg(test)]
mod tests {
    use super::number_to_activity;

    #[test]
    fn numbers_map_linearly_and_clamp() {
        assert_eq!(number_to_activity(0.5, 0.0, 2.0), 0.25);
        assert_eq!(number_to_activity(-1.0, 0.0, 2.0), 0.0);
        assert_eq!(number_to_activity(3.0, 0.0, 2.0), 1.0);
        // falling: charge 0.3 → 0, 0.15 → 1 (a low battery stimulates docking)
        assert_eq!(number_to_activity(0.3, 0.3, 0.15), 0.0);
        assert_eq!(number_to_activity(0.15, 0.3, 0.15), 1.0);
        assert!((number_to_activity(0.2, 0.3, 0.15) - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(number_to_activity(f64::NAN, 0.0, 1.0), 0.0);
        assert_eq!(number_to_activity(1.0, 1.0, 1.0), 1.0);
        assert_eq!(number_to_activity(0.9, 1.0, 1.0), 0.0);
        assert_eq!(
            number_to_activity(1.0, f64::NEG_INFINITY, f64::INFINITY),
            0.0
        );
    }
}
