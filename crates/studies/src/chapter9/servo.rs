//! The servo needle valve's opening law fitted to the optimiser's openings:
//! the opening is a straight line in the commanded speed through the optimal
//! openings at the two speeds, `A(v) = A_0 + s v`, and the commanded speed
//! is read from the pump command, `v = K u / A1` extending and
//! `v = −K u / A2` retracting (the steady speeds of the open-loop drive), so
//! `g₊ = s K / A1` and `g₋ = s K / A2`.

use super::run::parameter;
use hydrocyl_system::rig::RigError;
use serde::Serialize;
use serde_json::Value;

/// The fitted law, as `--set`s of the `servo_needle_valve`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ServoLaw {
    /// Opening at zero command \[m²\].
    pub area_min: f64,
    /// Opening per volt of positive command \[m²/V\].
    pub gain_positive: f64,
    /// Opening per volt of negative command \[m²/V\].
    pub gain_negative: f64,
}

impl ServoLaw {
    /// The law through `(v_a, A_a)` and `(v_b, A_b)` (speeds \[m/s\],
    /// openings \[m²\]) for the rig `v` (its `cylinder.area_1`,
    /// `cylinder.area_2`, `pump.gain`). When that line's intercept is
    /// negative the law is the proportional one through the slower point,
    /// `A = (A_a / v_a) v`: the damping limit binds at the slow, loaded
    /// case (the load running ahead), so the law keeps the slow optimum and
    /// opens less than the fast optimum (more loss there, never less damping).
    pub fn fit(v: &Value, a: (f64, f64), b: (f64, f64)) -> Result<Self, RigError> {
        let (a1, a2) = (
            parameter(v, "cylinder.area_1")?,
            parameter(v, "cylinder.area_2")?,
        );
        let k = parameter(v, "pump.gain")?;
        if !(a.0 > 0.0 && b.0 > a.0) {
            return Err(RigError::Invalid {
                path: "servo law".into(),
                why: format!(
                    "needs two optima at increasing positive speeds, got {} and {} m/s",
                    a.0, b.0
                ),
            });
        }
        let mut s = (b.1 - a.1) / (b.0 - a.0);
        let mut a0 = a.1 - s * a.0;
        if s < 0.0 {
            // the faster optimum is narrower: a constant opening at the
            // narrower of the two (never wider than either optimum)
            a0 = a.1.min(b.1);
            s = 0.0;
        } else if a0 < 0.0 {
            a0 = 0.0;
            s = a.1 / a.0;
        }
        Ok(Self {
            area_min: a0,
            gain_positive: s * k / a1,
            gain_negative: s * k / a2,
        })
    }

    /// The `--set` assignments for a `servo_needle_valve` named `needle_valve`.
    pub fn sets(&self) -> [String; 3] {
        [
            format!("needle_valve.area_min={}", self.area_min),
            format!("needle_valve.gain_positive={}", self.gain_positive),
            format!("needle_valve.gain_negative={}", self.gain_negative),
        ]
    }
}
