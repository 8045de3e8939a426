//! Force evaluations per second for each friction model: one evaluation is
//! `force` plus, for the dynamic models, `state_derivative` (what an
//! integrator's right-hand side calls), over 1024 inputs sweeping ±60 mm/s
//! with 0–20 bar across the piston. Criterion reports the throughput in
//! elements (evaluations) per second.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use hydrocyl_friction::{
    CoulombViscous, Dahl, FrictionInput, FrictionLaw, FrictionModel, Karnopp, LuGre, Stribeck,
    StribeckCurve, Wang,
};
use hydrocyl_ports::{Force, Pressure, Velocity};
use std::hint::black_box;

fn inputs() -> Vec<(FrictionInput, f64)> {
    (0..1024)
        .map(|i| {
            let s = i as f64 / 1023.0;
            let input = FrictionInput {
                velocity: Velocity::new(0.06 * (2.0 * s - 1.0)),
                p1: Pressure::from_bar(20.0 * s),
                p2: Pressure::from_bar(5.0),
                ..FrictionInput::default()
            };
            // A bristle deflection inside the stiction band.
            (input, 4e-6 * (7.0 * s).sin())
        })
        .collect()
}

fn laws() -> Vec<FrictionLaw> {
    let curve = StribeckCurve {
        coulomb: Force::new(110.0),
        stiction: Force::new(180.0),
        stribeck_velocity: Velocity::new(0.01),
        stribeck_exponent: 0.1087,
    };
    vec![
        FrictionLaw::CoulombViscous(CoulombViscous::leaney_moog()),
        FrictionLaw::Stribeck(Stribeck::table_5_11()),
        FrictionLaw::Karnopp(Karnopp::new(curve, 1000.0).expect("valid Karnopp")),
        FrictionLaw::Dahl(Dahl::new(110.0, 3e7, 1000.0).expect("valid Dahl")),
        FrictionLaw::LuGre(LuGre::table_5_11()),
        FrictionLaw::Wang(Wang::table_5_8()),
    ]
}

fn eval<M: FrictionModel>(m: &M, xs: &[(FrictionInput, f64)]) -> f64 {
    let mut acc = 0.0;
    let mut dz = [0.0];
    for (input, z) in xs {
        let z = [*z];
        acc += m.force(input, &z).si();
        if m.n_states() == 1 {
            m.state_derivative(input, &z, &mut dz);
            acc += dz[0];
        }
    }
    acc
}

fn bench(c: &mut Criterion) {
    let xs = inputs();
    let mut g = c.benchmark_group("friction_force_eval");
    g.throughput(Throughput::Elements(xs.len() as u64));
    for law in laws() {
        g.bench_function(law.name(), |b| {
            b.iter(|| eval(black_box(&law), black_box(&xs)))
        });
    }
    // The concrete type without the enum's dispatch, for comparison.
    let wang = Wang::table_5_8();
    g.bench_function("wang (concrete type)", |b| {
        b.iter(|| eval(black_box(&wang), black_box(&xs)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
