//! Energy: F v = dissipated + d(stored)/dt along solutions, the dissipation is
//! never negative, and the bristle never returns more energy than it stored
//! (passivity) over random velocity histories.

use hydrocyl_friction::{FrictionInput, FrictionModel, LuGre, Wang};
use hydrocyl_ports::{Pressure, Velocity};
use proptest::prelude::*;

use crate::common::{dahl_from, lugre_from, rk4};

/// A smooth random velocity history: a sum of sines with random amplitudes,
/// frequencies and phases [m/s].
#[derive(Clone, Debug)]
struct History(Vec<(f64, f64, f64)>);

impl History {
    fn v(&self, t: f64) -> f64 {
        self.0.iter().map(|(a, w, ph)| a * (w * t + ph).sin()).sum()
    }
}

fn history() -> impl Strategy<Value = History> {
    prop::collection::vec((0.0f64..0.05, 0.5f64..40.0, 0.0f64..6.3), 1..5).prop_map(History)
}

struct Ledger {
    work_in: f64,
    dissipated: f64,
    stored0: f64,
    stored_end: f64,
    min_margin: f64,
    min_dissipation: f64,
}

/// Integrates [z, ∫F v, ∫D] along the history and returns the ledger.
fn run<M: FrictionModel>(m: &M, h: &History, pd: f64, z0: f64, t_end: f64) -> Ledger {
    let input = |t: f64| FrictionInput {
        velocity: Velocity::new(h.v(t)),
        p1: Pressure::new(pd),
        ..FrictionInput::default()
    };
    let f = |t: f64, x: &[f64], dx: &mut [f64]| {
        let i = input(t);
        m.state_derivative(&i, &x[..1], &mut dx[..1]);
        dx[1] = (m.force(&i, &x[..1]) * i.velocity).si();
        dx[2] = m.dissipated_power(&i, &x[..1]).si();
    };
    let mut x = [z0, 0.0, 0.0];
    let stored0 = m.stored_energy(&x[..1]).si();
    let steps = 50_000;
    let dt = t_end / steps as f64;
    let mut min_margin = f64::INFINITY;
    let mut min_dissipation = f64::INFINITY;
    for k in 0..steps {
        let t = k as f64 * dt;
        min_dissipation = min_dissipation.min(m.dissipated_power(&input(t), &x[..1]).si());
        rk4(&f, t, &mut x, dt);
        min_margin = min_margin.min(x[1] + stored0);
    }
    Ledger {
        work_in: x[1],
        dissipated: x[2],
        stored0,
        stored_end: m.stored_energy(&x[..1]).si(),
        min_margin,
        min_dissipation,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// LuGre (random curve, σ1 within the passivity bound), random history:
    /// ∫F v = ∫D + ΔE, D ≥ 0 everywhere, and ∫₀ᵗ F v ≥ −E(0) at every t.
    #[test]
    fn lugre_is_passive_and_its_ledger_closes(
        fc in 10.0f64..200.0, ratio in 1.0f64..2.5, vs in 1e-3f64..0.05,
        delta in 0.3f64..2.0, sigma2 in 1.0f64..1000.0,
        z0r in -1.0f64..1.0, h in history(),
    ) {
        // σ0 = 1e5 keeps the bristle resolvable by a fixed RK4 step.
        let m = lugre_from(&[fc, ratio, vs, delta, 1e5, sigma2]);
        let z0 = z0r * fc * ratio / m.sigma0;
        let l = run(&m, &h, 0.0, z0, 1.0);
        let scale = l.work_in.abs() + l.dissipated.abs() + l.stored0 + 1e-9;
        prop_assert!((l.work_in - (l.dissipated + l.stored_end - l.stored0)).abs() <= 1e-6 * scale,
            "ledger {} vs {} + {} - {}", l.work_in, l.dissipated, l.stored_end, l.stored0);
        prop_assert!(l.min_dissipation >= -1e-9 * scale, "D = {}", l.min_dissipation);
        prop_assert!(l.min_margin >= -1e-9 * scale, "returned more than stored: {}", l.min_margin);
    }

    /// Dahl and Wang (pressure term on): the same ledger.
    #[test]
    fn dahl_and_wang_ledgers_close(h in history(), pd in 0.0f64..2e6) {
        let d = dahl_from(&[50.0, 1.0, 0.0, 0.0, 1e5, 10.0]);
        let l = run(&d, &h, 0.0, 0.0, 1.0);
        let scale = l.work_in.abs() + l.dissipated.abs() + 1e-9;
        prop_assert!((l.work_in - (l.dissipated + l.stored_end - l.stored0)).abs() <= 1e-6 * scale);
        prop_assert!(l.min_margin >= -1e-9 * scale);
        let mut w = Wang::table_5_8();
        w.sigma0 = 1e5;
        let l = run(&w, &h, pd, 0.0, 1.0);
        let scale = l.work_in.abs() + l.dissipated.abs() + 1e-9;
        prop_assert!((l.work_in - (l.dissipated + l.stored_end - l.stored0)).abs() <= 1e-6 * scale);
        prop_assert!(l.min_margin >= -1e-9 * scale);
    }
}

#[test]
fn stored_energy_is_half_sigma0_z_squared() {
    let m = LuGre::table_5_11();
    let z = 5e-6;
    assert!((m.stored_energy(&[z]).si() - 0.5 * 3e7 * z * z).abs() < 1e-15);
    let mut scale = [0.0];
    hydrocyl_friction::FrictionLaw::LuGre(m).state_scales(&mut scale);
    assert!((scale[0] - 188.0 / 3e7).abs() < 1e-15);
}

/// The bristle released from a deflection with v = 0 neither gains nor loses
/// energy (dz/dt = v − … = 0), and with v ≠ 0 against the deflection the power
/// F v is negative (energy flows back) but never more than was stored.
#[test]
fn a_loaded_bristle_returns_at_most_what_it_stored() {
    let mut m = LuGre::table_5_11();
    m.sigma0 = 1e5;
    let z0 = 170.0 / m.sigma0; // almost the stiction deflection
    let h = History(vec![(-0.002, 0.0, std::f64::consts::FRAC_PI_2)]); // v = −2 mm/s constant
    let l = run(&m, &h, 0.0, z0, 2.0);
    // Energy did flow back out of the bristle (∫F v went negative) ...
    assert!(l.min_margin < l.stored0);
    // ... but never more than it held.
    assert!(l.min_margin >= 0.0, "{}", l.min_margin);
}

/// The acceleration term's added mass `c(v)` is continuous across a reversal
/// (the blend of `ACCELERATION_BLEND_VELOCITY`), takes Table 5-8's `K H` away
/// from it, and stays conservative: `dΦ/dv = c(v) v` with `Φ(0) = 0`, so
/// `c a v = dΦ/dt` along any motion.
#[test]
fn acceleration_term_is_continuous_and_conservative() {
    use hydrocyl_friction::ACCELERATION_BLEND_VELOCITY as A;
    let w = Wang::table_5_8();
    let c = |v: f64| {
        w.acceleration_coefficient(&FrictionInput::at_velocity(Velocity::new(v)))
            .si()
    };
    // continuity at v = 0: the two one-sided values meet at the mean
    let (cp, cm) = (c(1e-12), c(-1e-12));
    assert!((cp - cm).abs() < 1e-6, "{cp} {cm}");
    assert!((c(0.0) - 0.5 * (76.25 + 36.0)).abs() < 1e-9);
    // Lipschitz: the slope is at most Δc/(2A) = 20.125 kg per mm/s
    let slope = (c(1e-6) - c(-1e-6)) / 2e-6;
    assert!(
        slope > 0.0 && slope <= 0.5 * (76.25 - 36.0) / A * (1.0 + 1e-6),
        "{slope}"
    );
    // the directions' values away from the band
    assert!((c(0.05) - 76.25).abs() < 0.01 && (c(-0.05) - 36.0).abs() < 0.01);
    // Φ' = c v by central differences, at points inside and outside the band
    assert_eq!(w.acceleration_energy(0.0), 0.0);
    for v in [-0.08, -0.01, -2e-3, -5e-4, 3e-4, 1e-3, 7e-3, 0.05] {
        let h = 1e-7;
        let d = (w.acceleration_energy(v + h) - w.acceleration_energy(v - h)) / (2.0 * h);
        assert!(
            (d - c(v) * v).abs() < 1e-6 * (c(v) * v).abs().max(1e-9),
            "{v}: {d} vs {}",
            c(v) * v
        );
    }
    // without the term both vanish
    let p = w.without_acceleration_term();
    assert_eq!(p.acceleration_energy(0.05), 0.0);
}
