//! Validation section: friction (issue 5).
//!
//! * the steady-state curve of every friction model against the thesis's
//!   measured Table 5-3 (`fixtures/measured/wang-table-5-3.csv`), RMSE per
//!   model and direction;
//! * hydrocyl's least-squares fit of eq 2.40 to Table 5-3 per direction, all
//!   five parameters free and with the thesis's protocol (Fc, Fs, vs fixed at
//!   Table 5-4, δ and σ2 fitted), with 95 % intervals, beside Tables 5-4, 5-5
//!   and 5-11;
//! * the pressure dependence of real seal friction (TU Delft records,
//!   `fixtures/measured/tudelft-seal-strokes.csv`): linear (eq 5.2) against
//!   quadratic (eq 5.3) laws;
//! * the inverse model (mass, offset, friction curve) of the EMPS
//!   electromechanical axis (`fixtures/measured/emps-inverse-model.csv`).

use std::path::{Path, PathBuf};

use hydrocyl_friction::ident::{
    fit_inverse_model, fit_seal_friction, fit_steady_curve, read_inverse_samples,
    read_seal_strokes, read_steady_points, Direction, FitReport, InverseLaw, PressureLaw,
    SealStroke, SteadyCurveFit, SteadyFitSpec, SteadyPoint,
};
use hydrocyl_friction::{
    CoulombViscous, Dahl, FrictionInput, FrictionLaw, FrictionModel, Karnopp, LuGre, Stribeck, Wang,
};
use hydrocyl_ports::Velocity;

use crate::report::Section;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Velocity at which a break-away (v = 0) point is evaluated: the limit
/// v → 0± of the steady curve, on the side of the measured force.
fn eval_velocity(p: &SteadyPoint) -> f64 {
    let v = p.velocity.si();
    if v != 0.0 {
        v
    } else {
        1e-300 * p.force.si().signum()
    }
}

fn rmse(errors: impl Iterator<Item = f64>) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for e in errors {
        s += e * e;
        n += 1;
    }
    if n == 0 {
        f64::NAN
    } else {
        (s / n as f64).sqrt()
    }
}

/// RMSE of `curve` over the points of one direction (None = all).
fn curve_rmse(points: &[SteadyPoint], dir: Option<Direction>, curve: &dyn Fn(f64) -> f64) -> f64 {
    rmse(
        points
            .iter()
            .filter(|p| dir.is_none_or(|d| p.direction() == d))
            .map(|p| p.force.si() - curve(eval_velocity(p))),
    )
}

fn models() -> Vec<(String, FrictionLaw)> {
    let t511 = Stribeck::table_5_11();
    let ext = t511.extending;
    vec![
        (
            "coulomb-viscous (Fc 110 N, b 1000 N s/m)".into(),
            FrictionLaw::CoulombViscous(CoulombViscous {
                coulomb: ext.curve.coulomb,
                viscous: ext.sigma2,
                smoothing_velocity: Velocity::new(1e-4),
            }),
        ),
        (
            "stribeck (Table 5-11 curve)".into(),
            FrictionLaw::Stribeck(t511),
        ),
        (
            "karnopp (Table 5-11 ext., symmetric)".into(),
            FrictionLaw::Karnopp(Karnopp::new(ext.curve, ext.sigma2).expect("valid")),
        ),
        (
            "dahl (Fc 110 N, sigma2 1000 N s/m)".into(),
            FrictionLaw::Dahl(Dahl::new(110.0, 3e7, 1000.0).expect("valid")),
        ),
        (
            "lugre (Table 5-11)".into(),
            FrictionLaw::LuGre(LuGre::table_5_11()),
        ),
        (
            "wang (Table 5-8, p1 - p2 = 0)".into(),
            FrictionLaw::Wang(Wang::table_5_8()),
        ),
    ]
}

fn steady(law: &FrictionLaw, v: f64) -> f64 {
    law.steady_force(&FrictionInput::at_velocity(Velocity::new(v)))
        .si()
}

/// The steady curve a law represents: the unsmoothed static curve for the
/// laws that smooth sgn(v) with a tanh (their smoothed force is 0 at v = 0,
/// which is not what the break-away points measure).
fn curve_value(law: &FrictionLaw, v: f64) -> f64 {
    match law {
        FrictionLaw::Stribeck(m) => m.static_curve(Velocity::new(v)).si(),
        FrictionLaw::CoulombViscous(m) => m.static_curve(Velocity::new(v)).si(),
        other => steady(other, v),
    }
}

fn fmt_param(fit: &SteadyCurveFit, name: &str, value: f64) -> String {
    match fit.report.get(name) {
        None => format!("{value:.4} (fixed)"),
        Some(p) if p.at_bound => format!("{:.4} (at bound)", p.value),
        Some(p) => match p.interval {
            Some((lo, hi)) => format!("{:.4} [{lo:.4}, {hi:.4}]", p.value),
            None => format!("{:.4} [undetermined]", p.value),
        },
    }
}

/// The signed curve of a fitted direction (magnitudes → sign of v).
fn fitted_curve(fit: &SteadyCurveFit) -> impl Fn(f64) -> f64 + '_ {
    move |v: f64| v.signum() * (fit.set.curve.g(v) + fit.set.sigma2 * v.abs())
}

fn table_5_3(s: &mut Section) {
    let path = root().join("fixtures/measured/wang-table-5-3.csv");
    let points = match read_steady_points(&path) {
        Ok(p) => p,
        Err(e) => {
            s.check(
                "read Table 5-3 fixture",
                e.to_string(),
                "12 points".into(),
                false,
            );
            return;
        }
    };
    s.check(
        "Table 5-3 fixture points",
        points.len().to_string(),
        "12 (6 per direction)".into(),
        points.len() == 12,
    );

    // Every model's steady curve with the thesis's (or derived) parameters.
    let dirs = [
        Some(Direction::Extending),
        Some(Direction::Retracting),
        None,
    ];
    s.note("steady curves vs Table 5-3 (RMSE in N; break-away points compared at v -> 0 on their side):");
    s.note(&format!(
        "  {:<40} {:>9} {:>9} {:>9}",
        "model", "extend", "retract", "all 12"
    ));
    let mut thesis_curve_rmse = [f64::NAN; 2];
    for (name, law) in models() {
        let r: Vec<f64> = dirs
            .iter()
            .map(|d| curve_rmse(&points, *d, &|v| curve_value(&law, v)))
            .collect();
        if name.starts_with("stribeck") {
            thesis_curve_rmse = [r[0], r[1]];
        }
        s.note(&format!(
            "  {:<40} {:>9.2} {:>9.2} {:>9.2}",
            name, r[0], r[1], r[2]
        ));
    }

    // Dynamic steady state = static curve at the measured points.
    let lugre = FrictionLaw::LuGre(LuGre::table_5_11());
    let stribeck = Stribeck::table_5_11();
    let dmax = points
        .iter()
        .filter(|p| p.velocity.si() != 0.0)
        .map(|p| (steady(&lugre, p.velocity.si()) - stribeck.static_curve(p.velocity).si()).abs())
        .fold(0.0, f64::max);
    s.check(
        "LuGre steady state = eq 2.40 at Table 5-3 velocities",
        format!("max diff {dmax:.1e} N"),
        "< 1e-9 N".into(),
        dmax < 1e-9,
    );

    // Fits per direction.
    let table_5_4 = [(110.0, 180.0, 0.01), (80.0, 188.0, 0.01)];
    let table_5_5_delta = [0.1087, 0.1138];
    let table_5_11_sigma2 = [1000.0, 900.0];
    for (k, dir) in [Direction::Extending, Direction::Retracting]
        .into_iter()
        .enumerate()
    {
        let (fc, fs, vs) = table_5_4[k];
        let label = if k == 0 { "extending" } else { "retracting" };
        let free = fit_steady_curve(
            &points,
            dir,
            &SteadyFitSpec::all_free([fc, fs, vs, 0.5, table_5_11_sigma2[k]]),
        );
        let proto = fit_steady_curve(&points, dir, &SteadyFitSpec::thesis_protocol(fc, fs, vs));
        let (free, proto) = match (free, proto) {
            (Ok(a), Ok(b)) => (a, b),
            (a, b) => {
                let e = a
                    .err()
                    .or(b.err())
                    .map(|e| e.to_string())
                    .unwrap_or_default();
                s.check(
                    &format!("eq 2.40 fit, {label}"),
                    e,
                    "converges".into(),
                    false,
                );
                continue;
            }
        };
        let r_free = curve_rmse(&points, Some(dir), &fitted_curve(&free));
        let r_proto = curve_rmse(&points, Some(dir), &fitted_curve(&proto));
        s.check(
            &format!("eq 2.40 fit {label}: RMSE <= Table 5-11 curve"),
            format!("{r_free:.2} N (5 free), {r_proto:.2} N (delta, sigma2 free)"),
            format!("{:.2} N", thesis_curve_rmse[k]),
            r_free <= thesis_curve_rmse[k] + 1e-9 && r_proto <= thesis_curve_rmse[k] + 1e-9,
        );
        s.note(&format!(
            "\neq 2.40 fit to Table 5-3, {label} ({} points; value [95 % interval]):",
            free.n_points
        ));
        let c = &free.set.curve;
        let pc = &proto.set.curve;
        let rows = [
            (
                "Fc [N]",
                "Fc",
                c.coulomb.si(),
                pc.coulomb.si(),
                format!("{fc} (Table 5-4, observed)"),
            ),
            (
                "Fs [N]",
                "Fs",
                c.stiction.si(),
                pc.stiction.si(),
                format!("{fs} (Table 5-4, observed)"),
            ),
            (
                "vs [m/s]",
                "vs",
                c.stribeck_velocity.si(),
                pc.stribeck_velocity.si(),
                format!("{vs} (Table 5-4)"),
            ),
            (
                "delta [-]",
                "delta",
                c.stribeck_exponent,
                pc.stribeck_exponent,
                format!("{} (Table 5-5)", table_5_5_delta[k]),
            ),
            (
                "sigma2 [N s/m]",
                "sigma2",
                free.set.sigma2,
                proto.set.sigma2,
                format!("{} (Table 5-11; 5-5 fits K instead)", table_5_11_sigma2[k]),
            ),
        ];
        s.note(&format!(
            "  {:<15} {:<36} {:<34} {}",
            "parameter", "hydrocyl, 5 free", "hydrocyl, thesis protocol", "thesis"
        ));
        for (label, name, v_free, v_proto, thesis) in rows {
            s.note(&format!(
                "  {:<15} {:<36} {:<34} {}",
                label,
                fmt_param(&free, name, v_free),
                fmt_param(&proto, name, v_proto),
                thesis
            ));
        }
        let unid: Vec<&str> = free
            .report
            .unidentifiable()
            .iter()
            .map(|&j| free.report.parameters[j].name.as_str())
            .collect();
        let corr: Vec<String> = free
            .report
            .strong_correlations(0.95)
            .iter()
            .map(|(i, j, r)| {
                format!(
                    "{}-{} {:+.3}",
                    free.report.parameters[*i].name, free.report.parameters[*j].name, r
                )
            })
            .collect();
        s.note(&format!(
            "  RMSE {:.2} N (5 free, dof {}), {:.2} N (protocol, dof {}); scaled condition number {:.1e}",
            r_free, free.report.dof, r_proto, proto.report.dof, free.report.condition_number
        ));
        s.note(&format!(
            "  not determined by these points (interval wider than +/-100 % or none): {}",
            if unid.is_empty() {
                "none".to_string()
            } else {
                unid.join(", ")
            }
        ));
        s.note(&format!(
            "  |correlation| > 0.95: {}",
            if corr.is_empty() {
                "none".to_string()
            } else {
                corr.join(", ")
            }
        ));
    }

    // What pressure difference Wang's Table 5-8 needs to reproduce each point.
    let w = Wang::table_5_8();
    let implied: Vec<String> = points
        .iter()
        .filter(|p| p.velocity.si() != 0.0)
        .map(|p| {
            let v = p.velocity.si();
            let set = w.set_for(v, 0.0);
            let excess = p.force.si().abs() - set.curve.g(v);
            if excess > 0.0 {
                let pd = (excess / (set.k_pressure * v.abs())).sqrt();
                format!("{:+.1} mm/s: {:.1} bar", v * 1e3, pd * 1e-5)
            } else {
                format!("{:+.1} mm/s: none (g(v) alone exceeds F)", v * 1e3)
            }
        })
        .collect();
    s.note(&format!(
        "\nWang Table 5-8: |p1 - p2| that makes eq 5.11 meet each Table 5-3 point (not measured in the table): {}",
        implied.join("; ")
    ));
}

fn seals(s: &mut Section) {
    let path = root().join("fixtures/measured/tudelft-seal-strokes.csv");
    let strokes = match read_seal_strokes(&path) {
        Ok(x) => x,
        Err(e) => {
            s.check(
                "read TU Delft seal strokes",
                e.to_string(),
                "fixture".into(),
                false,
            );
            return;
        }
    };
    let mut names: Vec<&str> = strokes.iter().map(|x| x.seal.as_str()).collect();
    names.dedup();
    s.note("\nTU Delft pneumatic seals (real data): friction magnitude Ff(p), p gauge in bar, per-stroke fit");
    s.note("  F - pA = o0 + o1 p + sgn(v) Ff(p); Ff = c0 + c1 p (eq 5.2) or c0 + c1 p + c2 p^2 (eq 5.2 + 5.3)");
    s.note(&format!(
        "  {:<10} {:>4} {:>24} {:>24} {:>27} {:>8} {:>8} {:>8}",
        "seal", "n", "c0 [N]", "c1 [N/bar]", "c2 [N/bar^2]", "RMSE lin", "quad", "p^2 only"
    ));
    let mut n_ok = 0;
    let (mut n_up, mut n_down) = (0, 0);
    for name in &names {
        let sel: Vec<SealStroke> = strokes
            .iter()
            .filter(|x| x.seal == *name)
            .cloned()
            .collect();
        let fits = (
            fit_seal_friction(&sel, PressureLaw::Linear),
            fit_seal_friction(&sel, PressureLaw::Quadratic),
            fit_seal_friction(&sel, PressureLaw::SquareOnly),
        );
        let (Ok(lin), Ok(quad), Ok(sq)) = fits else {
            continue;
        };
        n_ok += 1;
        let ci = |r: &FitReport, n: &str| {
            r.get(n)
                .map(|p| match p.interval {
                    Some((lo, hi)) => format!("{:.3} [{lo:.3}, {hi:.3}]", p.value),
                    None => format!("{:.3} [-]", p.value),
                })
                .unwrap_or_default()
        };
        let c2 = quad.get("c2").and_then(|p| p.interval);
        if c2.is_some_and(|(lo, _)| lo > 0.0) {
            n_up += 1;
        }
        if c2.is_some_and(|(_, hi)| hi < 0.0) {
            n_down += 1;
        }
        s.note(&format!(
            "  {:<10} {:>4} {:>24} {:>24} {:>27} {:>8.3} {:>8.3} {:>8.3}",
            name,
            sel.len(),
            ci(&quad, "c0"),
            ci(&quad, "c1"),
            ci(&quad, "c2"),
            lin.rmse,
            quad.rmse,
            sq.rmse
        ));
    }
    s.check(
        "seal friction fits (7 seals x 3 laws)",
        format!("{n_ok} seals fitted"),
        "7".into(),
        n_ok == names.len() && n_ok == 7,
    );
    s.note(&format!(
        "  c2 significantly > 0 (friction grows faster than p, eq 5.3) in {n_up} of {n_ok} seals; \
         significantly < 0 (saturating) in {n_down}"
    ));
}

fn emps(s: &mut Section) {
    let path = root().join("fixtures/measured/emps-inverse-model.csv");
    let samples = match read_inverse_samples(&path) {
        Ok(x) => x,
        Err(e) => {
            s.check(
                "read EMPS inverse-model fixture",
                e.to_string(),
                "fixture".into(),
                false,
            );
            return;
        }
    };
    let min = Velocity::new(0.005);
    let fits = (
        fit_inverse_model(&samples, InverseLaw::CoulombViscous, min),
        fit_inverse_model(&samples, InverseLaw::Stribeck, min),
    );
    let (cv, st) = match fits {
        (Ok(a), Ok(b)) => (a, b),
        (a, b) => {
            let e = a
                .err()
                .or(b.err())
                .map(|e| e.to_string())
                .unwrap_or_default();
            s.check("EMPS inverse-model fits", e, "converge".into(), false);
            return;
        }
    };
    s.check(
        "EMPS fit: eq 2.40 RMSE <= Coulomb-viscous RMSE (nested)",
        format!("{:.3} N vs {:.3} N", st.rmse, cv.rmse),
        "<=".into(),
        st.rmse <= cv.rmse * (1.0 + 1e-9),
    );
    s.note(&format!(
        "\nEMPS electromechanical axis (real data, {} samples with |v| >= 5 mm/s): F = M a + offset + Ff(v)",
        cv.residuals.len()
    ));
    let fmt = |r: &FitReport, n: &str| {
        r.get(n)
            .map(|p| match (p.at_bound, p.interval) {
                (true, _) => format!("{:.4} (at bound)", p.value),
                (false, Some((lo, hi))) => format!("{:.4} [{lo:.4}, {hi:.4}]", p.value),
                (false, None) => format!("{:.4} [undetermined]", p.value),
            })
            .unwrap_or_else(|| "-".into())
    };
    s.note(&format!(
        "  {:<8} {:<34} {}",
        "param", "Coulomb-viscous", "eq 2.40 (Stribeck)"
    ));
    for n in ["M", "offset", "Fc", "sigma2", "Fs", "vs", "delta"] {
        s.note(&format!("  {:<8} {:<34} {}", n, fmt(&cv, n), fmt(&st, n)));
    }
    s.note(&format!("  RMSE     {:<34.3} {:.3}", cv.rmse, st.rmse));
}

/// Runs this section and returns what it measured.
pub fn section() -> Section {
    let mut s = Section::new("friction");
    table_5_3(&mut s);
    seals(&mut s);
    emps(&mut s);
    s
}
