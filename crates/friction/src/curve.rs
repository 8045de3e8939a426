//! The Stribeck curve g(v) shared by the Stribeck, Karnopp, LuGre and Wang
//! models (thesis eqs 2.36, 5.1, 5.4):
//!
//! `g(v) = Fc + (Fs − Fc) exp(−|v / vs|^δ)`
//!
//! The thesis writes the exponent α (and also α for acceleration, eq 5.12);
//! hydrocyl calls it δ, [`StribeckCurve::stribeck_exponent`]. Eq 2.36 writes
//! `(v/vs)^n` without the absolute value, which is undefined for v < 0 and a
//! non-integer exponent (the thesis's δ ≈ 0.11); eqs 5.4/5.12 take `|v/vs|`,
//! and so does hydrocyl.

use hydrocyl_ports::{Force, Velocity};
use serde::{Deserialize, Serialize};

use crate::error::{positive, FrictionError};

/// Stribeck curve parameters. All magnitudes are positive: the thesis's
/// negative retracting values (Tables 5-4, 5-8 to 5-11) give the direction of
/// the force, which hydrocyl takes from the sign of the velocity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StribeckCurve {
    /// Coulomb friction level Fc \[N\], > 0.
    pub coulomb: Force,
    /// Stiction (break-away) level Fs = g(0) \[N\], > 0.
    pub stiction: Force,
    /// Stribeck velocity vs \[m·s⁻¹\], > 0.
    pub stribeck_velocity: Velocity,
    /// Stribeck exponent δ (the thesis's α in eqs 2.36, 5.1) \[–\], > 0.
    pub stribeck_exponent: f64,
}

impl StribeckCurve {
    /// A curve from SI values: Fc \[N\], Fs \[N\], vs \[m/s\], δ \[–\], validated.
    pub fn new(fc: f64, fs: f64, vs: f64, delta: f64) -> Result<Self, FrictionError> {
        let c = Self {
            coulomb: Force::new(fc),
            stiction: Force::new(fs),
            stribeck_velocity: Velocity::new(vs),
            stribeck_exponent: delta,
        };
        c.validate("Stribeck curve")?;
        Ok(c)
    }

    /// Checks every field is finite and positive.
    pub fn validate(&self, model: &'static str) -> Result<(), FrictionError> {
        positive(model, "Fc (coulomb)", self.coulomb.si())?;
        positive(model, "Fs (stiction)", self.stiction.si())?;
        positive(model, "vs (stribeck_velocity)", self.stribeck_velocity.si())?;
        positive(model, "delta (stribeck_exponent)", self.stribeck_exponent)
    }

    /// `g(v)` \[N\] (even in v).
    #[inline]
    pub fn g(&self, v: f64) -> f64 {
        let (fc, fs) = (self.coulomb.si(), self.stiction.si());
        fc + (fs - fc) * self.decay(v)
    }

    /// `exp(−|v/vs|^δ)`.
    #[inline]
    fn decay(&self, v: f64) -> f64 {
        (-(v / self.stribeck_velocity.si())
            .abs()
            .powf(self.stribeck_exponent))
        .exp()
    }

    /// `|v| · dg/d|v|` \[N\], finite at v = 0 for every δ > 0 (dg/d|v| itself
    /// is infinite there when δ < 1).
    #[inline]
    pub fn v_dg_dv(&self, v: f64) -> f64 {
        let (fc, fs) = (self.coulomb.si(), self.stiction.si());
        let x = (v / self.stribeck_velocity.si())
            .abs()
            .powf(self.stribeck_exponent);
        -(fs - fc) * (-x).exp() * self.stribeck_exponent * x
    }

    /// The same curve with new Coulomb and stiction levels \[N\] (the loaded
    /// variants of Tables 5-9 and 5-10 change only these).
    pub fn with_levels(self, coulomb: f64, stiction: f64) -> Self {
        Self {
            coulomb: Force::new(coulomb),
            stiction: Force::new(stiction),
            ..self
        }
    }
}
