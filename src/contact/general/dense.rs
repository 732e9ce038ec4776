//! A dense solve with row and column equilibration (the systems mix gap, potential and
//! resultant rows whose scales differ by many orders of magnitude).

use faer::Mat;
use faer::linalg::solvers::Solve;

/// Solve `A x = b` by LU with partial pivoting after scaling every row, then every column, to
/// unit max-norm. `None` if a row or column is zero or the result is not finite.
pub fn solve(mut a: Mat<f64>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = a.nrows();
    debug_assert!(a.ncols() == n && b.len() == n);
    for i in 0..n {
        let s = (0..n).map(|j| a[(i, j)].abs()).fold(0.0, f64::max);
        if s == 0.0 {
            return None;
        }
        for j in 0..n {
            a[(i, j)] /= s;
        }
        b[i] /= s;
    }
    let mut col = vec![0.0; n];
    for (j, c) in col.iter_mut().enumerate() {
        *c = (0..n).map(|i| a[(i, j)].abs()).fold(0.0, f64::max);
        if *c == 0.0 {
            return None;
        }
        for i in 0..n {
            a[(i, j)] /= *c;
        }
    }
    let lu = a.partial_piv_lu();
    lu.solve_in_place(faer::ColMut::from_slice_mut(&mut b));
    for (x, c) in b.iter_mut().zip(&col) {
        *x /= c;
    }
    b.iter().all(|x| x.is_finite()).then_some(b)
}
