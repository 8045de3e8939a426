//! Karnopp's stick mode with located events, on the mass-spring-belt, against
//! the closed-form stick-slip cycle of Coulomb friction with a stiction peak.

use hydrocyl_friction::{FrictionInput, FrictionMode, FrictionModel, Karnopp};
use hydrocyl_ports::{Force, Velocity};

use crate::common::{curve, rk4};

const MASS: f64 = 1.0;
const K: f64 = 2.0;
const VB: f64 = 0.1;

/// A minimal event-locating assembler: RK4 steps, falling crossings of the
/// model's switching functions located by bisection to 1e-12 s, mode
/// contract of the trait docs. Returns (break-away times, stick-start times,
/// spring force at each break-away, spring force at each stick start).
type Record = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);
fn run(model: &mut Karnopp, t_end: f64) -> Record {
    let drive = |t: f64, x: f64| K * (VB * t - x);
    let rhs = |m: &Karnopp, t: f64, s: &[f64], ds: &mut [f64]| {
        ds[0] = s[1];
        ds[1] = if m.mode() == FrictionMode::Stick {
            0.0
        } else {
            let i = FrictionInput::at_velocity(Velocity::new(s[1]));
            (drive(t, s[0]) - m.force(&i, &[]).si()) / MASS
        };
    };
    let events = |m: &Karnopp, t: f64, s: &[f64]| {
        let mut g = [0.0; 2];
        let i = FrictionInput::at_velocity(Velocity::new(s[1]));
        m.events(&i, Force::new(drive(t, s[0])), &[], &mut g);
        g
    };
    let mut s = [0.0, 0.0];
    let mut t = 0.0;
    let i0 = FrictionInput::at_velocity(Velocity::new(0.0));
    model.initialise_mode(&i0, Force::new(0.0));
    let (mut breaks, mut sticks, mut fbreak, mut fstick) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let h = 1e-4;
    while t < t_end {
        let g0 = events(model, t, &s);
        let mut trial = s;
        let m: &Karnopp = model;
        rk4(
            &|tt, x: &[f64], dx: &mut [f64]| rhs(m, tt, x, dx),
            t,
            &mut trial,
            h,
        );
        let g1 = events(model, t + h, &trial);
        let which = (0..2).find(|&j| g0[j] > 0.0 && g1[j] <= 0.0);
        let Some(j) = which else {
            s = trial;
            t += h;
            continue;
        };
        // Bisection on the step length for the crossing of g_j.
        let (mut lo, mut hi) = (0.0, h);
        while hi - lo > 1e-12 {
            let mid = 0.5 * (lo + hi);
            let mut x = s;
            rk4(
                &|tt, x: &[f64], dx: &mut [f64]| rhs(m, tt, x, dx),
                t,
                &mut x,
                mid,
            );
            if events(model, t + mid, &x)[j] > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let mut x = s;
        rk4(
            &|tt, x: &[f64], dx: &mut [f64]| rhs(m, tt, x, dx),
            t,
            &mut x,
            hi,
        );
        t += hi;
        s = x;
        let before = model.mode();
        let i = FrictionInput::at_velocity(Velocity::new(s[1]));
        let after = model.on_event(j, &i, Force::new(drive(t, s[0])), &mut []);
        s[1] = 0.0; // the contract: v = 0 after every Karnopp event
        match (before, after) {
            (FrictionMode::Slip, FrictionMode::Stick) => {
                sticks.push(t);
                fstick.push(drive(t, s[0]));
            }
            (FrictionMode::Stick, FrictionMode::Slip) => {
                breaks.push(t);
                fbreak.push(drive(t, s[0]));
            }
            _ => {}
        }
    }
    (breaks, sticks, fbreak, fstick)
}

#[test]
fn stick_slip_cycle_matches_the_closed_form() {
    // Fs = 1.5 N break-away, Stribeck drop to the kinetic level Fc = 1 N
    // within ~0.1 mm/s.
    let (fc, fs) = (1.0, 1.5);
    let mut m = Karnopp::new(curve(fc, fs, 1e-4, 2.0), 0.0).unwrap();
    let (breaks, sticks, fbreak, fstick) = run(&mut m, 40.0);
    assert!(
        breaks.len() >= 4 && sticks.len() >= 4,
        "{breaks:?} {sticks:?}"
    );
    // Exact properties of the modes: break-away exactly at Fs, the first
    // one after the spring has been loaded from zero at k vb; the stick
    // lasts exactly until the belt has reloaded the spring to Fs.
    assert!(
        (breaks[0] - fs / (K * VB)).abs() < 1e-6,
        "first break {}",
        breaks[0]
    );
    for f in &fbreak {
        assert!((f - fs).abs() < 1e-9, "break-away force {f}");
    }
    for ((s, b), f) in sticks.iter().zip(breaks.iter().skip(1)).zip(&fstick) {
        assert!((b - s - (fs - f) / (K * VB)).abs() < 1e-6);
    }
    // Closed form for Coulomb slip at Fc (the Stribeck drop delays the start
    // by a few hundredths of a second): a half-swing of the oscillator about
    // Fc/k from spring force Fs down to 2Fc − Fs, then a stick until the belt
    // reloads the spring to Fs.
    let w = (K / MASS).sqrt();
    let a = (fs - fc) / K;
    let beta = (VB / (a * w)).atan();
    let t_slip = (std::f64::consts::PI + 2.0 * beta) / w;
    let t_stick = 2.0 * (fs - fc) / (K * VB);
    for (b, s) in breaks.iter().zip(&sticks) {
        assert!(
            ((s - b) / t_slip - 1.0).abs() < 0.03,
            "slip {} vs {}",
            s - b,
            t_slip
        );
    }
    for (s, b) in sticks.iter().zip(breaks.iter().skip(1)) {
        assert!(
            ((b - s) / t_stick - 1.0).abs() < 0.03,
            "stick {} vs {}",
            b - s,
            t_stick
        );
    }
    for f in &fstick {
        assert!(
            (f - (2.0 * fc - fs)).abs() < 0.03,
            "spring force at stick {f}"
        );
    }
}

#[test]
fn a_drive_beyond_stiction_reverses_instead_of_sticking() {
    let mut m = Karnopp::new(curve(1.0, 1.5, 1e-3, 2.0), 0.0).unwrap();
    let i = FrictionInput::at_velocity(Velocity::new(0.01));
    assert_eq!(m.initialise_mode(&i, Force::new(0.0)), FrictionMode::Slip);
    let stop = FrictionInput::at_velocity(Velocity::new(0.0));
    assert_eq!(
        m.on_event(0, &stop, Force::new(-2.0), &mut []),
        FrictionMode::Slip
    );
    // Now slipping backwards: the force opposes the new direction at v = 0.
    assert_eq!(m.force(&stop, &[]).si(), -1.5);
    let mut g = [0.0; 2];
    m.events(
        &FrictionInput::at_velocity(Velocity::new(-1e-3)),
        Force::new(-2.0),
        &[],
        &mut g,
    );
    assert!(g[0] > 0.0);
    // Sticks at the next stop if the drive is inside the band.
    assert_eq!(
        m.on_event(0, &stop, Force::new(1.0), &mut []),
        FrictionMode::Stick
    );
    m.events(&stop, Force::new(1.0), &[], &mut g);
    assert_eq!(g, [1.0, 0.5]);
}
