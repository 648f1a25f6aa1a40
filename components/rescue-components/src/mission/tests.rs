use super::*;
use crate::drivers::sweep;
use crate::grid::Grid;
use crate::hardware::Robot;
use crate::mapper::{empty_map, integrate};
use search::SEARCH_RANGE;
use std::time::Duration;

fn victim(confidence: f32) -> Victim {
    Victim {
        x: 0.0,
        y: 1.2,
        id: 1,
        confidence,
    }
}

#[test]
fn contexts_switch_on_victims_and_battery() {
    let explore = Context::Explore;
    assert_eq!(explore.next(&[], 25.0, 21.5), Context::Explore);
    assert_eq!(
        explore.next(&[victim(0.75)], 25.0, 21.5),
        Context::ApproachVictim
    );
    assert_eq!(
        Context::ApproachVictim.next(&[victim(0.95)], 25.0, 21.5),
        Context::Explore
    );
    // No battery reading yet (0 V) is not a low battery; a low one stays low.
    assert_eq!(explore.next(&[], 0.0, 21.5), Context::Explore);
    assert_eq!(explore.next(&[], 21.0, 21.5), Context::LowBattery);
    assert_eq!(
        Context::LowBattery.next(&[], 25.0, 21.5),
        Context::LowBattery
    );
    // Idle and returning home ignore victims.
    assert_eq!(
        Context::Idle.next(&[victim(0.5)], 25.0, 21.5),
        Context::Idle
    );
    assert_eq!(Context::of_command(" pause "), Some(Context::Idle));
    assert_eq!(Context::of_command("dance"), None);
}

#[test]
fn the_approach_goal_lies_before_the_victim_facing_it() {
    let robot = Pose2D {
        x: -4.0,
        y: 1.2,
        theta: 0.0,
    };
    let g = approach_goal(&robot, &victim(0.7));
    assert!(
        (g.x + APPROACH_DISTANCE).abs() < 1e-9 && (g.y - 1.2).abs() < 1e-9,
        "{g:?}"
    );
    assert!(g.theta.abs() < 1e-9);
    // Closer than that already: stay, but face it.
    let near = Pose2D {
        x: 0.0,
        y: 0.2,
        theta: 3.0,
    };
    let g = approach_goal(&near, &victim(0.7));
    assert_eq!((g.x, g.y), (0.0, 0.2));
    assert!((g.theta - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
}

#[test]
fn the_camera_searches_the_floor_ahead_and_the_nearest_unsearched_floor_is_next() {
    let robot = Robot::default();
    let mut map = empty_map(0.05, 40.0).unwrap();
    integrate(
        &mut map,
        &sweep(&robot, &robot.pose, 30.0, Duration::ZERO),
        &robot.pose,
    );
    let grid = Grid::from_map(&map, 0.3, 0.15);
    let mut searched = Searched::default();
    searched.look(&grid, &robot.pose);
    let at = |x: f64, y: f64| grid.cell_of(x, y).unwrap();
    // Ahead within range: searched; beyond the range, beside, or behind: not.
    assert!(searched.contains(at(-2.0, 0.0)));
    assert!(!searched.contains(at(-4.0 + SEARCH_RANGE + 1.0, 0.0)));
    assert!(!searched.contains(at(-4.0, 2.0)));
    // The next goal is unsearched floor close by, not beyond the partition.
    let goal = nearest_unsearched(&grid, &searched, &robot.pose, &robot.pose, 30.0, 3).unwrap();
    let cell = at(goal.x, goal.y);
    assert!(!searched.contains(cell) && grid.get(cell) == crate::grid::Cell::Free);
    assert!(goal.distance_to(&robot.pose) < 3.0, "{goal:?}");
    // With a search radius of half a metre there is nothing to search.
    assert!(nearest_unsearched(&grid, &searched, &robot.pose, &robot.pose, 0.5, 3).is_none());
    // Looking round from the start searches more.
    let mut turned = robot.pose;
    turned.theta = std::f64::consts::FRAC_PI_2;
    searched.look(&grid, &turned);
    assert!(searched.contains(at(-4.0, 2.0)));
}
