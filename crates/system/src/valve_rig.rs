//! The valve-controlled rig (`kind = "valve-cylinder"`), preset
//! `leaney-moog`: a servovalve driving an asymmetric cylinder and a mass on a
//! slideway (thesis chapter 3; rigs.md). Every parameter is a field of
//! [`ValveRig`], which is also the JSON rig file (`fixtures/rigs/leaney-moog.json`).

use crate::circuit::Circuit;
use crate::rig::{gauge_pressure_problem, GaugePressure, RigError};
use crate::run::{Run, RunOptions};
use crate::signal::Signal;
use hydrocyl_actuator::Cylinder;
use hydrocyl_friction::{
    CoulombViscous, FrictionInput, FrictionLaw, FrictionModel, SealTerms, WithSealTerms,
};
use hydrocyl_ports::{Area, Density, Force, Position, Pressure, Velocity};
use hydrocyl_valves::orifice::Orifice;
use hydrocyl_valves::servovalve::{Metering, Spool, SpoolDynamics};
use serde::{Deserialize, Serialize};

/// The JSON `kind` of this rig.
pub const KIND: &str = "valve-cylinder";

/// Fluid properties.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidSpec {
    /// Density ρ \[kg·m⁻³\].
    pub density_kg_per_m3: f64,
    /// Effective bulk modulus B \[Pa\].
    pub bulk_modulus_pa: f64,
}

/// Supply and tank: a constant source pressure, optionally drooping with
/// the flow drawn (catalog `supply_droop`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupplySpec {
    /// Supply (source) pressure Ps0 \[Pa\].
    pub pressure_pa: f64,
    /// Tank (return) pressure \[Pa\].
    pub tank_pressure_pa: f64,
    /// Supply droop resistance Rs \[Pa·s·m⁻³\]: the valve's supply port sees
    /// `Ps = Ps0 − Rs Q_s`, `Q_s` the flow it draws (solved exactly at every
    /// instant, see `Metering::drooped_supply`). 0 (the default, and the value
    /// when the field is absent) = a stiff supply. Needs the `fundamental`
    /// formulation.
    #[serde(default)]
    pub droop_resistance_pa_s_per_m3: f64,
}

/// The measurement chain (catalog `sensor_lag`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSpec {
    /// First-order lag τ of the p1/p2 pressure transducers \[s\]; 0 (the
    /// default, and the value when the section is absent) = ideal sensors.
    /// With τ > 0 the output columns `p1`, `p2` are the sensor readings
    /// (what the rig logs) and `p1_chamber`, `p2_chamber` the chamber
    /// pressures themselves.
    #[serde(default)]
    pub pressure_lag_s: f64,
}

/// The servovalve.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ValveSpec {
    /// Spool stroke x_max: saturation, and the demand `x_ref = u · x_max` \[m\].
    pub stroke_m: f64,
    /// Equivalent underlap u0 \[m\] (eq 3.2).
    pub underlap_m: f64,
    /// Spool diameter D; area gradient `w = π D` \[m\].
    pub spool_diameter_m: f64,
    /// Discharge coefficient Cd \[-\].
    pub discharge_coefficient: f64,
    /// Transition pressure of the regularised orifice root \[Pa\].
    pub regularisation_pa: f64,
    /// Spool null bias x_b added to the spool position \[m\] (catalog `valve_null_bias`).
    pub null_bias_m: f64,
    /// Scale on the area gradient \[-\] (catalog `flow_gain_error`, 1 = nominal).
    pub flow_gain: f64,
    /// Spool dead band x_d \[m\]: the metering sees `sign(x_s) max(0, |x_s| − x_d)`
    /// (catalog `valve_dead_band`; absent = 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub dead_band_m: f64,
    /// Spool dynamics: `{"order": "first", "time_constant_s": τ}` or
    /// `{"order": "second", "natural_frequency_rad_per_s": ω, "damping_ratio": ζ}`.
    pub dynamics: SpoolDynamics,
}

/// Which actuator formulation to assemble.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Formulation {
    /// Two chamber pressures (eqs 2.8, 2.9, 2.10–2.15).
    Fundamental,
    /// One load pressure, X by a bracketing root finder (eq 3.4).
    GeneralisedNumerical,
    /// One load pressure, X from the exact quartic root.
    GeneralisedAnalytical,
}

impl Formulation {
    /// All three, in the order of the thesis's Table 3-5 columns.
    pub const ALL: [Formulation; 3] = [
        Formulation::GeneralisedNumerical,
        Formulation::GeneralisedAnalytical,
        Formulation::Fundamental,
    ];
    /// The JSON name.
    pub fn name(self) -> &'static str {
        match self {
            Formulation::Fundamental => "fundamental",
            Formulation::GeneralisedNumerical => "generalised-numerical",
            Formulation::GeneralisedAnalytical => "generalised-analytical",
        }
    }
}

/// The cylinder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CylinderSpec {
    /// Cap-side area A1 \[m²\].
    pub area_1_m2: f64,
    /// Rod-side area A2 \[m²\].
    pub area_2_m2: f64,
    /// Stroke \[m\]; the piston moves in ±stroke/2 (hard stops).
    pub stroke_m: f64,
    /// `V1 = A1 (l1 + x)` \[m\] (vt.m: 0.31).
    pub chamber_length_1_m: f64,
    /// `V2 = A2 (l2 − x)` \[m\].
    pub chamber_length_2_m: f64,
    /// Internal leakage coefficient Cl \[m³·s⁻¹·Pa⁻¹\].
    pub internal_leakage_m3_per_s_pa: f64,
    /// External leakage coefficient of chamber 1 \[m³·s⁻¹·Pa⁻¹\].
    pub external_leakage_1_m3_per_s_pa: f64,
    /// External leakage coefficient of chamber 2 \[m³·s⁻¹·Pa⁻¹\].
    pub external_leakage_2_m3_per_s_pa: f64,
    /// Chamber pressure below which cavitation is reported \[Pa\].
    pub cavitation_pressure_pa: f64,
    /// `fundamental`, `generalised-numerical` or `generalised-analytical`.
    pub formulation: Formulation,
    /// Absolute tolerance of the numerical X root \[-\].
    pub x_tolerance: f64,
}

/// The moving load.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// Moving mass m \[kg\].
    pub mass_kg: f64,
    /// External force opposing extension \[N\].
    pub external_force_n: f64,
}

/// The initial state (SI: m, m/s, Pa, m). `p1`/`p2` `null`: the steady
/// pressures of the rig at rest for the initial spool position (X factor,
/// section 3.3.4).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// Piston position from mid-stroke \[m\].
    pub position: f64,
    /// Piston velocity \[m·s⁻¹\].
    pub velocity: f64,
    /// Spool position \[m\].
    pub spool: f64,
    /// Chamber 1 pressure \[Pa\] or `null` (steady state).
    pub p1: Option<f64>,
    /// Chamber 2 pressure \[Pa\] or `null` (steady state).
    pub p2: Option<f64>,
}

/// A valve-controlled asymmetric-cylinder rig: the JSON rig file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ValveRig {
    /// Always `valve-cylinder`.
    pub kind: String,
    /// Rig name.
    pub name: String,
    /// Free text: source of the parameters.
    pub description: String,
    /// Fluid.
    pub fluid: FluidSpec,
    /// Supply and tank.
    pub supply: SupplySpec,
    /// Servovalve.
    pub valve: ValveSpec,
    /// Cylinder.
    pub cylinder: CylinderSpec,
    /// Load.
    pub load: LoadSpec,
    /// Friction: any law of the friction crate, tagged by `model`
    /// (`coulomb-viscous`, `stribeck`, `karnopp`, `dahl`, `lugre`, `wang`).
    pub friction: FrictionLaw,
    /// The seal terms `K (p1 − p2)² v` (eq 5.4) and `K H a` (eq 5.12) added
    /// to the friction law (absent = off; catalog `pressure_viscous`,
    /// `acceleration_friction`).
    #[serde(default, skip_serializing_if = "SealTerms::is_off")]
    pub friction_terms: SealTerms,
    /// Initial state.
    pub initial: InitialSpec,
    /// Sensors (absent = ideal).
    #[serde(default)]
    pub sensors: SensorSpec,
    /// A position controller closing the loop (absent = open loop: the
    /// run's input is the valve command; present: it is the position
    /// reference \[m\] and the controller computes the command).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller: Option<ControllerSpec>,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// The position controller of a closed-loop rig (netlist component
/// `position_controller`): `u = clip(Kp (e + ∫e dt / Ti) + u0, lo, hi)`,
/// `e = reference − position`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerSpec {
    /// Proportional gain Kp \[1/m\].
    pub gain_per_m: f64,
    /// Integral time Ti \[s\]; 0 = a P controller.
    #[serde(default)]
    pub integral_time_s: f64,
    /// Output offset u0 added before the limits \[-\].
    #[serde(default)]
    pub bias: f64,
    /// Lower output limit \[-\].
    pub output_min: f64,
    /// Upper output limit \[-\].
    pub output_max: f64,
}

impl ControllerSpec {
    /// The `leaney-moog-closed-loop` preset's: P, Kp = 10 /m, limits ±1.
    pub const P10: ControllerSpec = ControllerSpec {
        gain_per_m: 10.0,
        integral_time_s: 0.0,
        bias: 0.0,
        output_min: -1.0,
        output_max: 1.0,
    };
}

fn check(path: &str, value: f64, ok: bool, why: &str) -> Result<(), RigError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(RigError::OutOfRange {
            path: path.to_string(),
            value,
            why: why.to_string(),
        })
    }
}

impl ValveRig {
    /// The `leaney-moog` preset: exactly the values of rigs.md.
    pub fn leaney_moog() -> Self {
        Self {
            kind: KIND.into(),
            name: "leaney-moog".into(),
            description: "Moog 76-102 servovalve and 88533-002 asymmetric cylinder (Wang 2019, ch. 3, Tables 3-1/3-2, Appendix II); mass and friction assumed (rigs.md)".into(),
            fluid: FluidSpec {
                density_kg_per_m3: 870.0,
                bulk_modulus_pa: 7.0e8,
            },
            supply: SupplySpec {
                pressure_pa: 7.0e6,
                tank_pressure_pa: 0.0,
                droop_resistance_pa_s_per_m3: 0.0,
            },
            valve: ValveSpec {
                stroke_m: 0.375e-3,
                underlap_m: 0.0045e-3,
                spool_diameter_m: 7.938e-3,
                discharge_coefficient: 0.625,
                regularisation_pa: hydrocyl_valves::orifice::DEFAULT_DP_TRANSITION.si(),
                null_bias_m: 0.0,
                flow_gain: 1.0,
                dead_band_m: 0.0,
                dynamics: SpoolDynamics::First { time_constant_s: 0.004 },
            },
            cylinder: CylinderSpec {
                area_1_m2: 11.43e-4,
                area_2_m2: 5.8e-4,
                stroke_m: 0.52,
                chamber_length_1_m: 0.31,
                chamber_length_2_m: 0.31,
                internal_leakage_m3_per_s_pa: 0.0,
                external_leakage_1_m3_per_s_pa: 0.0,
                external_leakage_2_m3_per_s_pa: 0.0,
                cavitation_pressure_pa: 0.0,
                formulation: Formulation::Fundamental,
                x_tolerance: 1e-12,
            },
            load: LoadSpec {
                mass_kg: 100.0,
                external_force_n: 0.0,
            },
            friction: FrictionLaw::CoulombViscous(CoulombViscous::leaney_moog()),
            friction_terms: SealTerms::default(),
            initial: InitialSpec {
                position: 0.0,
                velocity: 0.0,
                spool: 0.0,
                p1: None,
                p2: None,
            },
            sensors: SensorSpec::default(),
            controller: None,
        }
    }

    /// Checks every parameter; the error names its JSON path.
    pub fn validate(&self) -> Result<(), RigError> {
        if self.kind != KIND {
            return Err(RigError::Invalid {
                path: "kind".into(),
                why: format!("expected `{KIND}`, got `{}`", self.kind),
            });
        }
        let pos = |p: &str, v: f64| check(p, v, v > 0.0, "must be positive");
        let nonneg = |p: &str, v: f64| check(p, v, v >= 0.0, "must be non-negative");
        let fin = |p: &str, v: f64| check(p, v, true, "must be finite");
        pos("fluid.density_kg_per_m3", self.fluid.density_kg_per_m3)?;
        pos("fluid.bulk_modulus_pa", self.fluid.bulk_modulus_pa)?;
        let (tank, cavitation) = (
            self.supply.tank_pressure_pa,
            self.cylinder.cavitation_pressure_pa,
        );
        if let Some((which, why)) = gauge_pressure_problem(tank, cavitation) {
            let (path, value) = match which {
                GaugePressure::Tank => ("supply.tank_pressure_pa", tank),
                GaugePressure::Vapour => ("cylinder.cavitation_pressure_pa", cavitation),
            };
            return Err(RigError::OutOfRange {
                path: path.into(),
                value,
                why,
            });
        }
        check(
            "supply.pressure_pa",
            self.supply.pressure_pa,
            self.supply.pressure_pa > 0.0 && self.supply.pressure_pa > self.supply.tank_pressure_pa,
            "must be positive and above the tank pressure",
        )?;
        nonneg(
            "supply.droop_resistance_pa_s_per_m3",
            self.supply.droop_resistance_pa_s_per_m3,
        )?;
        if self.supply.droop_resistance_pa_s_per_m3 > 0.0
            && self.cylinder.formulation != Formulation::Fundamental
        {
            return Err(RigError::Invalid {
                path: "supply.droop_resistance_pa_s_per_m3".into(),
                why: format!(
                    "supply droop needs the `fundamental` formulation (cylinder.formulation is `{}`)",
                    self.cylinder.formulation.name()
                ),
            });
        }
        nonneg("sensors.pressure_lag_s", self.sensors.pressure_lag_s)?;
        let v = &self.valve;
        pos("valve.stroke_m", v.stroke_m)?;
        nonneg("valve.underlap_m", v.underlap_m)?;
        pos("valve.spool_diameter_m", v.spool_diameter_m)?;
        check(
            "valve.discharge_coefficient",
            v.discharge_coefficient,
            v.discharge_coefficient > 0.0 && v.discharge_coefficient <= 1.0,
            "must be in (0, 1]",
        )?;
        pos("valve.regularisation_pa", v.regularisation_pa)?;
        fin("valve.null_bias_m", v.null_bias_m)?;
        pos("valve.flow_gain", v.flow_gain)?;
        nonneg("valve.dead_band_m", v.dead_band_m)?;
        if let Some(c) = &self.controller {
            fin("controller.gain_per_m", c.gain_per_m)?;
            nonneg("controller.integral_time_s", c.integral_time_s)?;
            fin("controller.bias", c.bias)?;
            fin("controller.output_min", c.output_min)?;
            fin("controller.output_max", c.output_max)?;
            if c.output_min >= c.output_max {
                return Err(RigError::Invalid {
                    path: "controller.output_min".into(),
                    why: "must be below controller.output_max".into(),
                });
            }
        }
        match v.dynamics {
            SpoolDynamics::First { time_constant_s } => {
                pos("valve.dynamics.time_constant_s", time_constant_s)?
            }
            SpoolDynamics::Second {
                natural_frequency_rad_per_s,
                damping_ratio,
            } => {
                pos(
                    "valve.dynamics.natural_frequency_rad_per_s",
                    natural_frequency_rad_per_s,
                )?;
                pos("valve.dynamics.damping_ratio", damping_ratio)?;
            }
        }
        let c = &self.cylinder;
        pos("cylinder.area_1_m2", c.area_1_m2)?;
        check(
            "cylinder.area_2_m2",
            c.area_2_m2,
            c.area_2_m2 > 0.0 && c.area_2_m2 <= c.area_1_m2,
            "must be positive and not above area_1_m2",
        )?;
        pos("cylinder.stroke_m", c.stroke_m)?;
        check(
            "cylinder.chamber_length_1_m",
            c.chamber_length_1_m,
            c.chamber_length_1_m > 0.5 * c.stroke_m,
            "must exceed half the stroke (chamber 1 keeps a volume at the retracted end)",
        )?;
        check(
            "cylinder.chamber_length_2_m",
            c.chamber_length_2_m,
            c.chamber_length_2_m > 0.5 * c.stroke_m,
            "must exceed half the stroke (chamber 2 keeps a volume at the extended end)",
        )?;
        nonneg(
            "cylinder.internal_leakage_m3_per_s_pa",
            c.internal_leakage_m3_per_s_pa,
        )?;
        nonneg(
            "cylinder.external_leakage_1_m3_per_s_pa",
            c.external_leakage_1_m3_per_s_pa,
        )?;
        nonneg(
            "cylinder.external_leakage_2_m3_per_s_pa",
            c.external_leakage_2_m3_per_s_pa,
        )?;
        check(
            "cylinder.x_tolerance",
            c.x_tolerance,
            c.x_tolerance > 0.0 && c.x_tolerance < 1e-3,
            "must be in (0, 1e-3)",
        )?;
        pos("load.mass_kg", self.load.mass_kg)?;
        fin("load.external_force_n", self.load.external_force_n)?;
        self.friction.validate().map_err(|e| RigError::Invalid {
            path: "friction".into(),
            why: e.to_string(),
        })?;
        self.friction_terms
            .validate()
            .map_err(|e| RigError::Invalid {
                path: "friction_terms".into(),
                why: e.to_string(),
            })?;
        let i = &self.initial;
        check(
            "initial.position",
            i.position,
            i.position.abs() <= 0.5 * c.stroke_m,
            "must be within the stroke (±stroke/2)",
        )?;
        fin("initial.velocity", i.velocity)?;
        check(
            "initial.spool",
            i.spool,
            i.spool.abs() <= v.stroke_m,
            "must be within the spool stroke",
        )?;
        if let Some(p) = i.p1 {
            fin("initial.p1", p)?;
        }
        if let Some(p) = i.p2 {
            fin("initial.p2", p)?;
        }
        Ok(())
    }

    /// The friction model.
    pub fn friction_model(&self) -> Box<dyn FrictionModel> {
        if self.friction_terms.is_off() {
            Box::new(self.friction)
        } else {
            Box::new(WithSealTerms {
                inner: self.friction,
                terms: self.friction_terms,
            })
        }
    }

    /// The cylinder model.
    pub fn cylinder_model(&self) -> Cylinder {
        let c = &self.cylinder;
        Cylinder {
            area_1: Area::new(c.area_1_m2),
            area_2: Area::new(c.area_2_m2),
            stroke: Position::new(c.stroke_m),
            chamber_length_1: Position::new(c.chamber_length_1_m),
            chamber_length_2: Position::new(c.chamber_length_2_m),
            bulk_modulus: Pressure::new(self.fluid.bulk_modulus_pa),
            internal_leakage: c.internal_leakage_m3_per_s_pa,
            external_leakage_1: c.external_leakage_1_m3_per_s_pa,
            external_leakage_2: c.external_leakage_2_m3_per_s_pa,
        }
    }

    /// The metering model.
    pub fn metering(&self) -> Metering {
        let v = &self.valve;
        Metering {
            underlap: Position::new(v.underlap_m),
            spool_diameter: Position::new(v.spool_diameter_m),
            orifice: Orifice {
                cd: v.discharge_coefficient,
                density: Density::new(self.fluid.density_kg_per_m3),
                dp_transition: Pressure::new(v.regularisation_pa),
            },
            null_bias: Position::new(v.null_bias_m),
            flow_gain: v.flow_gain,
        }
    }

    /// The spool model.
    pub fn spool(&self) -> Spool {
        Spool {
            stroke: Position::new(self.valve.stroke_m),
            dynamics: self.valve.dynamics,
        }
    }

    /// Normalised travel `(x_s + x_b)/u0` of spool position `xs` \[-\]
    /// (after the dead band).
    fn travel(&self, xs: f64) -> f64 {
        let u0 = self.valve.underlap_m;
        let xs = xs.signum() * (xs.abs() - self.valve.dead_band_m).max(0.0);
        let x = xs + self.valve.null_bias_m;
        if u0 > 0.0 {
            x / u0
        } else if x >= 0.0 {
            1.0
        } else {
            -1.0
        }
    }

    /// The initial chamber pressures `(p1, p2)` \[Pa\]: those given, else the
    /// steady pressures at rest for the initial spool position (section
    /// 3.3.4: X factor at the spool's travel, `P_LE = (F_ext + F_friction(v0))/A_E`).
    pub fn initial_pressures(&self) -> Result<(f64, f64), RigError> {
        if let (Some(a), Some(b)) = (self.initial.p1, self.initial.p2) {
            return Ok((a, b));
        }
        let fric = self
            .friction_model()
            .steady_force(&FrictionInput::at_velocity(Velocity::new(
                self.initial.velocity,
            )))
            .si();
        let (s1, s2) = steady_pressures_at_rest(&SteadyDrive {
            metering: self.metering(),
            cylinder: self.cylinder_model(),
            supply: self.supply.pressure_pa,
            tank: self.supply.tank_pressure_pa,
            droop_resistance: self.supply.droop_resistance_pa_s_per_m3,
            spool: self.initial.spool,
            load: self.load.external_force_n + fric,
        })
        .map_err(|why| RigError::Invalid {
            path: "initial.p1".into(),
            why,
        })?;
        Ok((self.initial.p1.unwrap_or(s1), self.initial.p2.unwrap_or(s2)))
    }

    /// Assembles the rig's circuit driven by `command` (normalised spool
    /// demand): the netlist of its formulation ([`ValveRig::to_netlist`])
    /// through the netlist assembler — the topology is in the netlist files.
    pub fn circuit(&self, command: Signal) -> Result<Circuit, RigError> {
        crate::netlist::circuit(&self.to_netlist()?, command)
    }

    /// Simulates the rig on `command`, output at `t_eval`. With lagged
    /// pressure sensors, `p1`/`p2` are what the sensors read and
    /// `p1_chamber`/`p2_chamber` the chamber pressures.
    pub fn simulate(
        &self,
        command: Signal,
        t_eval: &[f64],
        opts: &RunOptions,
    ) -> Result<Run, RigError> {
        crate::simulation::Simulation::of_circuit(self.circuit(command)?)
            .options(opts.clone())
            .run(t_eval)
    }

    /// Steady piston velocity at spool position `xs` \[m·s⁻¹\]: the exact
    /// two-chamber steady state (`Q1 = A1 v`, `Q2 = A2 v`, force balance with
    /// the friction at `v` and the external force), solved by fixed-point
    /// iteration on the load force.
    /// Not available with supply droop on (an error says so).
    pub fn steady_velocity(&self, xs: f64) -> Result<f64, RigError> {
        if self.supply.droop_resistance_pa_s_per_m3 > 0.0 {
            return Err(RigError::Invalid {
                path: "supply.droop_resistance_pa_s_per_m3".into(),
                why:
                    "the steady-velocity helpers assume a stiff supply; set the droop to 0 for them"
                        .into(),
            });
        }
        let cyl = self.cylinder_model();
        let m = self.metering();
        let ps = self.supply.pressure_pa - self.supply.tank_pressure_pa;
        let fric = self.friction_model();
        let travel = self.travel(xs);
        let c = m.orifice.coefficient() * m.area_gradient() * self.valve.underlap_m.max(1e-12);
        let (a, b) = ((1.0 + travel).max(0.0), (1.0 - travel).max(0.0));
        let mut v = 0.0;
        for _ in 0..200 {
            let f = self.load.external_force_n
                + fric
                    .steady_force(&FrictionInput::at_velocity(Velocity::new(v)))
                    .si();
            let s = hydrocyl_xfactor::steady_pressures_two_chamber(
                travel,
                Pressure::new(ps),
                cyl.gamma(),
                cyl.area_1,
                Force::new(f),
            )
            .map_err(|e| RigError::Invalid {
                path: "load".into(),
                why: format!("no steady state at spool {xs} m: {e}"),
            })?;
            let p1 = s.p1.si();
            let q1 = c * (a * (ps - p1).max(0.0).sqrt() - b * p1.max(0.0).sqrt());
            let vn = q1 / cyl.area_1.si();
            // damped update: the friction slope near v = 0 is steep
            let next = 0.5 * (v + vn);
            if (next - v).abs() < 1e-12 {
                return Ok(next);
            }
            v = next;
        }
        Ok(v)
    }

    /// Spool position \[m\] whose steady velocity is `v` (bisection over the
    /// spool stroke on [`ValveRig::steady_velocity`], monotone in `xs`).
    pub fn spool_for_velocity(&self, v: f64) -> Result<f64, RigError> {
        let xm = self.valve.stroke_m;
        let (mut lo, mut hi) = (-xm, xm);
        let (vlo, vhi) = (self.steady_velocity(lo)?, self.steady_velocity(hi)?);
        if !(vlo <= v && v <= vhi) {
            return Err(RigError::Invalid {
                path: "command".into(),
                why: format!(
                    "velocity {v} m/s is outside the valve's range [{vlo:.4}, {vhi:.4}] m/s"
                ),
            });
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if self.steady_velocity(mid)? < v {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Ok(0.5 * (lo + hi))
    }

    /// The open-loop bias of section 3.1.3: the normalised square-wave
    /// `(bias, amplitude)` whose two levels give steady velocities `+v` and
    /// `−v` on this asymmetric cylinder (a symmetric command would retract
    /// faster than it extends).
    pub fn open_loop_square(&self, v: f64) -> Result<(f64, f64), RigError> {
        let xm = self.valve.stroke_m;
        let ue = self.spool_for_velocity(v.abs())? / xm;
        let ur = self.spool_for_velocity(-v.abs())? / xm;
        Ok((0.5 * (ue + ur), 0.5 * (ue - ur)))
    }
}

/// A valve-controlled drive at rest, as [`steady_pressures_at_rest`] needs it.
#[derive(Clone, Copy, Debug)]
pub struct SteadyDrive {
    /// The four-way metering.
    pub metering: Metering,
    /// The cylinder.
    pub cylinder: Cylinder,
    /// Supply (source) pressure Ps0 \[Pa\].
    pub supply: f64,
    /// Tank pressure \[Pa\].
    pub tank: f64,
    /// Supply droop resistance Rs \[Pa·s·m⁻³\] (0 = stiff supply).
    pub droop_resistance: f64,
    /// Spool position \[m\].
    pub spool: f64,
    /// Force opposing extension: external load plus friction at the initial
    /// velocity \[N\].
    pub load: f64,
}

/// The steady chamber pressures `(p1, p2)` \[Pa\] of a valve-controlled drive
/// at rest for a spool position (section 3.3.4: the X factor at the spool's
/// travel, `P_LE = load / A_E`); with supply droop, the supply the valve sees
/// is solved by bisection. `Err` says why there is no steady state.
pub fn steady_pressures_at_rest(d: &SteadyDrive) -> Result<(f64, f64), String> {
    let pt = d.tank;
    let ps_source = d.supply - pt;
    let m = d.metering;
    let u0 = m.underlap.si();
    let x = d.spool + m.null_bias.si();
    let travel = if u0 > 0.0 {
        x / u0
    } else if x >= 0.0 {
        1.0
    } else {
        -1.0
    };
    let load = Force::new(d.load);
    let steady = |ps: f64| {
        hydrocyl_xfactor::steady_pressures(
            travel,
            Pressure::new(ps),
            d.cylinder.gamma(),
            d.cylinder.area_1,
            load,
        )
        .map(|s| (s.p1.si() + pt, s.p2.si() + pt))
        .map_err(|e| format!("no steady state to start from ({e}); give initial.p1 and initial.p2"))
    };
    let rs = d.droop_resistance;
    if rs <= 0.0 {
        return steady(ps_source);
    }
    // With droop the valve sees Ps0 − Rs Q_s, and Q_s (the underlap's flow
    // at rest) depends on the steady pressures: bisection on the supply
    // above tank, h(ps) = ps + Rs Q_s(ps) − (Ps0 − pt), which rises with ps
    // (h < 0 near 0 where nothing flows, h ≥ 0 at Ps0).
    let xs = Position::new(d.spool);
    let h = |ps: f64| -> Result<f64, String> {
        let (a, b) = steady(ps)?;
        let q = m
            .flows(
                xs,
                Pressure::new(ps + pt),
                Pressure::new(pt),
                Pressure::new(a),
                Pressure::new(b),
            )
            .qp
            .si();
        Ok(ps + rs * q - ps_source)
    };
    let (mut lo, mut hi) = (1e-9 * ps_source, ps_source);
    if h(hi)? > 0.0 {
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if h(mid)? < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
    }
    steady(hi)
}
