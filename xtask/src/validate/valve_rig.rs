//! Validation section: the valve-controlled rig `leaney-moog` (thesis chapter 3).
//!
//! * the three chapter-3 tests (square ±90 mm/s, sine inside a 20 % underlap,
//!   sawtooth across null) with the three actuator formulations: NRMSE between
//!   them, wall times beside Table 3-5, integrator statistics, stroke and
//!   pressure range, cavitation;
//! * the pressure transition across the underlap (Fig 3-13) against the
//!   X-factor steady pressures;
//! * chamber mass balance and the energy ledger on the square wave;
//! * convergence of the orifice regularisation and agreement of the solvers;
//! * SVG plots in `target/validate/valve-rig/`.

use crate::report::Section;
use hydrocyl_friction::FrictionInput;
use hydrocyl_ports::{Force, Pressure, Velocity};
use hydrocyl_studies::chapter3::{self, Case, Comparison, COMPARED};
use hydrocyl_system::circuit::LEDGER_TERMS;
use hydrocyl_system::run::{nrmse, Run, RunOptions, Solver};
use hydrocyl_system::simulation::Simulation;
use hydrocyl_system::valve_rig::ValveRig;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Tolerance of the formulation comparisons: tight, so that the numerical-X
/// and analytical-X runs differ only by the root solver, not by the step
/// sequences an adaptive solver picks (at rtol 1e-6 they differ at ~5e-6).
const RTOL: f64 = 1e-8;

fn out_dir() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let root = root.canonicalize().unwrap_or(root);
    root.join("target").join("validate").join("valve-rig")
}

/// Runs this section and returns what it measured.
pub fn section() -> Section {
    let mut s = Section::new("valve-rig (leaney-moog, chapter 3)");
    let dir = out_dir();
    if let Err(e) = std::fs::create_dir_all(&dir) {
        s.check(
            "plot directory",
            e.to_string(),
            dir.display().to_string(),
            false,
        );
    }
    let opts = RunOptions {
        rtol: RTOL,
        ..RunOptions::dp45()
    };
    let cases = [
        chapter3::square_wave(),
        chapter3::underlap_sine(),
        chapter3::sawtooth(),
    ];
    let mut table = Vec::new();
    for case in cases {
        let case = match case {
            Ok(c) => c,
            Err(e) => {
                s.check(
                    "chapter-3 case set-up",
                    e.to_string(),
                    "a case".into(),
                    false,
                );
                continue;
            }
        };
        match best_of(7, &case, &opts) {
            Ok(cmp) => {
                formulation_checks(&mut s, &case, &cmp);
                table.push((case.clone(), cmp.clone()));
                plot_case(&mut s, &dir, &case, &cmp);
            }
            Err(e) => s.check(
                &format!("{}: runs", case.name),
                e.to_string(),
                "all three run".into(),
                false,
            ),
        }
    }
    timing_table(&mut s, &table);
    sweep(&mut s, &dir);
    balances(&mut s);
    regularisation(&mut s);
    solvers(&mut s);
    s.note(&format!("plots: {}", dir.display()));
    s
}

/// Runs the comparison `n` times and keeps, per formulation, the fastest
/// wall time (the machine is shared; the results are identical each time).
fn best_of(
    n: usize,
    case: &Case,
    opts: &RunOptions,
) -> Result<Comparison, hydrocyl_system::rig::RigError> {
    let mut best = Comparison::run(case, opts)?;
    for _ in 1..n {
        let c = Comparison::run(case, opts)?;
        for (b, (_, r)) in best.runs.iter_mut().zip(c.runs) {
            b.1.wall = b.1.wall.min(r.wall);
        }
    }
    Ok(best)
}

fn range(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(*x), b.max(*x))
        })
}

fn formulation_checks(s: &mut Section, case: &Case, cmp: &Comparison) {
    let rig = &case.rig;
    let (num, ana, fund) = (0, 1, 2);
    for ch in COMPARED {
        let e = cmp.nrmse(num, ana, ch, rig);
        s.check(
            &format!("{}: {ch} NRMSE numerical-X vs analytical-X", case.name),
            format!("{e:.2e}"),
            "<= 1e-6 (same equations)".into(),
            e <= 1e-6,
        );
    }
    let mut line = format!(
        "{}: NRMSE fundamental vs generalised (analytical X):",
        case.name
    );
    for ch in COMPARED {
        line.push_str(&format!(
            " {ch} {:.3} %",
            100.0 * cmp.nrmse(fund, ana, ch, rig)
        ));
    }
    s.note(&line);
    if case.name == "square" {
        let ev = cmp.nrmse(ana, fund, "velocity", rig);
        let ep = cmp.nrmse(ana, fund, "p_le", rig);
        s.check(
            "square: velocity NRMSE generalised vs fundamental",
            format!("{:.3} %", 100.0 * ev),
            "<= 2 %".into(),
            ev <= 0.02,
        );
        s.check(
            "square: P_LE NRMSE generalised vs fundamental",
            format!("{:.3} %", 100.0 * ep),
            "<= 5 %".into(),
            ep <= 0.05,
        );
    }
    let half = 0.5 * rig.cylinder.stroke_m;
    let ps = rig.supply.pressure_pa;
    for (f, r) in &cmp.runs {
        let (xmin, xmax) = range(r.channel("position").unwrap_or(&[]));
        s.check(
            &format!("{}/{}: piston within the stroke", case.name, f.name()),
            format!("[{:.4}, {:.4}] m", xmin, xmax),
            format!("[{:.2}, {:.2}] m", -half, half),
            xmin >= -half && xmax <= half,
        );
        let pmin = r.min_chamber_pressure();
        let pmax = ["p1", "p2"]
            .iter()
            .filter_map(|n| r.channel(n))
            .flat_map(|v| v.iter().copied())
            .fold(f64::NEG_INFINITY, f64::max);
        let cav = r.cavitation_entries();
        let inside = pmin >= -1.0 && pmax <= ps + 1.0;
        s.check(
            &format!(
                "{}/{}: p1, p2 in [0, Ps] or cavitation reported",
                case.name,
                f.name()
            ),
            format!(
                "[{:.2}, {:.2}] bar, {cav} cavitation entries",
                pmin / 1e5,
                pmax / 1e5
            ),
            "[0, 70] bar, else entries > 0".into(),
            inside || cav > 0,
        );
        s.note(&format!(
            "  {} {:<22} wall {:>8.2} ms  steps {:>6}  rejected {:>4}  rhs {:>7}  events {:>3}  X evaluations {}",
            case.name,
            f.name(),
            r.wall.as_secs_f64() * 1e3,
            r.stats.steps,
            r.stats.rejected,
            r.stats.rhs_evals,
            r.stats.events,
            r.diagnostic("cylinder.x_factor_evaluations").map_or("-".into(), |v| format!("{v}")),
        ));
    }
}

fn timing_table(s: &mut Section, table: &[(Case, Comparison)]) {
    s.note("");
    s.note(&format!(
        "Table 3-5 shape — wall time per run (hydrocyl DP45 rtol {RTOL:e}, best of 7, one core) beside the thesis's Simulink times:"
    ));
    s.note(&format!(
        "  {:<15} {:>16} {:>16} {:>16} {:>12} {:>12}",
        "test", "numerical X", "analytical X", "fundamental", "ours num/ana", "thesis num/ana"
    ));
    for (case, cmp) in table {
        let w: Vec<f64> = cmp.runs.iter().map(|(_, r)| r.wall.as_secs_f64()).collect();
        let th = case.thesis_seconds.unwrap_or([f64::NAN; 3]);
        s.note(&format!(
            "  {:<15} {:>8.2} ms/{:>5.2} s {:>8.2} ms/{:>5.2} s {:>8.2} ms/{:>5.2} s {:>12.2} {:>12.1}",
            case.name,
            w[0] * 1e3,
            th[0],
            w[1] * 1e3,
            th[1],
            w[2] * 1e3,
            th[2],
            w[0] / w[1],
            th[0] / th[1]
        ));
    }
    s.note("  (ours: ms for 6 s simulated; thesis: s, simulated span not stated. Inside the underlap Brent");
    s.note("   costs a few times the quartic root per call; outside it both return 1 or γ² at once. The");
    s.note("   thesis's factor ~200 came from MATLAB fsolve called per step, not from the mathematics.)");
}

/// One underlap sweep: the run, the X-factor steady pressures along it, and
/// the largest deviations during the ramp from the X-factor and from the
/// exact two-chamber steady states \[Pa\].
struct Sweep {
    run: Run,
    x_steady: Vec<(f64, f64, f64)>,
    dev_x: f64,
    dev_exact: f64,
}

fn run_sweep(sweep_s: f64) -> Result<Sweep, String> {
    let case = chapter3::underlap_sweep(sweep_s).map_err(|e| e.to_string())?;
    let opts = RunOptions {
        rtol: RTOL,
        ..RunOptions::dp45()
    };
    let r = case
        .rig
        .simulate(case.command.clone(), &case.times, &opts)
        .map_err(|e| e.to_string())?;
    let rig = &case.rig;
    let ps = Pressure::new(rig.supply.pressure_pa);
    let u0 = rig.valve.underlap_m;
    let a1 = hydrocyl_ports::Area::new(rig.cylinder.area_1_m2);
    let gamma = rig.cylinder.area_1_m2 / rig.cylinder.area_2_m2;
    let fr = rig.friction_model();
    let ch = |n: &str| {
        r.channel(n)
            .map(<[f64]>::to_vec)
            .ok_or(format!("no channel {n}"))
    };
    let (p1, p2, xs, v) = (ch("p1")?, ch("p2")?, ch("spool")?, ch("velocity")?);
    let (mut dev_x, mut dev_exact): (f64, f64) = (0.0, 0.0);
    let mut x_steady = Vec::new();
    for k in 0..p1.len() {
        let t = r.time[k];
        let travel = xs[k] / u0;
        let load = Force::new(rig.load.external_force_n)
            + fr.steady_force(&FrictionInput::at_velocity(Velocity::new(v[k])));
        let sx = hydrocyl_xfactor::steady_pressures(travel.clamp(-1.0, 1.0), ps, gamma, a1, load)
            .map_err(|e| e.to_string())?;
        let se = hydrocyl_xfactor::steady_pressures_two_chamber(travel, ps, gamma, a1, load)
            .map_err(|e| e.to_string())?;
        x_steady.push((t, sx.p1.si(), sx.p2.si()));
        if t > 1.0 && t < 1.0 + sweep_s {
            dev_x = dev_x
                .max((p1[k] - sx.p1.si()).abs())
                .max((p2[k] - sx.p2.si()).abs());
            dev_exact = dev_exact
                .max((p1[k] - se.p1.si()).abs())
                .max((p2[k] - se.p2.si()).abs());
        }
    }
    Ok(Sweep {
        run: r,
        x_steady,
        dev_x,
        dev_exact,
    })
}

/// Fig 3-13: p1, p2 across the underlap against the X-factor steady state.
fn sweep(s: &mut Section, dir: &Path) {
    let ps = 7.0e6;
    let (fast, slow) = match (run_sweep(4.0), run_sweep(16.0)) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(e), _) | (_, Err(e)) => {
            s.check("underlap sweep: runs", e, "run".into(), false);
            return;
        }
    };
    let r = &fast.run;
    let (p1, p2) = (
        r.channel("p1").unwrap_or(&[]),
        r.channel("p2").unwrap_or(&[]),
    );
    let mut max_jump: f64 = 0.0;
    for k in 1..p1.len() {
        max_jump = max_jump
            .max((p1[k] - p1[k - 1]).abs())
            .max((p2[k] - p2[k - 1]).abs());
    }
    s.check(
        "underlap sweep +u0 → -u0 in 4 s: p1, p2 continuous (largest change per 1 ms)",
        format!("{:.3} bar", max_jump / 1e5),
        "< 1 % of Ps per ms".into(),
        max_jump < 0.01 * ps,
    );
    let ratio = fast.dev_exact / slow.dev_exact;
    s.check(
        "underlap sweep: lag behind the exact steady state, 4 s vs 16 s sweep",
        format!(
            "{:.2} % / {:.2} % of Ps (ratio {ratio:.2})",
            100.0 * fast.dev_exact / ps,
            100.0 * slow.dev_exact / ps
        ),
        "ratio 3..5 (quasi-static lag ∝ sweep rate)".into(),
        (3.0..=5.0).contains(&ratio),
    );
    s.check(
        "underlap sweep in 16 s: |p - exact two-chamber steady p|",
        format!("{:.3} % of Ps", 100.0 * slow.dev_exact / ps),
        "<= 1 %".into(),
        slow.dev_exact <= 0.01 * ps,
    );
    s.check(
        "underlap sweep in 16 s: |p - X-factor steady p| (zero-load X, friction load)",
        format!("{:.3} % of Ps", 100.0 * slow.dev_x / ps),
        "<= 2 %".into(),
        slow.dev_x <= 0.02 * ps,
    );
    let tp = |ch: &[f64]| {
        r.time
            .iter()
            .copied()
            .zip(ch.iter().copied())
            .collect::<Vec<_>>()
    };
    let series = vec![
        ("p1 fundamental".to_string(), tp(p1)),
        ("p2 fundamental".to_string(), tp(p2)),
        (
            "p1 X-factor steady".to_string(),
            fast.x_steady.iter().map(|(t, a, _)| (*t, *a)).collect(),
        ),
        (
            "p2 X-factor steady".to_string(),
            fast.x_steady.iter().map(|(t, _, b)| (*t, *b)).collect(),
        ),
    ];
    if let Err(e) = plot(
        &dir.join("underlap-sweep.svg"),
        "Fig 3-13: p1, p2 as the spool sweeps +u0 to -u0 (1 s to 5 s)",
        "pressure [bar]",
        1e-5,
        &series,
    ) {
        s.check("plot underlap-sweep.svg", e, "written".into(), false);
    }
}

/// Chamber mass balance (quadratures) and the energy ledger on the square wave.
fn balances(s: &mut Section) {
    let case = match chapter3::square_wave() {
        Ok(c) => c,
        Err(e) => {
            s.check("balances: set-up", e.to_string(), "".into(), false);
            return;
        }
    };
    let rig = &case.rig;
    let c = match rig.circuit(case.command.clone()) {
        Ok(c) => c,
        Err(e) => {
            s.check("balances: build", e.to_string(), "".into(), false);
            return;
        }
    };
    let opts = RunOptions {
        rtol: RTOL,
        quadratures: true,
        ledger: true,
        ..RunOptions::dp45()
    };
    let mut sim = Simulation::of_circuit(c).options(opts);
    let r = match sim.run(&case.times) {
        Ok(r) => r,
        Err(e) => {
            s.check("balances: run", e.to_string(), "".into(), false);
            return;
        }
    };
    let c = sim.circuit();
    let (res1, res2, swept) = mass_balance(rig, c, &r);
    for (i, res) in [(1, res1), (2, res2)] {
        s.check(
            &format!("square: chamber {i} mass balance |∫(Q{i} - A{i} v - V{i}/B dp{i}/dt) dt| / swept volume"),
            format!("{:.2e}", res.abs() / swept),
            "<= 1e-6".into(),
            res.abs() / swept <= 1e-6,
        );
    }
    // energy ledger: Σ∫source = Σ∫(dissipated + storage + load)
    let last = r.state(r.time.len() - 1);
    let o = c.ledger_offset();
    let n = c.components().count();
    let (mut src, mut out) = (0.0, 0.0);
    for i in 0..n {
        let k = o + LEDGER_TERMS * i;
        src += last[k];
        out += last[k + 1] + last[k + 2] + last[k + 3];
    }
    let rel = (src - out).abs() / src.abs().max(1e-30);
    s.check(
        "square: energy ledger closes (|Σ in − Σ(dissipated + stored + load)| / Σ in)",
        format!("{rel:.2e} (in {:.1} J)", src),
        "<= 1e-3".into(),
        rel <= 1e-3,
    );
    let eff_out = last[o + LEDGER_TERMS * (n - 2) + 3];
    s.note(&format!(
        "square: energy from supply {src:.1} J, to external load {eff_out:.1} J (no external force), dissipated in valve {:.1} J, friction {:.1} J",
        last[o + LEDGER_TERMS * c.component_index("valve").unwrap_or(0) + 1],
        last[o + LEDGER_TERMS * c.component_index("friction").unwrap_or(0) + 1]
    ));
}

/// `(residual 1, residual 2, swept volume)` of the chamber mass balances:
/// `∫Q_in dt − A Δx·(±1) − [V p/B] ± ∫p A v/B dt`.
pub fn mass_balance(rig: &ValveRig, c: &hydrocyl_system::Circuit, r: &Run) -> (f64, f64, f64) {
    let i = c.component_index("cylinder").unwrap_or(0);
    let q = c.quadrature_range(i);
    let st = c.state_range(i);
    let li = c.component_index("load").unwrap_or(0);
    let ls = c.state_range(li);
    let cyl = rig.cylinder_model();
    let b = rig.fluid.bulk_modulus_pa;
    let first = r.state(0);
    let last = r.state(r.time.len() - 1);
    let (x0, x1) = (first[ls.start], last[ls.start]);
    let v = |x: f64| cyl.volumes(hydrocyl_ports::Position::new(x));
    let (v10, v20) = v(x0);
    let (v11, v21) = v(x1);
    let (p10, p20) = (first[st.start], first[st.start + 1]);
    let (p11, p21) = (last[st.start], last[st.start + 1]);
    // chamber 1: ∫Q1 − A1 Δx − ∫V1/B dp1, ∫V1/B dp1 = [V1 p1/B] − ∫p1 A1 v/B
    let res1 = last[q.start]
        - cyl.area_1.si() * (x1 - x0)
        - ((v11.si() * p11 - v10.si() * p10) / b - last[q.start + 2]);
    // chamber 2: ∫Q2in + A2 Δx − ∫V2/B dp2, ∫V2/B dp2 = [V2 p2/B] + ∫p2 A2 v/B
    let res2 = last[q.start + 1] + cyl.area_2.si() * (x1 - x0)
        - ((v21.si() * p21 - v20.si() * p20) / b + last[q.start + 3]);
    let xs: Vec<f64> = (0..r.time.len()).map(|k| r.state(k)[ls.start]).collect();
    let travel: f64 = xs.windows(2).map(|w| (w[1] - w[0]).abs()).sum();
    (res1, res2, cyl.area_1.si() * travel)
}

/// The orifice regularisation converges as its transition pressure shrinks
/// (on the end-stop case, where open edges see pressure drops near zero),
/// and the piston is held at the stop.
fn regularisation(s: &mut Section) {
    let case = chapter3::end_stop();
    let opts = RunOptions {
        rtol: RTOL,
        ..RunOptions::dp45()
    };
    let sim = |dpt: f64| {
        let mut rig = case.rig.clone();
        rig.valve.regularisation_pa = dpt;
        rig.simulate(case.command.clone(), &case.times, &opts)
    };
    let reference = match sim(1.0) {
        Ok(r) => r,
        Err(e) => {
            s.check(
                "end-stop: reference run (Δp_t = 1 Pa)",
                e.to_string(),
                "runs".into(),
                false,
            );
            return;
        }
    };
    let (xmin, xmax) = range(reference.channel("position").unwrap_or(&[]));
    let half = 0.5 * case.rig.cylinder.stroke_m;
    s.check(
        "end-stop: piston held within the stroke (event-based hard stop)",
        format!(
            "[{xmin:.6}, {xmax:.6}] m, {} impacts",
            reference.diagnostic("load.stop_impacts").unwrap_or(0.0)
        ),
        format!("<= {half} m, 1 impact"),
        xmax <= half && xmin >= -half && reference.diagnostic("load.stop_impacts") == Some(1.0),
    );
    let mut errs = Vec::new();
    for dpt in [1e4, 1e3, 1e2] {
        match sim(dpt) {
            Ok(r) => errs.push((
                dpt,
                nrmse(
                    r.channel("p2").unwrap_or(&[]),
                    reference.channel("p2").unwrap_or(&[]),
                ),
            )),
            Err(e) => s.check(
                &format!("end-stop: run with Δp_t = {dpt} Pa"),
                e.to_string(),
                "runs".into(),
                false,
            ),
        }
    }
    let line: Vec<String> = errs
        .iter()
        .map(|(d, e)| format!("{d:.0e} Pa: {e:.2e}"))
        .collect();
    let monotone = errs.len() == 3 && errs.windows(2).all(|w| w[1].1 < w[0].1);
    let default_err = errs
        .iter()
        .find(|(d, _)| *d == 1e3)
        .map_or(f64::NAN, |e| e.1);
    s.check(
        "end-stop: p2 NRMSE vs Δp_t = 1 Pa, shrinking with Δp_t",
        line.join(", "),
        "decreasing; default 1e3 Pa <= 1e-3".into(),
        monotone && default_err <= 1e-3,
    );
}

/// DP45, Rosenbrock and RK4 agree on the square wave (fundamental).
fn solvers(s: &mut Section) {
    let case = match chapter3::square_wave() {
        Ok(c) => c,
        Err(_) => return,
    };
    let sim = |solver, rtol| {
        case.rig.simulate(
            case.command.clone(),
            &case.times,
            &RunOptions {
                solver,
                rtol,
                rk4_step: 2e-5,
                ..RunOptions::default()
            },
        )
    };
    let Ok(reference) = sim(Solver::Dp45, 1e-10) else {
        s.check("solvers: reference", "failed".into(), "".into(), false);
        return;
    };
    for solver in [Solver::Dp45, Solver::Rosenbrock, Solver::Rk4] {
        match sim(solver, 1e-6) {
            Ok(r) => {
                let e = nrmse(
                    r.channel("velocity").unwrap_or(&[]),
                    reference.channel("velocity").unwrap_or(&[]),
                );
                s.check(
                    &format!(
                        "square/fundamental {} (rtol 1e-6): velocity NRMSE vs DP45 at 1e-10",
                        solver.name()
                    ),
                    format!(
                        "{e:.2e} ({} steps, {} rhs, {:.1} ms)",
                        r.stats.steps,
                        r.stats.rhs_evals,
                        r.wall.as_secs_f64() * 1e3
                    ),
                    "<= 1e-4".into(),
                    e <= 1e-4,
                );
            }
            Err(e) => s.check(
                &format!("solver {}", solver.name()),
                e.to_string(),
                "runs".into(),
                false,
            ),
        }
    }
}

fn plot_case(s: &mut Section, dir: &Path, case: &Case, cmp: &Comparison) {
    for (ch, label, scale) in [
        ("velocity", "velocity [mm/s]", 1e3),
        ("p1", "p1 [bar]", 1e-5),
        ("p2", "p2 [bar]", 1e-5),
    ] {
        let series: Vec<(String, Vec<(f64, f64)>)> = cmp
            .runs
            .iter()
            .enumerate()
            .map(|(k, (f, r))| {
                let v = cmp.channel(k, ch, &case.rig);
                (
                    f.name().to_string(),
                    r.time.iter().copied().zip(v).collect(),
                )
            })
            .collect();
        let path = dir.join(format!("{}-{ch}.svg", case.name));
        if let Err(e) = plot(&path, &case.description, label, scale, &series) {
            s.check(
                &format!("plot {}", path.display()),
                e,
                "written".into(),
                false,
            );
        }
    }
}

/// Line plot of several series `(t, y·scale)` into an SVG.
fn plot(
    path: &Path,
    title: &str,
    ylabel: &str,
    scale: f64,
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<(), String> {
    let (mut t0, mut t1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (_, pts) in series {
        for (t, y) in pts {
            t0 = t0.min(*t);
            t1 = t1.max(*t);
            y0 = y0.min(y * scale);
            y1 = y1.max(y * scale);
        }
    }
    if t1 <= t0 || !t1.is_finite() || !y0.is_finite() || !y1.is_finite() {
        return Err("nothing to plot".into());
    }
    let pad = 0.05 * (y1 - y0).max(1e-9);
    let root = SVGBackend::new(path, (900, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(t0..t1, (y0 - pad)..(y1 + pad))
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc("time [s]")
        .y_desc(ylabel)
        .draw()
        .map_err(|e| e.to_string())?;
    let colours = [RED, BLUE, BLACK, GREEN, MAGENTA];
    for (i, (name, pts)) in series.iter().enumerate() {
        let c = colours[i % colours.len()];
        let style = if i == 0 {
            c.stroke_width(3)
        } else {
            c.stroke_width(1)
        };
        chart
            .draw_series(LineSeries::new(
                pts.iter().map(|(t, y)| (*t, y * scale)),
                style,
            ))
            .map_err(|e| e.to_string())?
            .label(name.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}
