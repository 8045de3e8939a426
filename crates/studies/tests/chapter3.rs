//! The chapter-3 test cases of the `leaney-moog` rig: the open-loop bias, the
//! chambers' mass balance, the agreement of the three formulations and the
//! end stop.

use hydrocyl_studies::chapter3;
use hydrocyl_system::run::{RunOptions, Solver};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::simulation::Simulation;

#[test]
fn open_loop_bias_gives_symmetric_velocity() {
    let case = chapter3::square_wave().unwrap();
    let Signal::Square { bias, .. } = case.command else {
        panic!("square wave expected")
    };
    assert!(
        bias < 0.0,
        "retraction needs less spool: the bias is negative ({bias})"
    );
    let r = case
        .rig
        .simulate(case.command.clone(), &case.times, &RunOptions::dp45())
        .unwrap();
    let v = r.channel("velocity").unwrap();
    // end of each half period: steady ±90 mm/s
    for (k, want) in [(990, 0.09), (1990, -0.09), (2990, 0.09), (3990, -0.09)] {
        assert!(
            (v[k] - want).abs() < 2e-4,
            "v({}) = {}",
            case.times[k],
            v[k]
        );
    }
}

#[test]
fn chamber_mass_balance_closes() {
    let case = chapter3::square_wave().unwrap();
    let opts = RunOptions {
        quadratures: true,
        ..RunOptions::dp45()
    };
    let mut sim =
        Simulation::of_circuit(case.rig.circuit(case.command.clone()).unwrap()).options(opts);
    let r = sim.run(&case.times).unwrap();
    let c = sim.circuit();
    let cyl = case.rig.cylinder_model();
    let (q, st) = (
        c.quadrature_range(c.component_index("cylinder").unwrap()),
        c.state_range(c.component_index("cylinder").unwrap()),
    );
    let ls = c.state_range(c.component_index("load").unwrap());
    let (a, b) = (r.state(0), r.state(r.time.len() - 1));
    let bm = case.rig.fluid.bulk_modulus_pa;
    let vol = |x: f64| cyl.volumes(hydrocyl_ports::Position::new(x));
    let ((v10, v20), (v11, v21)) = (vol(a[ls.start]), vol(b[ls.start]));
    let dx = b[ls.start] - a[ls.start];
    let res1 = b[q.start]
        - cyl.area_1.si() * dx
        - ((v11.si() * b[st.start] - v10.si() * a[st.start]) / bm - b[q.start + 2]);
    let res2 = b[q.start + 1] + cyl.area_2.si() * dx
        - ((v21.si() * b[st.start + 1] - v20.si() * a[st.start + 1]) / bm + b[q.start + 3]);
    let xs: Vec<f64> = (0..r.time.len()).map(|k| r.state(k)[ls.start]).collect();
    let swept = cyl.area_1.si() * xs.windows(2).map(|w| (w[1] - w[0]).abs()).sum::<f64>();
    assert!(swept > 1e-4);
    assert!(res1.abs() / swept < 1e-6, "chamber 1: {}", res1 / swept);
    assert!(res2.abs() / swept < 1e-6, "chamber 2: {}", res2 / swept);
}

#[test]
fn formulations_agree_on_the_square_wave() {
    let case = chapter3::square_wave().unwrap();
    let opts = RunOptions {
        rtol: 1e-8,
        ..RunOptions::dp45()
    };
    let cmp = chapter3::Comparison::run(&case, &opts).unwrap();
    for ch in chapter3::COMPARED {
        let e = cmp.nrmse(0, 1, ch, &case.rig);
        assert!(e < 1e-6, "numerical vs analytical X, {ch}: {e}");
    }
    assert!(cmp.nrmse(1, 2, "velocity", &case.rig) < 0.02);
    assert!(cmp.nrmse(1, 2, "p_le", &case.rig) < 0.05);
}

#[test]
fn stop_holds_the_piston_for_every_solver() {
    let case = chapter3::end_stop();
    for solver in [Solver::Dp45, Solver::Rosenbrock, Solver::Rk4] {
        let opts = RunOptions {
            solver,
            rk4_step: 5e-5,
            ..RunOptions::default()
        };
        let r = case
            .rig
            .simulate(case.command.clone(), &case.times, &opts)
            .unwrap();
        let x = r.channel("position").unwrap();
        let xmax = x.iter().cloned().fold(f64::MIN, f64::max);
        assert!(xmax <= 0.26, "{}: {xmax}", solver.name());
        assert!(xmax > 0.2599, "{}: reaches the stop", solver.name());
        assert_eq!(
            r.diagnostic("load.stop_impacts"),
            Some(1.0),
            "{}",
            solver.name()
        );
        // held at the stop at 2.4 s, moving back at 3.4 s
        assert_eq!(x[2400], 0.26, "{}", solver.name());
        assert!(x[3400] < 0.2, "{}", solver.name());
        // chamber volumes stayed positive: the fundamental state is finite
        assert!(r.channel("p2").unwrap().iter().all(|p| p.is_finite()));
    }
}
