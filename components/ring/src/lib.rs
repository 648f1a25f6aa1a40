//! `ring`: the module of benchmark B2 (FINROC's headline figure, benchmarks.md).
//!
//! Five `ring.Stage` modules pass a 4×4 `f64` matrix around a ring in one continuous
//! thread container. Each stage reads the matrix its predecessor published, changes one
//! element and publishes the result, so every cycle does real reads and writes that the
//! optimiser cannot remove. `models/control_loop.xml` is the model.

#![forbid(unsafe_code)]

use ferroc_runtime::builder::Registry;
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup};

/// The matrix travelling around the ring (`f64[4][4]` in models).
pub type Matrix = [[f64; 4]; 4];

/// Reads a matrix, adds `increment` to its element (0, 0), publishes it.
pub struct Stage {
    input: In<Matrix>,
    output: Out<Matrix>,
    increment: Parameter<f64>,
}

impl ModuleType for Stage {
    const NAME: &'static str = "ring.Stage";
    const DOC: &'static str = "Passes a 4x4 matrix on, adding `increment` to element (0, 0)";

    fn create(m: &mut Setup<'_>) -> Self {
        Stage {
            input: m.input("input").build(),
            output: m.output("output").build(),
            increment: m
                .param("increment")
                .default(1.0)
                .doc("added to element (0, 0) on the way through")
                .build(),
        }
    }
}

impl Module for Stage {
    fn update(&mut self) {
        let mut matrix = self.input.get();
        matrix[0][0] += self.increment.get();
        self.output.publish(matrix);
    }
}

/// Registers the library's module types.
pub fn register(registry: &mut Registry) {
    registry.register::<Stage>();
}

#[cfg(test)]
mod tests {
    use super::*;
    use ferroc_runtime::builder::{Builder, Conversion, ModuleSpec, Schedule, ThreadSpec};
    use ferroc_runtime::container::ThreadOptions;
    use ferroc_runtime::module::Value;
    use ferroc_runtime::port::{ConnectOptions, CopyInputPort};

    #[test]
    fn the_matrix_travels_the_ring_and_accumulates_every_increment() {
        let mut registry = Registry::new();
        register(&mut registry);
        let mut builder = Builder::new(&registry);
        let names = ["s1", "s2", "s3"];
        for (i, name) in names.iter().enumerate() {
            let increment = [("increment".to_string(), Value::Float(i as f64 + 1.0))];
            builder
                .add_module(ModuleSpec {
                    path: name,
                    type_name: "ring.Stage",
                    params: &increment,
                    queues: &[],
                    ports: &[],
                    violations: Default::default(),
                })
                .unwrap();
        }
        for i in 0..names.len() {
            let next = names[(i + 1) % names.len()];
            builder
                .connect(
                    (names[i], "output"),
                    (next, "input"),
                    Conversion::default(),
                    ConnectOptions::default(),
                )
                .unwrap();
        }
        let probe = CopyInputPort::<Matrix>::new("probe");
        builder
            .output("s3", "output")
            .unwrap()
            .connect(&probe.handle(), ConnectOptions::default())
            .unwrap();
        builder
            .add_thread(ThreadSpec {
                path: "ring".into(),
                schedule: Schedule::Continuous,
                options: ThreadOptions::default(),
                steps: names
                    .iter()
                    .map(|n| (n.to_string(), ferroc_runtime::builder::StepKind::Update))
                    .collect(),
            })
            .unwrap();
        let mut app = builder.start(Some(10)).unwrap();
        app.join();
        // Each cycle adds 1 + 2 + 3 on the way round: after 10 cycles s3 published 60,
        // and the rest of the matrix is untouched.
        assert_eq!(app.status()[0].cycles, 10);
        let matrix = probe.get();
        assert_eq!(matrix[0][0], 60.0);
        assert_eq!(matrix[3][3], 0.0);
    }
}
