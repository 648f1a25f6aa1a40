//! The fusion formulas on known inputs. Inputs are chosen so that most results are
//! exact binary fractions (compared with `==`); the others are compared with the
//! fraction they must equal, to 1e-12.

use super::*;

const M: FusionMethod = FusionMethod::Max;
const AVG: FusionMethod = FusionMethod::WeightedAverage;
const SUM: FusionMethod = FusionMethod::WeightedSum;

/// Fuses channels (activity, target rating, data) with activation `iota`:
/// (data, activity, target rating).
fn run(method: FusionMethod, iota: f64, channels: &[(f64, f64, f64)]) -> (f64, f64, f64) {
    let a: Vec<f64> = channels.iter().map(|c| c.0).collect();
    let r: Vec<f64> = channels.iter().map(|c| c.1).collect();
    let mut w = vec![f64::NAN; channels.len()];
    let out = weigh(method, iota, &a, &r, &mut w);
    let u = fuse(&w, channels.iter().map(|c| c.2));
    (u, out.activity, out.target_rating)
}

fn close(x: f64, y: f64) -> bool {
    (x - y).abs() < 1e-12
}

#[test]
fn winner_takes_all() {
    // a = (0.5, 0.25): channel 0 wins.
    assert_eq!(
        run(M, 1.0, &[(0.5, 0.5, 4.0), (0.25, 1.0, 8.0)]),
        (4.0, 0.5, 0.5)
    );
    // The activation scales the activity only.
    assert_eq!(
        run(M, 0.5, &[(0.25, 0.5, 4.0), (0.75, 0.25, 8.0)]),
        (8.0, 0.375, 0.25)
    );
}

#[test]
fn winner_takes_all_breaks_ties_by_the_first_channel() {
    assert_eq!(
        run(M, 1.0, &[(0.5, 0.5, 4.0), (0.5, 1.0, 8.0)]),
        (4.0, 0.5, 0.5)
    );
    assert_eq!(
        run(
            M,
            1.0,
            &[(0.25, 0.0, 1.0), (0.5, 0.5, 4.0), (0.5, 1.0, 8.0)]
        ),
        (4.0, 0.5, 0.5)
    );
}

#[test]
fn weighted_average() {
    // Σa = 1: weights 0.75, 0.25; activity Σa²/Σa = 0.625; rating 0.375 + 0.25.
    assert_eq!(
        run(AVG, 1.0, &[(0.75, 0.5, 4.0), (0.25, 1.0, 8.0)]),
        (5.0, 0.625, 0.625)
    );
    // Σa = 0.75 (not a binary fraction): the same formulas as fractions.
    let (u, a, r) = run(AVG, 0.5, &[(0.5, 0.5, 4.0), (0.25, 1.0, 8.0)]);
    assert!(close(u, 16.0 / 3.0), "{u}");
    assert!(close(a, 0.3125 / 0.75 * 0.5), "{a}");
    assert!(close(r, 2.0 / 3.0), "{r}");
}

#[test]
fn weighted_sum() {
    // a_max = 0.5: weights 1, 0.5; activity Σa²/a_max = 0.3125/0.5 = 0.625.
    let (u, a, r) = run(SUM, 1.0, &[(0.5, 0.5, 4.0), (0.25, 1.0, 8.0)]);
    assert_eq!((u, a), (8.0, 0.625));
    assert!(close(r, 2.0 / 3.0), "{r}");
    // Σa²/a_max = 2 is capped at 1, then scaled by ι.
    assert_eq!(
        run(SUM, 0.5, &[(1.0, 0.0, 4.0), (1.0, 0.5, 8.0)]),
        (12.0, 0.5, 0.25)
    );
}

#[test]
fn all_activities_zero() {
    let ch = [(0.0, 0.5, 4.0), (0.0, 1.0, 8.0)];
    // max: the first channel; activity 0.
    assert_eq!(run(M, 1.0, &ch), (4.0, 0.0, 0.5));
    // weighted average: plain averages of data and ratings; activity 0.
    assert_eq!(run(AVG, 1.0, &ch), (6.0, 0.0, 0.75));
    // weighted sum: zero data; ratings averaged; activity 0.
    assert_eq!(run(SUM, 1.0, &ch), (0.0, 0.0, 0.75));
}

#[test]
fn one_channel() {
    let ch = [(0.5, 0.25, 3.0)];
    assert_eq!(run(M, 1.0, &ch), (3.0, 0.5, 0.25));
    assert_eq!(run(AVG, 1.0, &ch), (3.0, 0.5, 0.25));
    assert_eq!(run(SUM, 1.0, &ch), (3.0, 0.5, 0.25));
    assert_eq!(run(SUM, 0.5, &ch), (3.0, 0.25, 0.25));
}

#[test]
fn no_channels() {
    for method in [M, AVG, SUM] {
        assert_eq!(run(method, 1.0, &[]), (0.0, 0.0, 0.0));
    }
}

#[test]
fn a_zero_weight_channel_cannot_spoil_the_result() {
    assert_eq!(
        run(M, 1.0, &[(0.0, 1.0, f64::NAN), (0.5, 0.0, 2.0)]),
        (2.0, 0.5, 0.0)
    );
}

#[test]
fn arrays_fuse_element_by_element() {
    let w = [0.75, 0.25];
    let u = fuse(&w, [[1.0, 2.0], [3.0, 4.0]]);
    assert_eq!(u, [1.5, 2.5]);
    let u: [[f32; 2]; 1] = fuse(&[0.5], [[[2.0f32, 4.0]]]);
    assert_eq!(u, [[1.0, 2.0]]);
}

/// A library type opts in field by field.
#[derive(Default, Debug, PartialEq)]
struct Twist {
    linear: f64,
    angular: f64,
}
impl Fuse for Twist {
    fn add_weighted(&mut self, x: &Self, w: f64) {
        self.linear.add_weighted(&x.linear, w);
        self.angular.add_weighted(&x.angular, w);
    }
}

#[test]
fn a_library_type_fuses_through_its_own_impl() {
    let data = [
        Twist {
            linear: 1.0,
            angular: -1.0,
        },
        Twist {
            linear: 0.0,
            angular: 1.0,
        },
    ];
    let mut w = [0.0; 2];
    weigh(AVG, 1.0, &[0.5, 0.5], &[0.0, 0.0], &mut w);
    assert_eq!(
        fuse(&w, data),
        Twist {
            linear: 0.5,
            angular: 0.0
        }
    );
}
