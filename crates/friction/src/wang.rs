//! Wang's new friction model for hydraulic cylinders (thesis chapter 5):
//! LuGre's bristle with the viscous term replaced by a pressure-energised seal
//! term (eq 5.4) and an acceleration term (eqs 5.12, 5.14):
//!
//! ```text
//! F     = σ0 z + σ1 dz/dt + K [ (p1 − p2)² v + H a ]      (5.12 / 5.14)
//! dz/dt = v − σ0 |v| z / g(v)
//! g(v)  = Fc + (Fs − Fc) exp(−|v/vs|^δ)
//! ```
//!
//! K \[m³·s·N⁻¹\] is the seal gain, H \[N²·s·m⁻⁴\] the acceleration gain; the
//! thesis writes α both for the Stribeck exponent (here δ) and for the
//! acceleration (here a). With H = 0 this is eq 5.4 (pressure term only).
//!
//! The acceleration term `K H a` is linear in a: it is **not** part of
//! [`FrictionModel::force`] but reported as
//! [`FrictionModel::acceleration_coefficient`] `c = K H` \[kg\] so the
//! assembler solves `(m + c) a = …` explicitly. Its power `c a v` is
//! `d/dt(½ c v²)`: it stores energy like an added mass and returns it, so it is
//! not friction in the energy sense; the assembler books it with the kinetic
//! energy. `c` changes with the direction (76.25 kg extending, 36 kg
//! retracting for Table 5-8); hydrocyl blends it across v = 0 over ±1 mm/s
//! ([`ACCELERATION_BLEND_VELOCITY`], a documented regularisation: the jump
//! makes the acceleration discontinuous and the solvers disagree), and the
//! model declares a switching function `g = v` so no integrator step
//! straddles a reversal of the other terms.
//!
//! **Disagreements with the thesis.** The thesis's retracting values are
//! negative (Fc = −80 N, vs = −0.01 m/s, …) to give the force its direction;
//! with negative g(v) the bristle law would be unstable, so hydrocyl stores
//! magnitudes and takes the direction from the velocity. Table 5-8 and
//! eq 5.12 take K outside the bracket, so the acceleration term is `K H a`
//! (K·H = 2.5e-8 × 3.05e9 = 76.25 kg extending).

use hydrocyl_ports::{Energy, Force, Mass, Power, Velocity};
use serde::{Deserialize, Serialize};

use crate::curve::StribeckCurve;
use crate::error::{non_negative, positive, FrictionError};
use crate::lugre::{bristle_partials, bristle_rate};
use crate::model::{FrictionInput, FrictionJacobian, FrictionMode, FrictionModel};
use crate::stribeck::sgn;

/// Half-width of the velocity band over which the acceleration term's added
/// mass `K H` passes from the retracting to the extending value \[m·s⁻¹\]
/// (1 mm/s; 98 % of the way at ±5 mm/s, 99.98 % at ±50 mm/s).
///
/// Eq 5.14 switches the parameter set with the direction of motion, so with
/// Table 5-8 the effective mass `m + K H` jumps at every reversal (96.25 kg
/// extending, 56 kg retracting, for the 20 kg of the rigs): the acceleration
/// `F/(m + c)` is discontinuous at v = 0. An integrator that locates the
/// reversal (DP45 with the `g = v` event) steps over it, but a
/// finite-difference Jacobian taken within ~1e-9 m/s of v = 0 (Rodas4's
/// `√ε · 0.1 m/s`) straddles the jump and reports `∂a/∂v` of order 1e9 s⁻¹:
/// the Rosenbrock step then pins v at 0 for milliseconds and auto's run
/// leaves the fluid model (docs/hybrid.md, item 7). Blending `c` smoothly,
/// `c(v) = c̄ + (Δc/2) v/√(v² + a²)`, makes the right-hand side Lipschitz
/// (its largest `∂a/∂v` is `|F| Δc / (2 a (m + c)²)`, ~1e3 s⁻¹ here) and keeps
/// the term conservative ([`Wang::acceleration_energy`]).
pub const ACCELERATION_BLEND_VELOCITY: f64 = 1e-3;

/// One direction's parameters of Wang's model.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WangSet {
    /// Stribeck curve g(v).
    pub curve: StribeckCurve,
    /// Seal gain K \[m³·s·N⁻¹\], ≥ 0.
    pub k_pressure: f64,
    /// Acceleration gain H \[N²·s·m⁻⁴\], ≥ 0.
    pub h_acceleration: f64,
}

impl WangSet {
    fn validate(&self, model: &'static str) -> Result<(), FrictionError> {
        self.curve.validate(model)?;
        non_negative(model, "K (k_pressure)", self.k_pressure)?;
        non_negative(model, "H (h_acceleration)", self.h_acceleration)
    }
}

/// Wang's pressure- and acceleration-dependent LuGre model (eq 5.14).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wang {
    /// Bristle stiffness σ0 \[N·m⁻¹\], > 0.
    pub sigma0: f64,
    /// Bristle damping σ1 \[N·s·m⁻¹\], ≥ 0.
    pub sigma1: f64,
    /// Parameters while extending (v > 0).
    pub extending: WangSet,
    /// Parameters while retracting (v < 0), magnitudes.
    pub retracting: WangSet,
    /// Bound Δp_max of the pressure difference in the seal term,
    /// `K min(|p1 − p2|, Δp_max)² v` \[Pa\] (module [`crate::seal`]);
    /// 0 = unbounded, the thesis's eq 5.4.
    #[serde(default, skip_serializing_if = "crate::seal::is_unbounded")]
    pub seal_dp_max: f64,
    /// Bound while extending (v > 0) \[Pa\]; 0 = [`Wang::seal_dp_max`]
    /// ([`crate::seal::bound_for`]).
    #[serde(default, skip_serializing_if = "crate::seal::is_unbounded")]
    pub seal_dp_max_extend: f64,
    /// Bound while retracting (v < 0) \[Pa\]; 0 = [`Wang::seal_dp_max`].
    #[serde(default, skip_serializing_if = "crate::seal::is_unbounded")]
    pub seal_dp_max_retract: f64,
}

fn set(fc: f64, fs: f64, delta: f64, k: f64, h: f64) -> WangSet {
    WangSet {
        curve: StribeckCurve {
            coulomb: Force::new(fc),
            stiction: Force::new(fs),
            stribeck_velocity: Velocity::new(0.01),
            stribeck_exponent: delta,
        },
        k_pressure: k,
        h_acceleration: h,
    }
}

impl Wang {
    /// Table 5-8, no added load: Fc 110 / 80 N, Fs 180 / 188 N, vs 0.01 m/s,
    /// δ 0.1087 / 0.1138, K 2.5e-8 / 4e-9 m³ s/N, σ0 3e7 N/m, σ1 0.1 N s/m,
    /// H 3.05e9 / 9e9 N² s/m⁴ (extending / retracting).
    pub fn table_5_8() -> Self {
        Self {
            sigma0: 3.0e7,
            sigma1: 0.1,
            extending: set(110.0, 180.0, 0.1087, 2.5e-8, 3.05e9),
            retracting: set(80.0, 188.0, 0.1138, 4.0e-9, 9.0e9),
            seal_dp_max: 0.0,
            seal_dp_max_extend: 0.0,
            seal_dp_max_retract: 0.0,
        }
    }

    /// Table 5-9, 25 kg load: Table 5-8 with Fc 120 / 90 N, Fs 200 / 190 N.
    pub fn table_5_9_25kg() -> Self {
        Self::table_5_8().with_levels([120.0, 200.0], [90.0, 190.0])
    }

    /// Table 5-10, 38 kg load: Table 5-8 with Fc 122 / 80 N, Fs 205 / 188 N.
    pub fn table_5_10_38kg() -> Self {
        Self::table_5_8().with_levels([122.0, 205.0], [80.0, 188.0])
    }

    /// The same model with new `[Fc, Fs]` levels \[N\] per direction.
    pub fn with_levels(mut self, extending: [f64; 2], retracting: [f64; 2]) -> Self {
        self.extending.curve = self.extending.curve.with_levels(extending[0], extending[1]);
        self.retracting.curve = self
            .retracting
            .curve
            .with_levels(retracting[0], retracting[1]);
        self
    }

    /// Eq 5.4: the same model without the acceleration term (H = 0).
    pub fn without_acceleration_term(mut self) -> Self {
        self.extending.h_acceleration = 0.0;
        self.retracting.h_acceleration = 0.0;
        self
    }

    /// The same model with the seal term bounded to `dp_max` \[Pa\]
    /// (0 = unbounded; module [`crate::seal`]).
    pub fn with_seal_bound(mut self, dp_max: f64) -> Self {
        self.seal_dp_max = dp_max;
        self
    }

    /// The same model with the seal term bounded per direction \[Pa\]:
    /// `extend` for v > 0, `retract` for v < 0 (0 = [`Wang::seal_dp_max`]).
    pub fn with_seal_bounds(mut self, extend: f64, retract: f64) -> Self {
        self.seal_dp_max_extend = extend;
        self.seal_dp_max_retract = retract;
        self
    }

    /// The pressure difference the seal term sees and its slope
    /// `d(bounded)/d(p1 − p2)` (0 or 1), with the bound of the direction
    /// whose set [`Wang::set_for`] takes.
    fn seal_dp(&self, input: &FrictionInput) -> (f64, f64) {
        let v = input.velocity.si();
        let extending = v > 0.0 || (v == 0.0 && input.acceleration.si() >= 0.0);
        let bound = crate::seal::bound_for(
            extending,
            self.seal_dp_max,
            self.seal_dp_max_extend,
            self.seal_dp_max_retract,
        );
        crate::seal::bounded(input.p1.si() - input.p2.si(), bound)
    }

    /// The set for velocity `v`; at v = 0 the acceleration's sign decides
    /// (extending for a ≥ 0), so a start from rest takes the set of the
    /// direction it is starting in.
    pub fn set_for(&self, v: f64, a: f64) -> &WangSet {
        if v > 0.0 || (v == 0.0 && a >= 0.0) {
            &self.extending
        } else {
            &self.retracting
        }
    }

    /// `(c̄, Δc/2)`: the mean of the two directions' added masses `K H` and
    /// half their difference (extending minus retracting) \[kg\].
    fn added_mass_levels(&self) -> (f64, f64) {
        let ce = self.extending.k_pressure * self.extending.h_acceleration;
        let cr = self.retracting.k_pressure * self.retracting.h_acceleration;
        (0.5 * (ce + cr), 0.5 * (ce - cr))
    }

    /// The kinetic energy of the acceleration term at velocity `v`,
    /// `Φ(v) = ∫₀ᵛ c(u) u du` \[J\], so that `c(v) a v = dΦ/dt` along every
    /// motion (the term stores and returns energy like a mass). With
    /// `c(u) = c̄ + (Δc/2) u/√(u² + a²)` (a = [`ACCELERATION_BLEND_VELOCITY`]):
    /// `Φ = c̄ v²/2 + (Δc/4) (v √(v² + a²) − a² asinh(v/a))`.
    pub fn acceleration_energy(&self, v: f64) -> f64 {
        let (mean, half_jump) = self.added_mass_levels();
        let a = ACCELERATION_BLEND_VELOCITY;
        0.5 * mean * v * v
            + 0.5 * half_jump * (v * (v * v + a * a).sqrt() - a * a * (v / a).asinh())
    }

    /// The static curve, eq 5.8/5.11: `sgn(v) g(v) + K (p1 − p2)² v` \[N\]
    /// (with the pressure difference bounded when [`Wang::seal_dp_max`] > 0).
    pub fn static_curve(&self, input: &FrictionInput) -> f64 {
        let v = input.velocity.si();
        let s = self.set_for(v, 0.0);
        let (pd, _) = self.seal_dp(input);
        sgn(v) * s.curve.g(v) + s.k_pressure * pd * pd * v
    }
}

impl FrictionModel for Wang {
    fn n_states(&self) -> usize {
        1
    }

    fn force(&self, input: &FrictionInput, state: &[f64]) -> Force {
        let v = input.velocity.si();
        let s = self.set_for(v, input.acceleration.si());
        let (pd, _) = self.seal_dp(input);
        let z = state[0];
        let zdot = bristle_rate(self.sigma0, v, z, s.curve.g(v));
        Force::new(self.sigma0 * z + self.sigma1 * zdot + s.k_pressure * pd * pd * v)
    }

    /// `c(v)`: the two directions' `K H` blended across v = 0 over
    /// [`ACCELERATION_BLEND_VELOCITY`] (see [`Wang::acceleration_energy`]).
    fn acceleration_coefficient(&self, input: &FrictionInput) -> Mass {
        let (mean, half_jump) = self.added_mass_levels();
        let v = input.velocity.si();
        let a = ACCELERATION_BLEND_VELOCITY;
        Mass::new(mean + half_jump * v / (v * v + a * a).sqrt())
    }

    /// `d/dv [c̄ + (Δc/2) v/√(v² + a²)] = (Δc/2) a²/(v² + a²)^{3/2}`.
    fn acceleration_coefficient_slope(&self, input: &FrictionInput) -> f64 {
        let (_, half_jump) = self.added_mass_levels();
        let v = input.velocity.si();
        let a = ACCELERATION_BLEND_VELOCITY;
        let r2 = v * v + a * a;
        half_jump * a * a / (r2 * r2.sqrt())
    }

    fn state_derivative(&self, input: &FrictionInput, state: &[f64], dstate: &mut [f64]) {
        let v = input.velocity.si();
        let s = self.set_for(v, input.acceleration.si());
        dstate[0] = bristle_rate(self.sigma0, v, state[0], s.curve.g(v));
    }

    fn steady_state(&self, input: &FrictionInput, state: &mut [f64]) {
        let v = input.velocity.si();
        state[0] = sgn(v) * self.set_for(v, 0.0).curve.g(v) / self.sigma0;
    }

    fn validate(&self) -> Result<(), FrictionError> {
        positive("wang", "sigma0", self.sigma0)?;
        non_negative("wang", "seal_dp_max", self.seal_dp_max)?;
        non_negative("wang", "seal_dp_max_extend", self.seal_dp_max_extend)?;
        non_negative("wang", "seal_dp_max_retract", self.seal_dp_max_retract)?;
        non_negative("wang", "sigma1", self.sigma1)?;
        self.extending.validate("wang (extending)")?;
        self.retracting.validate("wang (retracting)")
    }

    fn jacobian(&self, input: &FrictionInput, state: &[f64]) -> FrictionJacobian {
        let v = input.velocity.si();
        let s = self.set_for(v, input.acceleration.si());
        let (pd, slope) = self.seal_dp(input);
        let (dz, dv) = bristle_partials(self.sigma0, v, state[0], s.curve.g(v), s.curve.v_dg_dv(v));
        FrictionJacobian {
            dzdot_dz: dz,
            dzdot_dv: dv,
            df_dz: self.sigma0 + self.sigma1 * dz,
            df_dv: self.sigma1 * dv + s.k_pressure * pd * pd,
            df_dp1: 2.0 * s.k_pressure * pd * slope * v,
            df_dp2: -2.0 * s.k_pressure * pd * slope * v,
        }
    }

    /// The largest steady deflection, max(Fs)/σ0 \[m\].
    fn state_scales(&self, scales: &mut [f64]) {
        scales[0] = self
            .extending
            .curve
            .stiction
            .si()
            .max(self.retracting.curve.stiction.si())
            / self.sigma0;
    }

    fn stored_energy(&self, state: &[f64]) -> Energy {
        Energy::new(0.5 * self.sigma0 * state[0] * state[0])
    }

    fn dissipated_power(&self, input: &FrictionInput, state: &[f64]) -> Power {
        let mut zdot = [0.0];
        self.state_derivative(input, state, &mut zdot);
        Power::new(
            self.force(input, state).si() * input.velocity.si() - self.sigma0 * state[0] * zdot[0],
        )
    }

    fn n_events(&self) -> usize {
        1
    }

    /// `g = v`: a reversal switches the parameter set (and the acceleration
    /// coefficient K H).
    fn events(&self, input: &FrictionInput, _drive: Force, _state: &[f64], g: &mut [f64]) {
        g[0] = input.velocity.si();
    }

    fn on_event(
        &mut self,
        _which: usize,
        _input: &FrictionInput,
        _drive: Force,
        _state: &mut [f64],
    ) -> FrictionMode {
        FrictionMode::Slip
    }
}
