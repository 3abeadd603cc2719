//! The car of `examples/car.rs` at reduced size: the nonholonomic constraint as an equality
//! and forward-only speed as a hard bound.

use crate::car_models as car;

/// The tight U-turn (N = 150): without the bound the plan backs up (negative speed); with it
/// the speed stays >= 0 (the bound active: its minimum at 0) at a higher cost; the wheels
/// never slip, and both plans are certified.
#[test]
fn the_forward_only_car_does_not_back_up() {
    let free = car::plan_u_turn(0.2, 6.0, 150, false).unwrap();
    let forward = car::plan_u_turn(0.2, 6.0, 150, true).unwrap();
    let (free_speed, free_slip) = car::speed_and_slip(&free);
    let (speed, slip) = car::speed_and_slip(&forward);
    assert!(
        free_speed < -0.01,
        "the free plan's least speed {free_speed}"
    );
    assert!(
        (-1e-9..1e-3).contains(&speed),
        "the bounded plan's least speed {speed}"
    );
    assert!(
        free_slip < 1e-9 && slip < 1e-9,
        "slip {free_slip:e}, {slip:e}"
    );
    assert!(
        forward.cost > free.cost,
        "{} vs {}",
        forward.cost,
        free.cost
    );
    for plan in [&free, &forward] {
        let c = &plan.certificate;
        assert_eq!(c.negative_directions, 0);
        assert!(c.stationarity <= 1e-6 && c.feasibility <= 1e-9, "{c:?}");
    }
}
