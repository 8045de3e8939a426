//! A LuGre mass-friction system at the thesis's conditions (Table 5-11:
//! σ0 = 3e7 N/m, σ1 = 0.1 N s/m; 20 kg load) under the stiff Rosenbrock
//! integrator with the model's analytic Jacobian: it runs without step-size
//! collapse, sticks while the drive is inside the stiction band, and its
//! energy ledger closes.

use hydrocyl_friction::{FrictionInput, FrictionModel, LuGre};
use hydrocyl_integrators::{solve, Method, OdeSystem, Options};
use hydrocyl_ports::Velocity;

const MASS: f64 = 20.0;
const AMP: f64 = 260.0;
const FREQ: f64 = 0.2;

/// States: x [m], v [m/s], z [m], dissipated energy [J], drive work [J].
struct MassFriction {
    friction: LuGre,
}

impl MassFriction {
    fn drive(t: f64) -> f64 {
        AMP * (std::f64::consts::TAU * FREQ * t).sin()
    }
}

impl OdeSystem for MassFriction {
    fn dim(&self) -> usize {
        5
    }

    fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
        let input = FrictionInput::at_velocity(Velocity::new(x[1]));
        let f = self.friction.force(&input, &x[2..3]).si();
        dx[0] = x[1];
        dx[1] = (Self::drive(t) - f) / MASS;
        self.friction
            .state_derivative(&input, &x[2..3], &mut dx[2..3]);
        dx[3] = self.friction.dissipated_power(&input, &x[2..3]).si();
        dx[4] = Self::drive(t) * x[1];
    }

    fn jacobian(&self, t: f64, x: &[f64], jac: &mut [f64]) -> bool {
        let input = FrictionInput::at_velocity(Velocity::new(x[1]));
        let j = self.friction.jacobian(&input, &x[2..3]);
        let (v, z) = (x[1], x[2]);
        let s0 = self.friction.sigma0;
        let f = self.friction.force(&input, &x[2..3]).si();
        let mut zd = [0.0];
        self.friction.state_derivative(&input, &x[2..3], &mut zd);
        jac.fill(0.0);
        let n = 5;
        jac[1] = 1.0; // dx/dt = v
        jac[n + 1] = -j.df_dv / MASS;
        jac[n + 2] = -j.df_dz / MASS;
        jac[2 * n + 1] = j.dzdot_dv;
        jac[2 * n + 2] = j.dzdot_dz;
        // D = F v − σ0 z ż
        jac[3 * n + 1] = j.df_dv * v + f - s0 * z * j.dzdot_dv;
        jac[3 * n + 2] = j.df_dz * v - s0 * zd[0] - s0 * z * j.dzdot_dz;
        jac[4 * n + 1] = Self::drive(t);
        true
    }
}

#[test]
fn lugre_mass_runs_under_rosenbrock_without_step_collapse() {
    let mut sys = MassFriction {
        friction: LuGre::table_5_11(),
    };
    let opts = Options {
        rtol: 1e-6,
        atol: vec![1e-9, 1e-8, 1e-12, 1e-6, 1e-6],
        ..Options::default()
    };
    let t_end = 1.0 / FREQ;
    let sol = solve(Method::Rosenbrock, &mut sys, 0.0, &[0.0; 5], t_end, &opts).unwrap();
    let steps: Vec<f64> = sol
        .t
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|h| *h > 0.0)
        .collect();
    let h_min = steps.iter().copied().fold(f64::INFINITY, f64::min);
    eprintln!(
        "Rosenbrock, one 5 s period: {:?}, smallest step {h_min:e} s",
        sol.stats
    );
    assert!(h_min > 1e-8, "smallest step {h_min:e}");
    assert!(sol.stats.steps < 20_000, "{:?}", sol.stats);
    // The explicit method needs many more steps on the same problem (stiffness).
    let explicit = solve(
        Method::DormandPrince45,
        &mut sys,
        0.0,
        &[0.0; 5],
        t_end,
        &opts,
    )
    .unwrap();
    eprintln!("Dormand-Prince, same problem: {:?}", explicit.stats);
    assert!(explicit.stats.steps > 2 * sol.stats.steps);
    // Stuck while the drive is below the Coulomb level on the first rise
    // (F_d = 100 N at t = 0.315 s): only pre-sliding creep, a few µm at
    // a few hundredths of a mm/s (z ≈ F/σ0 = 3.3 µm).
    let t_stuck = (100.0f64 / AMP).asin() / (std::f64::consts::TAU * FREQ);
    let k = sol.t.iter().position(|&t| t >= t_stuck).unwrap();
    let s = sol.state(k);
    assert!(
        s[1].abs() < 1e-4 && s[0].abs() < 2e-5,
        "x = {}, v = {}",
        s[0],
        s[1]
    );
    // Then it slides: peak speed close to (AMP − Fc)/σ2 order, 0.05..0.2 m/s.
    let vmax = (0..sol.t.len())
        .map(|k| sol.state(k)[1])
        .fold(f64::MIN, f64::max);
    assert!(vmax > 0.05 && vmax < 0.2, "vmax {vmax}");
    // Energy: drive work = kinetic + bristle + dissipated.
    let x = sol.last().unwrap();
    let ke = 0.5 * MASS * x[1] * x[1];
    let stored = sys.friction.stored_energy(&x[2..3]).si();
    assert!(
        (x[4] - (ke + stored + x[3])).abs() < 1e-4 * x[4].abs(),
        "work {} vs {} + {} + {}",
        x[4],
        ke,
        stored,
        x[3]
    );
}
