use super::*;

fn at(x: f64, y: f64) -> Pose2D {
    Pose2D { x, y, theta: 0.0 }
}

fn task(id: u64) -> Task {
    Task {
        id,
        pickup: at(6.0, 1.5),
        dropoff: at(0.0, 4.0),
        priority: 255,
        ..Task::default()
    }
}

/// Inputs of a robot standing at `pose` with path following done.
fn there(pose: Pose2D) -> Inputs {
    Inputs {
        pose,
        goal_reached: true,
        charge: Some(0.9),
        ..Inputs::default()
    }
}

#[test]
fn a_task_goes_through_pickup_lift_dropoff_and_lowering() {
    let mut m = Mission::new(at(2.5, 0.0), 0.3);
    // Parking first: home is the goal.
    let (c, _) = m.step(&Inputs::default());
    assert_eq!(
        (m.phase, c.goal, c.urgency),
        (Phase::Parking, at(2.5, 0.0), URGENCY_HOME)
    );
    m.step(&there(at(2.5, 0.0)));
    assert_eq!(m.phase, Phase::Idle);
    assert!(m.ready() && !m.busy());

    m.start(task(7));
    let (c, _) = m.step(&Inputs::default());
    assert_eq!(
        (m.phase, c.goal, c.urgency),
        (Phase::ToPickup, at(6.0, 1.5), 1.0)
    );
    // "Reached", but still at the old goal: not there yet.
    m.step(&there(at(2.5, 0.0)));
    assert_eq!(m.phase, Phase::ToPickup);
    m.step(&there(at(6.0, 1.5)));
    assert_eq!(m.phase, Phase::Lifting);
    // Lifting: raise, stand still, wait for the load.
    let (c, _) = m.step(&there(at(6.0, 1.5)));
    assert!(c.lift_raise && c.urgency == 0.0);
    let loaded = Inputs {
        loaded: true,
        ..there(at(6.0, 1.5))
    };
    let (c, _) = m.step(&loaded);
    assert_eq!((m.phase, c.goal), (Phase::ToDropoff, at(0.0, 4.0)));
    let (c, done) = m.step(&Inputs {
        loaded: true,
        ..there(at(0.0, 4.0))
    });
    assert_eq!((m.phase, done), (Phase::Lowering, None));
    assert!(c.lift_raise, "lowering starts with the next step");
    let (c, _) = m.step(&Inputs {
        loaded: true,
        ..there(at(0.0, 4.0))
    });
    assert!(!c.lift_raise && m.phase == Phase::Lowering);
    let (_, done) = m.step(&there(at(0.0, 4.0)));
    assert_eq!(
        (m.phase, done, m.tasks_done, m.last_task),
        (Phase::Parking, Some(7), 1, 7)
    );
}

#[test]
fn a_protective_stop_holds_the_lift() {
    let mut m = Mission::new(at(0.0, 0.0), 0.3);
    m.start(task(1));
    m.step(&there(at(6.0, 1.5)));
    assert_eq!(m.phase, Phase::Lifting);
    let stopped = Inputs {
        protective_stop: true,
        ..there(at(6.0, 1.5))
    };
    let (c, _) = m.step(&stopped);
    assert!(!c.lift_raise, "the lift must not start with someone close");
    let (c, _) = m.step(&there(at(6.0, 1.5)));
    assert!(c.lift_raise);
}

#[test]
fn a_low_battery_sends_it_charging_and_it_takes_no_task() {
    let mut m = Mission::new(at(2.5, 3.0), 0.3);
    let low = Inputs {
        charge: Some(0.2),
        ..Inputs::default()
    };
    let (c, _) = m.step(&low);
    assert_eq!((m.phase, c.goal), (Phase::Charging, at(2.5, 3.0)));
    assert!(m.busy() && !m.ready());
    // At home, still low: it stays; charged above threshold + hysteresis: idle again.
    m.step(&Inputs {
        charge: Some(0.4),
        ..there(at(2.5, 3.0))
    });
    assert_eq!(m.phase, Phase::Charging);
    m.step(&Inputs {
        charge: Some(0.6),
        ..there(at(2.5, 3.0))
    });
    assert_eq!(m.phase, Phase::Idle);
    // Without a battery reading it never goes charging.
    let mut m = Mission::new(at(0.0, 0.0), 0.9);
    m.step(&Inputs {
        charge: None,
        ..there(at(0.0, 0.0))
    });
    assert_eq!(m.phase, Phase::Idle);
}

#[test]
fn tasks_without_id_or_with_nan_positions_are_refused() {
    assert!(valid(&task(3)));
    assert!(!valid(&task(0)));
    let mut t = task(4);
    t.dropoff.x = f64::NAN;
    assert!(!valid(&t));
}
