//! Gauss–Chebyshev collocation for Cauchy singular integral equations (Erdogan & Gupta 1972),
//! Chebyshev transforms, and closed-form Cauchy transforms of the Chebyshev representations.
//!
//! Everything here lives on the normalised interval [−1, 1] and depends only on the number of
//! nodes M, so a [`BoundedGrid`] or [`UnboundedGrid`] is built and LU-factored once per run
//! (faer) and reused by every solve. Geometry enters through the affine map to the physical
//! interval, which leaves `(1/π)⨍ f(θ)/(θ − τ) dθ` unchanged. For iterations that solve the
//! same system many times, right-hand side → coefficients is in closed form: by the discrete
//! orthogonality of the Chebyshev polynomials over the collocation points it is a cosine
//! (bounded) or sine (unbounded) transform, done by real FFTs ([`crate::transforms`];
//! `solve_coefficients`), as is a bounded series' density at the collocation points
//! (`densities_at_collocation`). The series provide evaluation rows (`density_row`,
//! `cauchy_row`, [`ColumnMatrix`]) to assemble products at other points.
//!
//! # Bounded at both ends (seed eqs. 36–38, 56, 58)
//! `f(θ) = √(1 − θ²) ψ(θ)`, `ψ = Σ_{n=1}^{M} β_n U_{n−1}`. Nodes `θ_l = cos(lπ/(M+1))`,
//! `l = 1..M` (zeros of U_M); collocation `τ_r = cos((2r−1)π/(2(M+1)))`, `r = 1..M+1`
//! (zeros of T_{M+1}):
//!
//! ```text
//! (1/π)⨍ √(1−t²) U_{n−1}(t)/(t − τ) dt = −T_n(τ)              (|τ| < 1)
//!                                      = −z^n, z = τ − sgn(τ)√(τ²−1)   (|τ| > 1)
//! Σ_l (1−θ_l²) ψ_l /((M+1)(θ_l − τ_r)) = h(τ_r),   r = 1..M+1
//! ```
//!
//! The M+1 equations in M unknowns are consistent only if the discrete Chebyshev mean
//! `h̄ = Σ_r h(τ_r)/(M+1)` vanishes (the columns of the matrix sum to zero because
//! `Σ_r 1/(θ_l − τ_r) = T'_{M+1}(θ_l)/T_{M+1}(θ_l) = 0`). We solve the square system
//! `[A | 1](ψ; λ) = h`, which returns `λ = h̄`: the consistency residual that fixes a free
//! geometric parameter (seed eq. 35).
//!
//! # Unbounded at both ends (seed eqs. 41–42)
//! `f(θ) = ϑ(θ)/√(1 − θ²)`, `ϑ = Σ_{n=0}^{M−1} γ_n T_n`. Nodes `θ_l = cos((2l−1)π/(2M))`
//! (zeros of T_M); collocation `τ_r = cos(rπ/M)`, `r = 1..M−1` (zeros of U_{M−1}), plus the
//! resultant `∫ f dθ = πγ_0 = (π/M) Σ_l ϑ_l`:
//!
//! ```text
//! (1/π)⨍ T_n(t)/(√(1−t²)(t − τ)) dt = U_{n−1}(τ)  (n ≥ 1),  0  (n = 0)      (|τ| < 1)
//!                                   = −sgn(τ) z^n / √(τ²−1)                 (|τ| > 1)
//! ```

mod grid;
mod legendre;
mod matrix;
mod series;

pub use grid::{BoundedGrid, UnboundedGrid};
pub use legendre::{gauss_legendre, gauss_legendre_cumulative};
pub use matrix::{ColumnMatrix, RowMatrix, dot};
pub use series::{BoundedSeries, UnboundedSeries, chebyshev_t_sum, chebyshev_t_sums};

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) fn t(n: usize, x: f64) -> f64 {
        let mut c = vec![0.0; n + 1];
        c[n] = 1.0;
        chebyshev_t_sum(&c, x)
    }
    pub(super) fn u(n: usize, x: f64) -> f64 {
        let mut c = vec![0.0; n + 1];
        c[n] = 1.0;
        series::chebyshev_u_sum(&c, x)
    }
}
