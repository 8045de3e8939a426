//! A circuit's probes read into a run's channels at its output points, on
//! the solving circuit ([`ProbeSet`]) or on a second circuit of its own on
//! another thread ([`ProbeReader`], fed by
//! [`Simulation::run_streaming_states`](crate::simulation::Simulation::run_streaming_states)).

use super::{initial, Channel, Run, RunOptions, SimError, ORDER};
use crate::circuit::{AnyWire, Circuit, CircuitMemory, Partial, Probe};

/// The probes of a circuit as a run's channels, in the measured-data order
/// (command, position, velocity, p1, p2, then the others in component
/// order).
#[derive(Clone, Debug)]
pub struct ProbeSet {
    wires: Vec<AnyWire>,
    /// Name, unit and probe path of each channel, in channel order.
    names: Vec<(String, &'static str, String)>,
    /// The wire of each channel, in channel order.
    order: Vec<usize>,
    row: Vec<f64>,
    /// What the reads left in the circuit, put back for the next reads:
    /// the reads go on from their own last solutions, not the solve's,
    /// so that they read the same whenever they are made (`None`: none yet).
    memory: Option<CircuitMemory>,
    /// How the probed wires are set at each output point.
    reading: Reading,
}

/// How a [`ProbeSet`] sets its wires at an output point: with as little of
/// the circuit's evaluation as they depend on (the values are those of a
/// full evaluation, bit for bit).
#[derive(Clone, Debug)]
enum Reading {
    /// The components and steps the probed wires depend on publish and run
    /// ([`Circuit::partial_for`], [`Circuit::read_partial`]): only the
    /// publishers when every probe is a stored effort.
    Partial(Partial),
    /// The whole circuit is evaluated ([`Circuit::read_wires`]).
    Full,
}

impl ProbeSet {
    /// The probes of `circuit`.
    pub fn of(circuit: &Circuit) -> Self {
        Self::of_probes(circuit, circuit.probes())
    }

    /// The probes of `circuit` named in `names` (every probe for `None`),
    /// in the channel order of [`ProbeSet::of`].
    ///
    /// # Errors
    /// [`SimError::Settings`] naming a channel the circuit has no probe for.
    pub fn selected(circuit: &Circuit, names: Option<&[String]>) -> Result<Self, SimError> {
        let all = circuit.probes();
        let Some(names) = names else {
            return Ok(Self::of_probes(circuit, all));
        };
        if let Some(n) = names.iter().find(|n| !all.iter().any(|p| p.name == **n)) {
            return Err(SimError::Settings(format!(
                "channel `{n}`: the circuit has no such output (it has {})",
                all.iter()
                    .map(|p| p.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
        let chosen = all
            .into_iter()
            .filter(|p| names.contains(&p.name))
            .collect();
        Ok(Self::of_probes(circuit, chosen))
    }

    /// The channel names, in channel order (a run's: command, position,
    /// velocity, p1, p2, then the others in component order).
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.names.iter().map(|(n, _, _)| n.as_str())
    }

    fn of_probes(circuit: &Circuit, probes: Vec<Probe>) -> Self {
        let wires: Vec<AnyWire> = probes.iter().map(|p| p.wire).collect();
        let reading = circuit
            .partial_for(&wires)
            .map_or(Reading::Full, Reading::Partial);
        let mut order: Vec<usize> = (0..probes.len()).collect();
        // stable: probes outside ORDER keep their component order
        order.sort_by_key(|&i| {
            ORDER
                .iter()
                .position(|o| *o == probes[i].name)
                .unwrap_or(ORDER.len())
        });
        Self {
            wires,
            names: order
                .iter()
                .map(|&i| {
                    (
                        probes[i].name.clone(),
                        probes[i].unit,
                        probes[i].path.clone(),
                    )
                })
                .collect(),
            order,
            row: vec![0.0; probes.len()],
            memory: None,
            reading,
        }
    }

    /// Reads the probes of `c` at the outputs `(t[k], x[k·dim..])` (`x`
    /// row-major, `dim = x.len() / t.len()`) into `out`: its time, states
    /// and channels are replaced, their buffers reused (no allocation once
    /// `out` has held a block this large).
    pub fn read(&mut self, c: &Circuit, t: &[f64], x: &[f64], out: &mut Run) {
        out.time.clear();
        out.time.extend_from_slice(t);
        out.states.clear();
        out.states.extend_from_slice(x);
        out.dim = if t.is_empty() { 0 } else { x.len() / t.len() };
        self.read_channels(c, t, x, &mut out.channels);
    }

    /// [`ProbeSet::read`] into the channels alone.
    pub fn read_channels(&mut self, c: &Circuit, t: &[f64], x: &[f64], out: &mut Vec<Channel>) {
        let dim = if t.is_empty() { 0 } else { x.len() / t.len() };
        out.truncate(self.names.len());
        for (j, (name, unit, probe)) in self.names.iter().enumerate() {
            if out.get(j).is_some_and(|ch| ch.name == *name) {
                out[j].values.clear();
                continue;
            }
            let ch = Channel {
                name: name.clone(),
                unit,
                probe: probe.clone(),
                values: Vec::with_capacity(t.len()),
            };
            if j < out.len() {
                out[j] = ch;
            } else {
                out.push(ch);
            }
        }
        if self.wires.is_empty() {
            return;
        }
        // the reads leave the circuit as they found it (a solve may go on),
        // and go on from where the last reads ended (the first from a fresh
        // start), whenever they are made
        let solving = c.memory();
        let reading = self
            .memory
            .take()
            .unwrap_or_else(|| solving.clone().forgetting_solutions());
        c.restore_memory(reading);
        for (k, &tk) in t.iter().enumerate() {
            let xk = &x[k * dim..(k + 1) * dim];
            match &self.reading {
                Reading::Partial(p) => {
                    c.read_partial(p, tk, xk, &self.wires, &mut self.row);
                    #[cfg(debug_assertions)]
                    self.check_against_full(c, tk, xk);
                }
                Reading::Full => c.read_wires(tk, xk, &self.wires, &mut self.row),
            }
            for (ch, &i) in out.iter_mut().zip(&self.order) {
                ch.values.push(self.row[i]);
            }
        }
        self.memory = Some(c.memory());
        c.restore_memory(solving);
    }

    /// Debug builds: the row just read from what the probes depend on is
    /// the row a full evaluation gives, bit for bit (a component that
    /// reads a wire it did not bind would break it); the circuit's memory
    /// is left as the partial read left it.
    #[cfg(debug_assertions)]
    fn check_against_full(&self, c: &Circuit, t: f64, x: &[f64]) {
        let kept = c.memory();
        let mut full = vec![0.0; self.wires.len()];
        c.read_wires(t, x, &self.wires, &mut full);
        c.restore_memory(kept);
        for ((a, b), &w) in self.row.iter().zip(&full).zip(&self.wires) {
            debug_assert!(
                a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                "probe wire `{}` at t = {t}: {a} from the steps it depends on, {b} from the whole circuit",
                c.wire_name(w)
            );
        }
    }
}

/// A run's probes read on a circuit of their own: built like the solving
/// circuit (the same rig, the same command) and set up from the same initial
/// state, it reads the same channels, bit for bit, from the raw outputs of
/// [`Simulation::run_streaming_states`](crate::simulation::Simulation::run_streaming_states), so that the solve's thread does not
/// evaluate the circuit once more per output row. Only for a circuit whose
/// wires do not depend on what ran before ([`Circuit::history_free`]).
pub struct ProbeReader {
    circuit: Circuit,
    probes: ProbeSet,
}

impl ProbeReader {
    /// Sets `circuit` up as [`Simulation::run_streaming_states`](crate::simulation::Simulation::run_streaming_states) sets up the
    /// solving one (from `x0` at `t0`, with `opts`' quadratures and ledger).
    ///
    /// # Errors
    /// [`SimError::Settings`] when the circuit is not
    /// [`Circuit::history_free`] (its probes must be read on the solving
    /// circuit) or `x0` does not fit it.
    pub fn new(
        mut circuit: Circuit,
        x0: &[f64],
        t0: f64,
        opts: &RunOptions,
    ) -> Result<Self, SimError> {
        if !circuit.history_free() {
            return Err(SimError::Settings(
                "the circuit's wires depend on its history (an algebraic node or a mode): read its probes on the solving circuit".into(),
            ));
        }
        initial(&mut circuit, x0, t0, opts)?;
        let probes = ProbeSet::of(&circuit);
        Ok(Self { circuit, probes })
    }

    /// Reads the channels at the outputs `(t, x)` into `out` (see
    /// [`ProbeSet::read`]).
    pub fn read(&mut self, t: &[f64], x: &[f64], out: &mut Run) {
        self.probes.read(&self.circuit, t, x, out);
    }

    /// [`ProbeReader::read`] without the states: `out`'s time and channels
    /// are replaced, its states left as they are.
    pub fn read_channels(&mut self, t: &[f64], x: &[f64], out: &mut Run) {
        out.time.clear();
        out.time.extend_from_slice(t);
        self.probes
            .read_channels(&self.circuit, t, x, &mut out.channels);
    }
}
