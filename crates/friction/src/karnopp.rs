//! Karnopp's stick–slip model (thesis section 2.4.2.1, ref [67]) with the
//! stick band as a **mode** and the transitions as located events.
//!
//! * Slip: `F = s g(v) + σ2 v`, s the direction of the slip mode (set by
//!   [`FrictionModel::initialise_mode`] and by each event, so the force is
//!   smooth inside the mode and the integrator never sees the sign flip), g
//!   the Stribeck curve (eq 2.36; Fs = Fc gives the classical model).
//! * Stick: the velocity is held at zero and the friction force equals the
//!   drive (all other forces on the mass) as long as |drive| ≤ Fs.
//!
//! Karnopp's original formulation declares "stuck" while |v| < Δv, a band
//! that exists because a fixed-step simulator cannot land on v = 0. With event
//! location the band shrinks to the exact zero crossing: the integrator finds
//! the time v crosses zero and the model decides there between sticking
//! (|drive| ≤ Fs) and reversing.
//!
//! Switching functions (positive while the mode holds, the event is the
//! falling crossing):
//!
//! | mode | g0 | g1 |
//! |---|---|---|
//! | Slip in direction s | `s v` (motion stops or reverses) | 1 |
//! | Stick | 1 | `Fs − |drive|` (break-away) |
//!
//! Assembler contract: while [`FrictionModel::mode`] is
//! [`FrictionMode::Stick`], set dv/dt = 0 and use `drive` as the friction
//! force; after every event of this model set v = 0 (the event is located at
//! v = 0, or v is already held there). Call
//! [`FrictionModel::initialise_mode`] at t0.

use hydrocyl_ports::Force;
use serde::{Deserialize, Serialize};

use crate::curve::StribeckCurve;
use crate::error::{non_negative, FrictionError};
use crate::model::{FrictionInput, FrictionJacobian, FrictionMode, FrictionModel};
use crate::stribeck::sgn;

/// Karnopp friction with stick as a mode.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Karnopp {
    /// Slip curve g(v) (Fs is also the break-away level).
    pub curve: StribeckCurve,
    /// Viscous coefficient σ2 \[N·s·m⁻¹\], ≥ 0.
    pub sigma2: f64,
    /// Current mode (run-time state, not serialised).
    #[serde(skip)]
    mode: FrictionMode,
    /// Direction of slip while v = 0 (+1, −1, or 0 = take sgn(v)).
    #[serde(skip)]
    direction: f64,
}

impl Karnopp {
    /// A validated Karnopp model, starting in slip.
    pub fn new(curve: StribeckCurve, sigma2: f64) -> Result<Self, FrictionError> {
        let m = Self {
            curve,
            sigma2,
            mode: FrictionMode::Slip,
            direction: 0.0,
        };
        m.validate()?;
        Ok(m)
    }

    /// The slip direction: the mode's (so the force stays smooth inside a
    /// step that overshoots v = 0 before the event is located), or sgn(v)
    /// before [`FrictionModel::initialise_mode`] set one.
    fn dir(&self, v: f64) -> f64 {
        if self.direction != 0.0 {
            self.direction
        } else {
            sgn(v)
        }
    }
}

impl FrictionModel for Karnopp {
    /// The slip force `s g(v) + σ2 v`. In Stick the force is the drive, which
    /// the model does not see; this returns zero then (v = 0, so no power).
    fn force(&self, input: &FrictionInput, _state: &[f64]) -> Force {
        if self.mode == FrictionMode::Stick {
            return Force::ZERO;
        }
        let v = input.velocity.si();
        Force::new(self.dir(v) * self.curve.g(v) + self.sigma2 * v)
    }

    fn steady_force(&self, input: &FrictionInput) -> Force {
        let v = input.velocity.si();
        Force::new(sgn(v) * self.curve.g(v) + self.sigma2 * v)
    }

    fn validate(&self) -> Result<(), FrictionError> {
        self.curve.validate("karnopp")?;
        non_negative("karnopp", "sigma2", self.sigma2)
    }

    fn jacobian(&self, input: &FrictionInput, _state: &[f64]) -> FrictionJacobian {
        let v = input.velocity.si();
        let g_term = if v != 0.0 && self.mode == FrictionMode::Slip {
            self.curve.v_dg_dv(v) / v.abs()
        } else {
            0.0
        };
        FrictionJacobian {
            df_dv: g_term + self.sigma2,
            ..FrictionJacobian::default()
        }
    }

    fn n_events(&self) -> usize {
        2
    }

    fn events(&self, input: &FrictionInput, drive: Force, _state: &[f64], g: &mut [f64]) {
        match self.mode {
            FrictionMode::Slip => {
                let v = input.velocity.si();
                // Direction 0: `initialise_mode` was not called; any sign
                // change of v is then the event.
                g[0] = if self.direction != 0.0 {
                    self.direction * v
                } else {
                    v
                };
                g[1] = 1.0;
            }
            FrictionMode::Stick => {
                g[0] = 1.0;
                g[1] = self.curve.stiction.si() - drive.si().abs();
            }
        }
    }

    fn on_event(
        &mut self,
        which: usize,
        _input: &FrictionInput,
        drive: Force,
        _state: &mut [f64],
    ) -> FrictionMode {
        let fs = self.curve.stiction.si();
        match (self.mode, which) {
            (FrictionMode::Slip, 0) => {
                if drive.si().abs() <= fs {
                    self.mode = FrictionMode::Stick;
                } else {
                    self.direction = sgn(drive.si());
                }
            }
            (FrictionMode::Stick, 1) => {
                self.mode = FrictionMode::Slip;
                self.direction = sgn(drive.si());
            }
            _ => {}
        }
        self.mode
    }

    fn initialise_mode(&mut self, input: &FrictionInput, drive: Force) -> FrictionMode {
        let v = input.velocity.si();
        if v == 0.0 && drive.si().abs() <= self.curve.stiction.si() {
            self.mode = FrictionMode::Stick;
            self.direction = 0.0;
        } else {
            self.mode = FrictionMode::Slip;
            self.direction = if v != 0.0 { sgn(v) } else { sgn(drive.si()) };
        }
        self.mode
    }

    fn mode(&self) -> FrictionMode {
        self.mode
    }

    fn can_stick(&self) -> bool {
        true
    }
}
