//! A command value set from outside the solver between integrations: the
//! input of a co-simulation slave (an FMU), which the host sets at each
//! communication point together with its slope over the next step.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// A shared, host-set signal `value + slope · (t − t0)` (first-order hold
/// across one communication step). Clones share the value: the host keeps
/// one clone and the circuit's [`Signal::External`](crate::signal::Signal::External)
/// reads another. Set it only between solver calls (the solver must see a
/// fixed function of time inside a step).
#[derive(Clone, Debug, Default)]
pub struct ExternalInput(Arc<[AtomicU64; 3]>);

impl ExternalInput {
    /// A new input, 0 for all t.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the value `value` at time `t0` and its slope `slope` \[1/s\].
    pub fn set(&self, t0: f64, value: f64, slope: f64) {
        for (cell, v) in self.0.iter().zip([t0, value, slope]) {
            cell.store(v.to_bits(), Ordering::Relaxed);
        }
    }

    /// `(t0, value, slope)` as last set.
    pub fn get(&self) -> (f64, f64, f64) {
        let g = |i: usize| f64::from_bits(self.0[i].load(Ordering::Relaxed));
        (g(0), g(1), g(2))
    }

    /// The value at time `t`.
    #[inline]
    pub fn value(&self, t: f64) -> f64 {
        let (t0, v, s) = self.get();
        if s == 0.0 {
            v
        } else {
            v + s * (t - t0)
        }
    }
}

/// Two handles are equal when they share the value.
impl PartialEq for ExternalInput {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clones_share_the_value_and_hold_first_order() {
        let a = ExternalInput::new();
        let b = a.clone();
        assert_eq!(b.value(3.0), 0.0);
        a.set(1.0, 2.0, -4.0);
        assert_eq!(b.value(1.0), 2.0);
        assert_eq!(b.value(1.5), 0.0);
        assert_eq!(a, b);
        assert_ne!(a, ExternalInput::new());
    }
}
