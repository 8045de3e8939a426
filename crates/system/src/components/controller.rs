//! A position controller: P or PI on the piston position, its output (the
//! valve command) clipped to limits.

use crate::circuit::{BuildError, Causality, Component, Netlist, Probe, Tangents, Wire, Wires};
use crate::wires::MechanicalNode;

/// The controller's law: `u = clip(Kp (e + I/Ti) + u0, lo, hi)` with the error
/// `e = reference − position` and, for a PI controller (`Ti > 0`), the
/// integral `I = ∫ e dt`. The integral is held while the output is clipped
/// and the error would drive it further out (conditional integration,
/// against wind-up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionLaw {
    /// Proportional gain Kp \[1/m\].
    pub gain: f64,
    /// Integral time Ti \[s\]; 0 = a P controller (no state).
    pub integral_time: f64,
    /// Output offset u0 added before the limits \[-\].
    pub bias: f64,
    /// Lower output limit \[-\].
    pub output_min: f64,
    /// Upper output limit \[-\].
    pub output_max: f64,
}

impl PositionLaw {
    /// The unclipped output for error `e` and integral `i`.
    fn raw(&self, e: f64, i: f64) -> f64 {
        let integral = if self.integral_time > 0.0 {
            i / self.integral_time
        } else {
            0.0
        };
        self.gain * (e + integral) + self.bias
    }

    /// The command for error `e` \[m\] and integral `i` \[m·s\].
    pub fn output(&self, e: f64, i: f64) -> f64 {
        self.raw(e, i).clamp(self.output_min, self.output_max)
    }

    /// `dI/dt`: the error, or 0 while the output is clipped and `e` pushes
    /// it further out.
    pub fn integral_rate(&self, e: f64, i: f64) -> f64 {
        let u = self.raw(e, i);
        let pushes_out = (u >= self.output_max && e * self.gain > 0.0)
            || (u <= self.output_min && e * self.gain < 0.0);
        if pushes_out {
            0.0
        } else {
            e
        }
    }
}

/// A position controller reading the reference signal \[m\] and the position
/// of a mechanical node, writing the command signal (algebraically).
#[derive(Debug)]
pub struct PositionController {
    name: String,
    reference_name: String,
    rod_name: String,
    output_name: String,
    /// The law.
    pub law: PositionLaw,
    /// Initial integral of the error \[m·s\] (PI only).
    integral0: f64,
    reference: Wire<f64>,
    rod: MechanicalNode,
    out: Wire<f64>,
}

impl PositionController {
    /// A controller named `name` reading signal `reference` and the position
    /// of mechanical node `rod`, writing signal `output`.
    pub fn new(name: &str, reference: &str, rod: &str, output: &str, law: PositionLaw) -> Self {
        Self {
            name: name.into(),
            reference_name: reference.into(),
            rod_name: rod.into(),
            output_name: output.into(),
            law,
            integral0: 0.0,
            reference: Wire::UNBOUND,
            rod: MechanicalNode::UNBOUND,
            out: Wire::UNBOUND,
        }
    }

    /// Starts the integral of the error at `i` \[m·s\] (a PI controller's
    /// state carried over from an earlier run; ignored by a P controller).
    pub fn with_integral(mut self, i: f64) -> Self {
        self.integral0 = i;
        self
    }

    fn has_integral(&self) -> bool {
        self.law.integral_time > 0.0
    }

    fn error(&self, w: &Wires) -> f64 {
        w.get(self.reference) - w.get(self.rod.position).si()
    }
}

impl Component for PositionController {
    fn name(&self) -> &str {
        &self.name
    }
    fn reads_time(&self, _t: f64) -> bool {
        false
    }
    fn has_tangents(&self) -> bool {
        true
    }
    fn evaluate_tangents(&self, _t: f64, x: &[f64], w: &Wires, d: &mut Tangents) {
        let i = x.first().copied().unwrap_or(0.0);
        let raw = self.law.raw(self.error(w), i);
        // flat where the output is clipped
        if raw <= self.law.output_min || raw >= self.law.output_max {
            return;
        }
        let k = self.law.gain;
        d.chain(self.out, k, self.reference);
        d.chain(self.out, -k, self.rod.position);
        if self.has_integral() {
            d.state(self.out, 0, k / self.law.integral_time);
        }
    }
    fn derivative_tangents(&self, _t: f64, x: &[f64], w: &Wires, d: &mut Tangents) {
        let e = self.error(w);
        // the anti-windup branch `integral_rate` takes
        if self.law.integral_rate(e, x[0]) == e {
            d.rate_chain(0, 1.0, self.reference);
            d.rate_chain(0, -1.0, self.rod.position);
        }
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        let l = self.law;
        if !(l.gain.is_finite()
            && l.integral_time.is_finite()
            && l.integral_time >= 0.0
            && l.output_min < l.output_max)
        {
            return Err(BuildError::Component {
                component: self.name.clone(),
                message: "needs a finite gain, integral_time ≥ 0 and output_min < output_max"
                    .into(),
            });
        }
        self.reference = net.signal(&self.reference_name);
        self.rod = net.mechanical(&self.rod_name);
        self.out = net.own_signal(&self.output_name, Causality::Algebraic)?;
        Ok(())
    }
    fn n_states(&self) -> usize {
        usize::from(self.has_integral())
    }
    fn state_names(&self) -> Vec<String> {
        (0..self.n_states())
            .map(|_| format!("{}.integral", self.name))
            .collect()
    }
    fn state_scales(&self, s: &mut [f64]) {
        // an integral of 1 mm over the integral time
        for v in s {
            *v = 1e-3 * self.law.integral_time.max(1e-3);
        }
    }
    fn initial_state(&self, x: &mut [f64]) {
        if let Some(v) = x.first_mut() {
            *v = self.integral0;
        }
    }
    fn evaluate(&self, _t: f64, x: &[f64], w: &mut Wires) {
        let i = x.first().copied().unwrap_or(0.0);
        let u = self.law.output(self.error(w), i);
        w.set(self.out, u);
    }
    fn derivatives(&self, _t: f64, x: &[f64], w: &Wires, dx: &mut [f64]) {
        if let (Some(d), Some(&i)) = (dx.first_mut(), x.first()) {
            *d = self.law.integral_rate(self.error(w), i);
        }
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe::of("command", self.out)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_law_clips_and_holds_the_integral_when_saturated() {
        let l = PositionLaw {
            gain: 10.0,
            integral_time: 0.5,
            bias: 0.0,
            output_min: -1.0,
            output_max: 1.0,
        };
        assert_eq!(l.output(0.01, 0.0), 0.1);
        assert!((l.output(0.01, 0.005) - 0.2).abs() < 1e-15);
        assert_eq!(l.output(0.5, 0.0), 1.0);
        assert_eq!(l.output(-0.5, 0.0), -1.0);
        assert_eq!(l.integral_rate(0.5, 0.0), 0.0);
        assert_eq!(l.integral_rate(-0.5, 0.0), 0.0);
        assert_eq!(l.integral_rate(0.01, 0.0), 0.01);
        // saturated high but the error now pulls back: integrate
        assert_eq!(l.integral_rate(-0.01, 1.0), -0.01);
        let p = PositionLaw {
            integral_time: 0.0,
            ..l
        };
        assert_eq!(p.output(0.01, 123.0), 0.1);
        let b = PositionLaw { bias: -0.05, ..p };
        assert!((b.output(0.01, 0.0) - 0.05).abs() < 1e-15);
    }
}
