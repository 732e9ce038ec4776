//! Element integrals of the surface response (module docs of [`super`]): the Galerkin
//! matrices of the logarithmic and sign kernels for piecewise-constant densities.

use faer::Mat;

use super::mesh::Mesh;

/// `G(t) = t²/2 · ln(|t|/d) − 3t²/4`, with `G'' = ln(|t|/d)` and `G(0) = 0`.
fn g2(t: f64, d: f64) -> f64 {
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

/// `∫_{x1}^{x2} ∫_{s1}^{s2} sign(x − s) ds dx` for elements `i` (field) and `j` (source) of a
/// mesh: `±Δi Δj` for distinct elements, 0 for the same element.
pub fn sign_pair(i: usize, j: usize, wi: f64, wj: f64) -> f64 {
    match i.cmp(&j) {
        std::cmp::Ordering::Greater => wi * wj,
        std::cmp::Ordering::Less => -wi * wj,
        std::cmp::Ordering::Equal => 0.0,
    }
}

/// The Galerkin matrices of a mesh: `log[i, j] = ∫_{e_i}∫_{e_j} ln(|x − s|/d)` (symmetric) and
/// `sign[i, j] = ∫_{e_i}∫_{e_j} sign(x − s)` (antisymmetric).
#[derive(Debug, Clone)]
pub struct Influence {
    /// The logarithmic kernel (m²).
    pub log: Mat<f64>,
    /// The sign kernel (m²).
    pub sign: Mat<f64>,
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
        let sign = Mat::<f64>::from_fn(n, n, |i, j| sign_pair(i, j, w[i], w[j]));
        Self { log, sign }
    }

    /// `out = M v` for one of the matrices.
    pub fn apply(m: &Mat<f64>, v: &[f64], out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = (0..v.len()).map(|j| m[(i, j)] * v[j]).sum();
        }
    }
}

/// `∫_{x1}^{x2} x²/(2R) dx`: the element integral of the punch profile.
pub fn profile_integral(x1: f64, x2: f64, radius: f64) -> f64 {
    (x2.powi(3) - x1.powi(3)) / (6.0 * radius)
}

#[cfg(test)]
mod tests {
    use super::*;

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
