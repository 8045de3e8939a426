//! Every dynamic model's steady state equals its static curve (eq 2.40 /
//! 5.8), computed here independently, both from `steady_state` and by
//! integrating the bristle at constant velocity.

use hydrocyl_friction::{FrictionInput, FrictionModel, Karnopp, Stribeck};
use hydrocyl_ports::{Pressure, Velocity};
use proptest::prelude::*;

use crate::common::{curve, dahl_from, lugre_from, rk4, wang_from};

/// Eq 2.40 written out: sgn(v) [Fc + (Fs − Fc) exp(−|v/vs|^δ)] + b v.
fn eq_2_40(fc: f64, fs: f64, vs: f64, delta: f64, b: f64, v: f64) -> f64 {
    v.signum() * (fc + (fs - fc) * (-(v / vs).abs().powf(delta)).exp()) + b * v
}

/// Integrates dz/dt at constant input from z = 0 for 40 time constants and
/// returns the force reached.
fn settle<M: FrictionModel>(m: &M, input: &FrictionInput, rate: f64) -> f64 {
    let f = |_t: f64, z: &[f64], dz: &mut [f64]| m.state_derivative(input, z, dz);
    let h = 0.05 / rate;
    let mut z = [0.0];
    for k in 0..800 {
        rk4(&f, k as f64 * h, &mut z, h);
    }
    m.force(input, &z).si()
}

fn params() -> impl Strategy<Value = [f64; 6]> {
    (
        1.0f64..500.0,  // Fc
        1.0f64..3.0,    // Fs / Fc
        1e-4f64..0.1,   // vs
        0.1f64..3.0,    // delta
        1e4f64..1e8,    // sigma0
        0.0f64..2000.0, // sigma2 or K scale
    )
        .prop_map(|(a, b, c, d, e, f)| [a, b, c, d, e, f])
}

fn velocity() -> impl Strategy<Value = f64> {
    prop_oneof![1e-5f64..0.5, -0.5f64..-1e-5]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn lugre_steady_state_is_eq_2_40(p in params(), v in velocity()) {
        let m = lugre_from(&p);
        let s = m.set(v);
        let input = FrictionInput::at_velocity(Velocity::new(v));
        let expect = eq_2_40(s.curve.coulomb.si(), s.curve.stiction.si(),
            s.curve.stribeck_velocity.si(), s.curve.stribeck_exponent, s.sigma2, v);
        let mut z = [0.0];
        m.steady_state(&input, &mut z);
        let mut dz = [1.0];
        m.state_derivative(&input, &z, &mut dz);
        prop_assert!(dz[0].abs() <= 1e-12 * v.abs().max(1e-12));
        let tol = 1e-9 * expect.abs().max(1.0);
        prop_assert!((m.steady_force(&input).si() - expect).abs() <= tol);
        let rate = m.sigma0 * v.abs() / s.curve.g(v);
        prop_assert!((settle(&m, &input, rate) - expect).abs() <= 1e-6 * expect.abs().max(1.0));
    }

    #[test]
    fn dahl_steady_state_is_coulomb_viscous(p in params(), v in velocity()) {
        let m = dahl_from(&p);
        let input = FrictionInput::at_velocity(Velocity::new(v));
        let expect = v.signum() * p[0] + p[5] * v;
        prop_assert!((m.steady_force(&input).si() - expect).abs() <= 1e-9 * expect.abs().max(1.0));
        let rate = m.sigma0 * v.abs() / p[0];
        prop_assert!((settle(&m, &input, rate) - expect).abs() <= 1e-6 * expect.abs().max(1.0));
    }

    #[test]
    fn wang_steady_state_is_eq_5_11(p in params(), v in velocity(), p1 in 0.0f64..2e7, p2 in 0.0f64..2e7) {
        let mut p = p;
        p[5] *= 1e-11; // K in m³ s/N
        let m = wang_from(&p);
        let input = FrictionInput {
            velocity: Velocity::new(v),
            p1: Pressure::new(p1),
            p2: Pressure::new(p2),
            ..FrictionInput::default()
        };
        let s = if v > 0.0 { &m.extending } else { &m.retracting };
        let c = &s.curve;
        let expect = eq_2_40(c.coulomb.si(), c.stiction.si(), c.stribeck_velocity.si(),
            c.stribeck_exponent, s.k_pressure * (p1 - p2).powi(2), v);
        prop_assert!((m.steady_force(&input).si() - expect).abs() <= 1e-9 * expect.abs().max(1.0));
        prop_assert!((m.static_curve(&input) - expect).abs() <= 1e-9 * expect.abs().max(1.0));
        let rate = m.sigma0 * v.abs() / c.g(v);
        prop_assert!((settle(&m, &input, rate) - expect).abs() <= 1e-6 * expect.abs().max(1.0));
    }

    #[test]
    fn static_laws_follow_eq_2_40(p in params(), v in velocity()) {
        let c = curve(p[0], p[0] * p[1], p[2], p[3]);
        let k = Karnopp::new(c, p[5]).unwrap();
        let input = FrictionInput::at_velocity(Velocity::new(v));
        let expect = eq_2_40(p[0], p[0] * p[1], p[2], p[3], p[5], v);
        prop_assert!((k.steady_force(&input).si() - expect).abs() <= 1e-9 * expect.abs().max(1.0));
        let mut s = Stribeck::table_5_11();
        s.extending = hydrocyl_friction::SteadySet { curve: c, sigma2: p[5] };
        s.retracting = s.extending;
        s.smoothing_velocity = Velocity::new(v.abs() / 30.0);
        // tanh(30) = 1 − 1.7e-26: the smoothing is invisible at 30 v_t.
        prop_assert!((s.force(&input, &[]).si() - expect).abs() <= 1e-9 * expect.abs().max(1.0));
        prop_assert!((s.static_curve(Velocity::new(v)).si() - expect).abs() <= 1e-9 * expect.abs().max(1.0));
    }
}

#[test]
fn thesis_sets_give_the_stiction_level_at_rest_and_zero_force_at_zero_velocity() {
    let w = hydrocyl_friction::Wang::table_5_8();
    let at = |v: f64| w.static_curve(&FrictionInput::at_velocity(Velocity::new(v)));
    assert!((at(1e-40) - 180.0).abs() < 0.05);
    assert!((at(-1e-40) + 188.0).abs() < 0.05);
    assert_eq!(at(0.0), 0.0);
    // Extending friction exceeds retracting at the same speed without pressure (Fc 110 vs 80).
    assert!(at(0.05) > -at(-0.05));
}
