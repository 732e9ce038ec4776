//! Surface response of the half-plane: the coefficients of the seed paper's eqs. (11)–(13),
//! computed from the material constants, and the in-plane surface fields of eqs. (64)–(65).
//!
//! # What is computed
//! Load the surface z = 0 of the half-plane z ≥ 0 with a pressure `p(x)` (compressive positive,
//! pushing into the solid), a shear traction `q(x)` (exerted *on the half-plane*, positive along
//! +x) and a surface charge `g(x)`, defined as in the seed paper by `Dz(x, 0⁺) = −g(x)`, so that
//! `σzz = −p, σzx = −q, Dz = −g` on the surface (seed paper Section 5). With
//! `H'f(x) = (1/π) ⨍ f(s)/(s − x) ds` the surface gradients are
//!
//! ```text
//! ∂ux/∂x = −w12 p − w13 g + y11 H'q            (A)  ↔ seed eq. (11)
//! ∂uz/∂x =  w12 q + y22 H'p + y23 H'g          (B)  ↔ seed eq. (12)
//! ∂φ/∂x  =  w13 q + y23 H'p + y33 H'g          (C)  ↔ seed eq. (13)
//! ```
//!
//! with `uz` positive *into* the solid. Mirror symmetry x → −x of the transversely isotropic
//! solid makes the other Cauchy and local coefficients vanish.
//!
//! # How: the extended Stroh formalism
//! With the generalised displacement `u = (ux, uz, φ)` and the z-face generalised traction
//! `t = (σzx, σzz, Dz)`, a mode `u = a f(x + p z)` satisfies `N (a; b) = p (a; b)` where
//! `N = [[−T⁻¹Rᵀ, T⁻¹], [R T⁻¹ Rᵀ − Q, −R T⁻¹]]` and `Q, R, T` are the x-x, x-z and z-z blocks of
//! the generalised constants (see [`crate::material`]). For `e^{ikx}` dependence with `k > 0`,
//! the decaying modes are those with `Im p > 0`; on them `u = A B⁻¹ t /(ik)`, so
//!
//! ```text
//! ∂u/∂x = Y_I t + Y_R H[t],     Y = i A B⁻¹ = Y_R + i Y_I,   H[f] = (1/π) ⨍ f(s)/(x − s) ds
//! ```
//!
//! (`Y` Hermitian: `Y_R` symmetric, `Y_I` antisymmetric — this is reciprocity). The decaying
//! subspace is found without eigenvectors: `P₊ = (I + sign(−iN))/2` with the matrix sign function
//! by Newton's iteration, which is insensitive to repeated roots (the isotropic limit has a
//! triple root p = i). Then `A B⁻¹ = P₊[u, t] P₊[t, t]⁻¹`. The constants are made dimensionless
//! (`c/c44`, `e/√(c44 ε33)`, `ε/ε33`) before the iteration. This is the seed paper's
//! Appendix A.1 recipe in a form that needs no root differences.
//!
//! Substituting `t = −(q, p, g)` gives (A)–(C) with
//! `y11 = Y_R[x,x], y22 = Y_R[z,z], y23 = Y_R[z,φ], y33 = Y_R[φ,φ], w12 = Y_I[x,z], w13 = Y_I[x,φ]`.
//!
//! # The paper's f_ij (Appendix A.2)
//! The paper writes (11)–(13) with `−i f11 = −w12`, `f12 = y11`, `−i f13 = −w13`, `f21 = y22`,
//! `−i f22 = w12`, `f23 = y23`, `f31 = y23`, `−i f32 = w13`, `f33 = y33` for its `q_paper = −q`
//! (the traction on the punch, see `docs` of [`crate::contact`]) and a potential of opposite sign;
//! [`SurfaceCompliance::paper_coefficients`] returns them. Reciprocity then reads
//! `f22 = −f11`, `f23 = f31`, `f32 = −f13`. A.2 prints `f22 = 7.4241e−12 i` but the constants of
//! Table 1 give `7.5241e−12 i = −f11`: the printed f22 is a digit typo (tested below).
//!
//! # Isotropic solid
//! Exact (Johnson, *Contact Mechanics*, eq. 2.25): `y11 = y22 = 2(1 − ν²)/E`,
//! `w12 = (1 − 2ν)(1 + ν)/E`, no electric terms.

use nalgebra::{Complex, Matrix3, Matrix6};
use serde::Serialize;

use crate::error::MaterialFailure;
use crate::material::{IsotropicConstants, Material, PiezoConstants};

type C64 = Complex<f64>;

/// Electric part of the surface response (piezoelectric half-plane only).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ElectricCompliance {
    /// Cauchy coefficient coupling pressure to potential gradient and charge to normal slope (m/C·… SI).
    pub y23: f64,
    /// Cauchy coefficient of charge in the potential gradient (negative for a dielectric).
    pub y33: f64,
    /// Local coefficient of charge in ∂ux/∂x (and of q in ∂φ/∂x).
    pub w13: f64,
}

/// The surface compliance coefficients of eqs. (A)–(C) (module docs), SI units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SurfaceCompliance {
    /// Cauchy coefficient of q in ∂ux/∂x (1/Pa).
    pub y11: f64,
    /// Cauchy coefficient of p in ∂uz/∂x (1/Pa).
    pub y22: f64,
    /// Local coefficient of p in ∂ux/∂x, with a minus sign (1/Pa).
    pub w12: f64,
    /// Electric coefficients, `None` for an elastic solid.
    pub electric: Option<ElectricCompliance>,
}

/// The paper's Appendix A.2 coefficients, `f_ij = re + i·im`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PaperCoefficients {
    /// `[f11, f12, f13, f21, f22, f23, f31, f32, f33]` as `(re, im)` pairs.
    pub f: [[(f64, f64); 3]; 3],
}

/// Coefficients of the surface in-plane fields, seed paper Section 5 (Δ1…Δ4).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SurfaceFieldCoefficients {
    /// Δ1 (–): σxx0 gets `Δ1 σzz`.
    pub delta1: f64,
    /// Δ2 (V/m… SI: Pa·m²/C): σxx0 gets `Δ2 Dz`.
    pub delta2: f64,
    /// Δ3 (Pa): σxx0 gets `Δ3 ∂ux/∂x`.
    pub delta3: f64,
    /// Δ4 (C/(V·m)): Dx0 gets `−Δ4 ∂φ/∂x`.
    pub delta4: f64,
    /// `e15/c44` (C/(N·m)… SI): Dx0 gets `(e15/c44) σzx`.
    pub e15_over_c44: f64,
}

impl SurfaceCompliance {
    /// Coefficients for a material, or why the constants give no decaying solution (a
    /// degenerate Stroh eigenproblem, or non-finite or wrongly signed coefficients).
    pub fn try_of(material: &Material) -> Result<Self, MaterialFailure> {
        let out = match material {
            Material::Piezoelectric(c) => piezoelectric(c)?,
            Material::Elastic(c) => isotropic(c),
        };
        out.check()?;
        Ok(out)
    }

    /// Coefficients for a material known to be sound (the presets, tests).
    ///
    /// # Panics
    /// If [`Self::try_of`] fails; use that on constants from the user.
    pub fn of(material: &Material) -> Self {
        Self::try_of(material).unwrap_or_else(|e| panic!("surface compliance: {e}"))
    }

    /// Every coefficient finite, `y11, y22 > 0` (a surface compliance is positive) and, for a
    /// piezoelectric solid, `y33 < 0` (a dielectric), so that `Y* ≥ y22 > 0`.
    fn check(&self) -> Result<(), MaterialFailure> {
        let e = self.electric;
        // (coefficient, value, required sign: +1 positive, −1 negative, 0 any).
        let rules = [
            ("y11", self.y11, 1.0),
            ("y22", self.y22, 1.0),
            ("w12", self.w12, 0.0),
            ("y23", e.map_or(0.0, |e| e.y23), 0.0),
            ("y33", e.map_or(-1.0, |e| e.y33), -1.0),
            ("w13", e.map_or(0.0, |e| e.w13), 0.0),
        ];
        for (coefficient, value, sign) in rules {
            let (holds, rule) = if sign > 0.0 {
                (value > 0.0, "finite and > 0")
            } else if sign < 0.0 {
                (value < 0.0, "finite and < 0")
            } else {
                (true, "finite")
            };
            if !(value.is_finite() && holds) {
                return Err(MaterialFailure::Compliance {
                    coefficient,
                    value,
                    rule,
                });
            }
        }
        Ok(())
    }

    /// `Y* = y22 − y23²/y33`: compliance of the pressure problem once the charge is eliminated
    /// at constant contact potential (elastic: `y22 = 2/E*`).
    pub fn pressure_compliance(&self) -> f64 {
        match self.electric {
            Some(e) => self.y22 - e.y23 * e.y23 / e.y33,
            None => self.y22,
        }
    }

    /// `κ = w12 − y23 w13/y33`: how the shear traction enters the pressure equation,
    /// `Y* H'p + κ q = ∂uz/∂x` (elastic: `κ/Y* = β`, Dundurs' constant for a rigid punch).
    pub fn pressure_shear_coupling(&self) -> f64 {
        match self.electric {
            Some(e) => self.w12 - e.y23 * e.w13 / e.y33,
            None => self.w12,
        }
    }

    /// `k = −y23/y33`: under a conducting punch `g = k p + w` with `H'w` driven by q only
    /// (C/N; zero for an elastic solid).
    pub fn charge_per_force(&self) -> f64 {
        match self.electric {
            Some(e) => -e.y23 / e.y33,
            None => 0.0,
        }
    }

    /// The same coefficients in the seed paper's convention (Appendix A.2).
    ///
    /// ```
    /// use fretsim::halfplane::SurfaceCompliance;
    /// use fretsim::material::{Material, PZT4};
    ///
    /// let f = SurfaceCompliance::of(&Material::Piezoelectric(PZT4)).paper_coefficients().f;
    /// // Table 1's constants give f11 = −7.5241e−12 i (1/Pa, as printed in A.2 to five
    /// // digits); reciprocity gives f22 = −f11 (A.2 prints 7.4241e−12 i, a digit typo).
    /// assert!((f[0][0].1 + 7.5241e-12).abs() < 5e-17 && f[0][0].0 == 0.0);
    /// assert!((f[1][1].1 + f[0][0].1).abs() < 1e-20);
    /// ```
    pub fn paper_coefficients(&self) -> PaperCoefficients {
        let e = self.electric.unwrap_or(ElectricCompliance {
            y23: 0.0,
            y33: 0.0,
            w13: 0.0,
        });
        // −i f = X  ⇔  f = i X (purely imaginary entries).
        let imag = |x: f64| (0.0, x);
        let real = |x: f64| (x, 0.0);
        PaperCoefficients {
            f: [
                [imag(-self.w12), real(self.y11), imag(-e.w13)],
                [real(self.y22), imag(self.w12), real(e.y23)],
                [real(e.y23), imag(e.w13), real(e.y33)],
            ],
        }
    }
}

/// Exact isotropic coefficients (Johnson eq. 2.25).
fn isotropic(c: &IsotropicConstants) -> SurfaceCompliance {
    let e = c.youngs_modulus();
    let nu = c.poisson_ratio;
    SurfaceCompliance {
        y11: 2.0 * (1.0 - nu * nu) / e,
        y22: 2.0 * (1.0 - nu * nu) / e,
        w12: (1.0 - 2.0 * nu) * (1.0 + nu) / e,
        electric: None,
    }
}

/// Dimensionless generalised constants blocks (Q, R, T) of a piezoelectric solid.
pub(crate) fn stroh_blocks(
    c: &PiezoConstants,
) -> (Matrix3<f64>, Matrix3<f64>, Matrix3<f64>, Scales) {
    let c0 = c.c44;
    let eps0 = c.eps33;
    let e0 = (c0 * eps0).sqrt();
    let (c11, c13, c33, c44) = (c.c11 / c0, c.c13 / c0, c.c33 / c0, c.c44 / c0);
    let (e31, e33, e15) = (c.e31 / e0, c.e33 / e0, c.e15 / e0);
    let (eps11, eps33) = (c.eps11 / eps0, c.eps33 / eps0);
    let q = Matrix3::new(c11, 0.0, 0.0, 0.0, c44, e15, 0.0, e15, -eps11);
    let r = Matrix3::new(0.0, c13, e31, c44, 0.0, 0.0, e15, 0.0, 0.0);
    let t = Matrix3::new(c44, 0.0, 0.0, 0.0, c33, e33, 0.0, e33, -eps33);
    (q, r, t, Scales { c0, e0, eps0 })
}

pub(crate) struct Scales {
    pub(crate) c0: f64,
    pub(crate) e0: f64,
    pub(crate) eps0: f64,
}

/// `Y = i A B⁻¹` for the decaying modes of the Stroh matrix built from (Q, R, T); an error
/// when the constants are degenerate (a singular block, no split into decaying and growing
/// modes).
fn surface_admittance(
    q: &Matrix3<f64>,
    r: &Matrix3<f64>,
    t: &Matrix3<f64>,
) -> Result<Matrix3<C64>, MaterialFailure> {
    let t_inv = t.try_inverse().ok_or(MaterialFailure::Singular {
        matrix: "z-z block T of the generalised constants",
    })?;
    let n1 = -t_inv * r.transpose();
    let n3 = r * t_inv * r.transpose() - q;
    let n4 = -r * t_inv;
    let mut n = Matrix6::<f64>::zeros();
    n.fixed_view_mut::<3, 3>(0, 0).copy_from(&n1);
    n.fixed_view_mut::<3, 3>(0, 3).copy_from(&t_inv);
    n.fixed_view_mut::<3, 3>(3, 0).copy_from(&n3);
    n.fixed_view_mut::<3, 3>(3, 3).copy_from(&n4);
    // Matrix sign of Z = −iN: eigenvalue −ip has real part Im p.
    let mut s: Matrix6<C64> = n.map(|v| C64::new(0.0, -v));
    let no_split = |s: &Matrix6<C64>| MaterialFailure::NoModeSplit {
        residual: (s * s - Matrix6::<C64>::identity()).norm() / s.norm_squared(),
    };
    for _ in 0..100 {
        // Singular: an eigenvalue of N on the real axis.
        let inv = s.try_inverse().ok_or_else(|| no_split(&s))?;
        // Determinant scaling accelerates the first iterations.
        let mu = s.determinant().norm().powf(-1.0 / 6.0);
        let next = (s * C64::new(mu, 0.0) + inv * C64::new(1.0 / mu, 0.0)) * C64::new(0.5, 0.0);
        let change = (next - s).norm() / next.norm();
        s = next;
        if change < 1e-15 {
            break;
        }
    }
    // A sign matrix squares to I; the iteration ends far below this bound when it converges.
    let failed = no_split(&s);
    if !matches!(failed, MaterialFailure::NoModeSplit { residual } if residual < 1e-8) {
        return Err(failed);
    }
    let p_plus = (Matrix6::<C64>::identity() + s) * C64::new(0.5, 0.0);
    let p12 = p_plus.fixed_view::<3, 3>(0, 3).into_owned();
    let p22 = p_plus.fixed_view::<3, 3>(3, 3).into_owned();
    let p22_inv = p22.try_inverse().ok_or(MaterialFailure::Singular {
        matrix: "traction block of the decaying modes' projector (surface impedance)",
    })?;
    Ok(p12 * p22_inv * C64::new(0.0, 1.0))
}

fn piezoelectric(c: &PiezoConstants) -> Result<SurfaceCompliance, MaterialFailure> {
    let (q, r, t, sc) = stroh_blocks(c);
    let y = surface_admittance(&q, &r, &t)?;
    // Undo the scaling: t̃ = (σ/c0, σ/c0, D/e0), ũ = (ux, uz, φ·e0/c0).
    let mech = 1.0 / sc.c0;
    let cross = 1.0 / sc.e0;
    let elec = 1.0 / sc.eps0;
    let (yr, yi) = (y.map(|z| z.re), y.map(|z| z.im));
    Ok(SurfaceCompliance {
        y11: yr[(0, 0)] * mech,
        y22: yr[(1, 1)] * mech,
        w12: yi[(0, 1)] * mech,
        electric: Some(ElectricCompliance {
            y23: yr[(1, 2)] * cross,
            y33: yr[(2, 2)] * elec,
            w13: yi[(0, 2)] * cross,
        }),
    })
}

/// Full dimensional `Y = Y_R + i Y_I` for a piezoelectric material (for the reciprocity tests).
pub fn admittance_matrix(c: &PiezoConstants) -> Result<[[(f64, f64); 3]; 3], MaterialFailure> {
    let (q, r, t, sc) = stroh_blocks(c);
    let y = surface_admittance(&q, &r, &t)?;
    let scale = [1.0 / sc.c0, 1.0 / sc.c0, 1.0 / sc.e0];
    let mut out = [[(0.0, 0.0); 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            // Row scaling by the displacement unit, column by the traction unit.
            let s = if i == 2 && j == 2 {
                1.0 / sc.eps0
            } else if i == 2 || j == 2 {
                1.0 / sc.e0
            } else {
                scale[0]
            };
            out[i][j] = (y[(i, j)].re * s, y[(i, j)].im * s);
        }
    }
    Ok(out)
}

impl SurfaceFieldCoefficients {
    /// Δ1…Δ4 of Section 5 from the constants (elastic: from the isotropic stiffness, e = 0).
    pub fn of(material: &Material) -> Self {
        let c = match material {
            Material::Piezoelectric(c) => *c,
            Material::Elastic(iso) => {
                let mu = iso.shear_modulus;
                let nu = iso.poisson_ratio;
                // Lamé λ = 2μν/(1 − 2ν); at ν = 1/2 only the combinations below stay finite.
                if (0.5 - nu).abs() < 1e-12 {
                    return SurfaceFieldCoefficients {
                        delta1: 1.0,
                        delta2: 0.0,
                        delta3: 4.0 * mu,
                        delta4: 0.0,
                        e15_over_c44: 0.0,
                    };
                }
                PiezoConstants::uncoupled_isotropic(mu, nu, 1.0, 1.0)
            }
        };
        let den = c.e33 * c.e33 + c.c33 * c.eps33;
        SurfaceFieldCoefficients {
            delta1: (c.e31 * c.e33 + c.c13 * c.eps33) / den,
            delta2: (c.c13 * c.e33 - c.c33 * c.e31) / den,
            delta3: (c.c11 * c.e33 * c.e33 - c.c13 * c.c13 * c.eps33
                + c.c33 * c.e31 * c.e31
                + c.c11 * c.c33 * c.eps33
                - 2.0 * c.c13 * c.e31 * c.e33)
                / den,
            delta4: if material.is_piezoelectric() {
                c.e15 * c.e15 / c.c44 + c.eps11
            } else {
                0.0
            },
            e15_over_c44: c.e15 / c.c44,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{ALUMINIUM, PZT4};
    use approx::assert_relative_eq;

    /// Appendix A.2 as printed: (re, im) of f11 … f33.
    const A2: [[(f64, f64); 3]; 3] = [
        [(0.0, -7.5241e-12), (1.8396e-11, 0.0), (0.0, 1.7328e-2)],
        [(1.7728e-11, 0.0), (0.0, 7.4241e-12), (2.2085e-2, 0.0)],
        [(2.2085e-2, 0.0), (0.0, -1.7328e-2), (-8.8307e7, 0.0)],
    ];

    #[test]
    fn pzt4_matches_appendix_a2_except_the_f22_typo() {
        let f = SurfaceCompliance::of(&Material::Piezoelectric(PZT4))
            .paper_coefficients()
            .f;
        for i in 0..3 {
            for j in 0..3 {
                let (re, im) = f[i][j];
                let (re2, im2) = A2[i][j];
                let value = if re2 != 0.0 { re } else { im };
                let printed = if re2 != 0.0 { re2 } else { im2 };
                let rel = (value - printed).abs() / printed.abs();
                if (i, j) == (1, 1) {
                    // The printed 7.4241e−12 is a digit typo for 7.5241e−12 (= −f11, reciprocity).
                    assert!(rel > 1e-2, "f22 unexpectedly matches the typo");
                    assert_relative_eq!(value, 7.5241e-12, max_relative = 5e-5);
                } else {
                    // A.2 gives 5 significant digits; 5e−5 is half a unit in the last one.
                    assert!(
                        rel < 5e-5,
                        "f{}{}: computed {value:e}, A.2 {printed:e}",
                        i + 1,
                        j + 1
                    );
                }
            }
        }
    }

    #[test]
    fn degenerate_constants_give_an_error_not_a_panic() {
        // Finite constants far outside the validated ranges (fuzz finds): the Stroh solution
        // fails, and says so.
        for c in [
            PiezoConstants {
                c44: 2.56e-90,
                ..PZT4
            },
            PiezoConstants {
                e15: 1.27e301,
                ..PZT4
            },
            PiezoConstants {
                eps11: 1e308,
                ..PZT4
            },
        ] {
            let m = Material::Piezoelectric(c);
            assert!(SurfaceCompliance::try_of(&m).is_err(), "{c:?}");
            assert!(admittance_matrix(&c).is_err(), "{c:?}");
        }
        assert!(SurfaceCompliance::try_of(&Material::Piezoelectric(PZT4)).is_ok());
    }

    #[test]
    fn admittance_is_hermitian_reciprocity() {
        for scale in [1.0, 0.3, 1e-3] {
            let m = Material::Piezoelectric(PZT4).with_scaled_coupling(scale);
            let Material::Piezoelectric(c) = m else {
                unreachable!()
            };
            let y = admittance_matrix(&c).unwrap();
            for i in 0..3 {
                for j in 0..3 {
                    let (a, b) = (y[i][j], y[j][i]);
                    let size = (y[i][i].0.abs() * y[j][j].0.abs()).sqrt();
                    assert!(
                        (a.0 - b.0).abs() < 1e-12 * size,
                        "Re Y not symmetric at {i}{j}"
                    );
                    assert!(
                        (a.1 + b.1).abs() < 1e-12 * size,
                        "Im Y not antisymmetric at {i}{j}"
                    );
                }
            }
            // Mirror symmetry: no Cauchy x–(z, φ) coupling, no local z–φ coupling.
            let size = y[0][0].0.abs();
            assert!(y[0][1].0.abs() < 1e-12 * size && y[0][2].0.abs() < 1e-12 * size);
            assert!(y[1][2].1.abs() < 1e-12 * size);
        }
    }

    #[test]
    fn stroh_reproduces_johnson_for_an_isotropic_solid() {
        // Isotropic stiffness with e = 0: triple root p = i, the case that breaks A.1.
        for nu in [0.0, 0.3, 0.45] {
            let iso = IsotropicConstants {
                shear_modulus: 27.3e9,
                poisson_ratio: nu,
            };
            let c = PiezoConstants::uncoupled_isotropic(iso.shear_modulus, nu, 1e-8, 1e-8);
            let stroh = piezoelectric(&c).unwrap();
            let exact = isotropic(&iso);
            assert_relative_eq!(stroh.y11, exact.y11, max_relative = 1e-10);
            assert_relative_eq!(stroh.y22, exact.y22, max_relative = 1e-10);
            assert_relative_eq!(
                stroh.w12,
                exact.w12,
                max_relative = 1e-10,
                epsilon = 1e-10 * exact.y11
            );
            // Electric part decoupled: y33 = −1/ε, no coupling.
            let e = stroh.electric.unwrap();
            assert_relative_eq!(e.y33, -1.0 / 1e-8, max_relative = 1e-10);
            assert!(e.y23.abs() < 1e-10 && e.w13.abs() < 1e-10);
        }
        // Johnson eq. 2.25 for aluminium, written out.
        let al = isotropic(&ALUMINIUM);
        let e = ALUMINIUM.youngs_modulus();
        assert_relative_eq!(al.y11, 2.0 * 0.91 / e, max_relative = 1e-14);
        assert_relative_eq!(al.w12, 0.4 * 1.3 / e, max_relative = 1e-14);
    }

    #[test]
    fn vanishing_coupling_tends_continuously_to_the_elastic_result() {
        let elastic = piezoelectric(&PiezoConstants {
            e31: 0.0,
            e33: 0.0,
            e15: 0.0,
            ..PZT4
        })
        .unwrap();
        let mut previous = f64::INFINITY;
        for scale in [1e-1, 1e-2, 1e-3] {
            let s =
                SurfaceCompliance::of(&Material::Piezoelectric(PZT4).with_scaled_coupling(scale));
            let gap = (s.y11 - elastic.y11)
                .abs()
                .max((s.y22 - elastic.y22).abs())
                .max((s.w12 - elastic.w12).abs())
                / elastic.y11;
            // Coefficients are even in the coupling: the gap falls like scale².
            assert!(
                gap < previous / 50.0 || gap < 1e-12,
                "gap {gap} at scale {scale}"
            );
            previous = gap;
        }
        assert!(previous < 1e-6);
    }

    #[test]
    fn surface_field_coefficients_give_sigma_xx_equal_minus_p_for_frictionless_elastic() {
        // Isotropic, frictionless: σxx0 = −Δ1 p + Δ3 (−w12 p) must equal −p inside the contact.
        let m = Material::Elastic(ALUMINIUM);
        let d = SurfaceFieldCoefficients::of(&m);
        let s = SurfaceCompliance::of(&m);
        assert_relative_eq!(-d.delta1 - d.delta3 * s.w12, -1.0, max_relative = 1e-12);
    }
}
