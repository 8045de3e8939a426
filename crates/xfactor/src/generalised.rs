//! Leaney's generalised one-pressure actuator (eqs 2.16-2.26, 3.3) and the
//! steady chamber pressures inside the underlap (section 3.3.4).
//!
//! The generalised form replaces the two chamber pressures by the effective
//! load pressure `P_LE` and recovers them through X:
//!
//! ```text
//!   A_E  = (A1 + A2) / 2                         P_LE = (p1 A1 - p2 A2) / A_E     (2.16)
//!   p1   = (X Ps + gamma^2 (1+gamma)/2 P_LE) / (1 + gamma^3)                      (2.21)
//!   p2   = (X gamma Ps - (1+gamma)/2 P_LE)   / (1 + gamma^3)                      (2.22)
//!   dP_LE/dt = 4 B / V_TE * Q_CE,   Q_CE = Q_LE - Q_DE - Q_KE                     (2.23, 3.3)
//!   V_TE = 2 A_E / A1 * (V1 + (A2/A1)^2 V2) / (1 + (A2/A1)^3)                     (2.24)
//!   Q_LE = Cd/sqrt(2 rho) (1+gamma)/sqrt(1+gamma^3)
//!          [Av1 sqrt(X gamma Ps - (1+gamma)/2 P_LE) - Av2 sqrt((1+gamma^3-X gamma) Ps + (1+gamma)/2 P_LE)]  (2.26)
//! ```
//!
//! Inverting 2.21/2.22 shows what X is: `X = (p1 + gamma^2 p2) / Ps`, the one
//! combination of the chamber pressures that the load does not move
//! ([`load_pressure_and_x`]).

use hydrocyl_ports::{Area, Density, Force, Pressure, Volume, VolumeFlow};

use crate::analytical::{check_inputs, x_factor};
use crate::error::XFactorError;
use crate::numerical::brent;

/// Chamber pressures p1 (piston side) and p2 (rod side) \[Pa\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChamberPressures {
    /// Piston-side (cap-end) chamber pressure p1 \[Pa\].
    pub p1: Pressure,
    /// Rod-side chamber pressure p2 \[Pa\].
    pub p2: Pressure,
}

/// Steady state inside (or outside) the underlap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyPressures {
    /// Piston-side chamber pressure p1 \[Pa\].
    pub p1: Pressure,
    /// Rod-side chamber pressure p2 \[Pa\].
    pub p2: Pressure,
    /// Effective load pressure `P_LE = (p1 A1 - p2 A2) / A_E` \[Pa\] (eq 2.16).
    pub p_le: Pressure,
    /// The X factor `(p1 + gamma^2 p2) / Ps` \[-\] (eq 3.4 in the generalised
    /// form; implied by the pressures in the two-chamber form).
    pub x: f64,
}

/// The valve's two metering paths as seen by eq 2.26: a symmetric-ported
/// four-way valve with port opening areas `av1` (P->A and B->T) and `av2`
/// (P->B and A->T).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PortOrifices {
    /// Discharge coefficient Cd \[-\].
    pub cd: f64,
    /// Fluid density rho \[kg m^-3\].
    pub rho: Density,
    /// Opening area of the paths P->A, B->T \[m^2\].
    pub av1: Area,
    /// Opening area of the paths P->B, A->T \[m^2\].
    pub av2: Area,
}

/// Effective piston area `A_E = (A1 + A2) / 2` \[m^2\] (eq 2.16).
#[inline]
pub fn effective_area(a1: Area, a2: Area) -> Area {
    (a1 + a2) * 0.5
}

/// Effective load pressure `P_LE = (p1 A1 - p2 A2) / A_E` \[Pa\] (eq 2.16).
#[inline]
pub fn load_pressure(p1: Pressure, p2: Pressure, a1: Area, a2: Area) -> Pressure {
    (p1 * a1 - p2 * a2) / effective_area(a1, a2)
}

/// Chamber pressures from the effective load pressure and X (eqs 2.21, 2.22):
/// `p1 = (X Ps + gamma^2 (1+gamma)/2 P_LE)/(1+gamma^3)`,
/// `p2 = (X gamma Ps - (1+gamma)/2 P_LE)/(1+gamma^3)`.
///
/// These satisfy `p1 A1 - p2 A2 = P_LE A_E` exactly when `gamma = A1/A2`.
/// Pure algebra: no check, no clamp (a transient may take them outside
/// `[0, Ps]`; the caller decides what that means).
///
/// ```
/// use hydrocyl_ports::Pressure;
/// use hydrocyl_xfactor::chamber_pressures_from_load_pressure;
/// // symmetric cylinder, X = 1: p1 = (Ps + P_LE)/2, p2 = (Ps - P_LE)/2
/// let c = chamber_pressures_from_load_pressure(Pressure::from_bar(10.0), Pressure::from_bar(70.0), 1.0, 1.0);
/// assert!((c.p1.bar() - 40.0).abs() < 1e-12 && (c.p2.bar() - 30.0).abs() < 1e-12);
/// ```
#[inline]
pub fn chamber_pressures_from_load_pressure(
    p_le: Pressure,
    ps: Pressure,
    x: f64,
    gamma: f64,
) -> ChamberPressures {
    let k = 1.0 + gamma * gamma * gamma;
    let half = 0.5 * (1.0 + gamma);
    ChamberPressures {
        p1: (ps * x + p_le * (gamma * gamma * half)) / k,
        p2: (ps * (x * gamma) - p_le * half) / k,
    }
}

/// The inverse of [`chamber_pressures_from_load_pressure`]: from the chamber
/// pressures, `P_LE = 2 (gamma p1 - p2) / (1 + gamma)` and
/// `X = (p1 + gamma^2 p2) / Ps`. Returns `(P_LE, X)`.
#[inline]
pub fn load_pressure_and_x(
    p1: Pressure,
    p2: Pressure,
    ps: Pressure,
    gamma: f64,
) -> (Pressure, f64) {
    let p_le = (p1 * gamma - p2) * (2.0 / (1.0 + gamma));
    let x = (p1 + p2 * (gamma * gamma)) / ps;
    (p_le, x)
}

/// Effective total volume `V_TE` \[m^3\] (eq 2.24), the capacitance volume of
/// the one-pressure form: `dP_LE/dt = 4 B / V_TE * Q_CE` (eq 2.23).
#[inline]
pub fn effective_total_volume(v1: Volume, v2: Volume, a1: Area, a2: Area) -> Volume {
    let r = a2 / a1;
    let ae = effective_area(a1, a2);
    (v1 + v2 * (r * r)) * (2.0 * (ae / a1) / (1.0 + r * r * r))
}

/// `sqrt(|x|) sgn(x)`: the orifice law where the pressure drop reverses.
#[inline(always)]
fn signed_sqrt(x: f64) -> f64 {
    x.abs().sqrt().copysign(x)
}

/// Effective load flow `Q_LE = (Q1 + Q2)/2` \[m^3 s^-1\] of eq 2.26, each
/// square root signed where its pressure difference reverses.
///
/// The two square-root arguments are `(1 + gamma^3) p2` and
/// `(1 + gamma^3) (Ps - p2)` with p2 from eq 2.22: eq 2.26 is the chamber-2
/// orifice flow scaled by `(1 + gamma)/2`, which equals `(Q1 + Q2)/2` exactly
/// when X solves eq 3.4 and `Q1 = gamma Q2`.
#[inline]
pub fn effective_load_flow(
    valve: &PortOrifices,
    ps: Pressure,
    p_le: Pressure,
    x: f64,
    gamma: f64,
) -> VolumeFlow {
    let k = 1.0 + gamma * gamma * gamma;
    let half = 0.5 * (1.0 + gamma);
    let r2 = x * gamma * ps.pa() - half * p_le.pa();
    let r2t = (k - x * gamma) * ps.pa() + half * p_le.pa();
    let coef = valve.cd / (2.0 * valve.rho.si()).sqrt() * (1.0 + gamma) / k.sqrt();
    VolumeFlow::new(coef * (valve.av1.m2() * signed_sqrt(r2) - valve.av2.m2() * signed_sqrt(r2t)))
}

fn check_positive(what: &'static str, value: f64) -> Result<(), XFactorError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(XFactorError::ParameterOutOfRange {
            what,
            value,
            why: "must be finite and > 0",
        })
    }
}

fn check_steady_inputs(
    travel: f64,
    ps: Pressure,
    gamma: f64,
    a1: Area,
    load: Force,
) -> Result<(), XFactorError> {
    check_inputs(gamma, travel)?;
    check_positive("supply pressure ps [Pa]", ps.pa())?;
    check_positive("piston area a1 [m^2]", a1.m2())?;
    if !load.n().is_finite() {
        return Err(XFactorError::ParameterOutOfRange {
            what: "load force [N]",
            value: load.n(),
            why: "must be finite",
        });
    }
    Ok(())
}

/// Steady chamber pressures by section 3.3.4 of the thesis: X from the
/// analytical solution at `travel`, `P_LE = F / A_E` from the force balance
/// `p1 A1 - p2 A2 = F` (eq 2.27 at rest or constant velocity; `F` = friction +
/// external force), then p1, p2 from eqs 2.21, 2.22.
///
/// `a1` is the piston-side area; `A2 = a1 / gamma`.
///
/// **Approximation (the thesis's, kept as written):** X from eq 3.4 is the
/// *zero-load* X; inside the underlap the true steady state of the two
/// orifice-fed chambers under a load differs (outside the underlap and at
/// zero load the two agree exactly). [`steady_pressures_two_chamber`] solves
/// the two-chamber steady state without that approximation.
///
/// Error if an argument is out of range, or if the result needs a chamber
/// pressure outside `[0, Ps]` (the supply cannot hold that load).
///
/// ```
/// use hydrocyl_ports::{Area, Force, Pressure};
/// use hydrocyl_xfactor::steady_pressures;
/// let s = steady_pressures(0.0, Pressure::from_bar(70.0), 11.43 / 5.8,
///                          Area::from_cm2(11.43), Force::new(500.0)).unwrap();
/// // the force balance holds whatever X is
/// let f = s.p1 * Area::from_cm2(11.43) - s.p2 * Area::from_cm2(5.8);
/// assert!((f.n() - 500.0).abs() < 1e-9);
/// ```
pub fn steady_pressures(
    travel: f64,
    ps: Pressure,
    gamma: f64,
    a1: Area,
    load: Force,
) -> Result<SteadyPressures, XFactorError> {
    check_steady_inputs(travel, ps, gamma, a1, load)?;
    let x = x_factor(gamma, travel);
    let a2 = a1 / gamma;
    let p_le = load / effective_area(a1, a2);
    let c = chamber_pressures_from_load_pressure(p_le, ps, x, gamma);
    let inside = |p: Pressure| p.pa() >= 0.0 && p.pa() <= ps.pa();
    if !(inside(c.p1) && inside(c.p2)) {
        return Err(XFactorError::NoSteadyState {
            travel,
            force_n: load.n(),
            ps_pa: ps.pa(),
        });
    }
    Ok(SteadyPressures {
        p1: c.p1,
        p2: c.p2,
        p_le,
        x,
    })
}

/// The exact steady state of the two orifice-fed chambers (no X, no
/// generalisation): port areas `Av1 ~ max(0, 1 + travel)`,
/// `Av2 ~ max(0, 1 - travel)` (eq 3.2), flows
/// `Q1 ~ Av1 sqrt(Ps - p1) - Av2 sqrt(p1)`, `Q2 ~ Av1 sqrt(p2) - Av2 sqrt(Ps - p2)`
/// (eqs 2.8, 2.9) in the ratio of the areas, `Q1 = gamma Q2` (constant
/// velocity), and the force balance `p1 A1 - p2 A2 = F`. One unknown (p1),
/// one strictly monotone equation, solved by Brent to `1e-12 Ps`.
///
/// At zero load it gives the same pressures as [`steady_pressures`]; under a
/// load inside the underlap it shows the error of the zero-load X.
///
/// Error if an argument is out of range or no steady state exists with both
/// pressures in `[0, Ps]`.
pub fn steady_pressures_two_chamber(
    travel: f64,
    ps: Pressure,
    gamma: f64,
    a1: Area,
    load: Force,
) -> Result<SteadyPressures, XFactorError> {
    check_steady_inputs(travel, ps, gamma, a1, load)?;
    let a = (1.0 + travel).max(0.0);
    let b = (1.0 - travel).max(0.0);
    let psv = ps.pa();
    let a2 = a1.m2() / gamma;
    let f2 = load.n() / a2; // p2 = gamma p1 - F/A2
    let lo = 0.0f64.max(f2 / gamma);
    let hi = psv.min((psv + f2) / gamma);
    let none = XFactorError::NoSteadyState {
        travel,
        force_n: load.n(),
        ps_pa: psv,
    };
    if lo > hi {
        return Err(none);
    }
    let g = |p1: f64| {
        let p2 = (gamma * p1 - f2).clamp(0.0, psv);
        let p1 = p1.clamp(0.0, psv);
        a * (psv - p1).sqrt() - b * p1.sqrt() - gamma * (a * p2.sqrt() - b * (psv - p2).sqrt())
    };
    let (glo, ghi) = (g(lo), g(hi));
    if glo < 0.0 || ghi > 0.0 {
        return Err(none);
    }
    let p1 = brent(g, lo, hi, 1e-12 * psv)?.x;
    let p2 = gamma * p1 - f2;
    let (p1, p2) = (Pressure::new(p1), Pressure::new(p2));
    let (p_le, x) = load_pressure_and_x(p1, p2, ps, gamma);
    Ok(SteadyPressures { p1, p2, p_le, x })
}

/// X under load: the root of eq 3.4 generalised to a non-zero effective
/// load pressure, i.e. with the chamber pressures of eqs 2.21, 2.22 put into
/// the orifice flows and `Q1 = gamma Q2` (steady motion):
///
/// `a sqrt(K Ps - K p1) - b sqrt(K p1) = gamma [a sqrt(K p2) - b sqrt(K Ps - K p2)]`,
/// `K p1 = X Ps + gamma^2 pi Ps`, `K p2 = gamma X Ps - pi Ps`,
/// `pi = (1 + gamma)/2 * P_LE / Ps`, `K = 1 + gamma^3`.
///
/// At `p_le_over_ps = 0` this is [`x_factor`]; outside the underlap it is 1 or
/// `gamma^2` whatever the load. Inside the underlap the thesis (and Leaney)
/// use the zero-load X for every load; this function gives the X that makes
/// the generalised model's steady state equal the two-chamber one
/// ([`steady_pressures_two_chamber`]). With the load the four radicals are
/// independent and the squared equation is a genuine quartic, so this is
/// solved by Brent (absolute tolerance `tol` on X).
///
/// Error for bad input, or when no X keeps both chamber pressures in
/// `[0, Ps]` ([`XFactorError::LoadBeyondSupply`]).
pub fn x_factor_loaded(
    gamma: f64,
    travel: f64,
    p_le_over_ps: f64,
    tol: f64,
) -> Result<f64, XFactorError> {
    check_inputs(gamma, travel)?;
    if !p_le_over_ps.is_finite() {
        return Err(XFactorError::ParameterOutOfRange {
            what: "p_le_over_ps",
            value: p_le_over_ps,
            why: "must be finite",
        });
    }
    if !(tol.is_finite() && tol > 0.0) {
        return Err(XFactorError::ToleranceOutOfRange { tol });
    }
    let k = 1.0 + gamma * gamma * gamma;
    let pi = 0.5 * (1.0 + gamma) * p_le_over_ps;
    let g2 = gamma * gamma;
    let none = XFactorError::LoadBeyondSupply {
        travel,
        p_le_over_ps,
    };
    // both chamber pressures in [0, Ps]
    let lo = (-g2 * pi).max(pi / gamma);
    let hi = (k - g2 * pi).min((k + pi) / gamma);
    if lo > hi {
        return Err(none);
    }
    let (x_edge_ext, x_edge_ret) = (1.0, g2);
    if travel >= 1.0 || travel <= -1.0 {
        let x = if travel >= 1.0 {
            x_edge_ext
        } else {
            x_edge_ret
        };
        return if (lo..=hi).contains(&x) {
            Ok(x)
        } else {
            Err(none)
        };
    }
    let (a, b) = (1.0 + travel, 1.0 - travel);
    // radicands clamped at 0 only against rounding at the bracket ends, which
    // are computed to make them exactly 0
    let f = |x: f64| {
        let r1 = (k - x - g2 * pi).max(0.0);
        let r2 = (x + g2 * pi).max(0.0);
        let r3 = (gamma * x - pi).max(0.0);
        let r4 = (k - gamma * x + pi).max(0.0);
        a * r1.sqrt() - b * r2.sqrt() - gamma * (a * r3.sqrt() - b * r4.sqrt())
    };
    let (flo, fhi) = (f(lo), f(hi));
    if flo < 0.0 || fhi > 0.0 {
        return Err(none);
    }
    Ok(brent(f, lo, hi, tol)?.x)
}
