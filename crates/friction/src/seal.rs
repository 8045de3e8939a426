//! The pressure-energised seal term bounded to its identification range.
//!
//! Eq 5.4 adds `K (p1 − p2)² v` to the friction. The thesis fitted K
//! (Table 5-5 / 5-8) on the steady square-wave tests of Table 5-3, at
//! |v| ≤ 49 mm/s on the horizontal rig with no load, where the chamber
//! pressure difference stays within a few bar. Extrapolated to the 20–200
//! bar of a loaded or fast drive the quadratic term predicts seal forces of
//! kN to hundreds of kN and makes the hybrid drive lock (the fold,
//! `hydrocyl_studies::chapter7`), which the rig never showed.
//!
//! hydrocyl's modelling choice: the pressure difference the seal term sees is
//! bounded to the largest one of the identification data,
//!
//! ```text
//! F_seal = K min(|p1 − p2|, Δp_max)² v        (Δp_max = 0: unbounded, eq 5.4)
//! ```
//!
//! which is eq 5.4 wherever it was identified and a pressure-independent
//! viscous term `K Δp_max² v` beyond. The thesis does not tabulate the
//! pressures of Table 5-3; [`identification_dp_max`] recovers them from
//! the fitted law itself: at each steady point `F = g(v) + K Δp² v`, so
//! `Δp = √((F − g(v)) / (K v))`. Over Table 5-3 this gives 1.1–2.7 bar
//! extending and 2.0–5.0 bar retracting ([`TABLE_5_3`]); the largest, 5.03
//! bar at −49 mm/s, is Δp_max.
//!
//! **Per direction.** The two directions were identified over different
//! ranges (2.72 bar at most extending, 5.03 bar retracting), and with one
//! bound the extending seal term is used up to 5.03 bar, outside its data: on
//! the chapter-7 square the hybrid drive then lands on the upper branch of a
//! fold (447 N at 50 mm/s against the rig's 220 N). So every seal term takes
//! an optional bound per direction, `Δp_max,ext` for v > 0 and `Δp_max,ret`
//! for v < 0 ([`bound_for`], [`identification_dp_max_per_direction`]); 0
//! falls back to the common `Δp_max`. No blend across v = 0 is needed: the
//! term is `K Δp² v`, so the force is continuous whatever the bound does at
//! v = 0 (only ∂F/∂v steps there, as it already does with Table 5-8's two
//! K values).

use crate::wang::Wang;

/// Table 5-3 (thesis section 5.1.2): the steady friction measured in square
/// waves, `(velocity [m/s], friction [N])`, the points in motion only (the
/// four stiction points at v = 0 carry no seal term).
pub const TABLE_5_3: [(f64, f64); 8] = [
    (0.04803, 220.0),
    (0.03618, 181.5),
    (0.025, 167.0),
    (0.015, 139.2),
    (-0.01473, -110.0),
    (-0.02467, -119.6),
    (-0.03671, -136.0),
    (-0.04905, -162.2),
];

/// [`identification_dp_max`] rounded to 1 Pa: the bound the presets with
/// Table 5-8 friction use \[Pa\] (a test keeps them equal).
pub const TABLE_5_8_DP_MAX: f64 = 502_888.0;

/// [`identification_dp_max_per_direction`]'s extending bound rounded to
/// 1 Pa \[Pa\] (a test keeps them equal); the retracting one is
/// [`TABLE_5_8_DP_MAX`].
pub const TABLE_5_8_DP_MAX_EXTEND: f64 = 271_667.0;

/// The bound of one direction: `extend` (v > 0, or `extending`) or
/// `retract`, the common `dp_max` where that is 0 \[Pa\] (0 = unbounded).
pub fn bound_for(extending: bool, dp_max: f64, extend: f64, retract: f64) -> f64 {
    let own = if extending { extend } else { retract };
    if own > 0.0 {
        own
    } else {
        dp_max
    }
}

/// `(min(|dp|, dp_max) sgn(dp), slope)` — the pressure difference the seal
/// term sees and its derivative with respect to `dp` (1 inside the bound,
/// 0 beyond); `dp_max = 0` leaves `dp` unbounded.
pub fn bounded(dp: f64, dp_max: f64) -> (f64, f64) {
    if dp_max > 0.0 && dp.abs() > dp_max {
        (dp_max.copysign(dp), 0.0)
    } else {
        (dp, 1.0)
    }
}

/// `true` for the unbounded form (`dp_max = 0`).
pub fn is_unbounded(dp_max: &f64) -> bool {
    *dp_max == 0.0
}

/// The chamber pressure difference implied by `law` at each point of
/// `data` (`(v [m/s], F [N])`): `√((|F| − g(v)) / (K |v|))`, 0 where the
/// measured force lies below the Stribeck curve \[Pa\].
pub fn implied_dp(law: &Wang, data: &[(f64, f64)]) -> Vec<f64> {
    data.iter()
        .map(|&(v, f)| {
            let s = law.set_for(v, 0.0);
            let rest = f.abs() - s.curve.g(v);
            if rest > 0.0 && s.k_pressure > 0.0 {
                (rest / (s.k_pressure * v.abs())).sqrt()
            } else {
                0.0
            }
        })
        .collect()
}

/// The largest pressure difference of the identification data of Table 5-8:
/// the maximum of [`implied_dp`] over [`TABLE_5_3`] under
/// [`Wang::table_5_8`] (≈ 5.03 bar) \[Pa\].
pub fn identification_dp_max() -> f64 {
    implied_dp(&Wang::table_5_8(), &TABLE_5_3)
        .into_iter()
        .fold(0.0, f64::max)
}

/// The largest pressure difference of Table 5-8's identification data per
/// direction, `(extending, retracting)`: the maxima of [`implied_dp`] over
/// the v > 0 and v < 0 points of [`TABLE_5_3`] (≈ 2.72 / 5.03 bar) \[Pa\].
pub fn identification_dp_max_per_direction() -> (f64, f64) {
    let law = Wang::table_5_8();
    let max = |pts: Vec<(f64, f64)>| implied_dp(&law, &pts).into_iter().fold(0.0, f64::max);
    let (ext, ret): (Vec<_>, Vec<_>) = TABLE_5_3.iter().partition(|p| p.0 > 0.0);
    (max(ext), max(ret))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bound_is_5_bar_at_the_fastest_retracting_point() {
        let dps = implied_dp(&Wang::table_5_8(), &TABLE_5_3);
        let max = identification_dp_max();
        assert!((max - 5.029e5).abs() < 0.01e5, "{max}");
        assert!((max - TABLE_5_8_DP_MAX).abs() < 1.0, "{max}");
        assert_eq!(dps[7], max);
        // the extending points stay within 2.8 bar, the slowest retracting one
        // lies under the curve
        assert!(dps[..4].iter().all(|&d| d > 1.0e5 && d < 2.8e5), "{dps:?}");
        assert_eq!(dps[4], 0.0);
    }

    #[test]
    fn the_extending_bound_is_2_7_bar_at_the_fastest_extending_point() {
        let dps = implied_dp(&Wang::table_5_8(), &TABLE_5_3);
        let (ext, ret) = identification_dp_max_per_direction();
        assert_eq!(ext, dps[0]);
        assert_eq!(ret, identification_dp_max());
        assert!((ext - 2.72e5).abs() < 0.01e5, "{ext}");
        assert!((ext - TABLE_5_8_DP_MAX_EXTEND).abs() < 1.0, "{ext}");
        assert!((ret - TABLE_5_8_DP_MAX).abs() < 1.0, "{ret}");
    }

    #[test]
    fn bound_for_takes_the_direction_and_falls_back_to_the_common_one() {
        assert_eq!(bound_for(true, 5e5, 2e5, 4e5), 2e5);
        assert_eq!(bound_for(false, 5e5, 2e5, 4e5), 4e5);
        assert_eq!(bound_for(true, 5e5, 0.0, 4e5), 5e5);
        assert_eq!(bound_for(false, 0.0, 2e5, 0.0), 0.0);
    }

    #[test]
    fn bounded_is_the_identity_inside_and_constant_beyond() {
        assert_eq!(bounded(3e5, 5e5), (3e5, 1.0));
        assert_eq!(bounded(-7e5, 5e5), (-5e5, 0.0));
        assert_eq!(bounded(-7e7, 0.0), (-7e7, 1.0));
    }
}
