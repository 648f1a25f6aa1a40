use super::*;
use crate::Pose2D;
use std::collections::HashSet;

fn order(id: u64, x: f64, priority: u8) -> Task {
    Task {
        id,
        pickup: Pose2D {
            x,
            y: 0.0,
            theta: 0.0,
        },
        priority,
        ..Task::default()
    }
}

fn idle(robot_id: u32, x: f64) -> RobotStatus {
    RobotStatus {
        robot_id,
        pose: Pose2D {
            x,
            y: 0.0,
            theta: 0.0,
        },
        battery_charge: 1.0,
        ..RobotStatus::default()
    }
}

/// Three idle robots at x = 0, 5, 10.
fn fleet() -> Dispatcher {
    let mut d = Dispatcher::new(3);
    for k in 0..3 {
        d.report(k, idle(k as u32 + 1, 5.0 * k as f64));
    }
    d
}

#[test]
fn nearest_gives_each_order_once_to_the_closest_free_robot() {
    let mut d = fleet();
    for (id, x) in [(1, 9.0), (2, 1.0), (3, 6.0), (4, 0.0)] {
        assert!(d.add_order(order(id, x, 0)));
    }
    let Round { sent, taken_back } = d.dispatch(Strategy::Nearest, 100);
    assert!(taken_back.is_empty());
    // Oldest first among equals: 1 → robot at 10, 2 → robot at 0, 3 → robot at 5.
    let ids: Vec<(usize, u64)> = sent.iter().map(|(k, t)| (*k, t.id)).collect();
    assert_eq!(ids, [(2, 1), (0, 2), (1, 3)]);
    assert_eq!(d.pending(), 1);
    // Nobody is free until a robot reports the task done: order 4 waits, nothing twice.
    let sent = d.dispatch(Strategy::Nearest, 100).sent;
    assert!(sent.is_empty());
    // Robot 0 acknowledges task 2 (busy), then finishes it.
    d.report(
        0,
        RobotStatus {
            task_id: 2,
            busy: true,
            ..idle(1, 1.0)
        },
    );
    assert!(d.dispatch(Strategy::Nearest, 100).sent.is_empty());
    d.report(
        0,
        RobotStatus {
            task_id: 2,
            busy: false,
            tasks_done: 1,
            ..idle(1, 1.0)
        },
    );
    let sent = d.dispatch(Strategy::Nearest, 100).sent;
    assert_eq!(sent.len(), 1);
    assert_eq!((sent[0].0, sent[0].1.id), (0, 4));
    assert_eq!(d.pending(), 0);
}

#[test]
fn many_orders_are_each_dispatched_exactly_once() {
    let mut d = fleet();
    for id in 1..=30 {
        d.add_order(order(id, (id % 7) as f64, (id % 4) as u8 * 64));
    }
    let mut seen = HashSet::new();
    for _ in 0..100 {
        let Round { sent, taken_back } = d.dispatch(Strategy::Auction, 1000);
        assert!(taken_back.is_empty());
        for (k, task) in sent {
            assert!(seen.insert(task.id), "task {} dispatched twice", task.id);
            // The robot does it at once.
            d.report(
                k,
                RobotStatus {
                    task_id: task.id,
                    ..idle(k as u32 + 1, 3.0)
                },
            );
        }
    }
    assert_eq!(seen.len(), 30);
    assert_eq!(d.pending(), 0);
}

#[test]
fn higher_priority_goes_first() {
    let mut d = Dispatcher::new(1);
    d.report(0, idle(1, 0.0));
    d.add_order(order(1, 0.0, 0));
    d.add_order(order(2, 50.0, 192));
    let sent = d.dispatch(Strategy::Nearest, 100).sent;
    assert_eq!(sent[0].1.id, 2);
}

#[test]
fn round_robin_takes_the_robots_in_turn_and_skips_busy_ones() {
    let mut d = fleet();
    d.report(
        1,
        RobotStatus {
            busy: true,
            ..idle(2, 5.0)
        },
    );
    for id in 1..=2 {
        d.add_order(order(id, 0.0, 0));
    }
    let sent = d.dispatch(Strategy::RoundRobin, 100).sent;
    let robots: Vec<usize> = sent.iter().map(|(k, _)| *k).collect();
    assert_eq!(robots, [0, 2]);
}

#[test]
fn the_auction_avoids_a_nearly_empty_robot() {
    let mut d = Dispatcher::new(2);
    d.report(
        0,
        RobotStatus {
            battery_charge: 0.3,
            ..idle(1, 0.0)
        },
    );
    d.report(1, idle(2, 3.0));
    d.add_order(order(1, 0.0, 0));
    let sent = d.dispatch(Strategy::Auction, 100).sent;
    assert_eq!(
        sent[0].0, 1,
        "7 m of missing charge outweigh 3 m of driving"
    );
    // The nearest strategy does not care.
    let mut d = Dispatcher::new(2);
    d.report(
        0,
        RobotStatus {
            battery_charge: 0.3,
            ..idle(1, 0.0)
        },
    );
    d.report(1, idle(2, 3.0));
    d.add_order(order(1, 0.0, 0));
    assert_eq!(d.dispatch(Strategy::Nearest, 100).sent[0].0, 0);
}

#[test]
fn an_unacknowledged_task_goes_to_another_robot_after_the_timeout() {
    let mut d = Dispatcher::new(2);
    d.report(0, idle(1, 0.0));
    d.report(1, idle(2, 8.0));
    d.add_order(order(9, 0.0, 0));
    assert_eq!(d.dispatch(Strategy::Nearest, 3).sent[0].0, 0);
    // Robot 0 never answers; robot 1 keeps reporting idle.
    assert!(d.dispatch(Strategy::Nearest, 3).sent.is_empty());
    assert!(d.dispatch(Strategy::Nearest, 3).sent.is_empty());
    let Round { sent, taken_back } = d.dispatch(Strategy::Nearest, 3);
    assert_eq!(taken_back, [(0, 9)]);
    assert_eq!((sent[0].0, sent[0].1.id), (1, 9));
    // Robots without any report yet, and unknown indices, get nothing.
    let mut d = Dispatcher::new(2);
    d.report(7, idle(8, 0.0));
    d.add_order(order(1, 0.0, 0));
    assert!(d.dispatch(Strategy::Nearest, 3).sent.is_empty());
    assert_eq!(d.pending(), 1);
}

#[test]
fn pending_orders_are_bounded_and_strategies_parse() {
    let mut d = Dispatcher::new(0);
    for id in 0..MAX_PENDING as u64 {
        assert!(d.add_order(order(id, 0.0, 0)));
    }
    assert!(!d.add_order(order(999, 0.0, 0)));
    assert_eq!(d.pending(), MAX_PENDING);
    // No robots: nothing happens, nothing panics.
    assert!(d.dispatch(Strategy::RoundRobin, 1).sent.is_empty());
    assert_eq!(Strategy::parse("auction"), Some(Strategy::Auction));
    assert_eq!(Strategy::parse("round_robin"), Some(Strategy::RoundRobin));
    assert_eq!(Strategy::parse("fastest"), None);
}
