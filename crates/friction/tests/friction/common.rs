//! Shared test helpers: models with random parameters, RK4 steps.

use hydrocyl_friction::{Dahl, LuGre, SteadySet, StribeckCurve, Wang, WangSet};
use hydrocyl_ports::{Force, Velocity};

/// A Stribeck curve from raw numbers (magnitudes).
pub fn curve(fc: f64, fs: f64, vs: f64, delta: f64) -> StribeckCurve {
    StribeckCurve {
        coulomb: Force::new(fc),
        stiction: Force::new(fs),
        stribeck_velocity: Velocity::new(vs),
        stribeck_exponent: delta,
    }
}

/// The classical LuGre test parameters (Canudas de Wit et al. 1995):
/// σ0 = 1e5 N/m, σ1 = √1e5 N s/m, σ2 = 0.4 N s/m, Fc = 1 N, Fs = 1.5 N,
/// vs = 1e-3 m/s, δ = 2.
pub fn lugre_classic() -> LuGre {
    LuGre::symmetric(
        1e5,
        1e5f64.sqrt(),
        SteadySet {
            curve: curve(1.0, 1.5, 1e-3, 2.0),
            sigma2: 0.4,
        },
    )
    .unwrap()
}

/// LuGre with a random curve; `sigma1` below the passivity bound
/// σ2 / (Fs/Fc − 1) of the docs.
pub fn lugre_from(p: &[f64; 6]) -> LuGre {
    let [fc, ratio, vs, delta, sigma0, sigma2] = *p;
    let fs = fc * ratio;
    let sigma1 = 0.5 * sigma2 / (ratio - 1.0).max(1e-3);
    LuGre::symmetric(
        sigma0,
        sigma1.min(1e3),
        SteadySet {
            curve: curve(fc, fs, vs, delta),
            sigma2,
        },
    )
    .unwrap()
}

/// Wang's model with random parameters per direction.
pub fn wang_from(p: &[f64; 6]) -> Wang {
    let [fc, ratio, vs, delta, sigma0, k] = *p;
    let set = |scale: f64| WangSet {
        curve: curve(fc * scale, fc * ratio, vs, delta),
        k_pressure: k * scale,
        h_acceleration: 1e9 * scale,
    };
    Wang {
        sigma0,
        sigma1: 0.1,
        extending: set(1.0),
        retracting: set(0.8),
        seal_dp_max: 0.0,
        seal_dp_max_extend: 0.0,
        seal_dp_max_retract: 0.0,
    }
}

/// Dahl with random parameters.
pub fn dahl_from(p: &[f64; 6]) -> Dahl {
    Dahl::new(p[0], p[4], p[5]).unwrap()
}

/// One classical RK4 step of `dx = f(t, x)`.
pub fn rk4<F: Fn(f64, &[f64], &mut [f64])>(f: &F, t: f64, x: &mut [f64], h: f64) {
    let n = x.len();
    let mut k1 = vec![0.0; n];
    let mut k2 = vec![0.0; n];
    let mut k3 = vec![0.0; n];
    let mut k4 = vec![0.0; n];
    let mut y = vec![0.0; n];
    f(t, x, &mut k1);
    for i in 0..n {
        y[i] = x[i] + 0.5 * h * k1[i];
    }
    f(t + 0.5 * h, &y, &mut k2);
    for i in 0..n {
        y[i] = x[i] + 0.5 * h * k2[i];
    }
    f(t + 0.5 * h, &y, &mut k3);
    for i in 0..n {
        y[i] = x[i] + h * k3[i];
    }
    f(t + h, &y, &mut k4);
    for i in 0..n {
        x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

/// Path of the repository's fixtures.
pub fn fixture(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/measured")
        .join(name)
}
