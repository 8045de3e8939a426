//! A measured velocity against the derivative of the record's own
//! position: a velocity column of the wrong sign.

use super::{problem, DataProblem, ProblemKind};
use crate::data::{Record, Signal};
use crate::smooth::noise_sigma;

/// Least correlation the two channels' noise must allow between a right
/// velocity and the derivative of the position (see
/// [`velocity_sign_problem`]) for the sign to be judged at all.
const JUDGED_CORRELATION: f64 = 0.5;

/// A `velocity` column whose sign contradicts the record's own position:
/// the velocity correlates with the position's central difference over
/// about 50 ms below minus half the correlation the two channels' noise
/// allows. Two noisy measurements of one motion correlate at
/// `ρ = √(1 − σd²/var d) · √(1 − σv²/var v)` (σ the white-noise sigma of
/// each, `σd = √2 σx / 2kΔt` for the difference over `2k` steps), whatever
/// the unit of either; a right column then correlates near `+ρ`, a flipped
/// one near `−ρ`, and the threshold `−ρ/2` sits halfway. Judged only where
/// `ρ ≥ 0.5` (the piston moves well above the noise in both channels; at
/// rest the correlation is noise against noise).
pub(super) fn velocity_sign_problem(rec: &Record) -> Option<DataProblem> {
    let (x, v) = (rec.get(Signal::Position)?, rec.get(Signal::Velocity)?);
    let t = &rec.time;
    let n = t.len().min(x.len()).min(v.len());
    if n < 50 {
        return None;
    }
    let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
    if dt.is_nan() || dt <= 0.0 {
        return None;
    }
    let k = ((0.025 / dt).round() as usize).clamp(1, n / 4);
    let pairs: Vec<(f64, f64)> = (k..n - k)
        .map(|i| (v[i], (x[i + k] - x[i - k]) / (t[i + k] - t[i - k])))
        .collect();
    let m = pairs.len() as f64;
    let (mv, md) = pairs
        .iter()
        .fold((0.0, 0.0), |(a, b), (v, d)| (a + v / m, b + d / m));
    let (mut svv, mut sdd, mut svd) = (0.0, 0.0, 0.0);
    for (v, d) in &pairs {
        svv += (v - mv).powi(2) / m;
        sdd += (d - md).powi(2) / m;
        svd += (v - mv) * (d - md) / m;
    }
    if !(svv > 0.0 && sdd > 0.0) {
        return None;
    }
    let corr = svd / (svv * sdd).sqrt();
    let sigma_d = 2f64.sqrt() * noise_sigma(t, x) / (2.0 * k as f64 * dt);
    let sigma_v = noise_sigma(t, v);
    let rho =
        ((1.0 - sigma_d.powi(2) / sdd).max(0.0) * (1.0 - sigma_v.powi(2) / svv).max(0.0)).sqrt();
    if !(rho >= JUDGED_CORRELATION && corr < -0.5 * rho) {
        return None;
    }
    Some(problem(
        Signal::Velocity,
        ProblemKind::Sign,
        format!("velocity runs against the derivative of the record's own position (correlation {corr:.2}; a right column correlates near +{rho:.2} at these noise levels): check the sign convention of the velocity transducer or of the logged column"),
    ))
}

#[cfg(test)]
mod tests {
    use crate::data::Signal;
    use crate::data_checks::tests::{facts, moving, rec};
    use crate::data_checks::{check_record, ProblemKind};

    /// The tests' piston (0.2 m/s sine at 1 Hz) with 20 µm of position
    /// noise and a velocity column `sign` times its true velocity, with
    /// 2 mm/s of noise.
    fn kinds(sign: f64, still: bool) -> Vec<(String, ProblemKind)> {
        let n = 2000;
        let (u, x) = moving(n);
        let w = 2.0 * std::f64::consts::PI;
        let (ex, ev) = (
            crate::smooth::gaussian_noise(n, 5),
            crate::smooth::gaussian_noise(n, 6),
        );
        let s = if still { 0.0 } else { 1.0 };
        let x: Vec<f64> = (0..n).map(|i| s * x[i] + 2e-5 * ex[i]).collect();
        let v: Vec<f64> = (0..n)
            .map(|i| sign * s * 0.2 * (w * i as f64 * 1e-3).sin() + 2e-3 * ev[i])
            .collect();
        let u = if still { vec![0.0; n] } else { u };
        check_record(
            &rec(&[
                (Signal::Command, u),
                (Signal::Position, x),
                (Signal::Velocity, v),
            ]),
            Some(&facts()),
        )
        .into_iter()
        .map(|p| (p.channel, p.kind))
        .collect()
    }

    #[test]
    fn a_velocity_of_the_right_sign_has_no_problem() {
        assert_eq!(kinds(1.0, false), vec![]);
        // in another unit (mm/s under [m/s]) it is still not a sign problem
        assert_eq!(kinds(1e3, false), vec![]);
    }

    /// Minus the derivative of the record's own position is a `sign`
    /// problem on `velocity` (it was kept in the fit, 20× its floor).
    #[test]
    fn a_velocity_of_the_wrong_sign_is_named() {
        assert_eq!(
            kinds(-1.0, false),
            [("velocity".to_string(), ProblemKind::Sign)]
        );
    }

    /// A piston at rest: velocity and position are noise, their
    /// correlation says nothing about the sign.
    #[test]
    fn a_piston_at_rest_is_not_judged() {
        assert_eq!(kinds(-1.0, true), vec![]);
    }
}
