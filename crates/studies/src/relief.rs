//! The readings of relief valves 1 and 2 of the hybrid drive (issue 17 item 2;
//! thesis section 6.2.2.2, eqs 6.6–6.10, Appendix II `rlv_1.m`).
//!
//! `rlv_1.m` gives `K_v` = 8.2864e-8 and `P_m` = 16 062 537.57 Pa (160.6 bar),
//! computed for its own cracking pressure `pc2 = 1e5` Pa (1 bar). By eq 6.8
//! `P_m` is a function of the cracking pressure: the performance curve's slope
//! `R_a` (eq 6.9) is what characterises the valve, and
//! `P_m² − (2 p_c + R_a² K_v²) P_m + p_c² = 0` (corrected eq 6.8,
//! `hydrocyl_valves::relief`). A reading is therefore a cracking pressure and
//! a slope; the text leaves both open:
//! * `p_c`: 1 bar (`rlv_1.m`), 10.34 bar (the pilot valve's shift pressure,
//!   rigs.md's assumption and the preset's), or 40 bar (a mid setting of the
//!   RBAE's 1.7–210 bar range);
//! * `R_a`: the one that makes `P_m` = 160.6 bar at 1 bar (`rlv_1.m` read in
//!   Pa, `Q_m` = 19.9 l/min, twice the valve's 9.5 l/min rating), or the one
//!   that makes `P_m` = 16.06 bar at 1 bar (the same digits read one decade
//!   lower, `Q_m` = 6.3 l/min, within the rating).
//!
//! [`readings`] gives each pair both ways: "derived" (`P_m` from `R_a` through
//! eq 6.8 at the reading's `p_c`, the consistent reading) and "stated"
//! (`P_m` kept as `rlv_1.m` states it whatever `p_c` is, the preset's reading,
//! which changes `R_a`).

use crate::chapter8::Drive;
use hydrocyl_ports::Pressure;
use hydrocyl_system::hybrid::WangHybrid;
use hydrocyl_valves::relief::{full_open_from_curve, ReliefValve, RBAE_KV, RBAE_PM};
use serde::Serialize;

/// `rlv_1.m`'s own cracking pressure, `pc2 = 1e5` \[Pa\].
pub const RLV_1_CRACKING: f64 = hydrocyl_valves::relief::RLV_1_CRACKING.si();

/// The cracking pressures of the sensitivity table \[Pa\].
pub const CRACKING: [f64; 3] = [1.0e5, 10.34e5, 40.0e5];

/// The two readings of `rlv_1.m`'s `P_m` at its 1-bar cracking pressure \[Pa\].
pub const PM_AT_1_BAR: [f64; 2] = [RBAE_PM.si() / 10.0, RBAE_PM.si()];

/// One reading of relief valves 1 and 2.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Reading {
    /// Cracking pressure `p_c` \[Pa\].
    pub cracking_pa: f64,
    /// `P_m` of `rlv_1.m` at 1 bar this reading starts from \[Pa\].
    pub pm_at_1_bar_pa: f64,
    /// `true`: `P_m` derived from `R_a` through eq 6.8 at `p_c`; `false`:
    /// `P_m` stated as at 1 bar (`R_a` changes with `p_c`).
    pub derived: bool,
    /// The resulting `P_m` \[Pa\].
    pub full_open_pa: f64,
    /// The resulting slope `R_a` \[Pa·s·m⁻³\].
    pub ra: f64,
    /// The resulting `Q_m = K_v √P_m` \[m³/s\].
    pub q_max_m3_s: f64,
}

impl Reading {
    /// A short name, e.g. `pc 10.34 bar, R_a of Pm 160.6 bar, derived`.
    pub fn label(&self) -> String {
        format!(
            "pc {} bar, Pm(1 bar) {:.2} bar, {}",
            trim(self.cracking_pa / 1e5),
            self.pm_at_1_bar_pa / 1e5,
            if self.derived { "derived" } else { "stated" }
        )
    }

    /// The relief valve of this reading.
    pub fn valve(&self) -> ReliefValve {
        ReliefValve {
            cracking: Pressure::new(self.cracking_pa),
            full_open: Pressure::new(self.full_open_pa),
            kv: RBAE_KV,
        }
    }

    /// The `wang-hybrid` preset with relief valves 1 and 2 of this reading.
    pub fn drive(&self) -> Drive {
        let mut rig = WangHybrid::preset();
        rig.relief_pilot = self.valve();
        Drive::Hybrid(Box::new(rig))
    }
}

fn trim(x: f64) -> String {
    let s = format!("{x:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// `R_a` of the curve through `(p_c, P_m)` with the RBAE's `K_v` \[Pa·s·m⁻³\].
pub fn slope(cracking: f64, full_open: f64) -> f64 {
    (full_open - cracking) / (RBAE_KV * full_open.sqrt())
}

/// The reading `(p_c, P_m at 1 bar, derived?)`; `None` where it has no valve
/// (a stated `P_m` at or below `p_c`).
pub fn reading(cracking: f64, pm_at_1_bar: f64, derived: bool) -> Option<Reading> {
    let ra_1 = slope(RLV_1_CRACKING, pm_at_1_bar);
    let pm = if derived {
        full_open_from_curve(Pressure::new(cracking), ra_1, RBAE_KV).si()
    } else {
        pm_at_1_bar
    };
    if pm <= cracking {
        return None;
    }
    Some(Reading {
        cracking_pa: cracking,
        pm_at_1_bar_pa: pm_at_1_bar,
        derived,
        full_open_pa: pm,
        ra: slope(cracking, pm),
        q_max_m3_s: RBAE_KV * pm.sqrt(),
    })
}

/// Every reading of the sensitivity table: [`CRACKING`] × [`PM_AT_1_BAR`] ×
/// {derived, stated}, those that have a valve, the 1-bar pair once.
pub fn readings() -> Vec<Reading> {
    let mut v = Vec::new();
    for derived in [true, false] {
        for pm in PM_AT_1_BAR {
            for pc in CRACKING {
                // at rlv_1.m's own 1 bar the two readings are the same valve
                if !derived && pc == RLV_1_CRACKING {
                    continue;
                }
                if let Some(r) = reading(pc, pm, derived) {
                    v.push(r);
                }
            }
        }
    }
    v
}

/// The pilot valve's shift pressure `p_shift = k_s x_o` \[Pa\]: the pump-line
/// pressure difference below which the four-way valve keeps the return line
/// shut. Every litre the pump moves while the drive runs is pushed against at
/// least this difference, so the pump's input is at least `p_shift ∫|Q_p| dt`
/// and the hybrid's efficiency is capped by `E_out / (p_shift ∫|Q_p| dt)`.
/// Zero for a critically lapped spool (overlap 0, which the valve accepts).
pub fn shift_pressure(rig: &WangHybrid) -> f64 {
    rig.four_way.shift_pressure().si()
}

/// The cap of [`shift_pressure`] on a square wave at steady speed with the
/// friction `f_ext`, `f_ret` \[N\] (magnitudes, ≥ 0) as the only output
/// \[-\]: the pump delivers `A1 v` and `A2 v` against at least `p_shift`, the
/// cylinder puts out `(f_ext + f_ret) v`, and the pump's input is also at
/// least that output (energy is not made), so
/// `η ≤ (f_ext + f_ret) / max(p_shift (A1 + A2), f_ext + f_ret)`.
///
/// The shift-pressure bound alone, `(f_ext + f_ret) / (p_shift (A1 + A2))`,
/// exceeds 1 once `p_shift (A1 + A2) < f_ext + f_ret` and is infinite at
/// overlap 0 (`p_shift` = 0: the valve then charges nothing, and only the
/// energy bound is left), where the cap is 1; it goes to 1 continuously as
/// the overlap goes to 0. With no friction there is no output: the cap is 0.
pub fn square_cap(rig: &WangHybrid, f_ext: f64, f_ret: f64) -> f64 {
    let (a1, a2) = (rig.cylinder.area_1.si(), rig.cylinder.area_2.si());
    let out = (f_ext + f_ret).max(0.0);
    if out == 0.0 {
        return 0.0;
    }
    out / (shift_pressure(rig) * (a1 + a2)).max(out)
}

/// [`square_cap`] with the friction the rig measured at ±48/−49 mm/s
/// (Table 5-3: 220 N extending, 162.2 N retracting) \[-\].
pub fn table_5_3_cap(rig: &WangHybrid) -> f64 {
    let t = hydrocyl_friction::seal::TABLE_5_3;
    square_cap(rig, t[0].1, -t[t.len() - 1].1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derived_readings_keep_the_slope_and_stated_ones_keep_pm() {
        for pm1 in PM_AT_1_BAR {
            let ra = slope(RLV_1_CRACKING, pm1);
            for pc in CRACKING {
                let d = reading(pc, pm1, true).unwrap();
                // eq 6.9 and the orifice meet at P_m with the same R_a
                assert!((d.ra / ra - 1.0).abs() < 1e-9, "{}", d.label());
                assert!(d.full_open_pa > pc);
                let q = RBAE_KV * d.full_open_pa.sqrt();
                assert!((pc + ra * q - d.full_open_pa).abs() < 1e-6 * d.full_open_pa);
                if let Some(s) = reading(pc, pm1, false) {
                    assert_eq!(s.full_open_pa, pm1);
                }
            }
            // at rlv_1.m's own 1 bar both readings are the same valve
            let (d, s) = (
                reading(RLV_1_CRACKING, pm1, true).unwrap(),
                reading(RLV_1_CRACKING, pm1, false).unwrap(),
            );
            assert!((d.full_open_pa / s.full_open_pa - 1.0).abs() < 1e-12);
        }
        // rlv_1.m's P_m = 160.6 bar at 1 bar is R_a = 8.01 bar per l/min,
        // Q_m = 19.9 l/min; the preset's stated reading at 10.34 bar has 7.54
        let r = reading(RLV_1_CRACKING, PM_AT_1_BAR[1], true).unwrap();
        let bar_per_lpm = 1e5 / (1e-3 / 60.0);
        assert!(
            (r.ra / bar_per_lpm - 8.01).abs() < 0.01,
            "{}",
            r.ra / bar_per_lpm
        );
        assert!((r.q_max_m3_s * 6e4 - 19.9).abs() < 0.05);
        let s = reading(10.34e5, PM_AT_1_BAR[1], false).unwrap();
        assert!(
            (s.ra / bar_per_lpm - 7.54).abs() < 0.01,
            "{}",
            s.ra / bar_per_lpm
        );
        // the preset is the derived reading of rlv_1.m at 10.34 bar
        let p = WangHybrid::preset().relief_pilot;
        let d = reading(10.34e5, PM_AT_1_BAR[1], true).unwrap();
        assert!((p.full_open.si() / d.full_open_pa - 1.0).abs() < 1e-12);
        assert!((p.ra() / r.ra - 1.0).abs() < 1e-9);
        // a stated 16.06 bar is no valve at 40 bar
        assert!(reading(40e5, PM_AT_1_BAR[0], false).is_none());
        assert_eq!(readings().len(), 9);
    }

    #[test]
    fn shift_pressure_is_the_pilot_valves_150_psi() {
        let rig = WangHybrid::preset();
        let p = shift_pressure(&rig);
        assert!((p - 10.34e5).abs() < 1e3, "{p}");
        // 382.2 N over 10.34 bar × 13.54 cm²
        let c = table_5_3_cap(&rig);
        assert!((c - 0.273).abs() < 1e-3, "{c}");
    }

    /// A critically lapped pilot valve (overlap 0, shift pressure 0) leaves
    /// only the energy bound: the cap is 1, not infinite, and the cap of a
    /// shrinking overlap rises to it and stays there (continuous at 0); the
    /// preset's 0.273 is the shift-pressure bound's, below 1.
    #[test]
    fn the_cap_at_zero_overlap_is_the_energy_bound_and_continuous() {
        use hydrocyl_ports::Position;
        let with_overlap = |mm: f64| {
            let mut rig = WangHybrid::preset();
            rig.four_way.overlap = Position::from_mm(mm);
            rig
        };
        let rig = with_overlap(0.0);
        assert_eq!(shift_pressure(&rig), 0.0);
        assert_eq!(table_5_3_cap(&rig), 1.0);
        assert_eq!(square_cap(&rig, 0.0, 0.0), 0.0);
        // the shift-pressure bound reaches 1 at x_o = F / (k_s (A1 + A2))
        let pre = WangHybrid::preset();
        let area = pre.cylinder.area_1.si() + pre.cylinder.area_2.si();
        let t = hydrocyl_friction::seal::TABLE_5_3;
        let f = t[0].1 - t[t.len() - 1].1;
        let knee_mm = f / (pre.four_way.spring_rate * area) * 1e3;
        assert!(knee_mm > 0.0 && knee_mm < 0.75, "{knee_mm}");
        let mut last = table_5_3_cap(&pre);
        for k in (0..=60).rev() {
            let x = 0.75 * f64::from(k) / 60.0;
            let c = table_5_3_cap(&with_overlap(x));
            assert!(
                c.is_finite() && c <= 1.0 && c >= last - 1e-15,
                "{x} mm: {c}"
            );
            if x <= knee_mm {
                assert_eq!(c, 1.0, "{x} mm");
            }
            last = c;
        }
        for x in [1e-3, 1e-6, 1e-9] {
            assert!((table_5_3_cap(&with_overlap(x)) - 1.0).abs() < 1e-12);
        }
        // just above the knee the cap is just below 1
        let c = table_5_3_cap(&with_overlap(knee_mm * (1.0 + 1e-9)));
        assert!(c < 1.0 && 1.0 - c < 1e-8, "{c}");
    }
}
