//! A dense solve with row and column equilibration (the systems mix gap, potential and
//! resultant rows whose scales differ by many orders of magnitude), factored once and reused.

use faer::Mat;
use faer::linalg::solvers::{PartialPivLu, Solve};

/// `D_r A D_c = L U` with `D_r`, `D_c` scaling every row, then every column, to unit max-norm.
#[derive(Debug, Clone)]
pub(super) struct Factored {
    lu: PartialPivLu<f64>,
    row: Vec<f64>,
    col: Vec<f64>,
}

impl Factored {
    /// Factor `a`; `None` if a row or column is zero.
    pub fn new(mut a: Mat<f64>) -> Option<Self> {
        let n = a.nrows();
        debug_assert!(a.ncols() == n);
        let mut row = vec![0.0; n];
        for (i, r) in row.iter_mut().enumerate() {
            let s = (0..n).map(|j| a[(i, j)].abs()).fold(0.0, f64::max);
            if s == 0.0 {
                return None;
            }
            *r = 1.0 / s;
            for j in 0..n {
                a[(i, j)] *= *r;
            }
        }
        let mut col = vec![0.0; n];
        for (j, c) in col.iter_mut().enumerate() {
            let s = (0..n).map(|i| a[(i, j)].abs()).fold(0.0, f64::max);
            if s == 0.0 {
                return None;
            }
            *c = 1.0 / s;
            for i in 0..n {
                a[(i, j)] *= *c;
            }
        }
        Some(Self {
            lu: a.partial_piv_lu(),
            row,
            col,
        })
    }

    /// `A⁻¹ b`; `None` if not finite.
    pub fn solve(&self, b: &[f64]) -> Option<Vec<f64>> {
        let mut x: Vec<f64> = b.iter().zip(&self.row).map(|(b, r)| b * r).collect();
        self.lu.solve_in_place(faer::ColMut::from_slice_mut(&mut x));
        for (x, c) in x.iter_mut().zip(&self.col) {
            *x *= c;
        }
        x.iter().all(|x| x.is_finite()).then_some(x)
    }
}

/// Factorizations kept through the outer iterations of one step, keyed by the element sets
/// that define the matrices.
#[derive(Debug, Default)]
pub(super) struct Workspace {
    /// The normal system for a contact set.
    pub normal: Option<(Vec<bool>, Factored)>,
    /// The tangential step system for (contact elements, free elements).
    pub tangential: Option<(Vec<usize>, Vec<usize>, Factored)>,
}
