//! The names a circuit's states go by in messages: the netlist's
//! `<component>.<state>` (the names `initial.<state>` sets and
//! `--print-rig` shows) where the netlist names the state, the circuit's
//! own ([`Circuit::state_names`]) otherwise.

use super::Circuit;

impl Circuit {
    /// Names the component states for messages ([`Circuit::state_label`]):
    /// `name(component, k, n)` gives the name of state `k` of the `n`
    /// states of `component`, `None` keeps its own
    /// ([`Circuit::state_names`]). The netlist reader gives the
    /// `<component>.<state>` of its `initial` objects.
    pub fn name_states(&mut self, name: impl Fn(&str, usize, usize) -> Option<String>) {
        let mut labels = Vec::with_capacity(self.n_states);
        for (i, c) in self.comps.iter().enumerate() {
            let n = self.offsets[i + 1] - self.offsets[i];
            labels.extend((0..n).map(|k| name(c.name(), k, n)));
        }
        self.state_labels = Some(labels);
    }

    /// The name of entry `i` of the full state vector (states, then the
    /// quadratures and the ledger's terms when on) in messages: the one
    /// given by [`Circuit::name_states`], else its [`Circuit::state_names`]
    /// entry; `None` beyond the vector.
    pub fn state_label(&self, i: usize) -> Option<String> {
        self.state_labels
            .as_ref()
            .and_then(|l| l.get(i).cloned().flatten())
            .or_else(|| self.state_names().into_iter().nth(i))
    }
}
