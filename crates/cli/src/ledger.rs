//! `hydrocyl simulate --ledger`: the energy ledger of the run, written as
//! JSON beside the CSV.
//!
//! The run integrates the ledger's quadratures with its states
//! (`RunOptions::ledger`); a streamed run keeps no states, so [`Ends`]
//! keeps the two the ledger needs (the first output at or after the
//! window's start, and the last), copied from the blocks as they pass. The
//! ledger is `hydrocyl_energy::ledger::ledger_between` on a circuit of the
//! rig, and its JSON [`hydrocyl_energy::ledger::Ledger::to_json`]: what
//! Python's `run.ledger` is, key for key.

use crate::error::CliError;
use hydrocyl_energy::ledger::{ledger_between, RodSide};
use hydrocyl_system::Circuit;

/// The window's first and last output states of a streamed run.
pub struct Ends {
    /// The window's start \[s\]: the first output at or after it opens it.
    from: f64,
    first: Option<(f64, Vec<f64>)>,
    last: Option<(f64, Vec<f64>)>,
}

impl Ends {
    /// Keeps the outputs from `from` \[s\] on (−∞: the whole run).
    pub fn new(from: f64) -> Self {
        Ends {
            from,
            first: None,
            last: None,
        }
    }

    /// Looks at one block: its output times `t` and full states `x`
    /// (row-major, `x.len() / t.len()` each).
    pub fn see(&mut self, t: &[f64], x: &[f64]) {
        let n = t.len();
        if n == 0 {
            return;
        }
        let dim = x.len() / n;
        if self.first.is_none() {
            if let Some(k) = t.iter().position(|&tk| tk >= self.from) {
                self.first = Some((t[k], x[k * dim..(k + 1) * dim].to_vec()));
            }
        }
        let last = self.last.get_or_insert_with(|| (0.0, Vec::new()));
        last.0 = t[n - 1];
        last.1.clear();
        last.1.extend_from_slice(&x[(n - 1) * dim..]);
    }

    /// The ledger over the window on `circuit` (the rig's, its ledger
    /// turned on here) as the JSON text written to the file, and a line
    /// that says what it found.
    pub fn json(&self, mut circuit: Circuit) -> Result<(Vec<u8>, String), CliError> {
        let bad = |why: String| CliError::Input(format!("--ledger: {why}"));
        let (Some((t0, x0)), Some((t1, x1))) = (&self.first, &self.last) else {
            return Err(bad("the run has no output in the ledger's window".into()));
        };
        if t1 <= t0 {
            return Err(bad(format!(
                "the window from t = {t0} s holds one output time only"
            )));
        }
        circuit.set_ledger(true);
        let l = ledger_between(&circuit, (*t0, x0), (*t1, x1), &RodSide::of(&circuit))
            .map_err(|e| bad(e.to_string()))?;
        let mut text = serde_json::to_vec_pretty(&l.to_json())
            .map_err(|e| bad(format!("writing JSON: {e}")))?;
        text.push(b'\n');
        // where no energy comes in (a volume discharging, a mass braking)
        // there is no efficiency, and the errors are of the largest term
        let (efficiency, of) = if l.energy_in_j > 0.0 {
            (format!("efficiency {:.4}", l.efficiency()), "the energy in")
        } else {
            (
                "no efficiency: no energy in".to_string(),
                "the largest term",
            )
        };
        let note = format!(
            "energy ledger over t = {t0} … {t1} s: energy in {:.6e} J, out of the cylinder {:.6e} J ({efficiency}), closure {:.3e} J ({:.1e} of {of}), storage check {:.1e}",
            l.energy_in_j,
            l.cylinder_out_j,
            l.closure_j(),
            l.error,
            l.storage_error
        );
        Ok((text, note))
    }
}
