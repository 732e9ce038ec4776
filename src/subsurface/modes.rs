//! The three decaying modes of the extended Stroh solution of a piezoelectric solid, with the
//! eigenvectors that [`crate::halfplane`] does not need (it works with the projector onto the
//! decaying subspace) but the fields below the surface do.
//!
//! A mode `u = a f(x + p z)` (u = (ux, uz, φ)) has the z-face generalised traction
//! `t = (σzx, σzz, Dz) = b f'`, `b = (Rᵀ + p T) a`, and the x-face one
//! `(σxx, σxz, Dx) = (Q + p R) a f' = −p b f'`, where `(Q + p(R + Rᵀ) + p² T) a = 0`
//! (the blocks as in [`crate::halfplane`]). The mirror symmetry x → −x makes
//! `det(Q + p(R + Rᵀ) + p²T)` even in p, a cubic in `λ = p²` with `d0 = det Q`,
//! `d3 = det T` and the middle coefficients from its values at `λ = ±1`; its roots
//! (Durand–Kerner, then Newton) give `p = √λ` with `Im p > 0`. (The Schur form of the 6×6
//! Stroh matrix, the other route, does not converge in nalgebra's QR iteration when all
//! roots lie on the imaginary axis, as for an uncoupled, nearly isotropic solid.) `a` is the
//! null vector of the 3×3 matrix, from the largest cross product of two of its rows; the three
//! roots give the columns of A and B. Everything is done on the dimensionless constants of
//! [`crate::halfplane`] and scaled back.
//!
//! For a distributed surface traction `t0(s)` the fields (module docs of [`super`]) are sums
//! over the modes of `M_k F(x + p_k z)` with the rank-one matrices
//! `T_k = B e_k e_kᵀ B⁻¹` (tractions) and `G_k = A e_k e_kᵀ B⁻¹` (displacement gradients).
//! They need distinct roots: B is singular at a repeated root (the isotropic solid's triple
//! root p = i), so a condition number of B above `MAX_CONDITION` is refused.

use nalgebra::{Complex, Matrix3, Vector3};

use crate::material::PiezoConstants;

use super::SubsurfaceError;

type C64 = Complex<f64>;

/// Largest accepted condition number `‖B‖‖B⁻¹‖` (Frobenius) of the decaying modes' traction
/// eigenvectors (unit-norm displacement eigenvectors): the kernel loses about its logarithm in
/// digits. Measured: PZT-4 16, PZT-5H 6.8, BaTiO3 10.5; at nearly repeated roots it grows like
/// the inverse root separation.
const MAX_CONDITION: f64 = 1e6;

/// Iterations allowed to the root finder of the characteristic cubic (PZT-4 needs about 10).
const ROOT_ITERATIONS: usize = 1000;

/// The decaying modes in SI units.
#[derive(Debug, Clone)]
pub(crate) struct Modes {
    /// `p_k`, `Im p_k > 0`, in increasing order of `Im p_k`.
    pub roots: [C64; 3],
    /// `T_k = B e_k e_kᵀ B⁻¹`: from the Cauchy integrals of the z-face traction to the
    /// z-face traction (and, times `−p_k`, the x-face traction).
    pub traction: [Matrix3<C64>; 3],
    /// `G_k = A e_k e_kᵀ B⁻¹`: to `∂u/∂x` (and, times `p_k`, `∂u/∂z`).
    pub gradient: [Matrix3<C64>; 3],
    /// `‖B‖‖B⁻¹‖` of the dimensionless eigenvectors.
    pub condition: f64,
}

/// Dimensionless blocks `(Q, R, T)` and the scales `(c0, e0, ε0)` of [`crate::halfplane`]:
/// `c/c44`, `e/√(c44 ε33)`, `ε/ε33`.
fn blocks(c: &PiezoConstants) -> ([Matrix3<f64>; 3], (f64, f64, f64)) {
    let (q, r, t, s) = crate::halfplane::stroh_blocks(c);
    ([q, r, t], (s.c0, s.e0, s.eps0))
}

/// The null vector of a singular complex 3×3 matrix, unit norm: the largest of the (bilinear)
/// cross products of two rows, which is orthogonal to all three rows when the rank is 2.
fn null_vector(m: &Matrix3<C64>) -> Vector3<C64> {
    let row = |i: usize| Vector3::new(m[(i, 0)], m[(i, 1)], m[(i, 2)]);
    let cross = |u: Vector3<C64>, v: Vector3<C64>| {
        Vector3::new(
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        )
    };
    let candidates = [
        cross(row(0), row(1)),
        cross(row(1), row(2)),
        cross(row(2), row(0)),
    ];
    let best = candidates
        .into_iter()
        .max_by(|a, b| a.norm().total_cmp(&b.norm()))
        .expect("three candidates");
    best / C64::new(best.norm(), 0.0)
}

/// The roots λ of the cubic `det Γ(√λ)` from the determinant `det` as a function of p (module
/// docs), or an error if the iteration does not settle.
fn cubic_roots(det: &dyn Fn(C64) -> C64) -> Result<[C64; 3], SubsurfaceError> {
    let one = C64::new(1.0, 0.0);
    // D(λ) = d0 + d1 λ + d2 λ² + d3 λ³ from its values at λ = 0, 1, −1, 2.
    let d0 = det(C64::new(0.0, 0.0));
    let at_one = det(one);
    let at_minus_one = det(C64::new(0.0, 1.0));
    let at_two = det(C64::new(2f64.sqrt(), 0.0));
    let d2 = 0.5 * (at_one + at_minus_one) - d0;
    let d1_plus_d3 = 0.5 * (at_one - at_minus_one);
    // D(2) = d0 + 2(d1 + d3) + 4 d2 + 6 d3.
    let d3 = (at_two - d0 - d1_plus_d3 * 2.0 - d2 * 4.0) / 6.0;
    let c = [d0 / d3, (d1_plus_d3 - d3) / d3, d2 / d3];
    let poly = |x: C64| ((x + c[2]) * x + c[1]) * x + c[0];
    let slope = |x: C64| (x * 3.0 + c[2] * 2.0) * x + c[1];
    let radius = 1.0 + c.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let seed = C64::new(0.4, 0.9);
    let mut z = [
        seed * radius,
        seed * seed * radius,
        seed * seed * seed * radius,
    ];
    let mut settled = false;
    for _ in 0..ROOT_ITERATIONS {
        let mut change = 0.0f64;
        for k in 0..3 {
            let mut den = one;
            for j in 0..3 {
                if j != k {
                    den *= z[k] - z[j];
                }
            }
            let step = poly(z[k]) / den;
            z[k] -= step;
            change = change.max(step.norm() / z[k].norm().max(1e-300));
        }
        // Converging quadratically: below 1e−12 the next steps are round-off, which the
        // Newton steps below absorb (a criterion at round-off level can cycle).
        if change < 1e-12 {
            settled = true;
            break;
        }
    }
    // Newton on the cubic polishes each root.
    for root in z.iter_mut() {
        for _ in 0..3 {
            let d = slope(*root);
            if d.norm() > 0.0 {
                *root -= poly(*root) / d;
            }
        }
    }
    if !settled || z.iter().any(|v| !(v.re.is_finite() && v.im.is_finite())) {
        return Err(SubsurfaceError::RootsNotFound {
            iterations: ROOT_ITERATIONS,
        });
    }
    Ok(z)
}

impl Modes {
    /// The modes of a piezoelectric solid, or why they cannot serve: not exactly three roots
    /// in the upper half-plane, or nearly repeated roots (module docs).
    pub fn of(c: &PiezoConstants) -> Result<Self, SubsurfaceError> {
        let ([q, r, t], (c0, e0, _)) = blocks(c);
        let cx = |m: &Matrix3<f64>| m.map(|v| C64::new(v, 0.0));
        let (qc, rc, tc) = (cx(&q), cx(&r), cx(&t));
        let gamma = |p: C64| qc + (rc + rc.transpose()) * p + tc * (p * p);
        let mut roots = Vec::new();
        for lambda in cubic_roots(&|p| gamma(p).determinant())? {
            // p = ±√λ: the root of the decaying mode has Im p > 0.
            let p = lambda.sqrt();
            let p = if p.im < 0.0 { -p } else { p };
            if p.im > 0.0 {
                roots.push(p);
            }
        }
        if roots.len() != 3 {
            return Err(SubsurfaceError::ModeCount { found: roots.len() });
        }
        roots.sort_by(|a, b| a.im.total_cmp(&b.im).then(a.re.total_cmp(&b.re)));
        let mut a = Matrix3::<C64>::zeros();
        let mut b = Matrix3::<C64>::zeros();
        for (k, &p) in roots.iter().enumerate() {
            let ak = null_vector(&gamma(p));
            let bk = (rc.transpose() + tc * p) * ak;
            a.set_column(k, &ak);
            b.set_column(k, &bk);
        }
        let b_inv = b.try_inverse().ok_or(SubsurfaceError::Singular {
            matrix: "traction eigenvector matrix B (repeated Stroh roots)",
        })?;
        let condition = b.norm() * b_inv.norm();
        if condition.is_nan() || condition > MAX_CONDITION {
            return Err(SubsurfaceError::NearlyRepeatedRoots { condition });
        }
        // Back to SI: t̃ = S_t t with S_t = diag(1/c0, 1/c0, 1/e0) and ũ = S_u u with
        // S_u = diag(1, 1, e0/c0), so T_k = S_t⁻¹ T̃_k S_t and G_k = S_u⁻¹ G̃_k S_t.
        let s_t = [1.0 / c0, 1.0 / c0, 1.0 / e0];
        let s_u = [1.0, 1.0, e0 / c0];
        let zero = Matrix3::<C64>::zeros();
        let mut traction = [zero; 3];
        let mut gradient = [zero; 3];
        for k in 0..3 {
            for i in 0..3 {
                for j in 0..3 {
                    let row = b_inv[(k, j)];
                    traction[k][(i, j)] = b[(i, k)] * row * (s_t[j] / s_t[i]);
                    gradient[k][(i, j)] = a[(i, k)] * row * (s_t[j] / s_u[i]);
                }
            }
        }
        Ok(Self {
            roots: [roots[0], roots[1], roots[2]],
            traction,
            gradient,
            condition,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::halfplane::admittance_matrix;
    use crate::material::{BATIO3, PZT4, PZT5H};

    #[test]
    fn modes_reproduce_the_surface_admittance_of_the_matrix_sign_route() {
        // Y = i A B⁻¹ = i Σ_k G_k, against crate::halfplane's projector P₊ (no eigenvectors):
        // two independent routes to the same surface response.
        let (mut worst_y, mut worst_t) = (0.0f64, 0.0f64);
        for c in [PZT4, PZT5H, BATIO3] {
            let modes = Modes::of(&c).unwrap();
            println!("roots {:?}, condition {:.3e}", modes.roots, modes.condition);
            let y = admittance_matrix(&c).unwrap();
            let sum: Matrix3<C64> =
                modes.gradient.iter().sum::<Matrix3<C64>>() * C64::new(0.0, 1.0);
            for i in 0..3 {
                for j in 0..3 {
                    let want = C64::new(y[i][j].0, y[i][j].1);
                    let size = (y[i][i].0.abs() * y[j][j].0.abs()).sqrt();
                    let err = (sum[(i, j)] - want).norm() / size;
                    worst_y = worst_y.max(err);
                    // Measured ≤ 2.1e−15 (PZT-4, PZT-5H, BaTiO3).
                    assert!(
                        err < 1e-13,
                        "Y[{i}][{j}]: {} vs {want}, {err:e}",
                        sum[(i, j)]
                    );
                }
            }
            // Σ_k T_k = I: the z-face traction of the modes is the applied traction; each
            // entry relative to the size of its terms (SI entries mix Pa and C/m²).
            let total: Matrix3<C64> = modes.traction.iter().sum();
            for i in 0..3 {
                for j in 0..3 {
                    let size: f64 = modes.traction.iter().map(|t| t[(i, j)].norm()).sum();
                    let delta = if i == j { 1.0 } else { 0.0 };
                    let err = (total[(i, j)] - delta).norm() / size.max(1.0);
                    worst_t = worst_t.max(err);
                    // Measured ≤ 6.0e−16.
                    assert!(err < 1e-14, "ΣT[{i}][{j}] = {}: {err:e}", total[(i, j)]);
                }
            }
            assert!(modes.condition < 1e3, "{}", modes.condition);
        }
        println!("Y {worst_y:e}, ΣT {worst_t:e}");
    }

    #[test]
    fn eigenpairs_satisfy_the_stroh_equation() {
        // (Q + p(R + Rᵀ) + p²T) a = 0 for each root, in the dimensionless constants.
        let ([q, r, t], _) = blocks(&PZT4);
        let cx = |m: &Matrix3<f64>| m.map(|v| C64::new(v, 0.0));
        let modes = Modes::of(&PZT4).unwrap();
        for &p in &modes.roots {
            let gamma = cx(&q) + (cx(&r) + cx(&r).transpose()) * p + cx(&t) * (p * p);
            let a = null_vector(&gamma);
            let residual = (gamma * a).norm() / gamma.norm();
            println!("p = {p}: residual {residual:e}");
            assert!(residual < 1e-14, "p = {p}: residual {residual:e}");
        }
    }

    #[test]
    fn isotropic_constants_are_refused_as_repeated_roots() {
        // The isotropic solid written as piezoelectric constants (e = 0, ε11 ≠ ε33 so the
        // electric root i·√(ε11/ε33) stays apart): the mechanical root p = i is double, B is
        // singular and the Stroh kernel does not apply (the isotropic kernel does).
        let c = PiezoConstants::uncoupled_isotropic(27.3e9, 0.3, 2e-9, 1e-9);
        let err = Modes::of(&c).unwrap_err();
        assert!(
            matches!(
                err,
                SubsurfaceError::NearlyRepeatedRoots { .. }
                    | SubsurfaceError::Singular { .. }
                    | SubsurfaceError::RootsNotFound { .. }
            ),
            "{err:?}"
        );
    }
}
