//! The numeric fields of this library's copy types that a model may take apart on a
//! connection (`<convert field="linear"/>` from a `Velocity2D` output to an `f64`
//! input).
//!
//! WAITING FOR THE RUNTIME: `ferroc_runtime::builder::Registry::register_field` is
//! being added on main. Until it is there, [`register_fields`] is written against the
//! [`RegisterField`] trait, which has exactly that method's signature, and
//! [`crate::register`] does not call it. On merge: call `register_fields(registry)`
//! from `register`, and either implement the trait for `Registry` (forwarding to the
//! inherent method) or change the parameter to `&mut Registry` and delete the trait.

use crate::types::{Pose2D, Velocity2D, Victim};
use ferroc_runtime::module::PortValue;

/// A registry that learns how to read a named field of a port value:
/// `ferroc_runtime::builder::Registry::register_field`'s signature.
pub trait RegisterField {
    /// Connections with `<convert field="FIELD"/>` from an `S` to an `F` read `get`.
    fn register_field<S: PortValue, F: PortValue>(
        &mut self,
        field: &'static str,
        get: fn(&S) -> F,
    ) -> &mut Self;
}

/// Registers every numeric field of `Pose2D`, `Velocity2D` and `Victim`.
pub fn register_fields(registry: &mut impl RegisterField) {
    registry
        .register_field::<Pose2D, f64>("x", |p| p.x)
        .register_field::<Pose2D, f64>("y", |p| p.y)
        .register_field::<Pose2D, f64>("theta", |p| p.theta)
        .register_field::<Velocity2D, f64>("linear", |v| v.linear)
        .register_field::<Velocity2D, f64>("angular", |v| v.angular)
        .register_field::<Victim, u32>("id", |v| v.id)
        .register_field::<Victim, f64>("x", |v| v.x)
        .register_field::<Victim, f64>("y", |v| v.y)
        .register_field::<Victim, f32>("confidence", |v| v.confidence);
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::any::Any;

    /// Reads a field of a type-erased value as `f64`.
    type Reader = Box<dyn Fn(&dyn Any) -> Option<f64>>;

    #[derive(Default)]
    struct Recorder(Vec<(String, &'static str, String, Reader)>);

    impl RegisterField for Recorder {
        fn register_field<S: PortValue, F: PortValue>(
            &mut self,
            field: &'static str,
            get: fn(&S) -> F,
        ) -> &mut Self {
            let read: Reader = Box::new(move |value: &dyn Any| {
                let f = get(value.downcast_ref::<S>()?);
                let f: &dyn Any = &f;
                f.downcast_ref::<f64>()
                    .copied()
                    .or_else(|| f.downcast_ref::<f32>().map(|&x| f64::from(x)))
                    .or_else(|| f.downcast_ref::<u32>().map(|&x| f64::from(x)))
            });
            self.0.push((S::model_type(), field, F::model_type(), read));
            self
        }
    }

    #[test]
    fn each_field_reads_its_own_value() {
        let mut r = Recorder::default();
        register_fields(&mut r);
        let read = |ty: &str, field: &str, value: &dyn Any| {
            let (_, _, _, reader) =
                r.0.iter()
                    .find(|(t, f, _, _)| t == ty && *f == field)
                    .unwrap_or_else(|| panic!("{ty}.{field} is not registered"));
            reader(value)
        };
        let v = Velocity2D {
            linear: 0.4,
            angular: -0.2,
        };
        assert_eq!(read("rescue.Velocity2D", "linear", &v), Some(0.4));
        assert_eq!(read("rescue.Velocity2D", "angular", &v), Some(-0.2));
        let p = Pose2D {
            x: 1.0,
            y: 2.0,
            theta: 3.0,
        };
        assert_eq!(read("rescue.Pose2D", "x", &p), Some(1.0));
        assert_eq!(read("rescue.Pose2D", "y", &p), Some(2.0));
        assert_eq!(read("rescue.Pose2D", "theta", &p), Some(3.0));
        let victim = Victim {
            x: 5.0,
            y: 6.0,
            id: 7,
            confidence: 0.5,
        };
        assert_eq!(read("rescue.Victim", "id", &victim), Some(7.0));
        assert_eq!(read("rescue.Victim", "y", &victim), Some(6.0));
        assert_eq!(read("rescue.Victim", "confidence", &victim), Some(0.5));
        // The field types are what the manifest declares.
        let types: Vec<(&str, &str, &str)> =
            r.0.iter()
                .map(|(ty, field, field_type, _)| (ty.as_str(), *field, field_type.as_str()))
                .collect();
        assert!(types.contains(&("rescue.Victim", "confidence", "f32")));
        assert!(types.contains(&("rescue.Victim", "id", "u32")));
        assert!(types.contains(&("rescue.Velocity2D", "linear", "f64")));
        assert_eq!(r.0.len(), 9);
    }
}
