//! The servovalve spool dynamics (eqs 2.2, 2.3/3.1).

use crate::circuit::{BuildError, Causality, Component, Netlist, Probe, Tangents, Wire, Wires};
use hydrocyl_ports::Position;
use hydrocyl_valves::servovalve::{Spool, SpoolDynamics};

/// The servovalve spool: normalised command in, spool position out
/// (first- or second-order dynamics with saturation, eqs 2.2, 2.3/3.1).
#[derive(Debug)]
pub struct ServoSpool {
    name: String,
    input_name: String,
    output_name: String,
    /// Stroke and dynamics.
    pub spool: Spool,
    /// Initial spool position \[m\].
    pub initial_position: f64,
    input: Wire<f64>,
    out: Wire<Position>,
}

impl ServoSpool {
    /// A spool reading signal `input` (normalised command) and writing signal `output` \[m\].
    pub fn new(name: &str, input: &str, output: &str, spool: Spool, initial_position: f64) -> Self {
        Self {
            name: name.into(),
            input_name: input.into(),
            output_name: output.into(),
            spool,
            initial_position,
            input: Wire::UNBOUND,
            out: Wire::UNBOUND,
        }
    }
}

impl Component for ServoSpool {
    fn name(&self) -> &str {
        &self.name
    }
    fn reads_time(&self, _t: f64) -> bool {
        false
    }
    fn has_tangents(&self) -> bool {
        true
    }
    fn publish_tangents(&self, _t: f64, x: &[f64], _w: &Wires, d: &mut Tangents) {
        // the position is clamped to the stroke: flat outside it
        if x[0].abs() <= self.spool.stroke.si() {
            d.state(self.out, 0, 1.0);
        }
    }
    fn derivative_tangents(&self, _t: f64, _x: &[f64], w: &Wires, d: &mut Tangents) {
        let xm = self.spool.stroke.si();
        let u = w.get(self.input);
        // demand = clamp(u x_m, ±x_m)
        let dd = if (u * xm).abs() <= xm { xm } else { 0.0 };
        match self.spool.dynamics {
            SpoolDynamics::First { time_constant_s } => {
                d.rate_chain(0, dd / time_constant_s, self.input);
                d.rate_state(0, 0, -1.0 / time_constant_s);
            }
            SpoolDynamics::Second {
                natural_frequency_rad_per_s: wn,
                damping_ratio: z,
            } => {
                d.rate_state(0, 1, 1.0);
                d.rate_chain(1, wn * wn * dd, self.input);
                d.rate_state(1, 0, -wn * wn);
                d.rate_state(1, 1, -2.0 * z * wn);
            }
        }
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.spool.validate().map_err(|e| BuildError::Component {
            component: self.name.clone(),
            message: e.to_string(),
        })?;
        self.input = net.signal(&self.input_name);
        self.out = net.own_signal(&self.output_name, Causality::Stored)?;
        Ok(())
    }
    fn n_states(&self) -> usize {
        self.spool.dynamics.n_states()
    }
    fn state_names(&self) -> Vec<String> {
        let mut v = vec![format!("{}.x", self.name)];
        if self.n_states() > 1 {
            v.push(format!("{}.v", self.name));
        }
        v
    }
    fn state_scales(&self, s: &mut [f64]) {
        s[0] = self.spool.stroke.si();
        if s.len() > 1 {
            s[1] = self.spool.stroke.si() * 100.0;
        }
    }
    fn initial_state(&self, x: &mut [f64]) {
        self.spool.dynamics.rest_state(self.initial_position, x);
    }
    fn publish(&self, _t: f64, x: &[f64], w: &mut Wires) {
        w.set(self.out, Position::new(self.spool.position(x)));
    }
    fn derivatives(&self, _t: f64, x: &[f64], w: &Wires, dx: &mut [f64]) {
        let d = self.spool.demand(w.get(self.input));
        self.spool.dynamics.derivatives(d, x, dx);
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe::of("spool", self.out)]
    }
}
