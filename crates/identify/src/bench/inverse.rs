//! The bench's force balance written out by hand, the bristle state
//! stepped over each sample interval with the velocity held at the
//! interval's mid value (z relaxes exponentially towards `g(v) sgn(v) / σ0`:
//! an exponential midpoint step of the bristle ODE, second order in the
//! sample interval).
//!
//! Two uses:
//! * the tests' independent reference for the bench's netlist run
//!   ([`super::BenchRun`]): equal to the closed form for a static law, and
//!   to this discretisation's error with LuGre;
//! * the fit's evaluator **for LuGre only** (`diagnose`'s bench loop): the
//!   netlist run integrates the bristle with RK4 (or Rodas4 when stiff) at
//!   20× to 100× this step's cost per evaluation (issue 13's note: EMPS
//!   3.7 s → 487 s), so the bristle's fits stay here for now. A static law
//!   is fitted on the netlist run.

use super::{BenchSignals, FrictionBench};
use crate::catalog::EffectId;

impl FrictionBench {
    /// The law's coefficients, looked up once per simulation.
    fn coeffs(&self) -> Coeffs {
        let fc = self.friction.coulomb;
        Coeffs {
            fc,
            vt: self.friction.smoothing_velocity,
            stribeck: self.has(EffectId::Stribeck).then(|| {
                (
                    self.eff(EffectId::Stribeck, "Fs"),
                    self.eff(EffectId::Stribeck, "vs").max(1e-12),
                    self.eff(EffectId::Stribeck, "alpha"),
                )
            }),
            lugre: self.has(EffectId::LugreDynamics).then(|| {
                (
                    self.eff(EffectId::LugreDynamics, "sigma0").max(1e-9),
                    self.eff(EffectId::LugreDynamics, "sigma1"),
                )
            }),
            b: self.eff(EffectId::Viscous, "b"),
            k: self.eff(EffectId::PressureViscous, "K"),
            h: self.eff(EffectId::AccelerationFriction, "H"),
            dfc: self.eff(EffectId::CoulombAsymmetry, "dFc"),
        }
    }

    /// The reference force on one record, the bristle from the record's
    /// first forces.
    pub(crate) fn reference(&self, s: &BenchSignals) -> Vec<f64> {
        self.simulate_from(s, false)
    }

    /// The reference force with the bristle from rest.
    #[cfg(test)]
    pub(super) fn reference_from_rest(&self, s: &BenchSignals) -> Vec<f64> {
        self.simulate_from(s, true)
    }

    fn simulate_from(&self, s: &BenchSignals, at_rest: bool) -> Vec<f64> {
        let c = self.coeffs();
        let n = s.t.len();
        let mut out = vec![0.0; n];
        let f0 = self.eff(EffectId::ExternalForce, "F0");
        let sg = self.force_sign;
        let pres = |i: usize| s.p1[i] * self.area1 - s.p2[i] * self.area2;
        let mut z = 0.0;
        if let (Some((s0, _)), false) = (c.lugre, at_rest) {
            // s F = m a + F_f + F0 − pA  →  F_f = s F − m a − F0 + pA.
            let k = n.min(5);
            let ff: f64 = (0..k)
                .map(|i| sg * s.force[i] - self.mass * s.a[i] - f0 + pres(i))
                .sum::<f64>()
                / k as f64;
            let zmax = c.g(s.v[0]) / s0;
            z = (ff / s0).clamp(-zmax, zmax);
        }
        for (i, o) in out.iter_mut().enumerate() {
            let ff = c.friction(s.v[i], s.a[i], s.p1[i], s.p2[i], z);
            *o = sg * (self.mass * s.a[i] + ff + f0 - pres(i));
            if let (Some((s0, _)), true) = (c.lugre, i + 1 < n) {
                let h = s.t[i + 1] - s.t[i];
                let vm = 0.5 * (s.v[i] + s.v[i + 1]);
                let g = c.g(vm).max(1e-9);
                let rate = s0 * vm.abs() / g;
                if rate * h > 1e-12 {
                    let zs = vm / rate;
                    z = zs + (z - zs) * (-rate * h).exp();
                } else {
                    z += vm * h;
                }
            }
        }
        out
    }
}

/// The friction law's coefficients in plain fields (the hot loop's view).
struct Coeffs {
    fc: f64,
    vt: f64,
    stribeck: Option<(f64, f64, f64)>,
    lugre: Option<(f64, f64)>,
    b: f64,
    k: f64,
    h: f64,
    dfc: f64,
}

impl Coeffs {
    /// g(v): Coulomb level plus the Stribeck hump if on \[N\].
    fn g(&self, v: f64) -> f64 {
        match self.stribeck {
            Some((fs, vs, al)) => {
                let r = (v / vs).abs();
                let e = if al == 1.0 { r } else { r.powf(al) };
                self.fc + (fs - self.fc) * (-e).exp()
            }
            None => self.fc,
        }
    }

    /// Friction force at one instant \[N\].
    fn friction(&self, v: f64, a: f64, p1: f64, p2: f64, z: f64) -> f64 {
        let th = (v / self.vt).tanh();
        let mut f = match self.lugre {
            Some((s0, s1)) => {
                let g = self.g(v).max(1e-9);
                let zdot = v - s0 * v.abs() * z / g;
                s0 * z + s1 * zdot
            }
            None => self.g(v) * th,
        };
        f += self.b * v;
        f += self.k * (p1 - p2).powi(2) * v;
        f += self.k * self.h * a;
        f += 0.5 * self.dfc * th.abs();
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::{preset, BenchFriction, KIND, PRESETS};
    use crate::data::ColumnMap;
    use std::collections::BTreeMap;

    fn rig() -> FrictionBench {
        FrictionBench {
            kind: KIND.into(),
            name: "t".into(),
            area1: 4.9e-4,
            area2: 0.0,
            mass: 0.5,
            force_sign: 1.0,
            friction: BenchFriction {
                coulomb: 5.0,
                smoothing_velocity: 1e-4,
                effects: BTreeMap::new(),
            },
            refit: vec![],
            columns: ColumnMap::default(),
            steady_state: false,
        }
    }

    fn signals(v: impl Fn(f64) -> f64, n: usize, dt: f64) -> BenchSignals {
        let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let vv: Vec<f64> = t.iter().map(|&t| v(t)).collect();
        BenchSignals {
            source: "x".into(),
            a: vec![0.0; n],
            p1: vec![3e5; n],
            p2: vec![0.0; n],
            force: vec![0.0; n],
            x: vec![0.0; n],
            v: vv,
            t,
        }
    }

    #[test]
    fn lugre_reaches_the_static_curve_at_constant_velocity() {
        // At constant velocity the bristle settles and LuGre's force equals
        // the static law g(v) (eq 5.7); the balance adds s(F_f − p A).
        let mut r = rig();
        let mut lug = BTreeMap::new();
        lug.insert("sigma0".to_string(), 1e6);
        lug.insert("sigma1".to_string(), 50.0);
        r.friction.effects.insert(EffectId::LugreDynamics, lug);
        let s = signals(|_| 0.01, 500, 1e-3);
        let f = r.reference(&s);
        let expect = 5.0 - 3e5 * 4.9e-4;
        assert!((f[499] - expect).abs() < 1e-6, "{} vs {expect}", f[499]);
        // Static model gives the same steady value.
        r.friction.effects.clear();
        let g = r.reference(&s);
        assert!((g[499] - expect).abs() < 1e-6);
    }

    #[test]
    fn lugre_presliding_follows_the_closed_form() {
        // Monotone motion from z = 0 with σ1 = 0: dz/dx = 1 − σ0 z / Fc, so
        // F = σ0 z = Fc (1 − exp(−σ0 x / Fc)) — a spring for x ≪ Fc/σ0,
        // saturating at Fc. Checked at several travels.
        let mut r = rig();
        r.area1 = 0.0;
        let mut lug = BTreeMap::new();
        lug.insert("sigma0".to_string(), 1e6);
        lug.insert("sigma1".to_string(), 0.0);
        r.friction.effects.insert(EffectId::LugreDynamics, lug);
        let dt = 1e-4;
        let v0 = 1e-4;
        let s = signals(|_| v0, 2000, dt);
        let f = r.reference(&s);
        for i in [10, 100, 400, 1999] {
            let x = v0 * dt * i as f64;
            let closed = 5.0 * (1.0 - (-1e6 * x / 5.0).exp());
            assert!(
                (f[i] - closed).abs() < 1e-3 * 5.0,
                "i={i}: {} vs {closed}",
                f[i]
            );
        }
        // Small travel: spring of stiffness σ0.
        assert!((f[10] / (v0 * dt * 10.0) / 1e6 - 1.0).abs() < 0.05);
    }

    /// The netlist run of a bench preset (`rig::simulate`, imposed velocity)
    /// and the bench's inverse model on the same motion give the same
    /// load-cell force: LuGre's bristle from rest on a velocity that ramps
    /// up, holds, reverses (the model integrates it exactly per sample, the
    /// netlist with DP45 at rtol 1e-9).
    #[test]
    fn netlist_run_equals_the_inverse_model() {
        use hydrocyl_system::{rig, run::RunOptions, signal::Signal as Cmd};
        for name in PRESETS {
            let bench = preset(name).unwrap();
            let dt = 1e-3;
            let t: Vec<f64> = (0..3000).map(|i| i as f64 * dt).collect();
            let v: Vec<f64> = t
                .iter()
                .map(|&t| 0.02 * (t / 0.5).min(1.0) * (std::f64::consts::PI * t / 1.5).cos())
                .collect();
            let mut opts = RunOptions::dp45();
            opts.rtol = 1e-9;
            let mut value = rig::preset(name).unwrap();
            // the record's chamber pressure is the preset's constant
            let p = if bench.area2 > 0.0 { 3e5 } else { 0.0 };
            if p > 0.0 {
                rig::apply_set(&mut value, "chamber.pressure=3e5").unwrap();
            }
            let run = rig::simulate(&value, Cmd::table(t.clone(), v.clone()).unwrap(), &t, &opts)
                .unwrap();
            let f = run.channel("force").unwrap();
            // the model's signals: acceleration as the netlist sees it (the
            // slope of the interval that starts at the sample)
            let mut a: Vec<f64> = v.windows(2).map(|w| (w[1] - w[0]) / dt).collect();
            a.push(0.0);
            let s = BenchSignals {
                source: "x".into(),
                x: vec![0.0; t.len()],
                p1: vec![0.0; t.len()],
                p2: vec![p; t.len()],
                force: vec![0.0; t.len()],
                v,
                a,
                t,
            };
            let model = bench.reference_from_rest(&s);
            let scale = model.iter().fold(0.0f64, |m, f| m.max(f.abs()));
            let worst = f
                .iter()
                .zip(&model)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            assert!(worst < 1e-6 * scale, "{name}: worst {worst} N of {scale} N");
        }
    }
}
