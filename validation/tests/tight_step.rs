//! The tight hand-written reduced step, the limit the report measures the generated step
//! against, is the scheme's step: it agrees with the general generated step (Newton on all
//! unknowns) at every state of the paper's 400-step run, and its guard refuses a step that
//! crosses the disc, also between its three samples.

use retract::{StepOptions, step};
use retract_validation::peers::tight_guarded_step;
use retract_validation::systems::{H, PAPER_STEPS, Z, paper_start, paper_system};

#[test]
fn the_tight_step_is_the_general_step_along_the_paper_run() {
    let system = paper_system();
    let options = StepOptions::default();
    let mut z = paper_start(&system);
    for i in 0..PAPER_STEPS {
        let general = step(&system, &z, H, &options).expect("the general step").0;
        let tight = tight_guarded_step(&z).expect("the tight step");
        let difference = (general - tight).amax();
        assert!(
            difference <= 1e-12 * (1.0 + general.amax()),
            "step {i}: {difference:e}"
        );
        z = general;
    }
}

#[test]
fn the_tight_step_refuses_a_step_across_the_disc() {
    for (x, v) in [(1.5, -100.0), (0.9, 100.0), (-1.2, 150.0)] {
        let mut z = Z::zeros();
        (z[0], z[3]) = (x, v);
        assert!(tight_guarded_step(&z).is_err(), "from x = {x}, v = {v}");
    }
    // q0, q_theta and q1 all outside, the chord through the disc between q_theta and q1
    // (its closest point to the centre, near (0, 0.95), is inside): the fit refuses it, as
    // the generated step's guard does
    let mut chord = Z::zeros();
    (chord[0], chord[1], chord[3]) = (-3.0, 0.95, 4.0 / H);
    let system = paper_system();
    assert!(step(&system, &chord, H, &StepOptions::default()).is_err());
    assert!(tight_guarded_step(&chord).is_err());
    let mut outside = Z::zeros();
    (outside[0], outside[3]) = (1.5, 1.0);
    let q1 = tight_guarded_step(&outside).expect("a step outside the disc")[0];
    assert!((q1 - 1.51).abs() < 1e-3, "{q1}");
}
