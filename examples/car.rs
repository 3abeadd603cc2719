//! A car's tight U-turn (`examples/common/car.rs`): minimum acceleration from the origin
//! heading +x at unit speed to (0, 0.2) heading -x, in T = 6 s with N = 600 steps, the wheels
//! not slipping sideways (an equality on the jet at every step); first free to reverse (the
//! free plan backs up), then forward only (speed >= 0, a hard bound). One line per plan:
//! `car <free|forward-only> T=<T> N=<N> J=<J> iterations=<n> min_speed=<v> max_slip=<s>`.
//!
//! Run: `cargo run --release --example car`.

#[path = "common/car.rs"]
mod car;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (t_end, steps) = (6.0, 600);
    for (label, forward_only) in [("free", false), ("forward-only", true)] {
        let plan = car::plan_u_turn(0.2, t_end, steps, forward_only)?;
        let (speed, slip) = car::speed_and_slip(&plan);
        println!(
            "car {label} T={t_end} N={steps} J={:.6} iterations={} min_speed={speed:.3e} \
             max_slip={slip:.1e}",
            plan.cost, plan.iterations
        );
    }
    Ok(())
}
