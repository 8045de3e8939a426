//! The analytic Jacobians agree with central finite differences.

use hydrocyl_friction::{
    finite_difference_jacobian, CoulombViscous, FrictionInput, FrictionJacobian, FrictionLaw,
    FrictionModel, Karnopp, LuGre, Stribeck, Wang,
};
use hydrocyl_ports::{Acceleration, Pressure, Velocity};
use proptest::prelude::*;

use crate::common::{curve, dahl_from};

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-5 * (a.abs().max(b.abs()) + scale)
}

fn compare<M: FrictionModel>(m: &M, input: &FrictionInput, z: &[f64]) -> Result<(), TestCaseError> {
    let a: FrictionJacobian = m.jacobian(input, z);
    let n = finite_difference_jacobian(m, input, z);
    prop_assert!(
        close(a.df_dv, n.df_dv, 1.0),
        "df_dv {} vs {}",
        a.df_dv,
        n.df_dv
    );
    prop_assert!(
        close(a.df_dz, n.df_dz, 1.0),
        "df_dz {} vs {}",
        a.df_dz,
        n.df_dz
    );
    prop_assert!(
        close(a.dzdot_dz, n.dzdot_dz, 1.0),
        "dzdot_dz {} vs {}",
        a.dzdot_dz,
        n.dzdot_dz
    );
    prop_assert!(
        close(a.dzdot_dv, n.dzdot_dv, 1e-3),
        "dzdot_dv {} vs {}",
        a.dzdot_dv,
        n.dzdot_dv
    );
    prop_assert!(
        close(a.df_dp1, n.df_dp1, 1e-9),
        "df_dp1 {} vs {}",
        a.df_dp1,
        n.df_dp1
    );
    prop_assert!(
        close(a.df_dp2, n.df_dp2, 1e-9),
        "df_dp2 {} vs {}",
        a.df_dp2,
        n.df_dp2
    );
    Ok(())
}

fn velocity() -> impl Strategy<Value = f64> {
    prop_oneof![1e-4f64..0.3, -0.3f64..-1e-4]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn analytic_jacobians_match_finite_differences(
        v in velocity(),
        zr in -1.2f64..1.2,
        p1 in 0.0f64..1e7,
        p2 in 0.0f64..1e7,
        a in -2.0f64..2.0,
    ) {
        let input = FrictionInput {
            velocity: Velocity::new(v),
            acceleration: Acceleration::new(a),
            p1: Pressure::new(p1),
            p2: Pressure::new(p2),
        };
        // z as a fraction of the stiction deflection Fs/σ0.
        let lugre = LuGre::table_5_11();
        compare(&lugre, &input, &[zr * 188.0 / lugre.sigma0])?;
        let wang = Wang::table_5_8();
        compare(&wang, &input, &[zr * 188.0 / wang.sigma0])?;
        let dahl = dahl_from(&[110.0, 1.0, 0.0, 0.0, 3e7, 50.0]);
        compare(&dahl, &input, &[zr * 110.0 / 3e7])?;
        compare(&Stribeck::table_5_11(), &input, &[])?;
        compare(&CoulombViscous::leaney_moog(), &input, &[])?;
        let k = Karnopp::new(curve(1.0, 1.5, 1e-3, 2.0), 0.4).unwrap();
        compare(&k, &input, &[])?;
        compare(&FrictionLaw::LuGre(lugre), &input, &[zr * 188.0 / lugre.sigma0])?;
    }
}
