//! A friction law acting on a rod.

use crate::circuit::{
    BuildError, Component, MechanicalNode, Netlist, PowerTerms, Probe, Tangents, Wire, Wires,
};
use hydrocyl_friction::{FrictionInput, FrictionMode, FrictionModel};
use hydrocyl_integrators::{Crossing, EventAction};
use hydrocyl_ports::{Force, Pressure};

/// A friction law acting on a rod, through the friction crate's
/// [`FrictionModel`] (any model: internal states, pressure and acceleration
/// terms, stick modes with events). The acceleration-proportional term goes
/// to the mass side as added mass; in a stick mode the component asks the
/// mass to hold the rod ([`MechanicalNode::hold`]) and the friction force is
/// the drive force (everything else acting on the rod).
pub struct Friction {
    name: String,
    rod_name: String,
    chambers: Option<(String, String)>,
    /// The friction law.
    pub model: Box<dyn FrictionModel>,
    mode: FrictionMode,
    /// The initial value of every internal state (a bristle's deflection z).
    initial: f64,
    rod: MechanicalNode,
    p1: Option<Wire<Pressure>>,
    p2: Option<Wire<Pressure>>,
    /// The friction force (the probe): the law's in slip, the drive in stick.
    force: Wire<Force>,
    /// What this component added to the rod's force accumulator, negated:
    /// the law's force in slip, 0 in stick.
    added: Wire<Force>,
}

impl std::fmt::Debug for Friction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Friction")
            .field("name", &self.name)
            .field("mode", &self.mode)
            .finish()
    }
}

impl Friction {
    /// Friction on body `rod`; `chambers` names the nodes whose pressures the
    /// law reads as p1, p2 (pressure-dependent laws).
    pub fn new(
        name: &str,
        rod: &str,
        chambers: Option<(&str, &str)>,
        model: Box<dyn FrictionModel>,
    ) -> Self {
        Self {
            name: name.into(),
            rod_name: rod.into(),
            chambers: chambers.map(|(a, b)| (a.to_string(), b.to_string())),
            model,
            mode: FrictionMode::Slip,
            initial: 0.0,
            rod: MechanicalNode::UNBOUND,
            p1: None,
            p2: None,
            force: Wire::UNBOUND,
            added: Wire::UNBOUND,
        }
    }

    /// Starts the law's internal state (a bristle's deflection z \[m\])
    /// at `z` instead of 0.
    pub fn with_initial_state(mut self, z: f64) -> Self {
        self.initial = z;
        self
    }

    fn input(&self, w: &Wires) -> FrictionInput {
        FrictionInput {
            velocity: w.get(self.rod.velocity),
            acceleration: hydrocyl_ports::Acceleration::ZERO,
            p1: self.p1.map_or(Pressure::ZERO, |p| w.get(p)),
            p2: self.p2.map_or(Pressure::ZERO, |p| w.get(p)),
        }
    }

    /// The drive force (all forces on the rod but this friction) \[N\]; valid
    /// once every component has been evaluated.
    fn drive(&self, w: &Wires) -> Force {
        // the accumulator holds −F (slip) or nothing (stick) from this component
        w.get(self.rod.force) + w.get(self.added)
    }
}

impl Component for Friction {
    fn name(&self) -> &str {
        &self.name
    }
    fn reads_time(&self, _t: f64) -> bool {
        false
    }
    fn has_tangents(&self) -> bool {
        // the friction Jacobian has one internal state at most
        self.model.n_states() <= 1
    }
    fn evaluate_tangents(&self, _t: f64, x: &[f64], w: &Wires, d: &mut Tangents) {
        if self.mode == FrictionMode::Stick {
            return; // the mass holds: the force is the drive's, dv/dt = 0
        }
        let input = self.input(w);
        let j = self.model.jacobian(&input, x);
        d.chain(self.force, j.df_dv, self.rod.velocity);
        if let (Some(p1), Some(p2)) = (self.p1, self.p2) {
            d.chain(self.force, j.df_dp1, p1);
            d.chain(self.force, j.df_dp2, p2);
        }
        if !x.is_empty() {
            d.state(self.force, 0, j.df_dz);
        }
        d.chain(self.rod.force, -1.0, self.force);
        d.chain(
            self.rod.added_mass,
            self.model.acceleration_coefficient_slope(&input),
            self.rod.velocity,
        );
    }
    fn derivative_tangents(&self, _t: f64, x: &[f64], w: &Wires, d: &mut Tangents) {
        let j = self.model.jacobian(&self.input(w), x);
        d.rate_state(0, 0, j.dzdot_dz);
        d.rate_chain(0, j.dzdot_dv, self.rod.velocity);
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.model.validate().map_err(|e| BuildError::Component {
            component: self.name.clone(),
            message: e.to_string(),
        })?;
        self.rod = net.mechanical(&self.rod_name);
        if let Some((a, b)) = self.chambers.clone() {
            self.p1 = Some(net.hydraulic(&a).pressure);
            self.p2 = Some(net.hydraulic(&b).pressure);
        }
        self.force = net.private("force");
        self.added = net.private("added");
        Ok(())
    }
    fn n_states(&self) -> usize {
        self.model.n_states()
    }
    fn state_names(&self) -> Vec<String> {
        (0..self.n_states())
            .map(|i| format!("{}.z{i}", self.name))
            .collect()
    }
    fn state_scales(&self, s: &mut [f64]) {
        s.fill(1.0e-4);
    }
    fn initial_state(&self, x: &mut [f64]) {
        x.fill(self.initial);
    }
    fn evaluate(&self, _t: f64, x: &[f64], w: &mut Wires) {
        let input = self.input(w);
        if self.mode == FrictionMode::Stick {
            w.add(self.rod.hold, 1.0);
            w.set(self.added, Force::ZERO);
            // the drive, once every force on the rod is in (`settle`)
            w.set(self.force, Force::ZERO);
        } else {
            let f = self.model.force(&input, x);
            w.add(self.rod.force, -f);
            w.set(self.added, f);
            w.set(self.force, f);
            w.add(
                self.rod.added_mass,
                self.model.acceleration_coefficient(&input),
            );
        }
    }
    fn derivatives(&self, _t: f64, x: &[f64], w: &Wires, dx: &mut [f64]) {
        self.model.state_derivative(&self.input(w), x, dx);
    }
    /// A law that can stick (Karnopp's) reports, while stuck, the force
    /// that holds the rod: everything else acting on it.
    fn settles(&self) -> bool {
        self.model.can_stick()
    }
    fn settle(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        if self.mode == FrictionMode::Stick {
            w.set(self.force, self.drive(w));
        }
    }
    fn n_events(&self) -> usize {
        self.model.n_events()
    }
    fn events(&self, _t: f64, x: &[f64], w: &Wires, g: &mut [f64]) {
        self.model.events(&self.input(w), self.drive(w), x, g);
    }
    fn on_event(
        &mut self,
        _t: f64,
        x: &mut [f64],
        w: &Wires,
        which: usize,
        dir: Crossing,
    ) -> EventAction {
        if dir == Crossing::Falling {
            let (input, drive) = (self.input(w), self.drive(w));
            self.mode = self.model.on_event(which, &input, drive, x);
        }
        EventAction::Continue
    }
    fn reset(&mut self, _t: f64, _x: &[f64], w: &Wires) {
        self.mode = FrictionMode::Slip;
        let (input, drive) = (self.input(w), self.drive(w));
        self.mode = self.model.initialise_mode(&input, drive);
    }
    fn power(&self, _t: f64, x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        let input = self.input(w);
        if self.mode == FrictionMode::Stick {
            return; // v = 0: no power
        }
        let f = self.model.force(&input, x).si();
        let diss = self.model.dissipated_power(&input, x).si();
        p.dissipated = diss;
        p.storage = f * input.velocity.si() - diss;
        p.stored = self.model.stored_energy(x).si();
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe::of(format!("{}_force", self.name), self.force)]
    }
}
