//! Identification of steady friction curves from measured points, on
//! [`hydrocyl_fit`]'s bounded Levenberg–Marquardt.
//!
//! * [`fit_steady_curve`] fits eq 2.40 / 5.8,
//!   `|F| = Fc + (Fs − Fc) exp(−|v/vs|^δ) + σ2 |v|`, to one direction's
//!   points (thesis Table 5-3), any subset of the five parameters free.
//!   Zero-velocity points are break-away (stiction) measurements and are
//!   fitted by g(0) = Fs.
//! * [`fit_pressure_polynomial`] fits `F = c0 + c1 p + c2 p²` to a seal's
//!   friction level against chamber pressure (thesis eqs 5.2 and 5.3: the
//!   seal friction is linear in the contact pressure, or quadratic for
//!   pressure-energised seals that wedge).
//!
//! Data files are plain CSV with a header and `#` comment lines.

use std::path::Path;

use hydrocyl_fit::Problem;
pub use hydrocyl_fit::{FitReport, Parameter};
use hydrocyl_ports::{Force, Pressure, Velocity};

use crate::curve::StribeckCurve;
use crate::error::FrictionError;
use crate::stribeck::SteadySet;

/// Direction of motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// v > 0 (and break-away points with F > 0).
    Extending,
    /// v < 0 (and break-away points with F < 0).
    Retracting,
}

/// One measured steady friction point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SteadyPoint {
    /// Steady velocity \[m·s⁻¹\] (zero for a break-away point).
    pub velocity: Velocity,
    /// Steady friction force \[N\], positive opposing extension.
    pub force: Force,
}

impl SteadyPoint {
    /// The direction this point belongs to: the sign of v, or of F at v = 0.
    pub fn direction(&self) -> Direction {
        let v = self.velocity.si();
        if v > 0.0 || (v == 0.0 && self.force.si() > 0.0) {
            Direction::Extending
        } else {
            Direction::Retracting
        }
    }
}

fn io(path: &Path, e: std::io::Error) -> FrictionError {
    FrictionError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

fn malformed(path: &Path, line: usize, message: String) -> FrictionError {
    FrictionError::Malformed {
        path: path.display().to_string(),
        line,
        message,
    }
}

/// Reads a CSV file with the header `velocity_mm_per_s,force_n` (velocity in
/// mm/s, force in N; `#` lines are comments) into points.
pub fn read_steady_points(path: &Path) -> Result<Vec<SteadyPoint>, FrictionError> {
    let text = std::fs::read_to_string(path).map_err(|e| io(path, e))?;
    let rows = parse_csv(path, &text, &["velocity_mm_per_s", "force_n"])?;
    Ok(rows
        .into_iter()
        .map(|r| SteadyPoint {
            velocity: Velocity::from_mm_per_s(r[0]),
            force: Force::new(r[1]),
        })
        .collect())
}

/// Parses a numeric CSV with exactly the `expected` header, skipping `#` and
/// blank lines; every value must be a finite number.
pub(crate) fn parse_csv(
    path: &Path,
    text: &str,
    expected: &[&str],
) -> Result<Vec<Vec<f64>>, FrictionError> {
    let mut rows = Vec::new();
    let mut header_seen = false;
    for (i, line) in text.lines().enumerate() {
        let ln = i + 1;
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = t.split(',').map(str::trim).collect();
        if !header_seen {
            if fields != expected {
                return Err(malformed(
                    path,
                    ln,
                    format!("header {:?}, expected {:?}", fields, expected),
                ));
            }
            header_seen = true;
            continue;
        }
        if fields.len() != expected.len() {
            return Err(malformed(
                path,
                ln,
                format!("{} fields, expected {}", fields.len(), expected.len()),
            ));
        }
        let mut row = Vec::with_capacity(fields.len());
        for (f, name) in fields.iter().zip(expected) {
            match f.parse::<f64>() {
                Ok(x) if x.is_finite() => row.push(x),
                _ => {
                    return Err(malformed(
                        path,
                        ln,
                        format!("{name} = {f:?} is not a finite number"),
                    ))
                }
            }
        }
        rows.push(row);
    }
    if !header_seen {
        return Err(malformed(path, 1, "no header line".into()));
    }
    Ok(rows)
}

/// Names of the five steady-curve parameters, in fit order.
pub const STEADY_NAMES: [&str; 5] = ["Fc", "Fs", "vs", "delta", "sigma2"];

/// Which steady-curve parameters a fit frees, their start values and bounds.
/// Order: [Fc \[N\], Fs \[N\], vs \[m/s\], δ \[–\], σ2 \[N s/m\]].
#[derive(Clone, Debug, PartialEq)]
pub struct SteadyFitSpec {
    /// Start values (the fixed parameters keep theirs).
    pub initial: [f64; 5],
    /// `true` for a parameter the fit estimates.
    pub free: [bool; 5],
    /// Lower bounds.
    pub lower: [f64; 5],
    /// Upper bounds.
    pub upper: [f64; 5],
}

impl SteadyFitSpec {
    /// All five free, from `initial`, within wide physical bounds
    /// (Fc, Fs in [1, 1e4] N, vs in [1e-5, 1] m/s, δ in [0.01, 10],
    /// σ2 in [0, 1e5] N s/m).
    pub fn all_free(initial: [f64; 5]) -> Self {
        Self {
            initial,
            free: [true; 5],
            lower: [1.0, 1.0, 1e-5, 0.01, 0.0],
            upper: [1e4, 1e4, 1.0, 10.0, 1e5],
        }
    }

    /// The thesis's protocol (section 5.2.1): Fc, Fs, vs fixed at the
    /// "observed" values of Table 5-4, δ and σ2 fitted (the thesis fitted δ and
    /// K with cftool; K (p1 − p2)² plays σ2's role when pressures are known).
    pub fn thesis_protocol(fc: f64, fs: f64, vs: f64) -> Self {
        Self {
            free: [false, false, false, true, true],
            ..Self::all_free([fc, fs, vs, 0.5, 500.0])
        }
    }
}

/// A fitted steady curve for one direction.
#[derive(Clone, Debug)]
pub struct SteadyCurveFit {
    /// Direction fitted.
    pub direction: Direction,
    /// The curve with every parameter (fitted or fixed).
    pub set: SteadySet,
    /// The solver's report over the free parameters.
    pub report: FitReport,
    /// Number of points used.
    pub n_points: usize,
}

/// `g(|v|) + σ2 |v|` for parameters `q` = [Fc, Fs, vs, δ, σ2].
fn steady_magnitude(q: &[f64; 5], v: f64) -> f64 {
    let v = v.abs();
    q[0] + (q[1] - q[0]) * (-(v / q[2]).powf(q[3])).exp() + q[4] * v
}

/// Fits eq 2.40 to the points of `direction` (magnitudes of v and F).
pub fn fit_steady_curve(
    points: &[SteadyPoint],
    direction: Direction,
    spec: &SteadyFitSpec,
) -> Result<SteadyCurveFit, FrictionError> {
    let what = format!("steady curve ({direction:?})");
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.direction() == direction)
        .map(|p| (p.velocity.si().abs(), p.force.si().abs()))
        .collect();
    let free_idx: Vec<usize> = (0..5).filter(|&j| spec.free[j]).collect();
    if pts.is_empty() || pts.len() < free_idx.len() {
        return Err(FrictionError::TooFewPoints {
            what,
            got: pts.len(),
            needed: free_idx.len().max(1),
        });
    }
    let full = |p: &[f64]| {
        let mut q = spec.initial;
        for (k, &j) in free_idx.iter().enumerate() {
            q[j] = p[k];
        }
        q
    };
    let model = |p: &[f64], r: &mut [f64]| {
        let q = full(p);
        for (i, (v, f)) in pts.iter().enumerate() {
            r[i] = f - steady_magnitude(&q, *v);
        }
    };
    let names: Vec<&str> = free_idx.iter().map(|&j| STEADY_NAMES[j]).collect();
    let p0: Vec<f64> = free_idx.iter().map(|&j| spec.initial[j]).collect();
    let lo: Vec<f64> = free_idx.iter().map(|&j| spec.lower[j]).collect();
    let hi: Vec<f64> = free_idx.iter().map(|&j| spec.upper[j]).collect();
    let report = Problem::new(model, pts.len(), &names)
        .bounds(&lo, &hi)
        .solve(&p0)
        .map_err(|source| FrictionError::Fit {
            what: what.clone(),
            source,
        })?;
    let q = full(&report.values());
    Ok(SteadyCurveFit {
        direction,
        set: SteadySet {
            curve: StribeckCurve {
                coulomb: Force::new(q[0]),
                stiction: Force::new(q[1]),
                stribeck_velocity: Velocity::new(q[2]),
                stribeck_exponent: q[3],
            },
            sigma2: q[4],
        },
        report,
        n_points: pts.len(),
    })
}

/// Fits `F = c0 + c1 p (+ c2 p²)` to (pressure, force) points; `quadratic`
/// adds the p² term (eq 5.3's pressure-energised seal). The fit works in bar:
/// parameters are reported as `c0` \[N\], `c1` \[N/bar\] and `c2` \[N/bar²\].
pub fn fit_pressure_polynomial(
    points: &[(Pressure, Force)],
    quadratic: bool,
) -> Result<FitReport, FrictionError> {
    let names: &[&str] = if quadratic {
        &["c0", "c1", "c2"]
    } else {
        &["c0", "c1"]
    };
    if points.len() < names.len() {
        return Err(FrictionError::TooFewPoints {
            what: "seal friction vs pressure".into(),
            got: points.len(),
            needed: names.len(),
        });
    }
    let model = |c: &[f64], r: &mut [f64]| {
        for (i, (p, f)) in points.iter().enumerate() {
            let p = p.bar();
            let mut m = c[0] + c[1] * p;
            if c.len() > 2 {
                m += c[2] * p * p;
            }
            r[i] = f.si() - m;
        }
    };
    let p0 = vec![0.0; names.len()];
    Problem::new(model, points.len(), names)
        .solve(&p0)
        .map_err(|source| FrictionError::Fit {
            what: "seal friction vs pressure".into(),
            source,
        })
}

/// One steady stroke of a seal friction test (the reduced TU Delft records,
/// `fixtures/measured/tudelft-seal-strokes.csv`).
#[derive(Clone, Debug, PartialEq)]
pub struct SealStroke {
    /// Seal name.
    pub seal: String,
    /// Cylinder bore \[m\].
    pub bore: f64,
    /// Nominal chamber pressure of the test \[bar gauge\].
    pub nominal_bar: f64,
    /// Direction of the stroke, +1 or −1 (sign of the velocity).
    pub direction: f64,
    /// Mean velocity over the stroke's steady part \[m·s⁻¹\].
    pub velocity: Velocity,
    /// Mean gauge pressure \[Pa\].
    pub pressure: Pressure,
    /// Mean `F − p A` with the nominal area: friction plus an area offset \[N\].
    pub force_minus_pa: Force,
}

/// Reads the reduced seal-stroke fixture (header
/// `seal,bore_mm,nominal_bar,stroke,direction,velocity_mm_per_s,pressure_bar,force_minus_pa_n,samples`).
pub fn read_seal_strokes(path: &Path) -> Result<Vec<SealStroke>, FrictionError> {
    const HEADER: [&str; 9] = [
        "seal",
        "bore_mm",
        "nominal_bar",
        "stroke",
        "direction",
        "velocity_mm_per_s",
        "pressure_bar",
        "force_minus_pa_n",
        "samples",
    ];
    let text = std::fs::read_to_string(path).map_err(|e| io(path, e))?;
    let mut out = Vec::new();
    let mut header_seen = false;
    for (i, line) in text.lines().enumerate() {
        let ln = i + 1;
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let f: Vec<&str> = t.split(',').map(str::trim).collect();
        if !header_seen {
            if f != HEADER {
                return Err(malformed(
                    path,
                    ln,
                    format!("header {f:?}, expected {HEADER:?}"),
                ));
            }
            header_seen = true;
            continue;
        }
        if f.len() != HEADER.len() {
            return Err(malformed(
                path,
                ln,
                format!("{} fields, expected {}", f.len(), HEADER.len()),
            ));
        }
        let mut num = [0.0; 9];
        for k in 1..9 {
            num[k] = f[k]
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| {
                    malformed(
                        path,
                        ln,
                        format!("{} = {:?} is not a finite number", HEADER[k], f[k]),
                    )
                })?;
        }
        if num[4] != 1.0 && num[4] != -1.0 {
            return Err(malformed(
                path,
                ln,
                format!("direction = {} is not ±1", num[4]),
            ));
        }
        out.push(SealStroke {
            seal: f[0].to_string(),
            bore: num[1] * 1e-3,
            nominal_bar: num[2],
            direction: num[4],
            velocity: Velocity::from_mm_per_s(num[5]),
            pressure: Pressure::from_bar(num[6]),
            force_minus_pa: Force::new(num[7]),
        });
    }
    if !header_seen {
        return Err(malformed(path, 1, "no header line".into()));
    }
    Ok(out)
}

/// How seal friction depends on the chamber pressure p (in bar).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PressureLaw {
    /// `Ff = c0 + c1 p` (eq 5.2: friction proportional to contact pressure).
    Linear,
    /// `Ff = c0 + c1 p + c2 p²` (eq 5.2 and 5.3 together).
    Quadratic,
    /// `Ff = c0 + c2 p²` (eq 5.3 alone: the form of Wang's `K pd² v` term at a
    /// fixed speed, plus a Coulomb level).
    SquareOnly,
}

/// Fits one seal's strokes with
/// `F − p A = o0 + o1 p + s · Ff(p)`, s = ±1 the stroke direction, Ff one of
/// the [`PressureLaw`]s, p in bar. The offset `o0 + o1 p` absorbs the
/// load-cell zero and the difference between the nominal and the effective
/// piston area (and any direction-independent part of the force); `Ff` is
/// the friction magnitude. Parameters: `o0` \[N\], `o1` \[N/bar\], `c0` \[N\],
/// then `c1` \[N/bar\] and/or `c2` \[N/bar²\].
pub fn fit_seal_friction(
    strokes: &[SealStroke],
    law: PressureLaw,
) -> Result<FitReport, FrictionError> {
    let names: &[&str] = match law {
        PressureLaw::Linear => &["o0", "o1", "c0", "c1"],
        PressureLaw::Quadratic => &["o0", "o1", "c0", "c1", "c2"],
        PressureLaw::SquareOnly => &["o0", "o1", "c0", "c2"],
    };
    let what = "seal friction vs pressure".to_string();
    if strokes.len() <= names.len() {
        return Err(FrictionError::TooFewPoints {
            what,
            got: strokes.len(),
            needed: names.len() + 1,
        });
    }
    let model = |c: &[f64], r: &mut [f64]| {
        for (i, s) in strokes.iter().enumerate() {
            let p = s.pressure.bar();
            let ff = match law {
                PressureLaw::Linear => c[2] + c[3] * p,
                PressureLaw::Quadratic => c[2] + c[3] * p + c[4] * p * p,
                PressureLaw::SquareOnly => c[2] + c[3] * p * p,
            };
            r[i] = s.force_minus_pa.si() - (c[0] + c[1] * p + s.direction * ff);
        }
    };
    let p0 = vec![0.0; names.len()];
    Problem::new(model, strokes.len(), names)
        .solve(&p0)
        .map_err(|source| FrictionError::Fit { what, source })
}

/// One sample of a drive's inverse model: velocity, acceleration and the
/// actuator force (the reduced EMPS record,
/// `fixtures/measured/emps-inverse-model.csv`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InverseSample {
    /// Time \[s\].
    pub t: f64,
    /// Velocity \[m·s⁻¹\].
    pub velocity: Velocity,
    /// Acceleration \[m·s⁻²\].
    pub acceleration: f64,
    /// Actuator force \[N\].
    pub force: Force,
}

/// Reads a CSV with header `t_s,velocity_m_per_s,acceleration_m_per_s2,force_n`.
pub fn read_inverse_samples(path: &Path) -> Result<Vec<InverseSample>, FrictionError> {
    let text = std::fs::read_to_string(path).map_err(|e| io(path, e))?;
    let rows = parse_csv(
        path,
        &text,
        &[
            "t_s",
            "velocity_m_per_s",
            "acceleration_m_per_s2",
            "force_n",
        ],
    )?;
    Ok(rows
        .into_iter()
        .map(|r| InverseSample {
            t: r[0],
            velocity: Velocity::new(r[1]),
            acceleration: r[2],
            force: Force::new(r[3]),
        })
        .collect())
}

/// The friction law inside an inverse model `F = M a + offset + F_f(v)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InverseLaw {
    /// `F_f = Fc sgn(v) + σ2 v` (the benchmark's reference structure; the
    /// offset carries the difference between the directions — separate Fc+
    /// and Fc− with an offset would not be identifiable). Parameters:
    /// `M, offset, Fc, sigma2`.
    CoulombViscous,
    /// `F_f = sgn(v) g(v) + σ2 v`, eq 2.40. Parameters:
    /// `M, offset, Fc, sigma2, Fs, vs, delta`.
    Stribeck,
}

/// Fits the inverse model to the samples with |v| ≥ `min_speed` (the sign of
/// v is unreliable near zero, and eq 2.40 is a steady-sliding curve).
/// Units: M \[kg\], offset and levels \[N\], σ2 \[N·s·m⁻¹\], vs \[m·s⁻¹\].
pub fn fit_inverse_model(
    samples: &[InverseSample],
    law: InverseLaw,
    min_speed: Velocity,
) -> Result<FitReport, FrictionError> {
    let what = "inverse model".to_string();
    let sel: Vec<&InverseSample> = samples
        .iter()
        .filter(|s| s.velocity.si().abs() >= min_speed.si())
        .collect();
    let (names, p0, lo, hi): (&[&str], Vec<f64>, Vec<f64>, Vec<f64>) = match law {
        InverseLaw::CoulombViscous => (
            &["M", "offset", "Fc", "sigma2"],
            vec![10.0, 0.0, 10.0, 100.0],
            vec![0.0, -1e4, 0.0, 0.0],
            vec![1e4, 1e4, 1e4, 1e5],
        ),
        InverseLaw::Stribeck => (
            &["M", "offset", "Fc", "sigma2", "Fs", "vs", "delta"],
            vec![10.0, 0.0, 10.0, 100.0, 20.0, 0.01, 1.0],
            vec![0.0, -1e4, 0.0, 0.0, 0.0, 1e-4, 0.1],
            vec![1e4, 1e4, 1e4, 1e5, 1e4, 1.0, 10.0],
        ),
    };
    if sel.len() <= names.len() {
        return Err(FrictionError::TooFewPoints {
            what,
            got: sel.len(),
            needed: names.len() + 1,
        });
    }
    let model = |c: &[f64], r: &mut [f64]| {
        for (i, s) in sel.iter().enumerate() {
            let v = s.velocity.si();
            let level = if c.len() > 4 {
                c[2] + (c[4] - c[2]) * (-(v / c[5]).abs().powf(c[6])).exp()
            } else {
                c[2]
            };
            let ff = v.signum() * level + c[3] * v;
            r[i] = s.force.si() - (c[0] * s.acceleration + c[1] + ff);
        }
    };
    Problem::new(model, sel.len(), names)
        .bounds(&lo, &hi)
        .solve(&p0)
        .map_err(|source| FrictionError::Fit { what, source })
}
