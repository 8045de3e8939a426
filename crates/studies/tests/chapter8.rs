//! The chapter-8 matrix: the ledger closes on every scenario, the
//! hybrid beats the valve drive, the closed forms of the square wave, and
//! bad scenarios are refused by name.

use hydrocyl_energy::ledger::trapezoid;
use hydrocyl_energy::EnergyError;
use hydrocyl_studies::chapter8::{
    base_matrix, run_scenario, scenarios_for, thesis_efficiency, Drive, FrictionCase, Outcome,
    Plan, Scenario, Wave,
};
use std::sync::OnceLock;

const CLOSURE: f64 = 1e-3;

/// `hybrid ±100 mm/s square 0 kg` and `valve` at the same scenario, as
/// `cargo xtask energy` measures them with the presets' per-direction seal
/// bound [%]: the one base scenario where hydrocyl's hybrid is behind
/// (`chapter8::HYBRID_NOT_AHEAD`; Table 8-2: 14.60 vs 8.59 %).
const HYBRID_PCT: f64 = 5.13;
/// See [`HYBRID_PCT`].
const VALVE_PCT: f64 = 5.50;

/// A short plan for tests: the run starts at rest and the ledger covers the
/// whole of one period (start-up included), so the runs stay short.
fn short() -> Plan {
    Plan {
        warmup_periods: 0,
        measured_periods: 1,
        sample_s: 5e-3,
        ..Plan::default()
    }
}

/// Every scenario of the tests, run once and shared.
fn matrix() -> &'static Vec<Outcome> {
    static M: OnceLock<Vec<Outcome>> = OnceLock::new();
    M.get_or_init(|| {
        let valve = Drive::wang_valve_c10().unwrap();
        let hybrid = Drive::wang_hybrid();
        let mut jobs: Vec<(Drive, Scenario)> = base_matrix()
            .into_iter()
            .map(|s| {
                let d = if s.system == "valve" {
                    valve.clone()
                } else {
                    hybrid.clone()
                };
                (d, s)
            })
            .collect();
        // the valve drive with K = 0 (the named variant `valve-k0`): the
        // closed form of the square wave below
        for s in scenarios_for("valve-k0") {
            if s.wave == Wave::Square && s.load_kg == 0.0 {
                jobs.push((valve.clone(), s));
            }
        }
        let plan = short();
        let k0 = Plan {
            friction: FrictionCase::WithoutSealTerm,
            ..short()
        };
        std::thread::scope(|scope| {
            let half = jobs.len() / 2;
            let (a, b) = jobs.split_at(half);
            let run_all = |js: &[(Drive, Scenario)]| -> Vec<Outcome> {
                js.iter()
                    .map(|(d, s)| {
                        let p = if s.system.ends_with("-k0") {
                            &k0
                        } else {
                            &plan
                        };
                        run_scenario(d, s, p).unwrap_or_else(|e| panic!("{}: {e}", s.label()))
                    })
                    .collect()
            };
            let h = scope.spawn(move || run_all(b));
            let mut out = run_all(a);
            out.extend(h.join().unwrap());
            out
        })
    })
}

mod chapter8 {
    use super::*;

    #[test]
    fn ledger_closes_on_every_scenario_and_variant() {
        let m = matrix();
        assert!(m.len() >= 16);
        for o in m {
            let l = &o.ledger;
            assert!(
                l.error.abs() < CLOSURE,
                "{}: balance error {:.3e}",
                o.scenario.label(),
                l.error
            );
            // chattering, cavitating runs (the solenoid variants): the
            // cross-check of storage against the end states is looser
            let limit = if o.cavitation_entries() > 0.0 {
                3e-3
            } else {
                CLOSURE
            };
            assert!(
                l.storage_error.abs() < limit,
                "{}: storage error {:.3e}",
                o.scenario.label(),
                l.storage_error
            );
            // nothing is created: every loss is non-negative
            for t in &l.losses {
                assert!(
                    t.energy_j > -1e-9 * l.energy_in_j,
                    "{}: {} {}",
                    o.scenario.label(),
                    t.name,
                    t.energy_j
                );
            }
            assert!(o.efficiency > 0.0 && o.efficiency < 1.0);
        }
    }

    /// Tables 8-2/8-3 have the hybrid ahead in all eight base scenarios;
    /// hydrocyl has it ahead in every one but those of
    /// `chapter8::HYBRID_NOT_AHEAD`, where it states the disagreement: the
    /// valve drive is ahead there, by the margin measured (docs/energy.md,
    /// "Where hydrocyl differs"). A list gone stale (hybrid ahead after all)
    /// fails as well as a new disagreement.
    #[test]
    fn hybrid_beats_valve_except_where_hydrocyl_says_it_does_not() {
        let m = matrix();
        for sc in scenarios_for("valve") {
            let find = |sys: &str| {
                m.iter()
                    .find(|o| {
                        o.scenario.system == sys
                            && o.scenario.speed_mm_s == sc.speed_mm_s
                            && o.scenario.wave == sc.wave
                            && o.scenario.load_kg == sc.load_kg
                    })
                    .unwrap()
            };
            let (v, h) = (find("valve"), find("hybrid"));
            if sc.hybrid_not_ahead() {
                // ±100 mm/s square, no load: measured HYBRID_PCT vs VALVE_PCT
                let (hp, vp) = (100.0 * h.efficiency, 100.0 * v.efficiency);
                assert!(
                    (hp - HYBRID_PCT).abs() < 0.2 && (vp - VALVE_PCT).abs() < 0.2 && hp < vp,
                    "{}: hybrid {hp:.2} % vs valve {vp:.2} % (measured {HYBRID_PCT} / {VALVE_PCT} %)",
                    sc.label()
                );
            } else {
                assert!(
                    h.efficiency > v.efficiency,
                    "{}: hybrid {} <= valve {}",
                    sc.label(),
                    h.efficiency,
                    v.efficiency
                );
            }
        }
    }

    /// The valve drive's input is the supply's, all of it lost at the
    /// metering edges but the cylinder's output (no load): E_in = E_edges +
    /// E_out + storage.
    #[test]
    fn valve_drive_input_goes_to_the_edges_and_the_cylinder() {
        for o in matrix().iter().filter(|o| o.scenario.system == "valve") {
            let l = &o.ledger;
            let rest = l.energy_in_j - l.loss("valve") - l.cylinder_out_j;
            assert!(
                rest.abs() < 0.02 * l.energy_in_j,
                "{}: {rest} J unaccounted by edges + output",
                o.scenario.label()
            );
        }
    }

    /// Without load and with K = 0, the valve drive's square-wave efficiency
    /// has a closed form: the supply gives `Ps A v` over each half period and
    /// the cylinder puts out the steady friction `g(v) v`, so
    /// `η = (g_ext(v) + g_ret(v)) / (Ps (A1 + A2))` — 2.57 % at 50 mm/s.
    #[test]
    fn valve_square_efficiency_is_friction_over_supply_force() {
        let w = hydrocyl_friction::Wang::table_5_8();
        let runs: Vec<_> = matrix()
            .iter()
            .filter(|o| o.scenario.system == "valve-k0")
            .collect();
        assert_eq!(runs.len(), 2);
        for o in runs.into_iter().filter(|o| {
            o.scenario.system == "valve-k0"
                && o.scenario.wave == Wave::Square
                && o.scenario.load_kg == 0.0
        }) {
            let v = o.scenario.speed();
            let eta =
                (w.extending.curve.g(v) + w.retracting.curve.g(v)) / (7.0e6 * (8.042e-4 + 5.50e-4));
            assert!(
                (o.efficiency / eta - 1.0).abs() < 0.05,
                "{}: {} vs closed form {eta}",
                o.scenario.label(),
                o.efficiency
            );
        }
    }

    /// The output of eq 8.7 from the ledger equals v (p1 A1 − p2 A2)
    /// integrated from the sampled channels of the power trace.
    #[test]
    fn eq_8_7_output_matches_the_sampled_trace() {
        for o in matrix().iter().take(16) {
            let tr = &o.trace;
            let n = tr.time_s.len() - 1;
            let sampled = trapezoid(&tr.time_s, &tr.power_out_w, 0, n);
            let e = o.ledger.cylinder_out_j;
            assert!(
                (sampled - e).abs() < 0.02 * e.abs().max(1.0),
                "{}: trace {sampled} J, ledger {e} J",
                o.scenario.label()
            );
            let sampled_in = trapezoid(&tr.time_s, &tr.power_in_w, 0, n);
            assert!(
                (sampled_in - o.ledger.energy_in_j).abs() < 0.02 * o.ledger.energy_in_j,
                "{}",
                o.scenario.label()
            );
        }
    }
}

mod tables {
    use super::*;

    #[test]
    fn thesis_values_are_there_for_the_base_matrix_only() {
        for s in base_matrix() {
            let e = thesis_efficiency(&s.system, s.speed_mm_s, s.wave, s.load_kg).unwrap();
            assert!(e > 0.0 && e < 0.3, "{}", s.label());
        }
        let close = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() < 1e-12);
        assert!(close(
            thesis_efficiency("valve", 50.0, Wave::Sine, 0.0),
            0.037
        ));
        assert!(close(
            thesis_efficiency("hybrid", 100.0, Wave::Square, 20.0),
            0.2714
        ));
        assert!(thesis_efficiency("valve", 75.0, Wave::Sine, 0.0).is_none());
        assert!(thesis_efficiency("hybrid-needle", 50.0, Wave::Sine, 0.0).is_none());
    }

    /// The fold of the seal term (`hydrocyl_studies::chapter7`):
    /// counting the return line's back pressure, Table 5-8's no-load set
    /// keeps a positive but thin reserve at every speed (its minimum lies
    /// between 50 and 100 mm/s), the heavier 38 kg set of Table 5-10 folds
    /// between 50 and 100 mm/s, and without K there is no fold at all.
    #[test]
    fn seal_term_fold_lies_between_50_and_100_mm_s() {
        use hydrocyl_studies::chapter7::{
            extend_fold_speed, extend_force_reserve, extend_reserve_minimum,
        };
        let rig = hydrocyl_system::hybrid::WangHybrid::preset();
        let w = hydrocyl_friction::Wang::table_5_8();
        let (v_min, r_min) = extend_reserve_minimum(&rig, &w);
        assert!(v_min > 0.05 && v_min < 0.1, "{v_min}");
        // thin: under 2 % of the friction it must overcome
        let g = w.extending.curve.g(v_min);
        assert!(r_min > 0.0 && r_min < 0.02 * g, "{r_min} of {g}");
        assert!(extend_fold_speed(&rig, &w).is_none());
        // the minimum is a minimum
        for dv in [-1e-3, 1e-3] {
            assert!(extend_force_reserve(&rig, &w, v_min + dv) > r_min);
        }
        let heavy = hydrocyl_friction::Wang::table_5_10_38kg();
        let fold = extend_fold_speed(&rig, &heavy).expect("the 38 kg set folds");
        assert!(fold > 0.05 && fold < 0.1, "{fold}");
        assert!(extend_force_reserve(&rig, &heavy, fold).abs() < 1e-6);
        assert!(extend_force_reserve(&rig, &heavy, 0.9 * fold) > 0.0);
        let mut no_k = w;
        no_k.extending.k_pressure = 0.0;
        assert!(extend_fold_speed(&rig, &no_k).is_none());
    }

    #[test]
    fn scenario_geometry_stays_inside_the_stroke() {
        for s in base_matrix() {
            // the travel of one half period, centred: inside ±150 mm
            assert!(s.start_position() < 0.0 && s.start_position() > -0.1);
            assert!((s.period() * s.speed() - 0.25).abs() < 1e-12);
        }
    }
}

mod bad_input {
    use super::*;

    #[test]
    fn bad_scenarios_are_refused_by_name() {
        let d = Drive::wang_hybrid();
        for (speed, load) in [(-50.0, 0.0), (f64::NAN, 0.0), (50.0, -1.0)] {
            let s = Scenario {
                system: "hybrid".into(),
                speed_mm_s: speed,
                wave: Wave::Sine,
                load_kg: load,
            };
            let e = run_scenario(&d, &s, &short()).unwrap_err();
            assert!(matches!(e, EnergyError::Scenario { .. }), "{e}");
        }
        let s = Scenario {
            system: "hybrid".into(),
            speed_mm_s: 50.0,
            wave: Wave::Sine,
            load_kg: 0.0,
        };
        let plan = Plan {
            measured_periods: 0,
            ..short()
        };
        assert!(run_scenario(&d, &s, &plan).is_err());
    }
}
