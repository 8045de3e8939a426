//! Steady-curve identification: the Table 5-3 fixture, synthetic recovery,
//! malformed files.

use hydrocyl_friction::ident::{
    fit_pressure_polynomial, fit_steady_curve, read_steady_points, Direction, SteadyFitSpec,
    SteadyPoint,
};
use hydrocyl_friction::FrictionError;
use hydrocyl_ports::{Force, Pressure, Velocity};

use crate::common::fixture;

#[test]
fn table_5_3_fixture_has_six_points_per_direction() {
    let pts = read_steady_points(&fixture("wang-table-5-3.csv")).unwrap();
    assert_eq!(pts.len(), 12);
    let ext = pts
        .iter()
        .filter(|p| p.direction() == Direction::Extending)
        .count();
    assert_eq!(ext, 6);
    assert!((pts[0].velocity.si() - 0.04803).abs() < 1e-12);
}

#[test]
fn a_noise_free_curve_is_recovered_from_many_points() {
    // Eq 2.40 with Fc 100, Fs 170, vs 5 mm/s, δ 1, σ2 1200, 20 velocities.
    let q = [100.0, 170.0, 0.005, 1.0, 1200.0];
    let pts: Vec<SteadyPoint> = (0..20)
        .map(|i| {
            let v = 0.0005 + 0.003 * i as f64;
            let f = q[0] + (q[1] - q[0]) * (-(v / q[2]).powf(q[3])).exp() + q[4] * v;
            SteadyPoint {
                velocity: Velocity::new(-v),
                force: Force::new(-f),
            }
        })
        .collect();
    let fit = fit_steady_curve(
        &pts,
        Direction::Retracting,
        &SteadyFitSpec::all_free([80.0, 150.0, 0.01, 0.7, 500.0]),
    )
    .unwrap();
    let v = fit.report.values();
    for j in 0..5 {
        assert!(
            (v[j] - q[j]).abs() < 1e-5 * q[j],
            "{j}: {} vs {}",
            v[j],
            q[j]
        );
    }
    assert!(fit.report.rmse < 1e-6);
}

#[test]
fn thesis_protocol_fits_two_parameters_on_table_5_3() {
    let pts = read_steady_points(&fixture("wang-table-5-3.csv")).unwrap();
    let fit = fit_steady_curve(
        &pts,
        Direction::Extending,
        &SteadyFitSpec::thesis_protocol(110.0, 180.0, 0.01),
    )
    .unwrap();
    assert_eq!(fit.report.parameters.len(), 2);
    assert_eq!(fit.report.dof, 4);
    // Fixed values stay fixed.
    assert_eq!(fit.set.curve.coulomb.si(), 110.0);
    // The fit beats the starting curve.
    assert!(fit.report.rmse < 30.0);
}

#[test]
fn too_few_points_and_bad_files_are_errors() {
    let one = [SteadyPoint {
        velocity: Velocity::new(0.01),
        force: Force::new(100.0),
    }];
    let e = fit_steady_curve(
        &one,
        Direction::Extending,
        &SteadyFitSpec::all_free([1.0, 2.0, 0.01, 1.0, 0.0]),
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            FrictionError::TooFewPoints {
                got: 1,
                needed: 5,
                ..
            }
        ),
        "{e}"
    );
    let dir = std::env::temp_dir().join(format!("hydrocyl-friction-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "velocity_mm_per_s,force_n\n1.0,2.0\n3.0,abc\n").unwrap();
    let e = read_steady_points(&bad).unwrap_err();
    assert!(matches!(e, FrictionError::Malformed { line: 3, .. }), "{e}");
    assert!(e.to_string().contains("force_n"), "{e}");
    std::fs::write(&bad, "v,f\n1,2\n").unwrap();
    assert!(matches!(
        read_steady_points(&bad).unwrap_err(),
        FrictionError::Malformed { line: 1, .. }
    ));
    let e = read_steady_points(&dir.join("missing.csv")).unwrap_err();
    assert!(matches!(e, FrictionError::Io { .. }));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_quadratic_pressure_law_is_recovered() {
    let pts: Vec<(Pressure, Force)> = (1..=7)
        .map(|b| {
            let p = b as f64;
            (
                Pressure::from_bar(p),
                Force::new(2.0 + 1.5 * p + 0.2 * p * p),
            )
        })
        .collect();
    let lin = fit_pressure_polynomial(&pts, false).unwrap();
    let quad = fit_pressure_polynomial(&pts, true).unwrap();
    let c = quad.values();
    assert!((c[0] - 2.0).abs() < 1e-8 && (c[1] - 1.5).abs() < 1e-8 && (c[2] - 0.2).abs() < 1e-9);
    assert!(quad.rmse < 1e-8 && lin.rmse > 0.1);
}

#[test]
fn real_seal_friction_rises_with_pressure() {
    use hydrocyl_friction::ident::{fit_seal_friction, read_seal_strokes, PressureLaw};
    let strokes = read_seal_strokes(&fixture("tudelft-seal-strokes.csv")).unwrap();
    assert_eq!(strokes.len(), 560);
    // NAPN: the authors' per-file levels rise from 4.5 N (1 bar) to 16 N (7 bar).
    let napn: Vec<_> = strokes
        .iter()
        .filter(|s| s.seal == "NAPN")
        .cloned()
        .collect();
    let lin = fit_seal_friction(&napn, PressureLaw::Linear).unwrap();
    let (lo, _) = lin.get("c1").unwrap().interval.unwrap();
    assert!(lo > 1.0, "friction slope lower bound {lo} N/bar");
    // The fitted friction magnitude at 1 and 7 bar brackets the half-range of
    // the measured levels (direction-independent offset removed).
    let c = lin.values();
    let ff = |p: f64| c[2] + c[3] * p;
    assert!(
        ff(1.0) > 2.0 && ff(1.0) < 5.0 && ff(7.0) > 10.0 && ff(7.0) < 13.0,
        "{c:?}"
    );
    // A stroke direction must be ±1.
    let dir = std::env::temp_dir().join(format!("hydrocyl-seal-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("s.csv");
    std::fs::write(
        &bad,
        "seal,bore_mm,nominal_bar,stroke,direction,velocity_mm_per_s,pressure_bar,force_minus_pa_n,samples\nX,25,1,0,2,1,1,1,100\n",
    )
    .unwrap();
    let e = read_seal_strokes(&bad).unwrap_err();
    assert!(e.to_string().contains("direction"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn emps_inverse_model_fits_and_stribeck_does_not_do_worse() {
    use hydrocyl_friction::ident::{fit_inverse_model, read_inverse_samples, InverseLaw};
    let s = read_inverse_samples(&fixture("emps-inverse-model.csv")).unwrap();
    assert!(s.len() > 2000);
    let min = Velocity::new(0.005);
    let cv = fit_inverse_model(&s, InverseLaw::CoulombViscous, min).unwrap();
    let st = fit_inverse_model(&s, InverseLaw::Stribeck, min).unwrap();
    eprintln!("EMPS Coulomb-viscous:\n{}", cv.summary());
    eprintln!("EMPS Stribeck:\n{}", st.summary());
    // A nested model fitted by least squares cannot be worse than its restriction.
    assert!(st.rmse <= cv.rmse * (1.0 + 1e-9));
    // Physical: positive mass and friction levels, determined to better than ±20 %.
    for name in ["M", "Fc", "sigma2"] {
        let p = cv.get(name).unwrap();
        assert!(
            p.value > 0.0 && p.relative_uncertainty() < 0.2,
            "{name}: {p:?}"
        );
    }
}
