//! The small dense LU factorisations agree and detect singular matrices.

use hydrocyl_integrators::linalg::{DenseLu, InPlaceLu};
use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;

fn residual(a: &[f64], x: &[f64], b: &[f64]) -> f64 {
    let n = b.len();
    (0..n)
        .map(|i| ((0..n).map(|j| a[i * n + j] * x[j]).sum::<f64>() - b[i]).abs())
        .fold(0.0, f64::max)
}

fn solve_with<L: DenseLu>(n: usize, a: &[f64], b: &[f64]) -> Option<Vec<f64>> {
    let mut lu = L::new(n);
    lu.matrix_mut().copy_from_slice(a);
    if !lu.factor() {
        return None;
    }
    let mut x = b.to_vec();
    lu.solve(&mut x);
    Some(x)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn lu_solves_random_systems(n in 1usize..17, seed in proptest::collection::vec(-1.0f64..1.0, 16 * 16 + 16)) {
        let mut a: Vec<f64> = seed[..n * n].to_vec();
        // Keep the matrix safely non-singular; pivoting is still exercised
        // because the off-diagonal entries can exceed the diagonal ones.
        for i in 0..n {
            a[i * n + i] += if seed[i] >= 0.0 { 0.5 } else { -0.5 };
        }
        let b: Vec<f64> = seed[n * n..n * n + n].to_vec();
        let x1 = solve_with::<InPlaceLu>(n, &a, &b).expect("non-singular");
        // Reference: nalgebra's LU.
        let x2 = DMatrix::from_row_slice(n, n, &a)
            .lu()
            .solve(&DVector::from_column_slice(&b))
            .expect("non-singular");
        let scale = 1.0 + x1.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        prop_assert!(residual(&a, &x1, &b) < 1e-10 * scale * n as f64);
        for (p, q) in x1.iter().zip(&x2) {
            prop_assert!((p - q).abs() < 1e-8 * scale);
        }
    }
}

#[test]
fn pivoting_handles_a_zero_leading_entry() {
    let a = [0.0, 1.0, 1.0, 0.0];
    let x = solve_with::<InPlaceLu>(2, &a, &[2.0, 3.0]).unwrap();
    assert_eq!(x, vec![3.0, 2.0]);
}

#[test]
fn singular_matrices_are_reported() {
    let a = [1.0, 2.0, 2.0, 4.0];
    assert!(solve_with::<InPlaceLu>(2, &a, &[1.0, 1.0]).is_none());
    let nan = [f64::NAN, 0.0, 0.0, 1.0];
    assert!(solve_with::<InPlaceLu>(2, &nan, &[1.0, 1.0]).is_none());
}
