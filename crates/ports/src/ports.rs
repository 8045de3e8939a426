//! Power-bond ports: the (effort, flow) pairs that join components.

use crate::{Force, Power, Pressure, Velocity, VolumeFlow};
use serde::{Deserialize, Serialize};

/// A hydraulic power bond: the pressure at the port and the volume flow
/// **into** the component through it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HydraulicPort {
    /// Pressure at the port \[Pa\].
    pub pressure: Pressure,
    /// Volume flow into the component through the port \[m³·s⁻¹\].
    pub flow: VolumeFlow,
}

impl HydraulicPort {
    /// A port from its effort and flow.
    #[inline(always)]
    pub const fn new(pressure: Pressure, flow: VolumeFlow) -> Self {
        Self { pressure, flow }
    }
    /// Power delivered to the component through this port, `p q` \[W\].
    #[inline(always)]
    pub fn power(&self) -> Power {
        self.pressure * self.flow
    }
}

/// A mechanical (translational) power bond: the force on the component at the
/// port and the velocity of the port in the force's direction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MechanicalPort {
    /// Force acting on the component at the port \[N\].
    pub force: Force,
    /// Velocity of the port, positive in the force's direction \[m·s⁻¹\].
    pub velocity: Velocity,
}

impl MechanicalPort {
    /// A port from its effort and flow.
    #[inline(always)]
    pub const fn new(force: Force, velocity: Velocity) -> Self {
        Self { force, velocity }
    }
    /// Power delivered to the component through this port, `F v` \[W\].
    #[inline(always)]
    pub fn power(&self) -> Power {
        self.force * self.velocity
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn port_power_is_effort_times_flow() {
        let h = HydraulicPort::new(Pressure::from_bar(100.0), VolumeFlow::from_l_per_min(6.0));
        assert!((h.power().watts() - 1000.0).abs() < 1e-9);
        let m = MechanicalPort::new(Force::new(-200.0), Velocity::new(0.05));
        assert!((m.power().watts() + 10.0).abs() < 1e-12);
    }
}
