//! LuGre's dynamic signatures as asserted properties: pre-sliding stiffness
//! ≈ σ0, the friction lag loop (Fig 2-35), stick-slip on the mass-spring-belt.

use hydrocyl_friction::{FrictionInput, FrictionModel, LuGre};
use hydrocyl_ports::Velocity;

use crate::common::{lugre_classic, rk4};

/// Drives the bristle with a prescribed velocity v(t); returns samples
/// (t, x, v, F) every `every` steps.
fn drive<M: FrictionModel>(
    m: &M,
    v: impl Fn(f64) -> f64,
    t_end: f64,
    h: f64,
    every: usize,
) -> Vec<(f64, f64, f64, f64)> {
    let f = |t: f64, s: &[f64], ds: &mut [f64]| {
        let i = FrictionInput::at_velocity(Velocity::new(v(t)));
        m.state_derivative(&i, &s[..1], &mut ds[..1]);
        ds[1] = v(t);
    };
    let mut s = [0.0, 0.0];
    let mut out = Vec::new();
    let n = (t_end / h).round() as usize;
    for k in 0..=n {
        let t = k as f64 * h;
        if k % every == 0 {
            let i = FrictionInput::at_velocity(Velocity::new(v(t)));
            out.push((t, s[1], v(t), m.force(&i, &s[..1]).si()));
        }
        rk4(&f, t, &mut s, h);
    }
    out
}

#[test]
fn pre_sliding_stiffness_is_sigma0_for_micro_displacements() {
    // Table 5-11: σ0 = 3e7 N/m, Fs/σ0 ≈ 6 µm; displace ±0.05 µm.
    let m = LuGre::table_5_11();
    let amp = 5e-8;
    let w = 2.0 * std::f64::consts::PI * 1.0;
    let samples = drive(&m, |t| amp * w * (w * t).cos(), 1.0, 1e-5, 10);
    // Secant stiffness at the extreme displacements (v = 0 there).
    let (xmax, fmax) =
        samples
            .iter()
            .map(|s| (s.1, s.3))
            .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a });
    let k = fmax / xmax;
    assert!(
        (k / m.sigma0 - 1.0).abs() < 0.02,
        "k = {k:e} vs σ0 = {:e}",
        m.sigma0
    );
    // And the motion is elastic: back at x = 0 the force is back near zero.
    let last = samples.last().unwrap();
    assert!(
        last.1.abs() < 1e-12 && last.3.abs() < 0.02 * fmax,
        "{last:?}"
    );
}

#[test]
fn friction_lag_force_is_higher_accelerating_than_decelerating() {
    // Classical parameters; velocity oscillates inside the Stribeck region,
    // v = 1 mm/s (1 + 0.9 sin ωt), ω = 25 rad/s (Canudas de Wit et al. 1995).
    let m = lugre_classic();
    let w = 25.0;
    let v = |t: f64| 1e-3 * (1.0 + 0.9 * (w * t).sin());
    let p = std::f64::consts::TAU / w;
    let samples = drive(&m, v, 8.0 * p, 2e-6, 5);
    // Eighth period, [7p, 8p]: F where v crosses 1 mm/s going up
    // (accelerating, t = 7p) and going down (decelerating, t = 7.5p).
    let t0 = 6.0 * p;
    let at = |t: f64| {
        samples
            .iter()
            .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
            .unwrap()
            .3
    };
    let f_up = at(t0 + p);
    let f_down = at(t0 + 1.5 * p);
    assert!(
        f_up > f_down + 0.02,
        "accelerating {f_up} N, decelerating {f_down} N"
    );
    // Both lie between Fc and Fs + σ2 v, and the loop encloses an area
    // (∮ F dv ≠ 0), i.e. it is a hysteresis loop, not a curve.
    assert!(f_up < 1.5 + 0.4 * 2e-3 && f_down > 1.0);
    let cycle: Vec<_> = samples
        .iter()
        .filter(|s| s.0 >= t0 + p && s.0 <= t0 + 2.0 * p)
        .collect();
    let area: f64 = cycle
        .windows(2)
        .map(|w| 0.5 * (w[0].3 + w[1].3) * (w[1].2 - w[0].2))
        .sum();
    assert!(area.abs() > 1e-6, "loop area {area:e}");
}

/// Mass-spring-belt: m ẍ = k (vb t − x) − F(ẋ). Returns (t, x, v, spring force).
pub fn belt_lugre(m: &LuGre, t_end: f64) -> Vec<(f64, f64, f64, f64)> {
    let (mass, k, vb) = (1.0, 2.0, 0.1);
    let f = |t: f64, s: &[f64], ds: &mut [f64]| {
        let i = FrictionInput::at_velocity(Velocity::new(s[1]));
        let fr = m.force(&i, &s[2..]).si();
        ds[0] = s[1];
        ds[1] = (k * (vb * t - s[0]) - fr) / mass;
        m.state_derivative(&i, &s[2..], &mut ds[2..]);
    };
    let h = 2e-5;
    let mut s = [0.0, 0.0, 0.0];
    let mut out = Vec::new();
    let n = (t_end / h) as usize;
    for i in 0..n {
        let t = i as f64 * h;
        if i % 50 == 0 {
            out.push((t, s[0], s[1], k * (vb * t - s[0])));
        }
        rk4(&f, t, &mut s, h);
    }
    out
}

#[test]
fn mass_spring_belt_shows_stick_slip() {
    let m = lugre_classic();
    let out = belt_lugre(&m, 30.0);
    let late: Vec<_> = out.iter().filter(|s| s.0 > 10.0).collect();
    // Stick: long stretches with the mass (nearly) at rest while the belt moves at 0.1 m/s.
    let stuck = late.iter().filter(|s| s.2.abs() < 1e-3).count() as f64 / late.len() as f64;
    assert!(stuck > 0.3, "fraction stuck {stuck}");
    // Slip: the mass overtakes the belt.
    let vmax = late.iter().map(|s| s.2).fold(f64::MIN, f64::max);
    assert!(vmax > 0.15, "peak velocity {vmax}");
    // Break-away happens at the stiction level: the spring force peaks near Fs = 1.5 N
    // (a little lower: the bristle creeps before break-away).
    let fmax = late.iter().map(|s| s.3).fold(f64::MIN, f64::max);
    assert!(fmax > 1.3 && fmax < 1.55, "peak spring force {fmax}");
    // Periodic: successive break-away times are evenly spaced.
    let breaks: Vec<f64> = late
        .windows(2)
        .filter(|w| w[0].2 < 0.05 && w[1].2 >= 0.05)
        .map(|w| w[1].0)
        .collect();
    assert!(breaks.len() >= 2, "{breaks:?}");
    let periods: Vec<f64> = breaks.windows(2).map(|w| w[1] - w[0]).collect();
    let (pmin, pmax) = periods
        .iter()
        .fold((f64::MAX, f64::MIN), |a, &p| (a.0.min(p), a.1.max(p)));
    assert!(pmax - pmin < 0.02 * pmax, "periods {periods:?}");
}
