//! The friction bench as the loop fits it: the records' simulated force,
//! residuals and LM refits ([`Bench`]), a candidate effect's starting
//! values and the out-of-catalog probes (delay, spring, sensor gains).

use super::*;
use crate::bench::{BenchInputs, BenchRun};

/// Which samples a residual uses.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Part {
    All,
    Train,
    Held,
}

pub(super) struct Bench<'a> {
    sigs: &'a [BenchSignals],
    holdout: f64,
    /// One assembled bench netlist per record, run again with each
    /// parameter set ([`BenchRun`]).
    runs: Vec<std::cell::RefCell<BenchRun>>,
}

impl<'a> Bench<'a> {
    pub(super) fn new(
        rig: &FrictionBench,
        sigs: &'a [BenchSignals],
        holdout: f64,
    ) -> Result<Self, String> {
        let runs = sigs
            .iter()
            .map(|s| {
                let inputs = BenchInputs::of(s)?;
                BenchRun::new(rig, &inputs).map(std::cell::RefCell::new)
            })
            .collect::<Result<_, String>>()?;
        Ok(Bench {
            sigs,
            holdout,
            runs,
        })
    }

    /// The predicted force of `rig` on record `k` (a failed simulation is
    /// a force of NaN everywhere: the fit's step is then refused).
    fn simulate(&self, rig: &FrictionBench, k: usize) -> Vec<f64> {
        let s = &self.sigs[k];
        self.runs[k]
            .borrow_mut()
            .force(rig, s, false)
            .unwrap_or_else(|_| vec![f64::NAN; s.t.len()])
    }

    /// The predicted force of `rig` on every record.
    pub(super) fn simulate_all(&self, rig: &FrictionBench) -> Vec<Vec<f64>> {
        (0..self.sigs.len())
            .map(|k| self.simulate(rig, k))
            .collect()
    }

    fn range(&self, s: &BenchSignals, part: Part) -> std::ops::Range<usize> {
        let n = s.t.len();
        let cut = ((1.0 - self.holdout) * n as f64) as usize;
        match part {
            Part::All => 0..n,
            Part::Train => 0..cut,
            Part::Held => cut..n,
        }
    }

    pub(super) fn residual(&self, rig: &FrictionBench, part: Part, out: &mut Vec<f64>) {
        out.clear();
        for (k, s) in self.sigs.iter().enumerate() {
            let sim = self.simulate(rig, k);
            for i in self.range(s, part) {
                out.push(s.force[i] - sim[i]);
            }
        }
    }

    pub(super) fn rss(&self, rig: &FrictionBench, part: Part) -> f64 {
        let mut r = Vec::new();
        self.residual(rig, part, &mut r);
        r.iter().map(|v| v * v).sum()
    }

    /// Fits `params` of `rig` in place on `part`; returns the LM result.
    pub(super) fn fit(
        &self,
        rig: &mut FrictionBench,
        params: &[ParamRef],
        part: Part,
    ) -> Result<lm::LmResult, lm::LmError> {
        let x0: Vec<f64> = params.iter().map(|p| rig.get(p)).collect();
        let (lo, hi): (Vec<f64>, Vec<f64>) = params.iter().map(|p| p.bounds()).unzip();
        let x0: Vec<f64> = x0
            .iter()
            .zip(lo.iter().zip(&hi))
            .map(|(x, (l, h))| x.clamp(*l, *h))
            .collect();
        let typ: Vec<f64> = params
            .iter()
            .zip(&x0)
            .map(|(p, x)| x.abs().max(fallback_scale(p)))
            .collect();
        let mut work = rig.clone();
        let res = lm::fit(
            |x, r| {
                for (p, v) in params.iter().zip(x) {
                    work.set(p, *v);
                }
                self.residual(&work, part, r);
                Ok(())
            },
            &x0,
            &lo,
            &hi,
            &typ,
            &LmOptions::default(),
        )?;
        for (p, v) in params.iter().zip(&res.x) {
            rig.set(p, *v);
        }
        Ok(res)
    }
}

/// A scale for a parameter whose start value is zero.
fn fallback_scale(p: &ParamRef) -> f64 {
    match p {
        ParamRef::Coulomb | ParamRef::Mass => 1.0,
        ParamRef::Effect(_, name) => match name.as_str() {
            "K" => 1e-12,
            "H" => 1e6,
            "vs" => 1e-3,
            "sigma0" => 1e4,
            "tau" => 1e-3,
            _ => 1.0,
        },
    }
}

pub(super) fn n_eff(r: &[f64]) -> f64 {
    let rho = lm::lag1_autocorrelation(r).clamp(0.0, 0.999);
    (r.len() as f64 * (1.0 - rho) / (1.0 + rho)).max(2.0)
}

/// Starting values of a candidate effect's parameters: linear terms by least
/// squares on the current residual, nonlinear ones from the data's scales.
pub(super) fn initial_guess(
    id: EffectId,
    rig: &FrictionBench,
    b: &Bench<'_>,
) -> BTreeMap<String, f64> {
    let mut g = BTreeMap::new();
    let sg = rig.force_sign;
    let vt = rig.friction.smoothing_velocity;
    let k = rig.get(&ParamRef::Effect(EffectId::PressureViscous, "K".into()));
    let regressor = |s: &BenchSignals, i: usize| -> f64 {
        sg * match id {
            EffectId::CoulombAsymmetry => 0.5 * (s.v[i] / vt).tanh().abs(),
            EffectId::Viscous => s.v[i],
            EffectId::PressureViscous => (s.p1[i] - s.p2[i]).powi(2) * s.v[i],
            EffectId::AccelerationFriction => k * s.a[i],
            EffectId::ExternalForce => 1.0,
            _ => 0.0,
        }
    };
    let mut r = Vec::new();
    b.residual(rig, Part::Train, &mut r);
    let (mut num, mut den) = (0.0, 0.0);
    let mut j = 0;
    for s in b.sigs {
        for i in b.range(s, Part::Train) {
            let phi = regressor(s, i);
            num += phi * r[j];
            den += phi * phi;
            j += 1;
        }
    }
    let ls = if den > 0.0 { num / den } else { 0.0 };
    let fc = rig.friction.coulomb.max(1e-3);
    let mut speeds: Vec<f64> = b
        .sigs
        .iter()
        .flat_map(|s| s.v.iter().map(|v| v.abs()))
        .filter(|v| *v > 10.0 * vt)
        .collect();
    let vmed = if speeds.is_empty() {
        1e-2
    } else {
        let m = speeds.len() / 2;
        *speeds.select_nth_unstable_by(m, f64::total_cmp).1
    };
    match id {
        EffectId::CoulombAsymmetry => {
            g.insert("dFc".into(), ls);
        }
        EffectId::Viscous => {
            g.insert("b".into(), ls);
        }
        EffectId::PressureViscous => {
            g.insert("K".into(), ls);
        }
        EffectId::AccelerationFriction => {
            g.insert("H".into(), ls);
        }
        EffectId::ExternalForce => {
            g.insert("F0".into(), ls);
        }
        EffectId::Stribeck => {
            g.insert("Fs".into(), 1.5 * fc);
            g.insert("vs".into(), (0.3 * vmed).clamp(2e-5, 0.5));
            g.insert("alpha".into(), 1.0);
        }
        EffectId::LugreDynamics => {
            // Presliding range Fc/σ0 of about 50 µm; little micro-damping.
            let s0 = (fc / 5e-5).clamp(1e3, 1e9);
            g.insert("sigma0".into(), s0);
            g.insert("sigma1".into(), 0.01 * (s0 * rig.mass.max(1e-2)).sqrt());
        }
        _ => {}
    }
    g
}

/// Out-of-catalog probes on the current model: a time shift of the measured
/// force (transport delay, up to ±40 samples), a force proportional to
/// the position (a spring the catalog lacks) and the sensors' gain errors
/// ([`gain_probes`]).
pub(super) fn probes(rig: &FrictionBench, b: &Bench<'_>) -> Probes {
    let sigs = b.sigs;
    let sims = b.simulate_all(rig);
    let rss0: f64 = sigs
        .iter()
        .zip(&sims)
        .flat_map(|(s, f)| s.force.iter().zip(f).map(|(a, b)| (a - b).powi(2)))
        .sum::<f64>()
        .max(1e-300);
    let mut out = Vec::new();
    // Delay: the measurement lags the model by τ.
    let dt = crate::smooth::median_step(&sigs[0].t);
    let mut best = (0.0, rss0);
    for k in (-40i32..=40).filter(|k| *k != 0) {
        let tau = k as f64 * dt;
        let rss: f64 = sigs
            .iter()
            .zip(&sims)
            .map(|(s, f)| {
                s.t.iter()
                    .zip(&s.force)
                    .map(|(&t, &m)| (m - crate::data::interp_linear(&s.t, f, t - tau)).powi(2))
                    .sum::<f64>()
            })
            .sum();
        if rss < best.1 {
            best = (tau, rss);
        }
    }
    out.push(Probe {
        kind: "delay".into(),
        what: "time shift of the measured force (transport delay)".into(),
        value: best.0,
        explained_share: 1.0 - best.1 / rss0,
    });
    // Spring: residual ∝ position.
    let (k, removed) =
        fit_regressor(sigs, &sims, |s, i, _| rig.force_sign * s.x[i]).unwrap_or((0.0, 0.0));
    out.push(Probe {
        kind: "spring".into(),
        what: "force proportional to position (spring)".into(),
        value: k,
        explained_share: removed / rss0,
    });
    Probes {
        shapes: out,
        gains: gain_probes(rig, sigs, &sims, rss0),
    }
}

/// The probes of one round: residual shapes no catalog effect has (delay,
/// spring) and the sensors' gain errors, which the loop weighs apart.
pub(super) struct Probes {
    pub(super) shapes: Vec<Probe>,
    pub(super) gains: Vec<Probe>,
}

/// A sensor's gain (calibration) error: the load cell reading `1 + g` times
/// the force, or a pressure sensor reading `1 + g` times its pressure. The
/// first leaves a residual proportional to the predicted force; the second
/// one proportional to that chamber's pressure force `±A p` in the balance
/// (the model is driven by the pressure as measured): `g/(1 + g)` of it,
/// of the sign that takes the excess pressure force back out.
/// Each is a one-parameter least-squares fit on the residual, like the
/// spring; a chamber without area, or whose pressure is not recorded
/// (all zero), has no probe.
fn gain_probes(
    rig: &FrictionBench,
    sigs: &[BenchSignals],
    sims: &[Vec<f64>],
    rss0: f64,
) -> Vec<Probe> {
    // (kind, column, regressor of sample i of record s given the model's force f)
    type Regressor = fn(&FrictionBench, &BenchSignals, usize, f64) -> f64;
    let cases: [(&str, &str, Regressor); 3] = [
        ("force_gain", "load cell (force)", |_, _, _, f| f),
        ("p1_gain", "p1 sensor", |r, s, i, _| {
            r.force_sign * r.area1 * s.p1[i]
        }),
        ("p2_gain", "p2 sensor", |r, s, i, _| {
            -r.force_sign * r.area2 * s.p2[i]
        }),
    ];
    let mut out = Vec::new();
    for (kind, sensor, phi) in cases {
        let Some((c, removed)) = fit_regressor(sigs, sims, |s, i, f| phi(rig, s, i, f)) else {
            continue;
        };
        // the force's own gain is c; a pressure read (1 + g) times too
        // high leaves c = g/(1 + g) of its force, so g = c/(1 − c)
        let g = if kind == "force_gain" {
            c
        } else {
            c / (1.0 - c)
        };
        out.push(Probe {
            kind: kind.into(),
            what: format!(
                "{sensor} gain error (reads {:+.1} % of its value)",
                100.0 * g
            ),
            value: g,
            explained_share: removed / rss0,
        });
    }
    out
}

/// The least-squares coefficient `c` of a regressor `φ` (of a record's
/// signals, the sample's index and the model's force there) on the force
/// residual of every record, and the sum of squares `c φ` removes; `None`
/// where `φ` is zero everywhere or not finite.
fn fit_regressor(
    sigs: &[BenchSignals],
    sims: &[Vec<f64>],
    phi: impl Fn(&BenchSignals, usize, f64) -> f64,
) -> Option<(f64, f64)> {
    let (mut num, mut den) = (0.0, 0.0);
    for (s, f) in sigs.iter().zip(sims) {
        for (i, (m, f)) in s.force.iter().zip(f).enumerate() {
            let x = phi(s, i, *f);
            num += x * (m - f);
            den += x * x;
        }
    }
    if den <= 0.0 || !den.is_finite() || !num.is_finite() {
        return None;
    }
    let c = num / den;
    Some((c, num * c))
}
