//! The crash-course demo does what the README says: its controller keeps the robot off
//! the walls. Runs in lockstep (model time, the same lines on every run), five minutes of
//! model time each, with the model's sensor noise and with none and much more.

mod common;

use common::ferroc;

/// The printed poses `(x, y)` of the visualisation's status lines.
fn poses(out: &str) -> Vec<(f64, f64)> {
    out.lines()
        .filter_map(|l| {
            let x = l.split("x=").nth(1)?.split(" m").next()?.parse().ok()?;
            let y = l.split("y=").nth(1)?.split(" m").next()?.parse().ok()?;
            Some((x, y))
        })
        .collect()
}

fn run(noise: &str) -> String {
    let param = format!("front-noise={noise}");
    let args = [
        "run",
        "models/crash_course.xml",
        "--lockstep",
        "--for",
        "300s",
        "-q",
        "--param",
        &param,
    ];
    let (code, out, err) = ferroc(&args);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("stopped (model time is up)"), "{err}");
    assert!(err.contains("fragile_bot/main: 7501 cycles"), "{err}");
    out
}

#[test]
fn five_minutes_in_the_arena_without_touching_a_wall() {
    for noise in ["15cm", "0cm", "40cm"] {
        let out = run(noise);
        assert!(!out.contains("collision"), "noise {noise}:\n{out}");
        let lines = out.lines().filter(|l| l.contains("] robot ")).count();
        assert_eq!(lines, 301, "noise {noise}: one status line a second");
        assert!(
            out.lines()
                .filter(|l| l.contains("] robot "))
                .all(|l| l.contains("] robot 1: ")),
            "noise {noise}: a second robot appeared:\n{out}"
        );
        let p = poses(&out);
        assert_eq!(p.len(), 301);
        // The arena is 8 m wide and the body reaches 0.15 m from the centre: the wall
        // is touched at 3.85 m. The controller keeps its clearance besides.
        let nearest = p
            .iter()
            .map(|(x, y)| x.abs().max(y.abs()))
            .fold(0.0, f64::max);
        assert!(nearest < 3.85 - 0.2, "noise {noise}: reached {nearest} m");
        // And it does drive around, rather than keeping safe by standing still.
        let path: f64 = p
            .windows(2)
            .map(|w| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1))
            .sum();
        let farthest = p.iter().map(|(x, y)| x.hypot(*y)).fold(0.0, f64::max);
        assert!(path > 20.0, "noise {noise}: drove only {path} m");
        assert!(farthest > 2.0, "noise {noise}: stayed within {farthest} m");
    }
}

/// With seeded noise a lockstep run is exactly reproducible.
#[test]
fn the_demo_repeats_exactly_in_lockstep() {
    assert_eq!(run("15cm"), run("15cm"));
}
