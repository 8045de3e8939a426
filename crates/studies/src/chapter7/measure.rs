//! What a chapter-7 run measures: the sampled trace, the phenomena of
//! sections 7.1–7.3, the mass balance of every volume and the valve events.

use super::{Chapter7Test, Shape};
use hydrocyl_integrators::{OdeSystem, Stats};
use hydrocyl_system::hybrid::WangHybrid;
use hydrocyl_system::Circuit;
use serde::Serialize;

/// The sampled signals of a run (SI units).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Trace {
    /// Time \[s\].
    pub t: Vec<f64>,
    /// Pump command \[V\].
    pub command: Vec<f64>,
    /// Pump flow \[m³·s⁻¹\].
    pub pump_flow: Vec<f64>,
    /// Pump line 1 pressure \[Pa\].
    pub pp1: Vec<f64>,
    /// Pump line 2 pressure \[Pa\].
    pub pp2: Vec<f64>,
    /// Chamber 1 pressure \[Pa\].
    pub p1: Vec<f64>,
    /// Chamber 2 pressure \[Pa\].
    pub p2: Vec<f64>,
    /// Piston position \[m\].
    pub position: Vec<f64>,
    /// Piston velocity \[m·s⁻¹\].
    pub velocity: Vec<f64>,
    /// Friction by eq 7.4, `p1 A1 − p2 A2 − m a` \[N\].
    pub friction: Vec<f64>,
    /// Pilot spool travel past the overlap \[m\].
    pub spool: Vec<f64>,
}

/// Steady values of one half period (means over its last second).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct SteadyState {
    /// Chamber 1 \[Pa\].
    pub p1: f64,
    /// Chamber 2 \[Pa\].
    pub p2: f64,
    /// Pump line 1 \[Pa\].
    pub pp1: f64,
    /// Pump line 2 \[Pa\].
    pub pp2: f64,
    /// Velocity \[m·s⁻¹\].
    pub velocity: f64,
}

/// The measured phenomena (means over the measured periods; NaN where a
/// quantity could not be found, e.g. no reversal in the trace).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Phenomena {
    /// Stall at the reversals from extending to retracting ([`super::stall`]) \[s\].
    pub stall_to_retract: f64,
    /// Stall at the reversals from retracting to extending \[s\].
    pub stall_to_extend: f64,
    /// The pressure-charging interval of section 7.1 at the extend→retract
    /// reversal: the time the pilot-operated four-way valve stays centred
    /// (both chambers shut) between the command's reversal and half the
    /// target speed in the new direction, while the pump charges the new
    /// line to the pilot shift pressure \[s\]. See [`super::stall`]: the
    /// piston is not held still during it, it rings on the shut chambers.
    pub charge_to_retract: f64,
    /// Same at the retract→extend reversal \[s\].
    pub charge_to_extend: f64,
    /// Range of the piston's position during the charging interval,
    /// extend→retract \[m\] (what a position sensor sees of the ringing).
    pub charge_travel_retract: f64,
    /// Same at the retract→extend reversal \[m\].
    pub charge_travel_extend: f64,
    /// Time from reversal to 90 % of the target speed, extending \[s\].
    pub t90_extend: f64,
    /// Same, retracting \[s\].
    pub t90_retract: f64,
    /// `t90_extend` less the same time for the command-implied velocity
    /// (`K u/A1`, `K u/A2`): the drive's own lag, extending \[s\] (for a
    /// sine the ideal time is not zero, and differs by direction because of
    /// the bias).
    pub lag_extend: f64,
    /// Same, retracting \[s\].
    pub lag_retract: f64,
    /// Largest chamber pressure after the first period \[Pa\].
    pub max_chamber_pressure: f64,
    /// `true` when the drive locked at the fold (module docs): a chamber
    /// above 100 bar, or the steady speed below half the target.
    pub locked: bool,
    /// Net displacement per period, + extending \[m\].
    pub drift_per_period: f64,
    /// Mean friction (eq 7.4) while extending within ±10 % of the target speed \[N\].
    pub friction_extend: f64,
    /// Mean friction while retracting within ±10 % of the target speed \[N\].
    pub friction_retract: f64,
    /// Steady state extending (square) / at peak speed (sine).
    pub steady_extend: SteadyState,
    /// Steady state retracting.
    pub steady_retract: SteadyState,
    /// Number of reversals measured.
    pub reversals: usize,
}

impl Phenomena {
    /// Mean stall over both directions \[s\].
    pub fn stall(&self) -> f64 {
        0.5 * (self.stall_to_retract + self.stall_to_extend)
    }
}

/// Mass balance of one volume: what flowed in by the component flows'
/// quadratures against what the states say was stored and displaced.
#[derive(Clone, Debug, Serialize)]
pub struct VolumeBalance {
    /// The volume.
    pub name: String,
    /// `∫ Q_in dt` from the connected components' flows \[m³\].
    pub inflow: f64,
    /// Compression plus displacement from the states \[m³\].
    pub accounted: f64,
    /// `|inflow − accounted|` over the volume pumped \[-\].
    pub relative_error: f64,
}

/// A simulated and measured chapter-7 test.
#[derive(Clone, Debug, Serialize)]
pub struct Chapter7Run {
    /// The test.
    pub test: Chapter7Test,
    /// The samples.
    pub trace: Trace,
    /// The phenomena.
    pub phenomena: Phenomena,
    /// Mass balance of each volume.
    pub balances: Vec<VolumeBalance>,
    /// Volume the pump moved, `∫|Q_p| dt` \[m³\].
    pub volume_pumped: f64,
    /// Event and diagnostic counters of every component (`pump.reversals`,
    /// `relief_1.cracked`, `pilot_valve.shifted_extend`, `check_1.opened`,
    /// `cylinder.cavitation_entries_1`, ...).
    pub diagnostics: Vec<(String, f64)>,
    /// Lowest pressure in each volume (chambers, pump lines) \[Pa\].
    pub min_pressures: Vec<(String, f64)>,
    /// Vapour pressure of the rig \[Pa\].
    pub vapour_pressure: f64,
    /// Solver work.
    #[serde(skip)]
    pub stats: Stats,
}

fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        s / n as f64
    }
}

impl Chapter7Run {
    pub(super) fn measure(
        test: Chapter7Test,
        rig: &WangHybrid,
        c: &mut Circuit,
        t: &[f64],
        x: &[f64],
        dim: usize,
        stats: Stats,
    ) -> Self {
        let probe = |name: &str| {
            c.probes()
                .into_iter()
                .find(|p| p.name == name)
                .map(|p| p.wire)
        };
        let wires = [
            probe("command"),
            probe("pump_flow"),
            probe("pp1"),
            probe("pp2"),
            probe("p1"),
            probe("p2"),
            probe("position"),
            probe("velocity"),
            probe("pilot_spool"),
        ];
        let load = c.component_index("load").map(|i| c.state_range(i));
        let (a1, a2) = (rig.cylinder.area_1.si(), rig.cylinder.area_2.si());
        let mut tr = Trace::default();
        let mut dx = vec![0.0; dim];
        for (k, &tk) in t.iter().enumerate() {
            let xk = &x[k * dim..(k + 1) * dim];
            let w = c.wires_at(tk, xk);
            let g = |i: usize| wires[i].map_or(f64::NAN, |wi| w.get(wi));
            c.rhs(tk, xk, &mut dx);
            let acc = load.as_ref().map_or(0.0, |r| dx[r.start + 1]);
            tr.t.push(tk);
            tr.command.push(g(0));
            tr.pump_flow.push(g(1));
            tr.pp1.push(g(2));
            tr.pp2.push(g(3));
            tr.p1.push(g(4));
            tr.p2.push(g(5));
            tr.position.push(g(6));
            tr.velocity.push(g(7));
            tr.spool.push(g(8));
            tr.friction
                .push(g(4) * a1 - g(5) * a2 - rig.mass * acc - rig.external_force);
        }
        let volume_pumped: f64 =
            tr.t.windows(2)
                .zip(tr.pump_flow.windows(2))
                .map(|(tt, q)| 0.5 * (tt[1] - tt[0]) * (q[0].abs() + q[1].abs()))
                .sum();
        let balances = balances(rig, c, x, dim, t.len(), volume_pumped);
        let min_of = |v: &[f64]| v.iter().cloned().fold(f64::INFINITY, f64::min);
        let min_pressures = vec![
            ("chamber_1".to_string(), min_of(&tr.p1)),
            ("chamber_2".to_string(), min_of(&tr.p2)),
            ("pump_line_1".to_string(), min_of(&tr.pp1)),
            ("pump_line_2".to_string(), min_of(&tr.pp2)),
        ];
        let phenomena = phenomena(&test, rig, &tr);
        Self {
            test,
            trace: tr,
            phenomena,
            balances,
            volume_pumped,
            diagnostics: c.diagnostics(),
            min_pressures,
            vapour_pressure: rig.vapour_pressure,
            stats,
        }
    }

    /// A diagnostic counter by its full name (e.g. `relief_1.cracked`); 0 when absent.
    pub fn count(&self, name: &str) -> f64 {
        self.diagnostics
            .iter()
            .find(|(n, _)| n == name)
            .map_or(0.0, |(_, v)| *v)
    }

    /// The valve-state events of the run: pilot-valve shifts, relief cracks
    /// and check-valve openings.
    pub fn valve_events(&self) -> Vec<(String, f64)> {
        self.diagnostics
            .iter()
            .filter(|(n, _)| {
                n.contains("pilot_")
                    || n.ends_with(".cracked")
                    || n.ends_with(".opened")
                    || n.contains("fully")
            })
            .cloned()
            .collect()
    }

    /// Largest relative mass-balance error over all volumes.
    pub fn worst_balance(&self) -> f64 {
        self.balances
            .iter()
            .map(|b| b.relative_error)
            .fold(0.0, f64::max)
    }
}

fn balances(
    rig: &WangHybrid,
    c: &Circuit,
    x: &[f64],
    dim: usize,
    n: usize,
    pumped: f64,
) -> Vec<VolumeBalance> {
    let first = &x[..dim];
    let last = &x[(n - 1) * dim..n * dim];
    let quad = |comp: &str, k: usize| -> f64 {
        c.component_index(comp)
            .map_or(f64::NAN, |i| last[c.quadrature_range(i).start + k])
    };
    let state = |comp: &str, k: usize, v: &[f64]| -> f64 {
        c.component_index(comp)
            .map_or(f64::NAN, |i| v[c.state_range(i).start + k])
    };
    let b_line = rig.bulk_modulus;
    let v_line = rig.pump_line_volume;
    // C(p) = ∫dp/B_eff (p/B without air): the content a unit volume gains
    let air = rig.entrained_air;
    let pump = quad("pump", 0);
    let mut out = Vec::new();
    let mut push = |name: &str, inflow: f64, accounted: f64| {
        out.push(VolumeBalance {
            name: name.into(),
            inflow,
            accounted,
            relative_error: (inflow - accounted).abs() / pumped,
        });
    };
    // pump lines: V ΔC(p) (V/B Δp without air)
    let line = |name: &str| {
        let (pa, pb) = (state(name, 0, first), state(name, 0, last));
        if air.is_none() {
            v_line / b_line * (pb - pa)
        } else {
            v_line * (air.compliance(b_line, pb) - air.compliance(b_line, pa))
        }
    };
    let in_1 = pump - quad("relief_1", 0) - quad("relief_3_line_1", 0) + quad("check_1", 0);
    push("pump_line_1", in_1, line("line_1"));
    let in_2 = -pump - quad("relief_2", 0) - quad("relief_3_line_2", 0) + quad("check_2", 0);
    push("pump_line_2", in_2, line("line_2"));
    // chambers: ∫q1 = A1 Δx + [V1 C(p1)] − ∫C(p1) A1 v;  ∫q2 = [V2 C(p2)] + ∫C(p2) A2 v − A2 Δx
    let cyl = &rig.cylinder;
    let b = cyl.bulk_modulus.si();
    // Δ(V C(p)) between the window's ends
    let stored = |(va, pa): (f64, f64), (vb, pb): (f64, f64)| {
        if air.is_none() {
            (vb * pb - va * pa) / b
        } else {
            vb * air.compliance(b, pb) - va * air.compliance(b, pa)
        }
    };
    let (x_a, x_b) = (state("load", 0, first), state("load", 0, last));
    let vols = |xp: f64| cyl.volumes(hydrocyl_ports::Position::new(xp));
    let (v1a, v2a) = vols(x_a);
    let (v1b, v2b) = vols(x_b);
    let (p1a, p2a) = (state("cylinder", 0, first), state("cylinder", 1, first));
    let (p1b, p2b) = (state("cylinder", 0, last), state("cylinder", 1, last));
    let in_c1 = quad("relief_1", 0) - quad("pilot_valve", 0);
    let acc_c1 = cyl.area_1.si() * (x_b - x_a) + stored((v1a.si(), p1a), (v1b.si(), p1b))
        - quad("cylinder", 2);
    push("chamber_1", in_c1, acc_c1);
    let in_c2 = quad("relief_2", 0) - quad("pilot_valve", 1);
    let acc_c2 = stored((v2a.si(), p2a), (v2b.si(), p2b)) + quad("cylinder", 3)
        - cyl.area_2.si() * (x_b - x_a);
    push("chamber_2", in_c2, acc_c2);
    out
}

/// Reversal times: sign changes of the command (after the first period).
fn reversals(tr: &Trace, t_from: f64) -> Vec<(usize, f64)> {
    let mut out = Vec::new();
    for k in 1..tr.t.len() {
        if tr.t[k] <= t_from {
            continue;
        }
        let (a, b) = (tr.command[k - 1], tr.command[k]);
        if a.signum() != b.signum() && b != 0.0 {
            out.push((k, b.signum()));
        }
    }
    out
}

fn phenomena(test: &Chapter7Test, rig: &WangHybrid, tr: &Trace) -> Phenomena {
    let period = 1.0 / test.frequency;
    let v = &tr.velocity;
    let (a1, a2) = (rig.cylinder.area_1.si(), rig.cylinder.area_2.si());
    let ideal: Vec<f64> = tr
        .command
        .iter()
        .map(|&u| {
            let q = rig.pump.gain * u;
            if q >= 0.0 {
                q / a1
            } else {
                q / a2
            }
        })
        .collect();
    let t90_of = |sig: &[f64], k: usize, dir: f64, end: usize| {
        let mut j = k;
        while j < end && sig[j] * dir < 0.9 * test.speed {
            j += 1;
        }
        (j < end).then(|| tr.t[j] - tr.t[k])
    };
    let n = v.len();
    let revs = reversals(tr, period);
    let (mut st_r, mut st_e, mut t9_e, mut t9_r) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut lag_e, mut lag_r) = (Vec::new(), Vec::new());
    let (mut ch_e, mut ch_r, mut tr_e, mut tr_r) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let half = (0.5 * period / test.sample_interval).round() as usize;
    for &(k, dir) in &revs {
        let end = (k + half).min(n - 1);
        // the stall (super::stall: total time with |v| < 1 mm/s until half
        // the target speed in the new direction)
        if let Some(d) = super::stall::stall_at(&tr.t, v, k, dir, 0.5 * test.speed, end) {
            if dir > 0.0 {
                st_e.push(d);
            } else {
                st_r.push(d);
            }
        }
        // the charging interval: samples with the pilot spool centred before
        // half the target speed in the new direction
        let mut j = k;
        while j < end && v[j] * dir < 0.5 * test.speed {
            j += 1;
        }
        if j < end {
            let centred: Vec<usize> = (k..j).filter(|&i| tr.spool[i].abs() <= 1e-12).collect();
            let time = centred.len() as f64 * test.sample_interval;
            let (lo, hi) = centred
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &i| {
                    (a.min(tr.position[i]), b.max(tr.position[i]))
                });
            let travel = if centred.is_empty() { 0.0 } else { hi - lo };
            if dir > 0.0 {
                ch_e.push(time);
                tr_e.push(travel);
            } else {
                ch_r.push(time);
                tr_r.push(travel);
            }
        }
        // time to 90 % of the target speed in the new direction, and the same for the
        // command-implied velocity
        if let Some(d) = t90_of(v, k, dir, end) {
            let lag = t90_of(&ideal, k, dir, end).map_or(f64::NAN, |d0| d - d0);
            if dir > 0.0 {
                t9_e.push(d);
                lag_e.push(lag);
            } else {
                t9_r.push(d);
                lag_r.push(lag);
            }
        }
    }
    // drift: position change over the measured whole periods
    let k0 = (period / test.sample_interval).round() as usize;
    let whole = test.periods.saturating_sub(1);
    let drift = if whole > 0 && n > k0 {
        let k1 = (k0 + whole * (period / test.sample_interval).round() as usize).min(n - 1);
        (tr.position[k1] - tr.position[k0]) / whole as f64
    } else {
        f64::NAN
    };
    // friction at the same speed, each direction, measured periods only
    let band = |sign: f64| {
        mean(
            (k0..n)
                .filter(|&k| (v[k] * sign - test.speed).abs() < 0.1 * test.speed)
                .map(|k| tr.friction[k]),
        )
    };
    // steady states: last second of each half period (square) / ±0.25 s around peak speed (sine)
    let steady = |dir: f64| {
        let ks: Vec<usize> = revs
            .iter()
            .filter(|r| r.1 == dir)
            .flat_map(|&(k, _)| {
                let (a, b) = match test.shape {
                    Shape::Square => (k + half.saturating_sub(1000), k + half),
                    Shape::Sine => {
                        // the peak of bias + A sin lies a quarter period after the zero crossing of sin,
                        // i.e. near the middle of the half period
                        let m = k + half / 2;
                        (m.saturating_sub(250), m + 250)
                    }
                };
                (a..b.min(n)).collect::<Vec<_>>()
            })
            .collect();
        let m = |f: &Vec<f64>| mean(ks.iter().map(|&k| f[k]));
        SteadyState {
            p1: m(&tr.p1),
            p2: m(&tr.p2),
            pp1: m(&tr.pp1),
            pp2: m(&tr.pp2),
            velocity: m(&tr.velocity),
        }
    };
    let max_chamber_pressure = (k0.min(n)..n)
        .map(|k| tr.p1[k].max(tr.p2[k]))
        .fold(f64::NEG_INFINITY, f64::max);
    let (se, sr) = (steady(1.0), steady(-1.0));
    let locked = max_chamber_pressure > 100.0e5
        || !(se.velocity.abs() > 0.5 * test.speed && sr.velocity.abs() > 0.5 * test.speed);
    Phenomena {
        stall_to_retract: mean(st_r.into_iter()),
        stall_to_extend: mean(st_e.into_iter()),
        charge_to_retract: mean(ch_r.into_iter()),
        charge_to_extend: mean(ch_e.into_iter()),
        charge_travel_retract: mean(tr_r.into_iter()),
        charge_travel_extend: mean(tr_e.into_iter()),
        t90_extend: mean(t9_e.into_iter()),
        t90_retract: mean(t9_r.into_iter()),
        lag_extend: mean(lag_e.into_iter()),
        lag_retract: mean(lag_r.into_iter()),
        max_chamber_pressure,
        locked,
        drift_per_period: drift,
        friction_extend: band(1.0),
        friction_retract: band(-1.0),
        steady_extend: se,
        steady_retract: sr,
        reversals: revs.len(),
    }
}
