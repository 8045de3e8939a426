//! Fixed-pressure sources (supply, tank) and command signal sources.

use crate::circuit::{
    BuildError, Causality, Component, HydraulicNode, Netlist, PowerTerms, Probe, Wire, Wires,
};
use crate::signal::Signal;
use hydrocyl_ports::{HydraulicPort, Pressure};
use std::cell::{Cell, OnceCell};

/// A node held at a fixed pressure: a supply (pressure-compensated pump with
/// accumulator) or the tank. It delivers whatever flow the circuit draws.
#[derive(Debug)]
pub struct PressureSource {
    name: String,
    node_name: String,
    /// The fixed pressure \[Pa\].
    pub pressure: Pressure,
    probe: Option<String>,
    node: HydraulicNode,
}

impl PressureSource {
    /// A source named `name` holding node `node` at `pressure`; `probe`
    /// names its pressure as an output column (e.g. `ps`).
    pub fn new(name: &str, node: &str, pressure: Pressure, probe: Option<&str>) -> Self {
        Self {
            name: name.into(),
            node_name: node.into(),
            pressure,
            probe: probe.map(str::to_string),
            node: HydraulicNode::UNBOUND,
        }
    }
}

impl Component for PressureSource {
    fn name(&self) -> &str {
        &self.name
    }
    fn reads_time(&self, _t: f64) -> bool {
        false
    }
    fn has_tangents(&self) -> bool {
        true
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.node = net.own_hydraulic(&self.node_name, Causality::Stored)?;
        Ok(())
    }
    fn publish(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        w.set(self.node.pressure, self.pressure);
    }
    fn power(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        // the flow drawn from the node is delivered at its pressure: the
        // source's port is the node with the flow reversed
        let port = HydraulicPort::new(self.pressure, -w.get(self.node.inflow));
        p.source = port.power().si();
    }
    fn probes(&self) -> Vec<Probe> {
        self.probe
            .iter()
            .map(|n| Probe::of(n.clone(), self.node.pressure))
            .collect()
    }
}

/// A command signal source (writes signal `output` from a [`Signal`] of time).
#[derive(Debug)]
pub struct CommandInput {
    name: String,
    output_name: String,
    /// The signal.
    pub signal: Signal,
    hint: Cell<usize>,
    /// The signal's kinks ([`kinks`]), found on first use.
    kinks: OnceCell<Vec<f64>>,
    /// A streamed table's scan: the index to resume from and the corner
    /// found last (`-∞` when none is pending).
    stream_scan: Cell<(usize, f64)>,
    out: Wire<f64>,
}

/// A corner of a table counts as a kink when the change of slope at it, times
/// the shorter of its two intervals, is at least this share of the table's
/// range: a square or step edge given as samples (the change is the whole
/// edge), not the corners of a sampled smooth or noisy signal (a 1 kHz sine
/// changes by ~1e-5 of its range, measurement noise by its own share).
pub const KINK_SHARE: f64 = 0.1;

/// The times where `signal` is continuous but its slope jumps by a lot (see
/// [`KINK_SHARE`]): the ends of a ramp, the corners of a table that edge a
/// step or a ramp of the command. A solver ends its steps there
/// ([`hydrocyl_integrators::OdeSystem::next_breakpoint`]). Jumps of the value
/// itself (a step, a square, a sawtooth's drop) are not kinks.
pub fn kinks(signal: &Signal) -> Vec<f64> {
    match signal {
        Signal::Ramp { t0_s, t1_s, .. } => vec![*t0_s, *t1_s],
        Signal::Table { time_s, value } if time_s.len() >= 3 => {
            // the values are finite (checked when the table was made): plain
            // comparisons give the range `f64::min`/`max` would
            let (lo, hi) = value
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                    (if v < l { v } else { l }, if v > h { v } else { h })
                });
            let range = hi - lo;
            if range <= 0.0 {
                return Vec::new();
            }
            (1..time_s.len() - 1)
                .filter(|&i| {
                    // three equal samples: both slopes 0, no kink (the
                    // divisions below would say so, at ten times the cost)
                    if value[i - 1] == value[i] && value[i] == value[i + 1] {
                        return false;
                    }
                    let (d0, d1) = (time_s[i] - time_s[i - 1], time_s[i + 1] - time_s[i]);
                    let s0 = (value[i] - value[i - 1]) / d0;
                    let s1 = (value[i + 1] - value[i]) / d1;
                    (s1 - s0).abs() * d0.min(d1) >= KINK_SHARE * range
                })
                .map(|i| time_s[i])
                .collect()
        }
        _ => Vec::new(),
    }
}

impl CommandInput {
    /// A source named `name` writing signal `output`.
    pub fn new(name: &str, output: &str, signal: Signal) -> Self {
        Self {
            name: name.into(),
            output_name: output.into(),
            signal,
            hint: Cell::new(0),
            kinks: OnceCell::new(),
            stream_scan: Cell::new((0, f64::NEG_INFINITY)),
            out: Wire::UNBOUND,
        }
    }
}

impl Component for CommandInput {
    fn name(&self) -> &str {
        &self.name
    }
    fn has_tangents(&self) -> bool {
        true
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.out = net.own_signal(&self.output_name, Causality::Stored)?;
        Ok(())
    }
    fn publish(&self, t: f64, _x: &[f64], w: &mut Wires) {
        w.set(self.out, self.signal.value_hinted(t, &self.hint));
    }
    fn reads_time(&self, _t: f64) -> bool {
        // piecewise constant: no slope between the jumps
        !matches!(
            self.signal,
            Signal::Constant { .. } | Signal::Step { .. } | Signal::Square { .. }
        )
    }
    fn next_breakpoint(&self, t: f64) -> f64 {
        if let Signal::Streamed(table) = &self.signal {
            // the window holds the samples ahead: scan only what is new
            let (from, found) = self.stream_scan.get();
            if found > t {
                return found;
            }
            let (k, next) = table.next_kink(from, t, KINK_SHARE);
            let pending = if k.is_finite() { k } else { f64::NEG_INFINITY };
            self.stream_scan.set((next, pending));
            return k;
        }
        let k = self.kinks.get_or_init(|| kinks(&self.signal));
        k.get(k.partition_point(|&b| b <= t))
            .copied()
            .unwrap_or(f64::INFINITY)
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe::of("command", self.out)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hydrocyl_integrators::OdeSystem;

    fn table(f: impl Fn(f64) -> f64) -> Signal {
        let t: Vec<f64> = (0..=4000).map(|k| k as f64 * 1e-3).collect();
        let v = t.iter().map(|&t| f(t)).collect();
        Signal::table(t, v).unwrap()
    }

    #[test]
    fn a_sampled_square_has_a_kink_at_each_end_of_each_edge() {
        // ±1, period 2 s: edges from 0.999 to 1.000 s, 1.999 to 2.000 s,
        // ...; the last edge starts at 3.999 s and ends at the table's end
        let square = table(|t| {
            if (t / 2.0).rem_euclid(1.0) < 0.5 {
                1.0
            } else {
                -1.0
            }
        });
        let k = kinks(&square);
        let expected = [0.999, 1.0, 1.999, 2.0, 2.999, 3.0, 3.999];
        assert_eq!(k.len(), expected.len(), "{k:?}");
        for (a, b) in k.iter().zip(expected) {
            assert!((a - b).abs() < 1e-12, "{k:?}");
        }
    }

    #[test]
    fn a_sampled_sine_and_a_noisy_constant_have_none() {
        let sine = table(|t| (std::f64::consts::TAU * 0.5 * t).sin());
        assert!(kinks(&sine).is_empty());
        // ±2 % noise on a signal with range 1 (a deterministic hash as noise)
        let noisy = table(|t| {
            let h = ((t * 1e3).round() as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40;
            (t / 4.0) + 0.02 * (h as f64 / (1u64 << 24) as f64 - 0.5)
        });
        assert!(kinks(&noisy).is_empty());
        // a ramp's two ends; no kinks in a step (a jump, not a kink)
        let ramp = Signal::Ramp {
            from: 0.0,
            to: 1.0,
            t0_s: 1.0,
            t1_s: 2.0,
        };
        assert_eq!(kinks(&ramp), vec![1.0, 2.0]);
        let step = Signal::Step {
            time_s: 1.0,
            before: 0.0,
            after: 1.0,
        };
        assert!(kinks(&step).is_empty());
    }

    #[test]
    fn the_circuit_offers_the_next_kink_of_its_command() {
        let square = table(|t| {
            if (t / 2.0).rem_euclid(1.0) < 0.5 {
                1.0
            } else {
                -1.0
            }
        });
        let c =
            crate::Circuit::build(vec![Box::new(CommandInput::new("cmd", "u", square))]).unwrap();
        // the table's own sample times
        let (a, b) = (999.0 * 1e-3, 1000.0 * 1e-3);
        assert_eq!(c.next_breakpoint(0.0), a);
        assert_eq!(c.next_breakpoint(a), b);
        assert_eq!(c.next_breakpoint(3999.0 * 1e-3), f64::INFINITY);
    }
}
