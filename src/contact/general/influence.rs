//! Element integrals of the surface response (module docs of [`super`]): the Galerkin
//! matrices of the logarithmic and sign kernels for piecewise-constant densities.

use faer::{Accum, ColMut, ColRef, Mat, Par};

use super::mesh::Mesh;

/// `G(t) = t²/2 · ln(|t|/d) − 3t²/4`, with `G'' = ln(|t|/d)` and `G(0) = 0`.
pub(super) fn g2(t: f64, d: f64) -> f64 {
    if t == 0.0 {
        0.0
    } else {
        t * t * (0.5 * (t.abs() / d).ln() - 0.75)
    }
}

/// `∫_{x1}^{x2} ∫_{s1}^{s2} ln(|x − s|/d) ds dx`, exact.
pub fn log_pair(x1: f64, x2: f64, s1: f64, s2: f64, d: f64) -> f64 {
    g2(x2 - s1, d) - g2(x1 - s1, d) - g2(x2 - s2, d) + g2(x1 - s2, d)
}

/// The Galerkin matrices of a mesh: `log[i, j] = ∫_{e_i}∫_{e_j} ln(|x − s|/d)` (symmetric),
/// stored, and `sign[i, j] = ∫_{e_i}∫_{e_j} sign(x − s)` (antisymmetric: `±Δi Δj` for
/// distinct elements, 0 on the diagonal), applied in O(N) by its structure.
#[derive(Debug, Clone)]
pub struct Influence {
    /// The logarithmic kernel (m²).
    pub log: Mat<f64>,
    /// Element widths (m).
    pub widths: Vec<f64>,
}

impl Influence {
    /// Both matrices for a mesh and datum distance d (m).
    pub fn new(mesh: &Mesh, d: f64) -> Self {
        let n = mesh.len();
        let e = &mesh.edges;
        let w = mesh.widths();
        let mut log = Mat::<f64>::zeros(n, n);
        for i in 0..n {
            for j in 0..=i {
                let v = log_pair(e[i], e[i + 1], e[j], e[j + 1], d);
                log[(i, j)] = v;
                log[(j, i)] = v;
            }
        }
        Self { log, widths: w }
    }

    /// `out = log · v`.
    pub fn log_apply(&self, v: &[f64], out: &mut [f64]) {
        mat_vec(&self.log, v, out);
    }

    /// `out_i = (log · v)_i` for the elements `i` with `rows[i]`, and 0 for the others, with
    /// `v` zero outside `support` (a range of elements): by the symmetry of `log`, each run of
    /// such rows is a block of columns, transposed, times `v` on its support.
    pub fn log_apply_rows(
        &self,
        v: &[f64],
        support: std::ops::Range<usize>,
        rows: &[bool],
        out: &mut [f64],
    ) {
        out.fill(0.0);
        let vs = ColRef::from_slice(&v[support.clone()]).as_mat();
        let mut start = 0;
        while start < rows.len() {
            if !rows[start] {
                start += 1;
                continue;
            }
            let end = (start..rows.len()).find(|&i| !rows[i]).unwrap_or(rows.len());
            let block = self
                .log
                .as_ref()
                .submatrix(support.start, start, support.len(), end - start);
            faer::linalg::matmul::matmul(
                ColMut::from_slice_mut(&mut out[start..end]).as_mat_mut(),
                Accum::Replace,
                block.transpose(),
                vs,
                1.0,
                Par::Seq,
            );
            start = end;
        }
    }

    /// `out = sign · v`: `out_i = w_i (Σ_{j<i} w_j v_j − Σ_{j>i} w_j v_j)`.
    pub fn sign_apply(&self, v: &[f64], out: &mut [f64]) {
        let total: f64 = v.iter().zip(&self.widths).map(|(v, w)| v * w).sum();
        let mut below = 0.0;
        for (i, o) in out.iter_mut().enumerate() {
            let own = v[i] * self.widths[i];
            *o = self.widths[i] * (below - (total - below - own));
            below += own;
        }
    }
}

/// `out = a v` for a square matrix `a`.
pub(super) fn mat_vec(a: &Mat<f64>, v: &[f64], out: &mut [f64]) {
    faer::linalg::matmul::matmul(
        ColMut::from_slice_mut(out).as_mat_mut(),
        Accum::Replace,
        a.as_ref(),
        ColRef::from_slice(v).as_mat(),
        1.0,
        Par::Seq,
    );
}

#[cfg(test)]
mod tests {
    use super::*;

/// `∫_{x1}^{x2} ∫_{s1}^{s2} sign(x − s) ds dx` for elements `i` (field) and `j` (source) of a
/// mesh: `±Δi Δj` for distinct elements, 0 for the same element.
fn sign_pair(i: usize, j: usize, wi: f64, wj: f64) -> f64 {
    match i.cmp(&j) {
        std::cmp::Ordering::Greater => wi * wj,
        std::cmp::Ordering::Less => -wi * wj,
        std::cmp::Ordering::Equal => 0.0,
    }
}

    /// The O(N) sign product against the matrix of [`sign_pair`].
    #[test]
    fn sign_apply_matches_the_matrix() {
        let mesh = Mesh {
            edges: vec![-1.0, -0.5, 0.1, 0.2, 0.7, 1.5],
        };
        let inf = Influence::new(&mesh, 3.0);
        let v = [0.3, -1.2, 2.0, 0.7, -0.4];
        let mut out = [0.0; 5];
        inf.sign_apply(&v, &mut out);
        let w = mesh.widths();
        for i in 0..5 {
            let direct: f64 = (0..5).map(|j| sign_pair(i, j, w[i], w[j]) * v[j]).sum();
            assert!(
                (out[i] - direct).abs() < 1e-14,
                "{i}: {} vs {direct}",
                out[i]
            );
        }
    }

    /// The product on chosen rows with `v` zero outside its support: the full product's
    /// rows, to round-off, and 0 on the other rows.
    #[test]
    fn log_apply_rows_matches_the_full_product_on_its_rows() {
        let mesh = Mesh::uniform(-1.0, 1.0, 9);
        let inf = Influence::new(&mesh, 3.0);
        let v = [0.0, 0.0, 0.3, -1.2, 2.0, 0.7, -0.4, 0.0, 0.0];
        let rows = [true, true, false, false, true, false, false, true, true];
        let (mut full, mut some) = ([0.0; 9], [1.0; 9]);
        inf.log_apply(&v, &mut full);
        inf.log_apply_rows(&v, 2..7, &rows, &mut some);
        for i in 0..9 {
            let expected = if rows[i] { full[i] } else { 0.0 };
            assert!((some[i] - expected).abs() < 1e-14, "{i}: {} vs {expected}", some[i]);
        }
    }

    /// The closed form against a fine midpoint rule in both variables (well separated and
    /// adjacent elements) and the self term `h²(ln(h/d) − 3/2)`.
    #[test]
    fn log_pair_matches_quadrature_and_self_term() {
        let d = 2.0;
        let h: f64 = 0.3;
        assert!((log_pair(0.0, h, 0.0, h, d) - h * h * ((h / d).ln() - 1.5)).abs() < 1e-15);
        for (x1, x2, s1, s2) in [(0.0, 0.3, 1.0, 1.5), (0.0, 0.3, 0.3, 0.5)] {
            let n = 2000;
            let mut sum = 0.0;
            for a in 0..n {
                let x = x1 + (x2 - x1) * (a as f64 + 0.5) / n as f64;
                for b in 0..n {
                    let s = s1 + (s2 - s1) * (b as f64 + 0.5) / n as f64;
                    sum += ((x - s).abs() / d).ln();
                }
            }
            sum *= (x2 - x1) * (s2 - s1) / (n * n) as f64;
            let exact = log_pair(x1, x2, s1, s2, d);
            assert!((sum - exact).abs() < 2e-6 * exact.abs(), "{sum} vs {exact}");
            // Symmetry of the kernel.
            assert!((log_pair(s1, s2, x1, x2, d) - exact).abs() < 1e-15);
        }
    }
}
