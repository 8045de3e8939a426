//! The quantity newtypes and the products between them.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

/// What every quantity newtype is: a `Copy` wrapper of its SI value, so that
/// generic code (the circuit assembler's typed wires) can store quantities as
/// bare `f64` and hand them back typed. `f64` itself is the dimensionless
/// quantity (a normalised command, a count, a ratio).
pub trait Quantity: Copy + fmt::Debug + 'static {
    /// The SI unit symbol, e.g. `"Pa"` (`"-"` for a dimensionless `f64`).
    const UNIT: &'static str;
    /// The quantity from its SI value.
    fn from_si(si: f64) -> Self;
    /// The SI value.
    fn si(self) -> f64;
}

impl Quantity for f64 {
    const UNIT: &'static str = "-";
    #[inline(always)]
    fn from_si(si: f64) -> Self {
        si
    }
    #[inline(always)]
    fn si(self) -> f64 {
        self
    }
}

/// Defines one SI quantity newtype with the operations every quantity has:
/// addition and subtraction of like quantities, scaling by `f64`, the ratio of
/// two like quantities as a plain `f64`, and summation.
macro_rules! quantity {
    ($(#[$doc:meta])* $name:ident, $unit:literal) => {
        $(#[$doc])*
        #[repr(transparent)]
        #[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd, Serialize, Deserialize)]
        #[serde(transparent)]
        pub struct $name(f64);

        impl $name {
            /// Zero of this quantity.
            pub const ZERO: Self = Self(0.0);
            #[doc = concat!("From the SI value in ", $unit, ".")]
            #[inline(always)]
            pub const fn new(si: f64) -> Self {
                Self(si)
            }
            #[doc = concat!("The SI value in ", $unit, ".")]
            #[inline(always)]
            pub const fn si(self) -> f64 {
                self.0
            }
            /// Absolute value.
            #[inline(always)]
            pub fn abs(self) -> Self {
                Self(self.0.abs())
            }
            /// Sign of the value as `f64` (`1.0`, `-1.0`; `signum` of `f64`).
            #[inline(always)]
            pub fn signum(self) -> f64 {
                self.0.signum()
            }
            /// `true` unless the value is NaN or infinite.
            #[inline(always)]
            pub fn is_finite(self) -> bool {
                self.0.is_finite()
            }
            /// The larger of two values.
            #[inline(always)]
            pub fn max(self, other: Self) -> Self {
                Self(self.0.max(other.0))
            }
            /// The smaller of two values.
            #[inline(always)]
            pub fn min(self, other: Self) -> Self {
                Self(self.0.min(other.0))
            }
        }

        impl Quantity for $name {
            const UNIT: &'static str = $unit;
            #[inline(always)]
            fn from_si(si: f64) -> Self {
                Self(si)
            }
            #[inline(always)]
            fn si(self) -> f64 {
                self.0
            }
        }

        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                if let Some(p) = f.precision() {
                    write!(f, "{:.*} {}", p, self.0, $unit)
                } else {
                    write!(f, "{} {}", self.0, $unit)
                }
            }
        }

        impl Add for $name {
            type Output = Self;
            #[inline(always)]
            fn add(self, rhs: Self) -> Self {
                Self(self.0 + rhs.0)
            }
        }
        impl Sub for $name {
            type Output = Self;
            #[inline(always)]
            fn sub(self, rhs: Self) -> Self {
                Self(self.0 - rhs.0)
            }
        }
        impl AddAssign for $name {
            #[inline(always)]
            fn add_assign(&mut self, rhs: Self) {
                self.0 += rhs.0;
            }
        }
        impl SubAssign for $name {
            #[inline(always)]
            fn sub_assign(&mut self, rhs: Self) {
                self.0 -= rhs.0;
            }
        }
        impl Neg for $name {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                Self(-self.0)
            }
        }
        impl Mul<f64> for $name {
            type Output = Self;
            #[inline(always)]
            fn mul(self, rhs: f64) -> Self {
                Self(self.0 * rhs)
            }
        }
        impl Mul<$name> for f64 {
            type Output = $name;
            #[inline(always)]
            fn mul(self, rhs: $name) -> $name {
                $name(self * rhs.0)
            }
        }
        impl Div<f64> for $name {
            type Output = Self;
            #[inline(always)]
            fn div(self, rhs: f64) -> Self {
                Self(self.0 / rhs)
            }
        }
        impl Div for $name {
            type Output = f64;
            #[inline(always)]
            fn div(self, rhs: Self) -> f64 {
                self.0 / rhs.0
            }
        }
        impl std::iter::Sum for $name {
            fn sum<I: Iterator<Item = Self>>(iter: I) -> Self {
                Self(iter.map(|q| q.0).sum())
            }
        }
    };
}

/// Defines `A * B = C` (both orders), `C / A = B` and `C / B = A`.
macro_rules! product {
    ($a:ident * $b:ident = $c:ident) => {
        impl Mul<$b> for $a {
            type Output = $c;
            #[inline(always)]
            fn mul(self, rhs: $b) -> $c {
                $c(self.0 * rhs.0)
            }
        }
        impl Mul<$a> for $b {
            type Output = $c;
            #[inline(always)]
            fn mul(self, rhs: $a) -> $c {
                $c(self.0 * rhs.0)
            }
        }
        impl Div<$a> for $c {
            type Output = $b;
            #[inline(always)]
            fn div(self, rhs: $a) -> $b {
                $b(self.0 / rhs.0)
            }
        }
        impl Div<$b> for $c {
            type Output = $a;
            #[inline(always)]
            fn div(self, rhs: $b) -> $a {
                $a(self.0 / rhs.0)
            }
        }
    };
}

quantity!(
    /// Pressure \[Pa\] (gauge unless said otherwise). Also used for bulk modulus.
    Pressure, "Pa"
);
quantity!(
    /// Volume flow rate \[m³·s⁻¹\].
    VolumeFlow, "m^3/s"
);
quantity!(
    /// Force \[N\].
    Force, "N"
);
quantity!(
    /// Linear velocity \[m·s⁻¹\].
    Velocity, "m/s"
);
quantity!(
    /// Linear acceleration \[m·s⁻²\].
    Acceleration, "m/s^2"
);
quantity!(
    /// Linear position or length \[m\] (piston position from mid-stroke, + extending).
    Position, "m"
);
quantity!(
    /// Volume \[m³\].
    Volume, "m^3"
);
quantity!(
    /// Area \[m²\].
    Area, "m^2"
);
quantity!(
    /// Mass \[kg\].
    Mass, "kg"
);
quantity!(
    /// Mass density \[kg·m⁻³\].
    Density, "kg/m^3"
);
quantity!(
    /// Time or duration \[s\].
    Time, "s"
);
quantity!(
    /// Power \[W\].
    Power, "W"
);
quantity!(
    /// Energy \[J\].
    Energy, "J"
);
quantity!(
    /// Torque \[N·m\].
    Torque, "N m"
);
quantity!(
    /// Angular velocity \[rad·s⁻¹\].
    AngularVelocity, "rad/s"
);
quantity!(
    /// Electric potential \[V\].
    Voltage, "V"
);
quantity!(
    /// Electric current \[A\].
    Current, "A"
);

product!(Pressure * VolumeFlow = Power);
product!(Force * Velocity = Power);
product!(Torque * AngularVelocity = Power);
product!(Voltage * Current = Power);
product!(Pressure * Area = Force);
product!(Area * Velocity = VolumeFlow);
product!(Area * Position = Volume);
product!(Mass * Acceleration = Force);
product!(Power * Time = Energy);
product!(Pressure * Volume = Energy);
product!(Velocity * Time = Position);
product!(VolumeFlow * Time = Volume);
product!(Acceleration * Time = Velocity);

impl Pressure {
    /// From bar (1 bar = 1e5 Pa).
    #[inline(always)]
    pub const fn from_bar(bar: f64) -> Self {
        Self(bar * 1.0e5)
    }
    /// From kilopascal.
    #[inline(always)]
    pub const fn from_kpa(kpa: f64) -> Self {
        Self(kpa * 1.0e3)
    }
    /// From megapascal.
    #[inline(always)]
    pub const fn from_mpa(mpa: f64) -> Self {
        Self(mpa * 1.0e6)
    }
    /// From pound-force per square inch (1 psi = 6894.757293168 Pa).
    #[inline(always)]
    pub const fn from_psi(psi: f64) -> Self {
        Self(psi * PSI_IN_PA)
    }
    /// From pascal (same as [`Pressure::new`]).
    #[inline(always)]
    pub const fn from_pa(pa: f64) -> Self {
        Self(pa)
    }
    /// In pascal.
    #[inline(always)]
    pub const fn pa(self) -> f64 {
        self.0
    }
    /// In bar.
    #[inline(always)]
    pub fn bar(self) -> f64 {
        self.0 / 1.0e5
    }
    /// In megapascal.
    #[inline(always)]
    pub fn mpa(self) -> f64 {
        self.0 / 1.0e6
    }
    /// In psi.
    #[inline(always)]
    pub fn psi(self) -> f64 {
        self.0 / PSI_IN_PA
    }
}

/// One pound-force per square inch in pascal.
pub const PSI_IN_PA: f64 = 6894.757293168361;

impl VolumeFlow {
    /// From litres per minute.
    #[inline(always)]
    pub const fn from_l_per_min(lpm: f64) -> Self {
        Self(lpm / 60_000.0)
    }
    /// From m³/s (same as [`VolumeFlow::new`]).
    #[inline(always)]
    pub const fn from_m3_per_s(q: f64) -> Self {
        Self(q)
    }
    /// In m³/s.
    #[inline(always)]
    pub const fn m3_per_s(self) -> f64 {
        self.0
    }
    /// In litres per minute.
    #[inline(always)]
    pub fn l_per_min(self) -> f64 {
        self.0 * 60_000.0
    }
}

impl Position {
    /// From millimetres.
    #[inline(always)]
    pub const fn from_mm(mm: f64) -> Self {
        Self(mm * 1.0e-3)
    }
    /// From metres (same as [`Position::new`]).
    #[inline(always)]
    pub const fn from_m(m: f64) -> Self {
        Self(m)
    }
    /// In metres.
    #[inline(always)]
    pub const fn m(self) -> f64 {
        self.0
    }
    /// In millimetres.
    #[inline(always)]
    pub fn mm(self) -> f64 {
        self.0 * 1.0e3
    }
}

impl Velocity {
    /// From millimetres per second.
    #[inline(always)]
    pub const fn from_mm_per_s(mm_s: f64) -> Self {
        Self(mm_s * 1.0e-3)
    }
    /// From metres per second (same as [`Velocity::new`]).
    #[inline(always)]
    pub const fn from_m_per_s(v: f64) -> Self {
        Self(v)
    }
    /// In metres per second.
    #[inline(always)]
    pub const fn m_per_s(self) -> f64 {
        self.0
    }
    /// In millimetres per second.
    #[inline(always)]
    pub fn mm_per_s(self) -> f64 {
        self.0 * 1.0e3
    }
}

impl Area {
    /// From square millimetres.
    #[inline(always)]
    pub const fn from_mm2(mm2: f64) -> Self {
        Self(mm2 * 1.0e-6)
    }
    /// From square centimetres.
    #[inline(always)]
    pub const fn from_cm2(cm2: f64) -> Self {
        Self(cm2 * 1.0e-4)
    }
    /// In square metres.
    #[inline(always)]
    pub const fn m2(self) -> f64 {
        self.0
    }
}

impl Volume {
    /// From cubic centimetres (cc).
    #[inline(always)]
    pub const fn from_cc(cc: f64) -> Self {
        Self(cc * 1.0e-6)
    }
    /// From litres.
    #[inline(always)]
    pub const fn from_litres(l: f64) -> Self {
        Self(l * 1.0e-3)
    }
    /// In cubic metres.
    #[inline(always)]
    pub const fn m3(self) -> f64 {
        self.0
    }
}

impl Force {
    /// From kilonewton.
    #[inline(always)]
    pub const fn from_kn(kn: f64) -> Self {
        Self(kn * 1.0e3)
    }
    /// In newton.
    #[inline(always)]
    pub const fn n(self) -> f64 {
        self.0
    }
}

impl Mass {
    /// In kilograms.
    #[inline(always)]
    pub const fn kg(self) -> f64 {
        self.0
    }
}

impl Power {
    /// In watts.
    #[inline(always)]
    pub const fn watts(self) -> f64 {
        self.0
    }
}

impl Energy {
    /// In joules.
    #[inline(always)]
    pub const fn joules(self) -> f64 {
        self.0
    }
}

impl Time {
    /// From milliseconds.
    #[inline(always)]
    pub const fn from_ms(ms: f64) -> Self {
        Self(ms * 1.0e-3)
    }
    /// In seconds.
    #[inline(always)]
    pub const fn s(self) -> f64 {
        self.0
    }
}

impl AngularVelocity {
    /// From revolutions per minute.
    #[inline(always)]
    pub fn from_rpm(rpm: f64) -> Self {
        Self(rpm * std::f64::consts::TAU / 60.0)
    }
    /// In revolutions per minute.
    #[inline(always)]
    pub fn rpm(self) -> f64 {
        self.0 * 60.0 / std::f64::consts::TAU
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn engineering_units_round_trip() {
        assert_eq!(Pressure::from_bar(70.0).pa(), 7.0e6);
        assert_eq!(Pressure::from_mpa(16.0626).pa(), 16.0626e6);
        assert!((Pressure::from_psi(150.0).pa() - 1.0342e6).abs() < 100.0);
        assert!((VolumeFlow::from_l_per_min(60.0).m3_per_s() - 1.0e-3).abs() < 1e-18);
        assert_eq!(Position::from_mm(260.0).m(), 0.26);
        assert_eq!(Velocity::from_mm_per_s(50.0).m_per_s(), 0.05);
        assert!((AngularVelocity::from_rpm(8000.0).rpm() - 8000.0).abs() < 1e-9);
    }

    #[test]
    fn products_have_physical_types() {
        let f: Force = Pressure::from_bar(10.0) * Area::from_cm2(10.0);
        assert!((f.n() - 1000.0).abs() < 1e-9);
        let p: Power = f * Velocity::from_mm_per_s(100.0);
        assert!((p.watts() - 100.0).abs() < 1e-9);
        let e: Energy = p * Time::new(2.0);
        assert!((e.joules() - 200.0).abs() < 1e-9);
        let back: Velocity = VolumeFlow::new(1e-4) / Area::new(1e-3);
        assert!((back.m_per_s() - 0.1).abs() < 1e-15);
    }

    #[test]
    fn serde_is_transparent() {
        let p = Pressure::from_bar(1.0);
        assert_eq!(serde_json::to_string(&p).unwrap(), "100000.0");
        let q: VolumeFlow = serde_json::from_str("2.5e-5").unwrap();
        assert_eq!(q.si(), 2.5e-5);
    }

    proptest! {
        #[test]
        fn bar_round_trip(x in -1.0e4f64..1.0e4) {
            let p = Pressure::from_bar(x);
            prop_assert!((p.bar() - x).abs() <= 1e-12 * x.abs().max(1.0));
        }

        #[test]
        fn product_then_ratio_recovers_factor(a in 1e-6f64..1.0, b in -1e7f64..1e7) {
            let f = Pressure::new(b) * Area::new(a);
            let back = f / Area::new(a);
            prop_assert!((back.pa() - b).abs() <= 1e-9 * b.abs().max(1.0));
        }
    }
}
