//! The thesis's own route, kept for comparison: Ferrari's formula with its
//! root names X1..X4 (eqs 3.18-3.22, Appendix II `x_roots.m`) and the fitted
//! root split of eq 3.30.
//!
//! Nothing in hydrocyl's physics uses these; `cargo xtask xfactor` and the
//! tests use them to put hydrocyl's exact results beside the thesis's.

use crate::analytical::thesis_quartic;

/// A complex number, just enough for Ferrari's formula.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Complex {
    /// Real part.
    pub re: f64,
    /// Imaginary part.
    pub im: f64,
}

impl Complex {
    /// `re + i im`.
    pub const fn new(re: f64, im: f64) -> Self {
        Self { re, im }
    }
    fn real(re: f64) -> Self {
        Self { re, im: 0.0 }
    }
    fn add(self, o: Self) -> Self {
        Self::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: Self) -> Self {
        Self::new(self.re - o.re, self.im - o.im)
    }
    fn scale(self, s: f64) -> Self {
        Self::new(self.re * s, self.im * s)
    }
    fn div(self, o: Self) -> Self {
        let d = o.re * o.re + o.im * o.im;
        Self::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    /// Modulus.
    pub fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }
    /// Principal power `z^p` (Matlab's `z^p` for non-integer p).
    fn powf(self, p: f64) -> Self {
        let r = self.abs();
        if r == 0.0 {
            return Self::real(0.0);
        }
        let th = self.im.atan2(self.re) * p;
        let m = r.powf(p);
        Self::new(m * th.cos(), m * th.sin())
    }
}

/// The four roots `[X1, X2, X3, X4]` of the thesis's quartic by Ferrari's
/// formula exactly as eqs 3.18-3.22 and `x_roots.m` write it, in complex
/// arithmetic with principal square and cube roots (Matlab's `^0.5`,
/// `^(1/3)`), with `Av1 = 1 + travel`, `Av2 = 1 - travel`.
///
/// This is the textbook formula that cancels catastrophically near
/// `travel = +-1` and breaks down at `a4 = 0`; it is here only to name the
/// roots the way the thesis does.
pub fn ferrari_roots(gamma: f64, travel: f64) -> [Complex; 4] {
    let [a0, a1, a2, a3, a4] = thesis_quartic(gamma, travel);
    let (a, b, c, d) = (a3 / a4, a2 / a4, a1 / a4, a0 / a4);
    let z0 = b * b - 3.0 * a * c + 12.0 * d;
    let z1 = 2.0 * b * b * b - 9.0 * a * b * c + 27.0 * a * a * d + 27.0 * c * c - 72.0 * b * d;
    let disc = Complex::real(z1 * z1 - 4.0 * z0 * z0 * z0).powf(0.5);
    let s = Complex::real(z1).add(disc).scale(0.5).powf(1.0 / 3.0);
    let u = a * a / 4.0 - 2.0 * b / 3.0;
    let v = s.scale(1.0 / 3.0).add(Complex::real(z0 / 3.0).div(s));
    let uv = Complex::real(u).add(v).powf(0.5);
    let w = Complex::real(a * a * a - 4.0 * a * b + 8.0 * c).div(uv.scale(4.0));
    let two_u_v = Complex::real(2.0 * u).sub(v);
    let rm = two_u_v.sub(w).powf(0.5);
    let rp = two_u_v.add(w).powf(0.5);
    let base = Complex::real(-a / 4.0);
    let h = |z: Complex| z.scale(0.5);
    [
        base.add(h(uv)).sub(h(rm)),
        base.sub(h(uv)).sub(h(rp)),
        base.add(h(uv)).add(h(rm)),
        base.sub(h(uv)).add(h(rp)),
    ]
}

/// The thesis's name (1..=4) of the root of [`ferrari_roots`] nearest to `x`.
pub fn label_of(gamma: f64, travel: f64, x: f64) -> usize {
    let roots = ferrari_roots(gamma, travel);
    let mut best = 0;
    for i in 1..4 {
        if roots[i].sub(Complex::real(x)).abs() < roots[best].sub(Complex::real(x)).abs() {
            best = i;
        }
    }
    best + 1
}

/// The thesis's curve fit of the share of the underlap where the X factor is
/// the root it names X1 (eq 3.30):
/// `0.00999 gamma^3 - 0.09352 gamma^2 + 0.3228 gamma + 0.2328`.
pub fn fit_share_x1(gamma: f64) -> f64 {
    ((0.00999 * gamma - 0.09352) * gamma + 0.3228) * gamma + 0.2328
}

/// Table 3-4 of the thesis: `(gamma, share of X4, share of X1)`.
pub const TABLE_3_4: [(f64, f64, f64); 5] = [
    (1.5, 0.46, 0.54),
    (1.9707, 0.4167, 0.5833),
    (2.5, 0.39, 0.61),
    (3.0, 0.37, 0.63),
    (4.0, 0.333, 0.667),
];

/// Table 3-3 of the thesis (gamma = 11.43/5.8, underlap 0.0045 mm):
/// `(x_s [mm], X, thesis's root name)`.
pub const TABLE_3_3: [(f64, f64, usize); 15] = [
    (-0.0045, 3.883617722, 4),
    (-0.004404, 3.867534491, 4),
    (-0.004296, 3.848941124, 4),
    (-0.004101, 3.814000308, 4),
    (-0.0009, 2.963117621, 4),
    (-0.000753, 2.911892307, 4),
    (-0.000735, 2.905559937, 1),
    (0.0, 2.637188916, 1),
    (0.0012, 2.172727301, 1),
    (0.00255, 1.65272018, 1),
    (0.004101, 1.119970977, 1),
    (0.0042, 1.0894822, 1),
    (0.004302, 1.058563937, 1),
    (0.00441, 1.026380398, 1),
    (0.0045, 1.0, 1),
];

/// The area ratio of Table 3-3, `11.43 / 5.8` (the thesis rounds it to 1.9707).
pub const GAMMA_TABLE_3_3: f64 = 11.43 / 5.8;
/// The equivalent underlap of Table 3-3 \[mm\].
pub const UNDERLAP_MM_TABLE_3_3: f64 = 0.0045;

/// The travel at which the thesis's name of the selected root changes from
/// X4 to X1, found by bisection (60 halvings) on [`label_of`] along the exact
/// X factor between `-0.95` and `0.95`. `None` when the names there are not
/// X4 on the left and X1 on the right (e.g. `gamma = 1`, where the quartic
/// degenerates at the null position).
///
/// This is the thesis's own split criterion made exact; [`crate::branch_split`]
/// gives the same travel in closed form.
pub fn label_switch_travel(gamma: f64) -> Option<f64> {
    let label = |t: f64| label_of(gamma, t, crate::x_factor(gamma, t));
    let (mut lo, mut hi) = (-0.95, 0.95);
    if label(lo) != 4 || label(hi) != 1 {
        return None;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if label(mid) == 4 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}
