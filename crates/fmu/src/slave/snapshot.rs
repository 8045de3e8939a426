//! A saved instance state (`fmi2FMUstate`): [`Snapshot`], its bytes, and
//! the slave's saving and restoring of it (`fmi2GetFMUstate`,
//! `fmi2SetFMUstate`).

use super::{Phase, Slave, SlaveError};
use serde_json::Value;

/// A saved instance state (`fmi2FMUstate`): the rig and variable values, and
/// the communication steps taken since initialisation. Restoring it
/// re-assembles the circuit and replays those steps, so the component modes
/// (stick/slip, stops, valve states) come back with the continuous state,
/// bit for bit; it costs a re-run from the start time.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    rig: Value,
    values: Vec<f64>,
    slope: f64,
    t_start: f64,
    phase: Phase,
    assembled: bool,
    history: Vec<[f64; 4]>,
}

impl Snapshot {
    /// The state as bytes (JSON, every number as its IEEE-754 bits).
    pub fn serialize(&self) -> Vec<u8> {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
        serde_json::json!({
            "rig": self.rig,
            "values": bits(&self.values),
            "slope": self.slope.to_bits(),
            "t_start": self.t_start.to_bits(),
            "phase": self.phase as u8,
            "assembled": self.assembled,
            "history": self.history.iter().map(|h| bits(h)).collect::<Vec<_>>(),
        })
        .to_string()
        .into_bytes()
    }

    /// A state from [`Snapshot::serialize`]'s bytes.
    pub fn deserialize(bytes: &[u8]) -> Result<Snapshot, SlaveError> {
        let bad = |what: &str| format!("serialized FMU state: {what}");
        let v: Value = serde_json::from_slice(bytes).map_err(|e| bad(&e.to_string()))?;
        let f = |x: &Value| {
            x.as_u64()
                .map(f64::from_bits)
                .ok_or_else(|| bad("a number"))
        };
        let list = |x: &Value| -> Result<Vec<f64>, SlaveError> {
            x.as_array()
                .ok_or_else(|| bad("a list"))?
                .iter()
                .map(f)
                .collect()
        };
        let phase = match v["phase"].as_u64() {
            Some(0) => Phase::Instantiated,
            Some(1) => Phase::Initializing,
            Some(2) => Phase::Stepping,
            Some(3) => Phase::Terminated,
            _ => return Err(bad("phase")),
        };
        let history = v["history"]
            .as_array()
            .ok_or_else(|| bad("history"))?
            .iter()
            .map(|h| list(h)?.try_into().map_err(|_| bad("a history entry")))
            .collect::<Result<Vec<[f64; 4]>, _>>()?;
        Ok(Snapshot {
            rig: v["rig"].clone(),
            values: list(&v["values"])?,
            slope: f(&v["slope"])?,
            t_start: f(&v["t_start"])?,
            phase,
            assembled: v["assembled"].as_bool().ok_or_else(|| bad("assembled"))?,
            history,
        })
    }
}

impl Slave {
    /// `fmi2GetFMUstate`: the instance's state.
    pub fn get_state(&self) -> Result<Snapshot, SlaveError> {
        if self.phase == Phase::Failed {
            return Err("fmi2GetFMUstate after an error: reset the instance first".into());
        }
        Ok(Snapshot {
            rig: self.rig.clone(),
            values: self.values.clone(),
            slope: self.slope,
            t_start: self.t_start,
            phase: self.phase,
            assembled: self.sim.is_some(),
            history: self.history.clone(),
        })
    }

    /// `fmi2SetFMUstate`: back to a saved state (of an instance of the same
    /// FMU): the circuit is re-assembled and the saved steps replayed.
    pub fn set_state(&mut self, snap: &Snapshot) -> Result<(), SlaveError> {
        if snap.values.len() != self.values.len() {
            return Err("fmi2SetFMUstate: the state is of another FMU".into());
        }
        self.rig = snap.rig.clone();
        self.values = snap.values.clone();
        self.t_start = snap.t_start;
        self.sim = None;
        self.history.clear();
        if snap.assembled {
            self.ensure_sim()?;
            self.phase = Phase::Stepping;
            for &[t, h, u, slope] in &snap.history {
                self.values[0] = u;
                self.slope = slope;
                if let Err(e) = self.do_step(t, h) {
                    self.phase = Phase::Failed;
                    return Err(format!("fmi2SetFMUstate: replaying the saved steps: {e}"));
                }
            }
        }
        self.values = snap.values.clone();
        self.slope = snap.slope;
        if let Some(s) = &self.sim {
            s.input.set(s.t, self.values[0], self.slope);
        }
        self.phase = snap.phase;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slave::tests::vr;
    use hydrocyl_system::rig;

    /// A state saved in mid-run, restored (directly and through its bytes),
    /// continues exactly as the uninterrupted run.
    #[test]
    fn a_restored_state_continues_the_run_bit_for_bit() {
        let mut s = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        let (cmd, pos) = (vr(&s, "command"), vr(&s, "position"));
        s.enter_initialization().unwrap();
        s.exit_initialization().unwrap();
        let go = |s: &mut Slave, from: usize, n: usize| -> Vec<f64> {
            (from..from + n)
                .map(|k| {
                    s.set_real(cmd, if k % 80 < 40 { 0.4 } else { -0.4 })
                        .unwrap();
                    s.do_step(k as f64 * 1e-3, 1e-3).unwrap();
                    s.get_real(pos).unwrap()
                })
                .collect()
        };
        go(&mut s, 0, 100);
        let snap = s.get_state().unwrap();
        let first = go(&mut s, 100, 150);
        s.set_state(&snap).unwrap();
        assert_eq!(go(&mut s, 100, 150), first);
        let back = Snapshot::deserialize(&snap.serialize()).unwrap();
        assert_eq!(back.serialize(), snap.serialize()); // NaN-safe equality
        let mut other = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        other.set_state(&back).unwrap();
        assert_eq!(other.time(), 0.1);
        assert_eq!(go(&mut other, 100, 150), first);
        assert!(Snapshot::deserialize(b"{}").is_err());
    }
}
