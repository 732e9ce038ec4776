//! The collocation grids for M nodes on [−1, 1] (module docs): [`BoundedGrid`] (nodes
//! `θ_l = cos(lπ/(M+1))`, collocation `τ_r = cos((2r−1)π/(2(M+1)))`; seed eqs. 36–38) and
//! [`UnboundedGrid`] (nodes `cos((2l−1)π/(2M))`, collocation `cos(rπ/M)` and the resultant;
//! seed eqs. 41–42), each LU-factored once (faer), with the right-hand side → coefficients
//! solves as cosine and sine transforms.

use std::f64::consts::PI;

use faer::Mat;
use faer::linalg::solvers::{PartialPivLu, Solve};

use crate::transforms::{HalfAngleTransforms, WholeAngleSines};

/// Grid and factored collocation matrix for densities bounded at both ends.
#[derive(Debug, Clone)]
pub struct BoundedGrid {
    m: usize,
    /// Nodes θ_l = cos(lπ/(M+1)), l = 1..M.
    pub nodes: Vec<f64>,
    /// Collocation points τ_r = cos((2r−1)π/(2(M+1))), r = 1..M+1.
    pub collocation: Vec<f64>,
    /// `sin(t_l) sin(n t_l)` table for the U-coefficient transform, row n−1.
    transform: Vec<f64>,
    lu: PartialPivLu<f64>,
    /// The cosine and sine sums at the collocation points (`solve_coefficients`,
    /// `densities_at_collocation`).
    transforms: HalfAngleTransforms,
}

/// Grid and factored collocation matrix for densities unbounded (inverse square root) at both ends.
#[derive(Debug, Clone)]
pub struct UnboundedGrid {
    m: usize,
    /// Nodes θ_l = cos((2l−1)π/(2M)), l = 1..M.
    pub nodes: Vec<f64>,
    /// Collocation points τ_r = cos(rπ/M), r = 1..M−1.
    pub collocation: Vec<f64>,
    /// `T_n(θ_l)` table, row n.
    transform: Vec<f64>,
    lu: PartialPivLu<f64>,
    /// The sine sums at the collocation points `rπ/M` (`solve_coefficients`).
    sines: WholeAngleSines,
    /// `sin(rπ/M)` at the collocation points.
    collocation_sines: Vec<f64>,
}

impl BoundedGrid {
    /// Build and factor for `m ≥ 2` nodes.
    pub fn new(m: usize) -> Self {
        assert!(m >= 2, "at least two collocation nodes");
        let nodes: Vec<f64> = (1..=m)
            .map(|l| (l as f64 * PI / (m as f64 + 1.0)).cos())
            .collect();
        let collocation: Vec<f64> = (1..=m + 1)
            .map(|r| ((2 * r - 1) as f64 * PI / (2.0 * (m as f64 + 1.0))).cos())
            .collect();
        let a = Mat::<f64>::from_fn(m + 1, m + 1, |r, l| {
            if l == m {
                1.0
            } else {
                (1.0 - nodes[l] * nodes[l]) / ((m as f64 + 1.0) * (nodes[l] - collocation[r]))
            }
        });
        let lu = a.partial_piv_lu();
        let mut transform = vec![0.0; m * m];
        for n in 1..=m {
            for l in 1..=m {
                let t = l as f64 * PI / (m as f64 + 1.0);
                transform[(n - 1) * m + (l - 1)] =
                    2.0 / (m as f64 + 1.0) * t.sin() * (n as f64 * t).sin();
            }
        }
        Self {
            m,
            nodes,
            collocation,
            transform,
            lu,
            transforms: HalfAngleTransforms::new(m + 1),
        }
    }

    /// Number of nodes M.
    pub fn len(&self) -> usize {
        self.m
    }

    /// Always false (M ≥ 2).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Solve `(1/π)⨍ √(1−θ²)ψ(θ)/(θ − τ) dθ = h(τ)` from `h` at the M+1 collocation points.
    /// Writes ψ at the nodes into `psi` and returns the consistency residual `h̄`.
    pub fn solve(&self, rhs: &[f64], psi: &mut [f64]) -> f64 {
        debug_assert_eq!(rhs.len(), self.m + 1);
        let mut x = rhs.to_vec();
        self.lu.solve_in_place(faer::ColMut::from_slice_mut(&mut x));
        psi.copy_from_slice(&x[..self.m]);
        x[self.m]
    }

    /// `∫_{−1}^{1} √(1−θ²) ψ dθ = π/(M+1) Σ (1−θ_l²) ψ_l` (seed eq. 38).
    pub fn integral(&self, psi: &[f64]) -> f64 {
        let s: f64 = self
            .nodes
            .iter()
            .zip(psi)
            .map(|(t, p)| (1.0 - t * t) * p)
            .sum();
        PI / (self.m as f64 + 1.0) * s
    }

    /// [`Self::solve`] followed by [`Self::coefficients`] in closed form: writes β and
    /// returns λ. With `ψ = Σ β_n U_{n−1}` the collocation equations read
    /// `−Σ_{n=1}^{M} β_n T_n(τ_r) + λ = h_r` (module docs), and the T_n, n ≤ M, are orthogonal
    /// over the M + 1 points τ_r (`Σ_r T_n T_k = (M+1)/2 δ_nk`, `Σ_r T_n = 0` for n ≥ 1), so
    ///
    /// ```text
    /// β_n = −(2/(M+1)) Σ_r h_r T_n(τ_r),    λ = (1/(M+1)) Σ_r h_r,
    /// ```
    ///
    /// a discrete cosine transform ([`HalfAngleTransforms::cosines`]).
    pub fn solve_coefficients(&self, rhs: &[f64], beta: &mut [f64]) -> f64 {
        debug_assert_eq!(rhs.len(), self.m + 1);
        let n = (self.m + 1) as f64;
        let sum = self.transforms.cosines(rhs, beta);
        for b in beta.iter_mut() {
            *b *= -2.0 / n;
        }
        sum / n
    }

    /// The density `√(1−τ²) Σ β_n U_{n−1}(τ) = Σ β_n sin(n t_r)` of the series with
    /// coefficients `beta` at the M + 1 collocation points `τ_r = cos t_r` into `out` (a
    /// discrete sine transform, [`HalfAngleTransforms::sines`]).
    pub fn densities_at_collocation(&self, beta: &[f64], out: &mut [f64]) {
        self.transforms.sines(beta, out);
    }

    /// Coefficients β_n, n = 1..M, of `ψ = Σ β_n U_{n−1}` from nodal values (index n−1).
    pub fn coefficients(&self, psi: &[f64], beta: &mut [f64]) {
        for (n, b) in beta.iter_mut().enumerate() {
            let row = &self.transform[n * self.m..(n + 1) * self.m];
            *b = row.iter().zip(psi).map(|(a, p)| a * p).sum();
        }
    }
}

impl UnboundedGrid {
    /// Build and factor for `m ≥ 2` nodes.
    pub fn new(m: usize) -> Self {
        assert!(m >= 2, "at least two collocation nodes");
        let nodes: Vec<f64> = (1..=m)
            .map(|l| ((2 * l - 1) as f64 * PI / (2.0 * m as f64)).cos())
            .collect();
        let collocation: Vec<f64> = (1..m).map(|r| (r as f64 * PI / m as f64).cos()).collect();
        let a = Mat::<f64>::from_fn(m, m, |r, l| {
            if r == m - 1 {
                PI / m as f64
            } else {
                1.0 / (m as f64 * (nodes[l] - collocation[r]))
            }
        });
        let lu = a.partial_piv_lu();
        let mut transform = vec![0.0; m * m];
        for n in 0..m {
            for l in 0..m {
                let scale = if n == 0 { 1.0 } else { 2.0 } / m as f64;
                transform[n * m + l] = scale * (n as f64 * nodes[l].acos()).cos();
            }
        }
        Self {
            m,
            collocation_sines: (1..m).map(|r| (r as f64 * PI / m as f64).sin()).collect(),
            nodes,
            collocation,
            transform,
            lu,
            sines: WholeAngleSines::new(m),
        }
    }

    /// Number of nodes M.
    pub fn len(&self) -> usize {
        self.m
    }

    /// Always false (M ≥ 2).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Solve `(1/π)⨍ ϑ(θ)/(√(1−θ²)(θ − τ)) dθ = h(τ_r)` (M−1 values) with
    /// `∫ ϑ/√(1−θ²) dθ = resultant`; writes ϑ at the nodes.
    pub fn solve(&self, rhs: &[f64], resultant: f64, theta: &mut [f64]) {
        debug_assert_eq!(rhs.len(), self.m - 1);
        theta[..self.m - 1].copy_from_slice(rhs);
        theta[self.m - 1] = resultant;
        self.lu.solve_in_place(faer::ColMut::from_slice_mut(theta));
    }

    /// [`Self::solve`] followed by [`Self::coefficients`] in closed form: writes γ. With
    /// `ϑ = Σ γ_n T_n` the collocation equations read `Σ_{n=1}^{M−1} γ_n U_{n−1}(τ_r) = h_r`
    /// (module docs), i.e. `Σ_n γ_n sin(nrπ/M) = h_r sin(rπ/M)`, and the resultant
    /// `(π/M) Σ_l ϑ_l = π γ_0` (`Σ_l T_n(θ_l) = 0` for 1 ≤ n < M); by the orthogonality of the
    /// sines over r = 1..M−1 (`Σ_r sin(nrπ/M) sin(krπ/M) = (M/2) δ_nk`),
    ///
    /// ```text
    /// γ_n = (2/M) Σ_r h_r sin(rπ/M) sin(nrπ/M),    γ_0 = resultant/π,
    /// ```
    ///
    /// a discrete sine transform ([`WholeAngleSines::sines`]).
    pub fn solve_coefficients(&self, rhs: &[f64], resultant: f64, gamma: &mut [f64]) {
        debug_assert_eq!(rhs.len(), self.m - 1);
        let weighted: Vec<f64> = rhs
            .iter()
            .zip(&self.collocation_sines)
            .map(|(h, s)| h * s)
            .collect();
        self.sines.sines(&weighted, &mut gamma[1..]);
        let scale = 2.0 / self.m as f64;
        for g in gamma[1..].iter_mut() {
            *g *= scale;
        }
        gamma[0] = resultant / PI;
    }

    /// The density `√(1−τ²) Σ_{n=1}^{M} β_n U_{n−1}(τ) = Σ β_n sin(nrπ/M)` of a bounded
    /// series with M coefficients `beta` at the M − 1 collocation points `τ_r = cos(rπ/M)`
    /// into `out` (the n = M term vanishes there; [`WholeAngleSines::sines`]).
    pub fn bounded_densities_at_collocation(&self, beta: &[f64], out: &mut [f64]) {
        debug_assert_eq!(beta.len(), self.m);
        self.sines.sines(&beta[..self.m - 1], out);
    }

    /// Coefficients γ_n, n = 0..M−1, of `ϑ = Σ γ_n T_n` from nodal values.
    pub fn coefficients(&self, theta: &[f64], gamma: &mut [f64]) {
        for (n, g) in gamma.iter_mut().enumerate() {
            let row = &self.transform[n * self.m..(n + 1) * self.m];
            *g = row.iter().zip(theta).map(|(a, p)| a * p).sum();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{t, u};
    use crate::quadrature::{BoundedSeries, UnboundedSeries};

    use super::*;

    /// (1/π)⨍ √(1−t²) U_{n−1}(t)/(t−x) dt = −T_n(x), discretely, at the collocation points.
    #[test]
    fn bounded_quadrature_reproduces_minus_t_n() {
        let m = 24;
        let g = BoundedGrid::new(m);
        for n in 1..m {
            for &x in &g.collocation {
                let s: f64 = g
                    .nodes
                    .iter()
                    .map(|&th| (1.0 - th * th) * u(n - 1, th) / ((m as f64 + 1.0) * (th - x)))
                    .sum();
                assert!(
                    (s + t(n, x)).abs() < 1e-12,
                    "n = {n}, x = {x}: {s} vs {}",
                    -t(n, x)
                );
            }
        }
    }

    /// (1/π)⨍ T_n(t)/(√(1−t²)(t−x)) dt = U_{n−1}(x), discretely, at the collocation points.
    #[test]
    fn unbounded_quadrature_reproduces_u_n_minus_1() {
        let m = 24;
        let g = UnboundedGrid::new(m);
        for n in 0..m {
            for &x in &g.collocation {
                let s: f64 = g
                    .nodes
                    .iter()
                    .map(|&th| t(n, th) / (m as f64 * (th - x)))
                    .sum();
                let expected = if n == 0 { 0.0 } else { u(n - 1, x) };
                assert!((s - expected).abs() < 1e-11, "n = {n}, x = {x}");
            }
        }
    }

    #[test]
    fn bounded_solve_inverts_and_reports_consistency() {
        let m = 20;
        let g = BoundedGrid::new(m);
        // h = −T_3 − 0.5 T_1 + 0.25 ⇒ ψ = U_2 + 0.5 U_0, consistency residual 0.25.
        let rhs: Vec<f64> = g
            .collocation
            .iter()
            .map(|&x| -t(3, x) - 0.5 * t(1, x) + 0.25)
            .collect();
        let mut psi = vec![0.0; m];
        let lambda = g.solve(&rhs, &mut psi);
        assert!((lambda - 0.25).abs() < 1e-13);
        for (th, p) in g.nodes.iter().zip(&psi) {
            assert!((p - (u(2, *th) + 0.5)).abs() < 1e-12);
        }
        let series = BoundedSeries::from_nodes(&g, &psi);
        assert!((series.beta[0] - 0.5).abs() < 1e-13 && (series.beta[2] - 1.0).abs() < 1e-13);
        // The same in closed form (the cosine transform).
        let mut beta = vec![0.0; m];
        assert!((g.solve_coefficients(&rhs, &mut beta) - 0.25).abs() < 1e-13);
        for (b, s) in beta.iter().zip(&series.beta) {
            assert!((b - s).abs() < 1e-13);
        }
        assert!((g.integral(&psi) - series.integral()).abs() < 1e-13);
        assert!((series.integral() - PI / 4.0).abs() < 1e-13);
        // Cauchy transform inside and outside, against direct formulas for ψ = 1 (β_1 = 1).
        let one = BoundedSeries { beta: vec![1.0] };
        for &x in &[-0.7, 0.3] {
            assert!((one.cauchy(x) + x).abs() < 1e-15);
        }
        for &x in &[-3.0f64, 1.5] {
            let exact = -x + x.signum() * (x * x - 1.0).sqrt();
            assert!((one.cauchy(x) - exact).abs() < 1e-14);
        }
        assert!((series.psi(1.0) - (3.0 + 0.5)).abs() < 1e-12, "U_2(1) = 3");
    }

    /// A bounded series' density at both grids' collocation points by the sine transforms,
    /// against its Clenshaw sums there, for an even and an odd M.
    #[test]
    fn densities_at_collocation_points_by_transforms() {
        for m in [24, 37] {
            let (b, u) = (BoundedGrid::new(m), UnboundedGrid::new(m));
            let series = BoundedSeries {
                beta: (0..m)
                    .map(|n| 1.0 / (n as f64 + 1.0) * (0.3 * n as f64).cos())
                    .collect(),
            };
            let size: f64 = series.beta.iter().map(|v| v.abs()).sum();
            let mut at = vec![0.0; m + 1];
            b.densities_at_collocation(&series.beta, &mut at);
            for (&tau, v) in b.collocation.iter().zip(&at) {
                assert!((v - series.density(tau)).abs() < 1e-14 * size, "τ = {tau}");
            }
            let mut at = vec![0.0; m - 1];
            u.bounded_densities_at_collocation(&series.beta, &mut at);
            for (&tau, v) in u.collocation.iter().zip(&at) {
                assert!((v - series.density(tau)).abs() < 1e-14 * size, "τ = {tau}");
            }
        }
    }

    #[test]
    fn unbounded_solve_inverts() {
        let m = 16;
        let g = UnboundedGrid::new(m);
        // ϑ = 2 + T_2 − 0.5 T_5 ⇒ h = U_1 − 0.5 U_4, resultant 2π.
        let rhs: Vec<f64> = g
            .collocation
            .iter()
            .map(|&x| u(1, x) - 0.5 * u(4, x))
            .collect();
        let mut th = vec![0.0; m];
        g.solve(&rhs, 2.0 * PI, &mut th);
        let series = UnboundedSeries::from_nodes(&g, &th);
        let mut gamma = vec![0.0; m];
        g.solve_coefficients(&rhs, 2.0 * PI, &mut gamma);
        let expected = [2.0, 0.0, 1.0, 0.0, 0.0, -0.5];
        for (n, (g_lu, g_product)) in series.gamma.iter().zip(&gamma).enumerate() {
            let e = expected.get(n).copied().unwrap_or(0.0);
            assert!((g_lu - e).abs() < 1e-12, "γ_{n}");
            assert!((g_product - e).abs() < 1e-12, "γ_{n} by the sine transform");
        }
        assert!((series.integral() - 2.0 * PI).abs() < 1e-12);
        // Outside Cauchy transform of 1/√(1−t²): −sgn(x)/√(x²−1).
        let one = UnboundedSeries { gamma: vec![1.0] };
        assert!((one.cauchy(2.0) + 1.0 / 3f64.sqrt()).abs() < 1e-15);
        assert!((one.cauchy(-2.0) - 1.0 / 3f64.sqrt()).abs() < 1e-15);
        // T_1: 1 − |x|/√(x²−1).
        let t1 = UnboundedSeries {
            gamma: vec![0.0, 1.0],
        };
        assert!((t1.cauchy(1.25) - (1.0 - 1.25 / (1.25f64 * 1.25 - 1.0).sqrt())).abs() < 1e-14);
    }
}
