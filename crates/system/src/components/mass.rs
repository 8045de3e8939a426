//! The moving mass with stroke-end stops (eq 2.27).

use crate::circuit::{
    BuildError, Component, MechanicalNode, Netlist, PowerTerms, Probe, Tangents, Wires,
};
use hydrocyl_actuator::StrokeEnds;
use hydrocyl_integrators::{Crossing, EventAction};
use hydrocyl_ports::{Force, MechanicalPort, Position, Velocity};

/// Mode of the stroke-end stop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum StopMode {
    Free,
    AtMin,
    AtMax,
}

/// The moving mass (piston, rod and load, eq 2.27): owns the rod's position
/// and velocity, `(m + Σc) dv/dt = ΣF − F_ext`, with the hard stroke-end stops
/// of [`StrokeEnds`] as events (see there).
#[derive(Debug)]
pub struct Mass {
    name: String,
    rod_name: String,
    /// Moving mass m \[kg\].
    pub mass: f64,
    /// External force F_ext opposing extension (eq 2.27) \[N\].
    pub external_force: f64,
    /// The stroke ends (`None`: unlimited travel).
    pub stops: Option<StrokeEnds>,
    /// Initial (x, v) \[m, m·s⁻¹\].
    pub initial: (f64, f64),
    mode: StopMode,
    impacts: usize,
    impact_energy: f64,
    rod: MechanicalNode,
}

impl Mass {
    /// A mass owning body `rod`.
    pub fn new(
        name: &str,
        rod: &str,
        mass: f64,
        external_force: f64,
        stops: Option<StrokeEnds>,
        initial: (f64, f64),
    ) -> Self {
        Self {
            name: name.into(),
            rod_name: rod.into(),
            mass,
            external_force,
            stops,
            initial,
            mode: StopMode::Free,
            impacts: 0,
            impact_energy: 0.0,
            rod: MechanicalNode::UNBOUND,
        }
    }

    fn net_force(&self, w: &Wires) -> f64 {
        w.get(self.rod.force).si()
    }
}

impl Component for Mass {
    fn name(&self) -> &str {
        &self.name
    }
    fn reads_time(&self, _t: f64) -> bool {
        false
    }
    fn has_tangents(&self) -> bool {
        true
    }
    fn publish_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, d: &mut Tangents) {
        d.state(self.rod.position, 0, 1.0);
        d.state(self.rod.velocity, 1, 1.0);
    }
    fn derivative_tangents(&self, _t: f64, _x: &[f64], w: &Wires, d: &mut Tangents) {
        // the branch `derivatives` takes: held, free, or resting at a stop
        if w.get(self.rod.hold) > 0.0 {
            d.rate_state(0, 1, 1.0);
        } else if self.mode == StopMode::Free {
            d.rate_state(0, 1, 1.0);
            let m = self.mass + w.get(self.rod.added_mass).si();
            d.rate_chain(1, 1.0 / m, self.rod.force);
            d.rate_chain(1, -self.net_force(w) / (m * m), self.rod.added_mass);
        }
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        if !(self.mass > 0.0 && self.mass.is_finite()) {
            return Err(BuildError::Component {
                component: self.name.clone(),
                message: format!("mass must be positive, got {} kg", self.mass),
            });
        }
        if !self.external_force.is_finite() {
            return Err(BuildError::Component {
                component: self.name.clone(),
                message: format!(
                    "external force must be finite, got {} N",
                    self.external_force
                ),
            });
        }
        if let Some(s) = self.stops {
            if !s.contains(Position::new(self.initial.0)) {
                return Err(BuildError::Component {
                    component: self.name.clone(),
                    message: format!(
                        "initial position {} m is outside the stroke [{}, {}] m",
                        self.initial.0,
                        s.min.si(),
                        s.max.si()
                    ),
                });
            }
        }
        self.rod = net.own_mechanical(&self.rod_name)?;
        Ok(())
    }
    fn n_states(&self) -> usize {
        2
    }
    fn state_names(&self) -> Vec<String> {
        vec![format!("{}.x", self.name), format!("{}.v", self.name)]
    }
    fn state_scales(&self, s: &mut [f64]) {
        s[0] = 0.1;
        s[1] = 0.1;
    }
    fn initial_state(&self, x: &mut [f64]) {
        x[0] = self.initial.0;
        x[1] = self.initial.1;
    }
    fn publish(&self, _t: f64, x: &[f64], w: &mut Wires) {
        w.set(self.rod.position, Position::new(x[0]));
        w.set(self.rod.velocity, Velocity::new(x[1]));
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        w.add(self.rod.force, Force::new(-self.external_force));
    }
    fn derivatives(&self, _t: f64, x: &[f64], w: &Wires, dx: &mut [f64]) {
        if w.get(self.rod.hold) > 0.0 {
            dx[0] = x[1];
            dx[1] = 0.0;
        } else if self.mode == StopMode::Free {
            dx[0] = x[1];
            dx[1] = self.net_force(w) / (self.mass + w.get(self.rod.added_mass).si());
        } else {
            dx[0] = 0.0;
            dx[1] = 0.0;
        }
    }
    fn n_events(&self) -> usize {
        if self.stops.is_some() {
            2
        } else {
            0
        }
    }
    fn events(&self, _t: f64, x: &[f64], w: &Wires, g: &mut [f64]) {
        let Some(s) = self.stops else { return };
        match self.mode {
            StopMode::Free => {
                g[0] = x[0] - s.min.si();
                g[1] = s.max.si() - x[0];
            }
            StopMode::AtMin => {
                g[0] = -self.net_force(w);
                g[1] = 1.0;
            }
            StopMode::AtMax => {
                g[0] = 1.0;
                g[1] = self.net_force(w);
            }
        }
    }
    fn on_event(
        &mut self,
        _t: f64,
        x: &mut [f64],
        w: &Wires,
        which: usize,
        dir: Crossing,
    ) -> EventAction {
        let Some(s) = self.stops else {
            return EventAction::Continue;
        };
        if dir != Crossing::Falling {
            return EventAction::Continue;
        }
        match self.mode {
            StopMode::Free => {
                // plastic impact: clamp to the end and stop; `after_event`
                // decides, with the forces at rest, whether it is held there
                self.impacts += 1;
                let m = self.mass + w.get(self.rod.added_mass).si();
                self.impact_energy += 0.5 * m * x[1] * x[1];
                x[1] = 0.0;
                if which == 0 {
                    x[0] = s.min.si();
                    self.mode = StopMode::AtMin;
                } else {
                    x[0] = s.max.si();
                    self.mode = StopMode::AtMax;
                }
            }
            StopMode::AtMin | StopMode::AtMax => self.mode = StopMode::Free,
        }
        EventAction::Continue
    }
    fn after_event(&mut self, _t: f64, x: &mut [f64], w: &Wires) {
        if w.get(self.rod.hold) > 0.0 {
            x[1] = 0.0;
        }
        // held at a stop while the force at rest pushes into it, released
        // when it pulls away; at an exact tie it stays, and its release
        // function (the force, exactly 0) is armed to leave zero: pulling
        // away releases it then (the event driver's `from_zero`)
        let f = self.net_force(w);
        if (self.mode == StopMode::AtMin && f > 0.0) || (self.mode == StopMode::AtMax && f < 0.0) {
            self.mode = StopMode::Free;
        }
    }
    fn reset(&mut self, _t: f64, x: &[f64], w: &Wires) {
        self.impacts = 0;
        self.impact_energy = 0.0;
        self.mode = StopMode::Free;
        if let Some(s) = self.stops {
            let f = self.net_force(w);
            if x[0] <= s.min.si() && f < 0.0 && x[1] <= 0.0 {
                self.mode = StopMode::AtMin;
            } else if x[0] >= s.max.si() && f > 0.0 && x[1] >= 0.0 {
                self.mode = StopMode::AtMax;
            }
        }
    }
    fn power(&self, _t: f64, x: &[f64], w: &Wires, dx: &[f64], p: &mut PowerTerms) {
        // acceleration-proportional friction terms (c a) act as added mass:
        // their power c a v is stored with the kinetic energy
        p.storage = (self.mass + w.get(self.rod.added_mass).si()) * x[1] * dx[1];
        // the external force opposes extension: the load's port
        let load = MechanicalPort::new(Force::new(self.external_force), Velocity::new(x[1]));
        p.load = load.power().si();
        p.stored = 0.5 * (self.mass + w.get(self.rod.added_mass).si()) * x[1] * x[1];
    }
    /// The stop mode changes only the derivatives: the wires are the state's.
    fn events_change_evaluation(&self) -> bool {
        false
    }
    fn probes(&self) -> Vec<Probe> {
        vec![
            Probe::of("position", self.rod.position),
            Probe::of("velocity", self.rod.velocity),
        ]
    }
    fn diagnostics(&self) -> Vec<(String, f64)> {
        vec![
            ("stop_impacts".into(), self.impacts as f64),
            ("stop_impact_energy_j".into(), self.impact_energy),
        ]
    }
}
