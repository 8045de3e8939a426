//! [`FrictionLaw`]: every model behind one serialisable enum, so a rig file
//! picks its friction model by name.

use hydrocyl_ports::{Energy, Force, Mass, Power};
use serde::{Deserialize, Serialize};

use crate::error::FrictionError;
use crate::model::{FrictionInput, FrictionJacobian, FrictionMode, FrictionModel};
use crate::{CoulombViscous, Dahl, Karnopp, LuGre, Stribeck, Wang};

/// Any of the friction models, tagged by `"model"` in JSON:
///
/// ```
/// use hydrocyl_friction::{FrictionLaw, FrictionModel};
///
/// let json = r#"{"model": "dahl", "coulomb": 110.0, "sigma0": 3e7, "sigma2": 0.0}"#;
/// let law: FrictionLaw = serde_json::from_str(json).unwrap();
/// law.validate().unwrap();
/// assert_eq!(law.name(), "dahl");
/// assert_eq!(law.n_states(), 1);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model")]
pub enum FrictionLaw {
    /// [`CoulombViscous`], `"coulomb-viscous"`.
    #[serde(rename = "coulomb-viscous")]
    CoulombViscous(CoulombViscous),
    /// [`Stribeck`], `"stribeck"`.
    #[serde(rename = "stribeck")]
    Stribeck(Stribeck),
    /// [`Karnopp`], `"karnopp"`.
    #[serde(rename = "karnopp")]
    Karnopp(Karnopp),
    /// [`Dahl`], `"dahl"`.
    #[serde(rename = "dahl")]
    Dahl(Dahl),
    /// [`LuGre`], `"lugre"`.
    #[serde(rename = "lugre")]
    LuGre(LuGre),
    /// [`Wang`], `"wang"`.
    #[serde(rename = "wang")]
    Wang(Wang),
}

impl FrictionLaw {
    /// The model's tag in rig files.
    pub fn name(&self) -> &'static str {
        match self {
            Self::CoulombViscous(_) => "coulomb-viscous",
            Self::Stribeck(_) => "stribeck",
            Self::Karnopp(_) => "karnopp",
            Self::Dahl(_) => "dahl",
            Self::LuGre(_) => "lugre",
            Self::Wang(_) => "wang",
        }
    }
}

macro_rules! each {
    ($self:expr, $m:ident => $e:expr) => {
        match $self {
            FrictionLaw::CoulombViscous($m) => $e,
            FrictionLaw::Stribeck($m) => $e,
            FrictionLaw::Karnopp($m) => $e,
            FrictionLaw::Dahl($m) => $e,
            FrictionLaw::LuGre($m) => $e,
            FrictionLaw::Wang($m) => $e,
        }
    };
}

impl FrictionModel for FrictionLaw {
    fn n_states(&self) -> usize {
        each!(self, m => m.n_states())
    }
    fn force(&self, input: &FrictionInput, state: &[f64]) -> Force {
        each!(self, m => m.force(input, state))
    }
    fn acceleration_coefficient(&self, input: &FrictionInput) -> Mass {
        each!(self, m => m.acceleration_coefficient(input))
    }
    fn state_derivative(&self, input: &FrictionInput, state: &[f64], dstate: &mut [f64]) {
        each!(self, m => m.state_derivative(input, state, dstate))
    }
    fn steady_state(&self, input: &FrictionInput, state: &mut [f64]) {
        each!(self, m => m.steady_state(input, state))
    }
    fn steady_force(&self, input: &FrictionInput) -> Force {
        each!(self, m => m.steady_force(input))
    }
    fn validate(&self) -> Result<(), FrictionError> {
        each!(self, m => m.validate())
    }
    fn state_scales(&self, scales: &mut [f64]) {
        each!(self, m => m.state_scales(scales))
    }
    fn jacobian(&self, input: &FrictionInput, state: &[f64]) -> FrictionJacobian {
        each!(self, m => m.jacobian(input, state))
    }
    fn acceleration_coefficient_slope(&self, input: &FrictionInput) -> f64 {
        each!(self, m => m.acceleration_coefficient_slope(input))
    }
    fn stored_energy(&self, state: &[f64]) -> Energy {
        each!(self, m => m.stored_energy(state))
    }
    fn dissipated_power(&self, input: &FrictionInput, state: &[f64]) -> Power {
        each!(self, m => m.dissipated_power(input, state))
    }
    fn n_events(&self) -> usize {
        each!(self, m => m.n_events())
    }
    fn events(&self, input: &FrictionInput, drive: Force, state: &[f64], g: &mut [f64]) {
        each!(self, m => m.events(input, drive, state, g))
    }
    fn on_event(
        &mut self,
        which: usize,
        input: &FrictionInput,
        drive: Force,
        state: &mut [f64],
    ) -> FrictionMode {
        each!(self, m => m.on_event(which, input, drive, state))
    }
    fn initialise_mode(&mut self, input: &FrictionInput, drive: Force) -> FrictionMode {
        each!(self, m => m.initialise_mode(input, drive))
    }
    fn mode(&self) -> FrictionMode {
        each!(self, m => m.mode())
    }
    fn can_stick(&self) -> bool {
        each!(self, m => m.can_stick())
    }
}
