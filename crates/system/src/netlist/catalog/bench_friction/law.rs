//! The bench law's arithmetic (eqs 5.1, 5.4, 5.12): the force, the
//! bristle's rate and their partial derivatives (the analytic tangents of
//! `friction_bench`).

/// The coefficients of the bench law \[SI\].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchLaw {
    /// Coulomb level Fc \[N\].
    pub coulomb: f64,
    /// Smoothing velocity v_t of the tanh \[m·s⁻¹\].
    pub smoothing_velocity: f64,
    /// Stiction level Fs, Stribeck velocity vs \[m·s⁻¹\] and exponent α,
    /// when the curve has a hump.
    pub stribeck: Option<(f64, f64, f64)>,
    /// Bristle stiffness σ0 \[N·m⁻¹\] and damping σ1 \[N·s·m⁻¹\] (LuGre), when on.
    pub lugre: Option<(f64, f64)>,
    /// Viscous coefficient b \[N·s·m⁻¹\].
    pub viscous: f64,
    /// Seal gain K \[m³·s·N⁻¹\].
    pub k_pressure: f64,
    /// Acceleration gain H \[N²·s·m⁻⁴\] (the term is K H a).
    pub h_acceleration: f64,
    /// Direction asymmetry dFc \[N\].
    pub asymmetry: f64,
    /// Constant force F0 \[N\].
    pub external_force: f64,
}

impl BenchLaw {
    /// What the law's terms need of the velocity `v`: g(v) (the Coulomb
    /// level plus the Stribeck hump if any), dg/dv (0 without the hump; the
    /// one-sided slope of the `+` side at `v = 0` with `α = 1`) and
    /// tanh(v/v_t), computed once (one power, one exponential, one tanh).
    pub fn shape(&self, v: f64) -> Shape {
        let th = (v / self.smoothing_velocity).tanh();
        let (g, dg) = match self.stribeck {
            Some((fs, vs, al)) => {
                let vs = vs.max(1e-12);
                let r = (v / vs).abs();
                let (e, de) = if al == 1.0 {
                    (r, 1.0)
                } else if r == 0.0 {
                    (0.0, if al > 1.0 { 0.0 } else { f64::INFINITY })
                } else {
                    let e = r.powf(al);
                    (e, al * e / r)
                };
                let hump = (fs - self.coulomb) * (-e).exp();
                (self.coulomb + hump, -hump * de * v.signum() / vs)
            }
            None => (self.coulomb, 0.0),
        };
        Shape { v, g, dg, th }
    }

    /// The bristle's rate `ż` at deflection `z` \[m·s⁻¹\].
    pub fn z_rate(&self, v: f64, z: f64) -> f64 {
        self.z_rate_at(&self.shape(v), z)
    }

    /// [`BenchLaw::z_rate`] at a velocity's [`Shape`].
    pub fn z_rate_at(&self, s: &Shape, z: f64) -> f64 {
        let s0 = self.lugre.map_or(0.0, |(s0, _)| s0);
        s.v - s0 * s.v.abs() * z / s.g.max(1e-9)
    }

    /// The friction force without the acceleration term `K H a` and without
    /// `F0` \[N\] (+ opposing + motion), at deflection `z`.
    pub fn force(&self, v: f64, p1: f64, p2: f64, z: f64) -> f64 {
        self.force_at(&self.shape(v), p1, p2, z)
    }

    /// [`BenchLaw::force`] at a velocity's [`Shape`].
    pub fn force_at(&self, s: &Shape, p1: f64, p2: f64, z: f64) -> f64 {
        let (v, th) = (s.v, s.th);
        let mut f = match self.lugre {
            Some((s0, s1)) => s0 * z + s1 * self.z_rate_at(s, z),
            None => s.g * th,
        };
        f += self.viscous * v;
        f += self.k_pressure * (p1 - p2).powi(2) * v;
        f += 0.5 * self.asymmetry * th.abs();
        f
    }

    /// The acceleration coefficient `K H` \[kg\] (the term's mass side).
    pub fn added_mass(&self) -> f64 {
        self.k_pressure * self.h_acceleration
    }

    /// The partials of [`BenchLaw::force_at`] and [`BenchLaw::z_rate_at`]
    /// at a velocity's [`Shape`] and `(p1, p2, z)` (the bench's analytic
    /// tangents).
    pub fn partials_at(&self, s: &Shape, p1: f64, p2: f64, z: f64) -> BenchPartials {
        let (v, g, dg, th) = (s.v, s.g, s.dg, s.th);
        let dth = (1.0 - th * th) / self.smoothing_velocity;
        let mut d = BenchPartials::default();
        match self.lugre {
            Some((s0, s1)) => {
                let gg = g.max(1e-9);
                let dgg = if g > 1e-9 { dg } else { 0.0 };
                // ż = v − σ0 |v| z / g
                d.dzdot_dz = -s0 * v.abs() / gg;
                d.dzdot_dv = 1.0 - s0 * z * (v.signum() * gg - v.abs() * dgg) / (gg * gg);
                d.df_dz = s0 + s1 * d.dzdot_dz;
                d.df_dv = s1 * d.dzdot_dv;
            }
            None => d.df_dv = dg * th + g * dth,
        }
        let dp = p1 - p2;
        d.df_dv +=
            self.viscous + self.k_pressure * dp * dp + 0.5 * self.asymmetry * th.signum() * dth;
        d.df_dp1 = 2.0 * self.k_pressure * dp * v;
        d.df_dp2 = -d.df_dp1;
        d
    }
}

/// What the bench law needs of one velocity ([`BenchLaw::shape`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shape {
    /// The velocity \[m·s⁻¹\].
    pub v: f64,
    /// g(v) \[N\].
    pub g: f64,
    /// dg/dv \[N·s·m⁻¹\].
    pub dg: f64,
    /// tanh(v / v_t).
    pub th: f64,
}

/// Partial derivatives of the bench law (SI): of the friction force `F`
/// ([`BenchLaw::force`]) and of the bristle's rate `ż`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BenchPartials {
    /// ∂F/∂v.
    pub df_dv: f64,
    /// ∂F/∂p1.
    pub df_dp1: f64,
    /// ∂F/∂p2.
    pub df_dp2: f64,
    /// ∂F/∂z.
    pub df_dz: f64,
    /// ∂ż/∂v.
    pub dzdot_dv: f64,
    /// ∂ż/∂z.
    pub dzdot_dz: f64,
}
