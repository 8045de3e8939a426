//! The interface every friction law implements.

use hydrocyl_ports::{Acceleration, Energy, Force, Mass, Power, Pressure, Velocity};

use crate::error::FrictionError;

/// The signals a friction model may read.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrictionInput {
    /// Piston velocity, + extending \[m·s⁻¹\].
    pub velocity: Velocity,
    /// Piston acceleration \[m·s⁻²\].
    pub acceleration: Acceleration,
    /// Cap-side chamber pressure p1 \[Pa\].
    pub p1: Pressure,
    /// Rod-side chamber pressure p2 \[Pa\].
    pub p2: Pressure,
}

impl FrictionInput {
    /// Input at velocity `v` with zero acceleration and zero pressures.
    pub fn at_velocity(v: Velocity) -> Self {
        Self {
            velocity: v,
            ..Self::default()
        }
    }
}

/// The contact mode of a model with stick as a mode (Karnopp). Models without
/// modes are always [`FrictionMode::Slip`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FrictionMode {
    /// Sliding: the friction force is [`FrictionModel::force`].
    #[default]
    Slip,
    /// Stuck: the assembler holds the velocity at zero (`dv/dt = 0`) and the
    /// friction force equals the drive force (everything else acting on the
    /// mass), which stays inside the stiction band until an event ends it.
    Stick,
}

/// Partial derivatives of a friction model at one point, for the stiff
/// integrator's Jacobian. `z` is the model's single internal state (absent
/// for static laws: its entries are then zero). The assembler adds
/// `−df_d* / m` to the velocity row and `dzdot_d*` to the z row.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrictionJacobian {
    /// ∂(dz/dt)/∂z \[s⁻¹\].
    pub dzdot_dz: f64,
    /// ∂(dz/dt)/∂v \[–\].
    pub dzdot_dv: f64,
    /// ∂F/∂z \[N·m⁻¹\].
    pub df_dz: f64,
    /// ∂F/∂v \[N·s·m⁻¹\].
    pub df_dv: f64,
    /// ∂F/∂p1 \[m²\].
    pub df_dp1: f64,
    /// ∂F/∂p2 \[m²\].
    pub df_dp2: f64,
}

/// A friction law. The force is the friction force on the piston, positive
/// when it opposes extension (so the load balance is
/// `m a = p1 A1 − p2 A2 − F_friction − F_ext`, thesis eq 2.27).
///
/// Terms linear in acceleration (the thesis's `K H a`, eq 5.12) are **not**
/// in [`FrictionModel::force`]; they are reported by
/// [`FrictionModel::acceleration_coefficient`] so that the assembler can move
/// them to the mass side of the balance and solve it explicitly:
/// `(m + c) a = p1 A1 − p2 A2 − force(..) − F_ext`.
///
/// `state` slices passed to every method have exactly
/// [`n_states`](FrictionModel::n_states) entries (the assembler's slice of its
/// state vector); the hot-path methods do not re-check it.
///
/// # How an assembler uses a model
///
/// * **States**: it reserves [`n_states`](FrictionModel::n_states) entries of
///   its state vector, fills them with
///   [`steady_state`](FrictionModel::steady_state) (or zeros) at t0, and
///   writes [`state_derivative`](FrictionModel::state_derivative) into its
///   right-hand side. The bristle deflection z is of order Fs/σ0 ≈ 6 µm: give
///   it an absolute tolerance near 1e-10 m
///   ([`state_scales`](FrictionModel::state_scales) gives the scale).
/// * **Stiffness**: its analytic Jacobian takes
///   [`jacobian`](FrictionModel::jacobian) (analytic for every model here;
///   the default is finite differences).
/// * **Events**: it appends [`n_events`](FrictionModel::n_events) switching
///   functions from [`events`](FrictionModel::events) to its own, and on a
///   located event forwards it to [`on_event`](FrictionModel::on_event). Every
///   switching function here is positive while the current mode holds and the
///   event is its falling crossing. `drive` is the net force on the mass
///   except friction, `p1 A1 − p2 A2 − F_ext` \[N\].
/// * **Modes**: while [`mode`](FrictionModel::mode) is
///   [`FrictionMode::Stick`] it sets `dv/dt = 0` and uses `drive` as the
///   friction force; when `on_event` returns `Stick` it sets v = 0.
/// * **Energy**: [`stored_energy`](FrictionModel::stored_energy) and
///   [`dissipated_power`](FrictionModel::dissipated_power) satisfy
///   `F v = dissipated + d(stored)/dt` along every solution.
pub trait FrictionModel {
    /// Number of internal states (0 for static laws, 1 for LuGre/Dahl's z).
    fn n_states(&self) -> usize {
        0
    }

    /// Friction force without the acceleration-proportional term \[N\].
    fn force(&self, input: &FrictionInput, state: &[f64]) -> Force;

    /// Coefficient `c` of a friction term `c a` \[kg\] (zero by default).
    fn acceleration_coefficient(&self, _input: &FrictionInput) -> Mass {
        Mass::ZERO
    }

    /// `∂c/∂v` of [`acceleration_coefficient`](FrictionModel::acceleration_coefficient)
    /// \[kg·s·m⁻¹\], for the analytic Jacobian: zero (the default) for a
    /// constant coefficient; a model whose coefficient moves with the
    /// velocity overrides it.
    fn acceleration_coefficient_slope(&self, _input: &FrictionInput) -> f64 {
        0.0
    }

    /// Time derivative of the internal states.
    fn state_derivative(&self, _input: &FrictionInput, _state: &[f64], _dstate: &mut [f64]) {}

    /// The internal state that is steady at this input (for initial conditions).
    fn steady_state(&self, _input: &FrictionInput, _state: &mut [f64]) {}

    /// Steady-state force at constant velocity (the static friction curve).
    fn steady_force(&self, input: &FrictionInput) -> Force {
        let mut z = vec![0.0; self.n_states()];
        self.steady_state(input, &mut z);
        self.force(input, &z)
    }

    /// Typical magnitude of each internal state, for the integrator's absolute
    /// tolerances (the bristle deflection is of order Fs/σ0 ≈ 6e-6 m for the
    /// thesis's parameters). The default fills 1.
    fn state_scales(&self, scales: &mut [f64]) {
        scales.fill(1.0);
    }

    /// Checks the parameters (finite, in range); call after deserialising.
    fn validate(&self) -> Result<(), FrictionError> {
        Ok(())
    }

    /// Partial derivatives at this point (see [`FrictionJacobian`]). The
    /// default takes central finite differences of
    /// [`force`](FrictionModel::force) and
    /// [`state_derivative`](FrictionModel::state_derivative).
    fn jacobian(&self, input: &FrictionInput, state: &[f64]) -> FrictionJacobian {
        finite_difference_jacobian(self, input, state)
    }

    /// Energy stored in the model's internal state \[J\] (zero by default).
    fn stored_energy(&self, _state: &[f64]) -> Energy {
        Energy::ZERO
    }

    /// Power dissipated \[W\]: `F v − d(stored)/dt`. The default, right for
    /// static laws, is `F v`.
    fn dissipated_power(&self, input: &FrictionInput, state: &[f64]) -> Power {
        self.force(input, state) * input.velocity
    }

    /// Number of switching functions (0 by default).
    fn n_events(&self) -> usize {
        0
    }

    /// Switching functions `g` (length [`n_events`](FrictionModel::n_events)),
    /// positive while the current mode holds; `drive` is the net non-friction
    /// force on the mass \[N\].
    fn events(&self, _input: &FrictionInput, _drive: Force, _state: &[f64], _g: &mut [f64]) {}

    /// Handles the located falling crossing of switching function `which` and
    /// returns the new mode. The model may edit its own states.
    fn on_event(
        &mut self,
        _which: usize,
        _input: &FrictionInput,
        _drive: Force,
        _state: &mut [f64],
    ) -> FrictionMode {
        FrictionMode::Slip
    }

    /// Sets the mode at the start of a simulation (e.g. Karnopp sticks when at
    /// rest with the drive inside the stiction band) and returns it;
    /// [`FrictionMode::Slip`] by default.
    fn initialise_mode(&mut self, _input: &FrictionInput, _drive: Force) -> FrictionMode {
        FrictionMode::Slip
    }

    /// The current contact mode ([`FrictionMode::Slip`] by default).
    fn mode(&self) -> FrictionMode {
        FrictionMode::Slip
    }

    /// Whether the model can enter [`FrictionMode::Stick`] (a stick–slip
    /// model with a held mode, e.g. Karnopp's); `false` by default.
    fn can_stick(&self) -> bool {
        false
    }
}

/// Central finite-difference [`FrictionJacobian`] of any model with at most
/// one state (the default of [`FrictionModel::jacobian`]; the tests compare
/// the analytic Jacobians with it).
pub fn finite_difference_jacobian<M: FrictionModel + ?Sized>(
    model: &M,
    input: &FrictionInput,
    state: &[f64],
) -> FrictionJacobian {
    let mut j = FrictionJacobian::default();
    let f = |inp: &FrictionInput, s: &[f64]| model.force(inp, s).si();
    let zdot = |inp: &FrictionInput, s: &[f64]| {
        if s.is_empty() {
            0.0
        } else {
            let mut d = [0.0; 1];
            model.state_derivative(inp, s, &mut d);
            d[0]
        }
    };
    let v = input.velocity.si();
    let hv = 1e-6 * v.abs().max(1e-6);
    let mut up = *input;
    let mut dn = *input;
    up.velocity = Velocity::new(v + hv);
    dn.velocity = Velocity::new(v - hv);
    j.df_dv = (f(&up, state) - f(&dn, state)) / (2.0 * hv);
    j.dzdot_dv = (zdot(&up, state) - zdot(&dn, state)) / (2.0 * hv);
    for (which, p) in [(1, input.p1.si()), (2, input.p2.si())] {
        let hp = 1e-6 * p.abs().max(1.0);
        let (mut up, mut dn) = (*input, *input);
        if which == 1 {
            up.p1 = Pressure::new(p + hp);
            dn.p1 = Pressure::new(p - hp);
        } else {
            up.p2 = Pressure::new(p + hp);
            dn.p2 = Pressure::new(p - hp);
        }
        let d = (f(&up, state) - f(&dn, state)) / (2.0 * hp);
        if which == 1 {
            j.df_dp1 = d;
        } else {
            j.df_dp2 = d;
        }
    }
    if let Some(&z) = state.first() {
        // z is a bristle deflection of order F/σ0 (micrometres); a step
        // relative to |z| alone would be ~1e-15 m at z = 0, where rounding in
        // a force of kN (the seal term) swamps the difference.
        let hz = 1e-6 * z.abs().max(1e-7);
        let (zu, zd) = ([z + hz], [z - hz]);
        j.df_dz = (f(input, &zu) - f(input, &zd)) / (2.0 * hz);
        j.dzdot_dz = (zdot(input, &zu) - zdot(input, &zd)) / (2.0 * hz);
    }
    j
}
