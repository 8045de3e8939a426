//! The out-of-catalog probes of the loop on a netlist rig: shapes the
//! catalog does not have, offered the residual each round beside the
//! catalog's top candidate, so that a residual of foreign shape is reported
//! unexplained rather than dressed up as the nearest catalog effect.
//!
//! * a transport delay of the command (`delay`);
//! * a declared parameter other than declared, found by its role in the
//!   netlist (never by preset name): the load's mass (`mass`), the friction
//!   component's Coulomb level(s) (`coulomb`), the pressure of the source
//!   feeding the valve's `P` port (`supply_pressure`). Each is scaled on a
//!   log grid (a quarter to four times the round model's value) with the
//!   initial position and velocity held as in the round model, then
//!   refined by successive parabolas in the log-factor;
//! * a constant offset on the measured p1 or p2 (a pressure sensor's zero
//!   error, `p1_offset`, `p2_offset`): the best offset and the sum of
//!   squares it removes follow in closed form from the channel's weighted
//!   residual (no simulation);
//! * a sensor's gain error on p1, p2 or the position (`p1_gain`,
//!   `p2_gain`, `position_gain`), in closed form the same way, named only
//!   where it explains the record down to its noise ([`GAIN_PROBE_FLOOR`]).
//!
//! A probe whose best fit sits at the edge of its searched range (a
//! quarter or four times the value, a delay of 60 ms) says so in its words:
//! the true value may lie beyond it, or the residual is something else.
//!
//! A scaled parameter is first screened by two simulations a tenth below
//! and above its value ([`screen_share`]): the grid is run only where they
//! say it could explain at least [`SCREEN_SHARE`] of what a probe needs to
//! outrank the catalog's top candidate (the screen the catalog's
//! candidates pass), and only on the side found lower. A scaled run keeps
//! the round model's initial state up to a constant shift of the simulated
//! position ([`unshift_position`]).

use super::*;
use hydrocyl_system::netlist::registry;
use serde_json::Value;

/// Out-of-catalog probe: the command reaching the rig late by τ (a
/// transport delay), τ on a grid up to 60 ms, scored against `rss0`, the
/// weighted sum of squares of `rig` on the whole record.
fn delay_probe(rig: &Model, p: &Prepared, holdout: f64, rss0: f64) -> Option<Probe> {
    if p.closed {
        // the input is the reference, not the command the valve receives
        return None;
    }
    const TAUS: [f64; 8] = [0.002, 0.005, 0.01, 0.015, 0.02, 0.03, 0.045, 0.06];
    let shifted = |tau: &f64| {
        let mut q = p.clone();
        let mut input: Vec<f64> =
            p.t.iter()
                .map(|&t| crate::data::interp_linear(&p.t, &p.input, t - tau))
                .collect();
        input[0] = p.input[0];
        q.input = input.into();
        rss(rig, &q, holdout, Part::All)
    };
    let scores = trace_parallel(&TAUS, &shifted);
    let mut best = (0.0, rss0);
    for (tau, r) in TAUS.iter().zip(scores) {
        if r < best.1 {
            best = (*tau, r);
        }
    }
    let longest = TAUS[TAUS.len() - 1];
    (best.0 > 0.0).then(|| Probe {
        kind: "delay".into(),
        what: if best.0 >= longest {
            format!(
                "transport delay of the command ({} ms, the longest delay searched; {EDGE})",
                sig(1e3 * longest)
            )
        } else {
            "transport delay of the command".into()
        },
        value: best.0,
        explained_share: 1.0 - best.1 / rss0.max(1e-300),
    })
}

/// A declared parameter a probe scales: one or more `<component>.<param>`
/// paths scaled by one factor (a friction law with a Coulomb level per
/// direction has two).
#[derive(Clone, Debug)]
struct Scaled {
    /// The probe's kind (`mass`, `coulomb`, `supply_pressure`).
    kind: &'static str,
    /// What it is, in words.
    name: &'static str,
    /// The unit it is shown in, and that unit in SI.
    unit: (&'static str, f64),
    /// The paths and their values in the round model.
    paths: Vec<(String, String, f64)>,
}

impl Scaled {
    /// `rig` with every path scaled by `exp(x)`.
    fn apply(&self, rig: &Model, x: f64) -> Model {
        let mut m = rig.clone();
        for (c, q, v) in &self.paths {
            m.set_param(c, q, Value::from(v * x.exp()));
        }
        m
    }

    /// The probe at log-factor `x`, explaining `share`.
    fn probe(&self, x: f64, share: f64) -> Probe {
        let (unit, si) = self.unit;
        let list = |f: f64| {
            self.paths
                .iter()
                .map(|(_, _, v)| format!("{} {unit}", sig(f * v / si)))
                .collect::<Vec<_>>()
                .join(" and ")
        };
        let names: Vec<String> = self
            .paths
            .iter()
            .map(|(c, q, _)| format!("`{c}.{q}`"))
            .collect();
        let limit = GRID[GRID.len() - 1];
        let edge = if x.abs() >= limit - 1e-12 {
            let side = if x > 0.0 {
                "four times the model's value, the upper end"
            } else {
                "a quarter of the model's value, the lower end"
            };
            format!("; {side} of the range searched: {EDGE}")
        } else {
            String::new()
        };
        Probe {
            kind: self.kind.into(),
            what: format!(
                "{} other than declared ({} fits {}, declared {}{edge})",
                self.name,
                names.join(", "),
                list(x.exp()),
                list(1.0)
            ),
            value: self.paths[0].2 * x.exp(),
            explained_share: share,
        }
    }
}

/// What a probe whose fit sits at the edge of its searched range adds to
/// its words: the minimum may lie beyond the range, or the residual may be
/// something else that the probe's shape only leans toward.
const EDGE: &str = "the fit sits at the edge of the searched range, so the true value may lie beyond it, or the residual is something else";

/// `x` with three significant digits (no exponent between 1e-3 and 1e6).
fn sig(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || !(1e-3..1e6).contains(&a) {
        return format!("{x:.3e}");
    }
    let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}

/// The endpoints joined to `end` (`<component>.<port>`) through the rig's
/// connections (bare node names joining several entries included).
fn node_of(net: &Value, end: &str) -> Vec<String> {
    let conns: Vec<Vec<String>> = net
        .get("connections")
        .and_then(Value::as_array)
        .map(|cs| {
            cs.iter()
                .filter_map(Value::as_array)
                .map(|c| {
                    c.iter()
                        .filter_map(Value::as_str)
                        .map(str::to_string)
                        .collect()
                })
                .collect()
        })
        .unwrap_or_default();
    let mut node = vec![end.to_string()];
    loop {
        let before = node.len();
        for c in &conns {
            if c.iter().any(|e| node.contains(e)) {
                for e in c {
                    if !node.contains(e) {
                        node.push(e.clone());
                    }
                }
            }
        }
        if node.len() == before {
            return node;
        }
    }
}

/// The components of `net` by name and type.
fn components(net: &Value) -> Vec<(String, String)> {
    net.get("components")
        .and_then(Value::as_object)
        .map(|cs| {
            cs.iter()
                .filter_map(|(n, c)| Some((n.clone(), c.get("type")?.as_str()?.to_string())))
                .collect()
        })
        .unwrap_or_default()
}

/// The declared parameters the probes scale on `rig`, found by role: the
/// load's mass; the friction component's Coulomb level(s) (every parameter
/// its type calls `coulomb` or `*.coulomb`); the pressure of the
/// `pressure_source` on the node of a valve's `P` port (a component type
/// with a `P` port: the servovalve, the generalised cylinder). A parameter
/// the rig does not have, or at zero, is left out.
fn scaled_params(rig: &Model) -> Vec<Scaled> {
    let positive = |c: &str, q: &str| {
        rig.param(c, q)
            .filter(|v| v.is_finite() && *v > 0.0)
            .map(|v| (c.to_string(), q.to_string(), v))
    };
    let mut out = Vec::new();
    if let Some(m) = positive(&rig.roles.load, "mass") {
        out.push(Scaled {
            kind: "mass",
            name: "load mass",
            unit: ("kg", 1.0),
            paths: vec![m],
        });
    }
    let friction = rig.roles.friction.as_deref().zip(rig.friction_type());
    if let Some((f, ty)) = friction {
        let paths: Vec<_> = registry::lookup(&ty)
            .map(|t| t.params)
            .unwrap_or_default()
            .iter()
            .filter(|q| q.name == "coulomb" || q.name.ends_with(".coulomb"))
            .filter_map(|q| positive(f, q.name))
            .collect();
        if !paths.is_empty() {
            out.push(Scaled {
                kind: "coulomb",
                name: "friction Coulomb level",
                unit: ("N", 1.0),
                paths,
            });
        }
    }
    let comps = components(&rig.net);
    let valve = comps
        .iter()
        .find(|(_, ty)| registry::lookup(ty).is_some_and(|t| t.port("P").is_some()));
    if let Some((v, _)) = valve {
        let node = node_of(&rig.net, &format!("{v}.P"));
        let source = comps.iter().find(|(n, ty)| {
            ty == "pressure_source" && node.iter().any(|e| e == &format!("{n}.port"))
        });
        if let Some(s) = source.and_then(|(n, _)| positive(n, "pressure")) {
            out.push(Scaled {
                kind: "supply_pressure",
                name: "supply pressure",
                unit: ("bar", 1e5),
                paths: vec![s],
            });
        }
    }
    out
}

/// The screen's step in log-factor (a tenth: the screen runs at 1/1.1 and 1.1 times the value).
const SCREEN_STEP: f64 = 0.0953101798043249; // ln 1.1

/// The grid in log-factor, on the side the screen found lower: √2, 2,
/// 2√2 and 4 times the value (or their inverses).
const GRID: [f64; 4] = [
    0.5 * std::f64::consts::LN_2,
    std::f64::consts::LN_2,
    1.5 * std::f64::consts::LN_2,
    2.0 * std::f64::consts::LN_2,
];

/// What a scaled parameter could explain, from its screen: the round
/// model's residual `r0` (sum of squares `rss0`) and the sums of squares
/// and residuals a step `SCREEN_STEP` below and above. The largest of the
/// share either step explains, the linearised Gauss–Newton step's along
/// the central difference, and the minimum of the parabola through the
/// three sums of squares: a response far from linear over the step (the
/// supply pressure, where the chamber pressures come near it) makes each
/// of the last two underestimate on its own.
fn screen_share(r0: &[f64], rss0: f64, lo: (f64, &[f64]), hi: (f64, &[f64])) -> f64 {
    let h = SCREEN_STEP;
    let mut best = [lo.0, hi.0]
        .iter()
        .map(|f| 1.0 - f / rss0)
        .fold(f64::NEG_INFINITY, f64::max);
    if lo.1.len() == r0.len() && hi.1.len() == r0.len() {
        let (mut jr, mut jj) = (0.0, 0.0);
        for ((a, b), c) in hi.1.iter().zip(lo.1).zip(r0) {
            let j = (a - b) / (2.0 * h);
            jr += j * c;
            jj += j * j;
        }
        if jj > 0.0 {
            best = best.max(jr * jr / jj / rss0);
        }
    }
    let (a, b) = (
        (hi.0 + lo.0 - 2.0 * rss0) / (2.0 * h * h),
        (hi.0 - lo.0) / (2.0 * h),
    );
    if a > 0.0 && a.is_finite() && b.is_finite() {
        best = best.max(b * b / (4.0 * a) / rss0);
    }
    best
}

/// Successive parabolas after the grid.
const REFINEMENTS: usize = 4;

/// The scaled-parameter probes on the round model `rig`, whose weighted
/// residual on the whole record is `r0` (sum of squares `rss0`): the best
/// of them, if any explains a share. `need`: the share a probe must
/// explain to outrank the catalog's top candidate (a probe whose screen
/// says it cannot come near is not run further).
fn scaled_probes(
    rig: &Model,
    p: &Prepared,
    holdout: f64,
    r0: &[f64],
    rss0: f64,
    need: f64,
) -> Option<Probe> {
    let params = scaled_params(rig);
    if params.is_empty() || rss0.is_nan() || rss0 <= 0.0 {
        return None;
    }
    // (probe, log-factor) → weighted residual's sum of squares, and the
    // residual itself (for the screen's linearised step)
    let run = |(k, x): &(usize, f64)| -> (f64, Vec<f64>) {
        let mut r = Vec::new();
        match residual(&params[*k].apply(rig, *x), p, holdout, Part::All, &mut r) {
            Ok(()) => {
                unshift_position(p, &mut r);
                (sum_sq(&r), r)
            }
            Err(_) => (f64::INFINITY, Vec::new()),
        }
    };
    // every point scored, per probe: (log-factor, sum of squares)
    let mut points: Vec<Vec<(f64, f64)>> = params.iter().map(|_| vec![(0.0, rss0)]).collect();
    let screens: Vec<(usize, f64)> = (0..params.len())
        .flat_map(|k| [(k, -SCREEN_STEP), (k, SCREEN_STEP)])
        .collect();
    let screened = trace_parallel(&screens, &run);
    let mut gridded: Vec<(usize, f64)> = Vec::new();
    for (k, pair) in screened.chunks(2).enumerate() {
        let ((f_lo, r_lo), (f_hi, r_hi)) = (&pair[0], &pair[1]);
        points[k].extend([(-SCREEN_STEP, *f_lo), (SCREEN_STEP, *f_hi)]);
        let reach = screen_share(r0, rss0, (*f_lo, r_lo), (*f_hi, r_hi));
        if reach < SCREEN_SHARE * need {
            continue;
        }
        let dir = if f_lo < f_hi { -1.0 } else { 1.0 };
        gridded.extend(GRID.iter().map(|g| (k, dir * g)));
    }
    if !gridded.is_empty() {
        let scores = trace_parallel(&gridded, &|j| run(j).0);
        for ((k, x), s) in gridded.iter().zip(scores) {
            points[*k].push((*x, s));
        }
        let mut live: Vec<usize> = gridded.iter().map(|(k, _)| *k).collect();
        live.dedup();
        for _ in 0..REFINEMENTS {
            let next: Vec<(usize, f64)> = live
                .iter()
                .filter_map(|&k| parabola_step(&points[k]).map(|x| (k, x)))
                .collect();
            if next.is_empty() {
                break;
            }
            let scores = trace_parallel(&next, &|j| run(j).0);
            for ((k, x), s) in next.iter().zip(scores) {
                points[*k].push((*x, s));
            }
            live = next.iter().map(|(k, _)| *k).collect();
        }
    }
    params
        .iter()
        .zip(&points)
        .filter_map(|(sc, pts)| {
            let best = pts
                .iter()
                .copied()
                .filter(|(_, s)| s.is_finite())
                .min_by(|a, b| a.1.total_cmp(&b.1))?;
            (best.0 != 0.0).then(|| sc.probe(best.0, 1.0 - best.1 / rss0))
        })
        .max_by(|a, b| a.explained_share.total_cmp(&b.explained_share))
}

/// Removes the mean of the position channel's block from the weighted
/// residual `r` (whole record): the best constant shift of the simulated
/// position. The round model's initial position and velocity were fitted
/// under the declared value, and a run with the value scaled keeps them:
/// the position then carries a constant offset (the initial transient's
/// travel) that a refit of the initial state would remove — on the valve
/// rig with a supply 14 % low, enough to hide the minimum at the true
/// supply. The shift stands in for that refit at no cost.
fn unshift_position(p: &Prepared, r: &mut [f64]) {
    let n = p.t.len();
    let compared = p.meas.iter().zip(&p.weights).filter(|(_, w)| **w > 0.0);
    for (i, ((ch, _), _)) in compared.enumerate() {
        if *ch != Signal::Position {
            continue;
        }
        if let Some(block) = r.get_mut(i * n..(i + 1) * n) {
            let mean = block.iter().sum::<f64>() / n.max(1) as f64;
            block.iter_mut().for_each(|v| *v -= mean);
        }
    }
}

/// The next point of a successive-parabola search on `points` (log-factor,
/// sum of squares): the vertex of the parabola through the lowest point and
/// its neighbours on either side, where the lowest is not at an end (else a
/// golden-section step into the larger side, where the vertex is outside
/// them or (nearly) scored already).
fn parabola_step(points: &[(f64, f64)]) -> Option<f64> {
    let mut pts: Vec<(f64, f64)> = points.to_vec();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let k = (0..pts.len())
        .filter(|&i| pts[i].1.is_finite())
        .min_by(|&a, &b| pts[a].1.total_cmp(&pts[b].1))?;
    if k == 0 || k + 1 == pts.len() {
        return None;
    }
    let ((a, fa), (b, fb), (c, fc)) = (pts[k - 1], pts[k], pts[k + 1]);
    if !(fa.is_finite() && fc.is_finite()) {
        return None;
    }
    let num = (b - a).powi(2) * (fb - fc) - (b - c).powi(2) * (fb - fa);
    let den = (b - a) * (fb - fc) - (b - c) * (fb - fa);
    let close = 0.01 * (c - a);
    let x = b - 0.5 * num / den;
    if den < 0.0 && x > a && x < c && pts.iter().all(|(p, _)| (p - x).abs() > close) {
        return Some(x);
    }
    // a vertex outside the bracket or (nearly) scored already: a golden
    // section step into the larger side
    const GOLD: f64 = 0.381_966_011_250_105;
    Some(if c - b > b - a {
        b + GOLD * (c - b)
    } else {
        b - GOLD * (b - a)
    })
}

/// The pressure sensors' zero errors: a constant `c` added to the measured
/// p1 (or p2) removes `n · mean(r)²` of the weighted residual `r` of that
/// channel (`r = (simulated − measured) w`: the best `c` is `−mean(r)/w`,
/// what the sensor reads above the pressure). The larger of the two, if a
/// channel is compared.
fn offset_probe(p: &Prepared, r0: &[f64], rss0: f64) -> Option<Probe> {
    let n = p.t.len();
    let compared = p.meas.iter().zip(&p.weights).filter(|(_, w)| **w > 0.0);
    compared
        .enumerate()
        .filter_map(|(i, ((ch, _), w))| {
            let kind = match ch {
                Signal::P1 => "p1_offset",
                Signal::P2 => "p2_offset",
                _ => return None,
            };
            let block = r0.get(i * n..(i + 1) * n)?;
            let mean = block.iter().sum::<f64>() / n.max(1) as f64;
            let c = -mean / w;
            let side = if c > 0.0 { "high" } else { "low" };
            Some(Probe {
                kind: kind.into(),
                what: format!(
                    "{} sensor zero error ({} reads {} bar {side})",
                    ch.name(),
                    ch.name(),
                    sig(c.abs() / 1e5)
                ),
                value: c,
                explained_share: n as f64 * mean * mean / rss0.max(1e-300),
            })
        })
        .max_by(|a, b| a.explained_share.total_cmp(&b.explained_share))
}

/// What a gain probe may leave of the weighted residual to stand in for the
/// catalog, as a factor on the noise (NRMSE over the floor): a sensor's
/// gain error resembles catalog effects in part (a position read 3 % long
/// is a flow gain 3 % high with a stiffer oil; a pressure read 5 % high
/// looks like its zero error where it varies little), so a gain is named
/// only where it alone explains the record down to its noise.
const GAIN_PROBE_FLOOR: f64 = 1.5;

/// The sensors' gain (calibration) errors: p1, p2 or the position read
/// `1 + g` times their value (`p1_gain`, `p2_gain`, `position_gain`). With
/// `r = (simulated − measured) w` and the measurement `(1 + g)` times the
/// simulated value, `r = g φ` with `φ = −simulated · w`: `g` and the sum of
/// squares it removes follow in closed form from the channel's block (the
/// position's with a free zero, which its initial state holds anyway). The
/// largest, if it leaves no more than [`GAIN_PROBE_FLOOR`]² times the noise
/// of a residual that was above it (the weights are one over each channel's
/// noise, so the noise's weighted sum of squares is the number of compared
/// samples). A pair of catalog effects must explain more than it by
/// `--min-share`: two catalog parameters that do no better than one
/// out-of-catalog parameter are not established (a position read 3 % long
/// is a flow gain 3 % high beside a stiffer oil).
pub(super) fn gain_probe(p: &Prepared, r0: &[f64], rss0: f64) -> Option<Probe> {
    let n = p.t.len();
    let compared: Vec<_> = p
        .meas
        .iter()
        .zip(&p.weights)
        .filter(|(_, w)| **w > 0.0)
        .collect();
    let noise_ss = (n * compared.len()) as f64;
    if rss0 <= GAIN_PROBE_FLOOR.powi(2) * noise_ss {
        // nothing above the noise to explain
        return None;
    }
    compared
        .iter()
        .enumerate()
        .filter_map(|(i, ((ch, m), w))| {
            let (kind, centred) = match ch {
                Signal::P1 => ("p1_gain", false),
                Signal::P2 => ("p2_gain", false),
                Signal::Position => ("position_gain", true),
                _ => return None,
            };
            let block = r0.get(i * n..(i + 1) * n)?;
            let phi: Vec<f64> = block
                .iter()
                .zip(m.iter())
                .map(|(r, y)| -(y + r / **w) * **w)
                .collect();
            let mean = |v: &[f64]| v.iter().sum::<f64>() / n.max(1) as f64;
            let (mp, mr) = if centred {
                (mean(&phi), mean(block))
            } else {
                (0.0, 0.0)
            };
            let (mut num, mut den) = (0.0, 0.0);
            for (f, r) in phi.iter().zip(block) {
                num += (f - mp) * (r - mr);
                den += (f - mp).powi(2);
            }
            if den <= 0.0 || !den.is_finite() || !num.is_finite() {
                return None;
            }
            let g = num / den;
            let removed = num * g + n as f64 * mr * mr;
            if rss0 - removed > GAIN_PROBE_FLOOR.powi(2) * noise_ss {
                return None;
            }
            Some(Probe {
                kind: kind.into(),
                what: format!(
                    "{} sensor gain error ({} reads {:+.2} % of its value)",
                    ch.name(),
                    ch.name(),
                    100.0 * g
                ),
                value: g,
                explained_share: removed / rss0.max(1e-300),
            })
        })
        .max_by(|a, b| a.explained_share.total_cmp(&b.explained_share))
}

/// Every out-of-catalog probe on the round model `rig` (weighted residual
/// `r0` on the whole record, sum of squares `rss0`): the one explaining
/// the largest share. `need`: the share a probe must explain to outrank
/// the catalog's top candidate.
pub(super) fn best_probe(
    rig: &Model,
    p: &Prepared,
    holdout: f64,
    r0: &[f64],
    rss0: f64,
    need: f64,
) -> Option<Probe> {
    let (delay, scaled) = rayon::join(
        || delay_probe(rig, p, holdout, rss0),
        || scaled_probes(rig, p, holdout, r0, rss0, need),
    );
    [
        delay,
        scaled,
        offset_probe(p, r0, rss0),
        gain_probe(p, r0, rss0),
    ]
    .into_iter()
    .flatten()
    .max_by(|a, b| a.explained_share.total_cmp(&b.explained_share))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(preset: &str) -> Vec<(&'static str, Vec<String>)> {
        let m = Model::new(&hydrocyl_system::rig::preset(preset).unwrap()).unwrap();
        scaled_params(&m)
            .into_iter()
            .map(|s| {
                let paths = s.paths.iter().map(|(c, q, _)| format!("{c}.{q}")).collect();
                (s.kind, paths)
            })
            .collect()
    }

    #[test]
    fn the_scaled_parameters_are_found_by_role() {
        assert_eq!(
            kinds("leaney-moog"),
            [
                ("mass", vec!["load.mass".to_string()]),
                ("coulomb", vec!["friction.coulomb".to_string()]),
                ("supply_pressure", vec!["supply.pressure".to_string()]),
            ]
        );
        // pump-driven: no source on a valve's P port; a Coulomb level per
        // direction
        assert_eq!(
            kinds("wang-hybrid"),
            [
                ("mass", vec!["load.mass".to_string()]),
                (
                    "coulomb",
                    vec![
                        "friction.extending.curve.coulomb".to_string(),
                        "friction.retracting.curve.coulomb".to_string()
                    ]
                ),
            ]
        );
    }

    #[test]
    fn a_parabola_step_lands_on_the_vertex() {
        // (x − 0.3)² sampled at 0, 0.5, 1: the vertex itself
        let f = |x: f64| (x - 0.3f64).powi(2) + 1.0;
        let pts: Vec<(f64, f64)> = [0.0, 0.5, 1.0].iter().map(|&x| (x, f(x))).collect();
        let x = parabola_step(&pts).unwrap();
        assert!((x - 0.3).abs() < 1e-12, "{x}");
        // the lowest at an end: no step
        assert_eq!(parabola_step(&pts[1..]), None);
        assert_eq!(sig(39.97), "40.0");
        assert_eq!(sig(0.1234), "0.123");
        assert_eq!(sig(150.0), "150");
    }
}
