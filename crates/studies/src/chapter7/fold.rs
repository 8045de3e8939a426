//! The fold of the pressure-energised seal term in steady extension (module
//! docs of [`super`], "the fold"): the force reserve, its minimum over speed,
//! the fold speed and the two pressure roots.

use hydrocyl_friction::Wang;
use hydrocyl_system::hybrid::WangHybrid;

/// Force reserve of steady extension at speed `v` \[N\] under the Wang law
/// `wang` on `rig` (module docs, "the fold"): `A1²/(4 K v) + p2 (A1 − A2) − g(v)`,
/// `p2` the pressure that passes `A2 v` through the open four-way valve and the
/// needle valve. Negative: no steady extension at `v` exists.
pub fn extend_force_reserve(rig: &WangHybrid, wang: &Wang, v: f64) -> f64 {
    let (a1, a2) = (rig.cylinder.area_1.si(), rig.cylinder.area_2.si());
    let k_ret = hydrocyl_valves::pilot_valve::series_coefficient(
        rig.four_way.k_t,
        rig.needle.coefficient(),
    );
    let p2 = (a2 * v / k_ret).powi(2);
    let k = wang.extending.k_pressure;
    a1 * a1 / (4.0 * k * v) + p2 * (a1 - a2) - wang.extending.curve.g(v)
}

/// The lowest force reserve of steady extension between 1 mm/s and 1 m/s
/// under `wang` on `rig`, as `(speed [m/s], reserve [N])`: a scan of
/// [`extend_force_reserve`] in 1 mm/s steps refined by golden-section search.
/// A negative reserve means a band of speeds without steady extension.
pub fn extend_reserve_minimum(rig: &WangHybrid, wang: &Wang) -> (f64, f64) {
    let f = |v: f64| extend_force_reserve(rig, wang, v);
    let (mut v_best, mut r_best) = (1e-3, f(1e-3));
    for k in 2..=1000 {
        let v = k as f64 * 1e-3;
        let r = f(v);
        if r < r_best {
            (v_best, r_best) = (v, r);
        }
    }
    let (mut lo, mut hi) = ((v_best - 1e-3).max(1e-3), (v_best + 1e-3).min(1.0));
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..60 {
        let (a, b) = (hi - phi * (hi - lo), lo + phi * (hi - lo));
        if f(a) < f(b) {
            hi = b;
        } else {
            lo = a;
        }
    }
    let v = 0.5 * (lo + hi);
    (v, f(v).min(r_best))
}

/// The fold speed: the lowest speed in (1 mm/s, 1 m/s) at which
/// [`extend_force_reserve`] reaches zero \[m/s\] (scan in 1 mm/s steps, then
/// bisection to 1e-12 m/s); `None` when K = 0 or the reserve stays positive
/// (see [`extend_reserve_minimum`] for how close it comes).
pub fn extend_fold_speed(rig: &WangHybrid, wang: &Wang) -> Option<f64> {
    if wang.extending.k_pressure <= 0.0 {
        return None;
    }
    let f = |v: f64| extend_force_reserve(rig, wang, v);
    let hi = (1..=1000).map(|k| k as f64 * 1e-3).find(|&v| f(v) <= 0.0)?;
    let (mut lo, mut hi) = ((hi - 1e-3).max(1e-4), hi);
    while hi - lo > 1e-12 {
        let m = 0.5 * (lo + hi);
        if f(m) > 0.0 {
            lo = m;
        } else {
            hi = m;
        }
    }
    Some(0.5 * (lo + hi))
}

/// The two roots `(Δp_s, Δp*)` of the steady extension balance at speed `v`
/// \[Pa\]: the stable operating pressure difference and the unstable one
/// beyond which the drive locks (module docs, "the fold"); `None` when the
/// reserve is negative (no steady state).
pub fn extend_pressure_roots(rig: &WangHybrid, wang: &Wang, v: f64) -> Option<(f64, f64)> {
    let (a1, a2) = (rig.cylinder.area_1.si(), rig.cylinder.area_2.si());
    let k_ret = hydrocyl_valves::pilot_valve::series_coefficient(
        rig.four_way.k_t,
        rig.needle.coefficient(),
    );
    let p2 = (a2 * v / k_ret).powi(2);
    let kv = wang.extending.k_pressure * v;
    // K v Δp² − A1 Δp + (g − p2 (A1 − A2)) = 0
    let c = wang.extending.curve.g(v) - p2 * (a1 - a2);
    let disc = a1 * a1 - 4.0 * kv * c;
    (disc >= 0.0).then(|| {
        (
            (a1 - disc.sqrt()) / (2.0 * kv),
            (a1 + disc.sqrt()) / (2.0 * kv),
        )
    })
}
