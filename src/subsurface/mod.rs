//! Fields below the surface: the stresses, and for a piezoelectric solid the electric
//! displacement and field, at points (x, z) of the half-plane from the surface pressure p,
//! shear traction q and charge g of a contact state; with σyy of plane strain, the von Mises
//! stress and the in-plane principal stress and shear.
//!
//! # Conventions
//! As in [`crate::contact`] and [`crate::halfplane`]: x along the surface, z ≥ 0 the depth
//! into the solid (the poling axis), u = (ux, uz, φ), `E = −∇φ`, SI units. On the surface
//! (seed paper Section 5, before eq. 64)
//!
//! ```text
//! σzz(x, 0⁺) = −p(x),   σzx(x, 0⁺) = −q(x),   Dz(x, 0⁺) = −g(x),
//! ```
//!
//! p compressive positive, q the shear traction on the half-plane (+x positive), g the surface
//! charge. Off the contact all three vanish.
//!
//! # Piezoelectric solid: the extended Stroh solution
//! With the decaying modes `u = a f(x + p_k z)`, `Im p_k > 0` ([`crate::halfplane`], whose
//! Stroh matrix this is; the eigenvectors are computed here, `modes`), a line load on the
//! surface, z-face generalised traction `t0 = t̂ δ(x − s)`, gives
//!
//! ```text
//! u               = −(1/π) Im Σ_k a_k (B⁻¹ t̂)_k ln(x − s + p_k z)
//! (σzx, σzz, Dz)  = −(1/π) Im Σ_k T_k t̂ /(x − s + p_k z),      T_k = B e_k e_kᵀ B⁻¹
//! (σxx, σxz, Dx)  =  (1/π) Im Σ_k p_k T_k t̂ /(x − s + p_k z)
//! ```
//!
//! (`1/(x + i0) = PV 1/x − iπδ(x)` and `Σ_k T_k = I` return `t̂ δ(x − s)` on the surface; the
//! seed paper's eqs. (1)–(3) are the surface values of u). Integrated over
//! `t0(s) = −(q, p, g)(s)` with the Cauchy integrals `F(ζ) = (1/π) ∫ t0(s)/(s − ζ) ds`:
//!
//! ```text
//! (σzx, σzz, Dz)  =  Im Σ_k T_k F(ζ_k),        ζ_k = x + p_k z
//! (σxx, σxz, Dx)  = −Im Σ_k p_k T_k F(ζ_k)
//! ∂u/∂x = Im Σ_k G_k F(ζ_k),   ∂u/∂z = Im Σ_k p_k G_k F(ζ_k),   G_k = A e_k e_kᵀ B⁻¹
//! ```
//!
//! As z → 0⁺, `F(x + i0) = H't0(x) + i t0(x)` (`H'f = (1/π)⨍ f(s)/(s − x) ds`), so the z-face
//! traction tends to `t0` and `∂u/∂x = Re(AB⁻¹) t0 + Im(AB⁻¹) H't0` is eqs. (A)–(C) of
//! [`crate::halfplane`] (`Y = iAB⁻¹`): σxx and Dx tend to the surface fields of the seed
//! paper's eqs. (64)–(65) (tested). σxz comes out twice, from the z face and the x face; the
//! two agree to round-off (tested).
//!
//! # Isotropic elastic solid: Flamant's line loads
//! The isotropic solid has the triple root p = i, where B is singular and the sum over modes
//! has no meaning; its confluent limit is the classical line-load solution (Johnson, *Contact
//! Mechanics*, §2.2): for a normal load P (compressive) and a tangential load Q (+x) at s,
//! `X = x − s`, `r² = X² + z²`,
//!
//! ```text
//! σxx = −(2/π)(P X² z + Q X³)/r⁴,   σzz = −(2/π)(P z³ + Q X z²)/r⁴,   σxz = −(2/π)(P X z² + Q X² z)/r⁴.
//! ```
//!
//! With `ζ = x + iz`, `F_f(ζ) = (1/π)∫ f(s)/(s − ζ) ds` and `F'_f = dF_f/dζ`, the distributed
//! loads give (`X²z/r⁴ = (−Im(1/ζ) + z Re(1/ζ²))/2`, and so on):
//!
//! ```text
//! σzz = −Im F_p + z Re F'_p + z Im F'_q
//! σxx = −Im F_p − z Re F'_p + 2 Re F_q − z Im F'_q
//! σxz =  z Im F'_p − Im F_q − z Re F'_q
//! ```
//!
//! The `z F'` terms are the Jordan-block terms of the repeated root. On the surface
//! `σxx = −p + 2H'q`, the isotropic form of eq. (64) (`Δ1 + Δ3 w12 = 1`, `Δ3 y11 = 2`). The
//! electric fields of the elastic solid are zero.
//!
//! # Out-of-plane stress, von Mises, principal stresses
//! Plane strain, `εyy = 0`, and `Ey = 0` (the fields do not depend on y). The constitutive law
//! of the transversely isotropic piezoelectric solid (stiffness at constant field, [`crate::material`])
//! gives
//!
//! ```text
//! σyy = c12 εxx + c11 εyy + c13 εzz − e31 Ez = c12 ∂ux/∂x + c13 ∂uz/∂z + e31 ∂φ/∂z,
//! ```
//!
//! and for the isotropic solid (`c12 = c13 = λ`, e = 0, `σxx + σzz = 2(λ + μ)(εxx + εzz)`)
//! `σyy = ν(σxx + σzz)`. c12 is not one of the in-plane constants that a plane problem needs,
//! so [`PiezoConstants`] does not carry it: [`SubsurfaceKernel`] knows it for the built-in
//! presets ([`preset_c12`]), takes it from [`SubsurfaceKernel::with_c12`] otherwise, and
//! leaves σyy and von Mises out (`None`) without it. Then
//!
//! ```text
//! σ_vM = √(½[(σxx − σyy)² + (σyy − σzz)² + (σzz − σxx)²] + 3σxz²),
//! τ_max = √(((σxx − σzz)/2)² + σxz²),   σ1 = (σxx + σzz)/2 + τ_max   (in-plane).
//! ```
//!
//! # Quadrature
//! The Cauchy integrals are computed by product integration on a composite rule over the
//! contact ([`SurfaceRule`], details in its module): the contact is cut at the breakpoints of
//! the state (stick ends, kinks: [`state_breakpoints`]), each half piece is mapped by
//! `s = e ± v²` so that the square-root and inverse-square-root end behaviours of p, q and g
//! become smooth, the panels next to an interior breakpoint are graded geometrically (the
//! charge has a `t log|t|` term at a kink of the traction), and on each 16-node
//! Gauss–Legendre panel the kernel is integrated exactly against the polynomial interpolant
//! (Legendre moments) when its pole is near, by Gauss–Legendre itself when far. So the fields
//! are as accurate at depth 1e−9 a as at depth a: the error is the interpolation error of the
//! densities. Loads constant on elements (the general solver's element states,
//! [`SurfaceLoads::of_elements`]) are integrated exactly element by element instead.
//!
//! Measured (tests of this module and of `rule`):
//! - closed-form Cauchy transforms (`√(1 − t²)`, `1/√(1 − t²)`, an interior half-ellipse) at
//!   depths 1e−10 … 40: F within 7e−12, `z F'` within 6e−12 (worst at 1e−10 from a contact
//!   end; 1e−13 from depth 1e−6 on);
//! - McEwen's sliding Hertz contact: σxx, σzz, σxz within 2.4e−15 p0 from depth 1e−9 a to
//!   10 a; the maximum shear under Hertz at z = 0.786151 a, 0.300283 p0 (exact to 15 digits);
//! - the default scenario (PZT-4): against 16 panels per half piece, the default 4 give
//!   8e−10 (end of normal loading) and 3e−12 (Q = 0.5 ηP) of p0 or max|Dz|; the surface limit
//!   agrees with eqs. (64)–(65) to 1.3e−9 and 7e−11; the resultants equal P, Q and Γ to
//!   6e−14 (stresses) and 9e−12 (charge) at every depth;
//! - a Stroh kernel of isotropic stiffness with c44 = μ(1 + δ) differs from Flamant's by
//!   8.2 δ p0 (δ = 1e−2 … 1e−4);
//! - Hertz loads as averages on N elements: McEwen's fields to 6e−4 … 1.1e−5 p0 for
//!   N = 64 … 512 (second order), resultants exact to 3e−15.
//!
//! # Use
//! [`SubsurfaceKernel::try_new`] for the material, [`SurfaceLoads::of_state`] (a spectral
//! state), [`SurfaceLoads::of_elements`] (an element state), [`SurfaceLoads::from_samples`] or
//! [`SurfaceLoads::from_elements`] (plain arrays), then [`subsurface_fields`] at the points.
//! Cost, measured on a loaded 2-core machine: 20,000 points take 1.8 s for PZT-4 (three modes,
//! 1,920 nodes for the default state at Q = 0.5 ηP) and 0.66 s for an isotropic solid.
//!
//! # References
//! T. C. T. Ting, *Anisotropic Elasticity* (1996), ch. 8 (the half-space line-load solution in
//! Stroh's formalism); K. L. Johnson, *Contact Mechanics* (1985), §2.2 and §7.1 (McEwen 1949);
//! J. Helsing and R. Ojala, J. Comput. Phys. 227 (2008) 2899–2921 (product integration).

mod modes;
mod rule;

#[cfg(test)]
mod tests;

use nalgebra::{Complex, Vector3};
use serde::Serialize;

use crate::contact::ContactState;
use crate::material::{BATIO3, Material, PZT4, PZT5H, PiezoConstants};

pub use rule::{DEFAULT_PANELS_PER_HALF, SurfaceRule};

use modes::Modes;

type C64 = Complex<f64>;

/// Why the subsurface fields could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SubsurfaceError {
    /// A field point is not strictly below the surface.
    #[error(
        "the point (x = {x:e} m, z = {z:e} m) is not below the surface: z must be finite and > 0"
    )]
    NotBelowSurface {
        /// x (m).
        x: f64,
        /// z (m).
        z: f64,
    },
    /// A sampled density has the wrong length.
    #[error("{density}: {given} samples for a rule of {expected} nodes")]
    SampleCount {
        /// Which density.
        density: &'static str,
        /// Samples given.
        given: usize,
        /// Nodes of the rule.
        expected: usize,
    },
    /// A sampled density is not finite.
    #[error("{density} is not finite at x = {x:e} m")]
    NotFinite {
        /// Which density.
        density: &'static str,
        /// Where.
        x: f64,
    },
    /// The contact is empty or not finite, or the rule has no panels.
    #[error(
        "no rule on the contact of centre {centre:e} m and half-width {half_width:e} m with {panels_per_half} panel(s) per half piece"
    )]
    Contact {
        /// c (m).
        centre: f64,
        /// a (m).
        half_width: f64,
        /// Panels per half piece.
        panels_per_half: usize,
    },
    /// Element edges that are not finite and increasing, or fewer than two.
    #[error("{edges} element edges: at least 2, finite and increasing, are needed")]
    Elements {
        /// How many edges were given.
        edges: usize,
    },
    /// A matrix of the Stroh solution is singular.
    #[error("the {matrix} is singular")]
    Singular {
        /// Which matrix.
        matrix: &'static str,
    },
    /// The iteration for the roots of the characteristic cubic did not settle (nearly
    /// repeated roots).
    #[error(
        "the roots of the Stroh characteristic polynomial did not settle in {iterations} iterations (nearly repeated roots)"
    )]
    RootsNotFound {
        /// The iterations allowed.
        iterations: usize,
    },
    /// The Stroh characteristic polynomial does not have three roots in the upper half-plane.
    #[error("the Stroh characteristic polynomial has {found} roots with Im p > 0, not 3")]
    ModeCount {
        /// How many.
        found: usize,
    },
    /// Nearly repeated Stroh roots (an almost isotropic solid): the modes' sum loses its
    /// digits.
    #[error(
        "the Stroh roots are nearly repeated (condition of B {condition:.3e}); the modal sum would lose its accuracy"
    )]
    NearlyRepeatedRoots {
        /// `‖B‖‖B⁻¹‖`.
        condition: f64,
    },
}

/// c12 (Pa) of the built-in piezoelectric presets (stiffness at constant field), for σyy:
/// Berlincourt, Curran & Jaffe (1964), the source of the presets' other constants, as
/// tabulated by Auld, *Acoustic Fields and Waves in Solids* I (1973), App. 2: PZT-4 7.78e10,
/// PZT-5H 7.95e10, BaTiO3 6.6e10. (Consistent with the tabulated `c66 = (c11 − c12)/2`:
/// 3.06e10, 2.33e10, 4.2e10.)
pub const PRESET_C12: [(&str, f64); 3] = [("pzt4", 77.8e9), ("pzt5h", 79.5e9), ("batio3", 66.0e9)];

/// c12 of a built-in preset whose constants these are exactly ([`PRESET_C12`]), else `None`.
pub fn preset_c12(constants: &PiezoConstants) -> Option<f64> {
    [PZT4, PZT5H, BATIO3]
        .iter()
        .zip(PRESET_C12)
        .find(|(c, _)| *c == constants)
        .map(|(_, (_, c12))| c12)
}

/// The half-plane's response to surface loads, for field points below the surface.
#[derive(Debug, Clone)]
pub struct SubsurfaceKernel {
    kind: Kind,
}

#[derive(Debug, Clone)]
enum Kind {
    Isotropic {
        poisson_ratio: f64,
    },
    Piezoelectric {
        modes: Box<Modes>,
        constants: PiezoConstants,
        c12: Option<f64>,
    },
}

impl SubsurfaceKernel {
    /// The kernel of a material: Flamant's for an isotropic solid, the Stroh modes for a
    /// piezoelectric one (an error if they are degenerate); c12 from [`preset_c12`].
    pub fn try_new(material: &Material) -> Result<Self, SubsurfaceError> {
        let kind = match material {
            Material::Elastic(iso) => Kind::Isotropic {
                poisson_ratio: iso.poisson_ratio,
            },
            Material::Piezoelectric(c) => Kind::Piezoelectric {
                modes: Box::new(Modes::of(c)?),
                constants: *c,
                c12: preset_c12(c),
            },
        };
        Ok(Self { kind })
    }

    /// With c12 (Pa) for σyy of a piezoelectric solid (no effect on an isotropic one, whose
    /// σyy needs only ν).
    pub fn with_c12(mut self, c12: f64) -> Self {
        if let Kind::Piezoelectric { c12: own, .. } = &mut self.kind {
            *own = Some(c12);
        }
        self
    }

    /// Whether the fields have σyy and the von Mises stress: always for an isotropic solid,
    /// with c12 for a piezoelectric one.
    pub fn has_sigma_yy(&self) -> bool {
        match &self.kind {
            Kind::Isotropic { .. } => true,
            Kind::Piezoelectric { c12, .. } => c12.is_some(),
        }
    }

    /// `‖B‖‖B⁻¹‖` of the decaying modes' eigenvectors (dimensionless, unit displacement
    /// eigenvectors): the modal sum loses about its logarithm in digits (PZT-4: 16; refused
    /// above 1e6). `None` for the isotropic solid.
    pub fn mode_condition(&self) -> Option<f64> {
        match &self.kind {
            Kind::Isotropic { .. } => None,
            Kind::Piezoelectric { modes, .. } => Some(modes.condition),
        }
    }

    /// The roots `p_k` (re, im) of the decaying modes; `None` for the isotropic solid (p = i,
    /// triple).
    pub fn roots(&self) -> Option<[(f64, f64); 3]> {
        match &self.kind {
            Kind::Isotropic { .. } => None,
            Kind::Piezoelectric { modes, .. } => Some(modes.roots.map(|p| (p.re, p.im))),
        }
    }
}

/// The surface loads of one instant: p, q and g at the nodes of a [`SurfaceRule`] (a spectral
/// state, sampled densities), or constant on elements (the general solver's element states).
#[derive(Debug, Clone)]
pub struct SurfaceLoads {
    representation: Representation,
}

#[derive(Debug, Clone)]
enum Representation {
    /// `2v f` at the rule's nodes for f = q, p, g (the order of the z-face traction).
    Rule {
        rule: Box<SurfaceRule>,
        weighted: [Vec<f64>; 3],
    },
    /// Element edges `e_j` (increasing) and the values `f_j` on `[e_j, e_{j+1}]`, for
    /// f = q, p, g: exactly
    /// `F(ζ) = (1/π) Σ_j f_j Log((e_{j+1} − ζ)/(e_j − ζ))` (the principal logarithm of the
    /// ratio is the integral along the element, which does not pass through ζ) and
    /// `F'(ζ) = (1/π) Σ_j f_j (e_{j+1} − e_j)/((e_j − ζ)(e_{j+1} − ζ))`. Far from an element
    /// the logarithm is `ln(1 + w)`, `w = (e_{j+1} − e_j)/(e_j − ζ)`, by its series, so that
    /// the fields keep their relative accuracy as they decay.
    Elements {
        edges: Vec<f64>,
        values: [Vec<f64>; 3],
    },
}

impl Representation {
    /// `(1/π)∫ f/(s − ζ) ds` (and its ζ-derivative when `derivative`) of the densities
    /// `which` (0 = q, 1 = p, 2 = g).
    fn cauchy<const D: usize>(
        &self,
        which: [usize; D],
        zeta: C64,
        derivative: bool,
    ) -> ([C64; D], [C64; D]) {
        match self {
            Representation::Rule { rule, weighted } => {
                rule.cauchy(which.map(|k| weighted[k].as_slice()), zeta, derivative)
            }
            Representation::Elements { edges, values } => {
                let zero = C64::new(0.0, 0.0);
                let (mut f, mut df) = ([zero; D], [zero; D]);
                for (j, e) in edges.windows(2).enumerate() {
                    if which.iter().all(|&k| values[k][j] == 0.0) {
                        continue;
                    }
                    let (from, to) = (C64::new(e[0], 0.0) - zeta, C64::new(e[1], 0.0) - zeta);
                    let w = (e[1] - e[0]) / from;
                    let log = ln_1p(w);
                    let slope = (from * to).inv() * (e[1] - e[0]);
                    for (d, &k) in which.iter().enumerate() {
                        f[d] += log * values[k][j];
                        if derivative {
                            df[d] += slope * values[k][j];
                        }
                    }
                }
                let pi = std::f64::consts::PI;
                (f.map(|v| v / pi), df.map(|v| v / pi))
            }
        }
    }
}

impl SurfaceLoads {
    /// From p (Pa), q (Pa) and g (C/m²) sampled at the rule's nodes ([`SurfaceRule::nodes`]).
    pub fn from_samples(
        rule: SurfaceRule,
        pressure: &[f64],
        traction: &[f64],
        charge: &[f64],
    ) -> Result<Self, SubsurfaceError> {
        let nodes = rule.nodes();
        let mut weighted: [Vec<f64>; 3] = Default::default();
        for (k, (density, values)) in [("q", traction), ("p", pressure), ("g", charge)]
            .into_iter()
            .enumerate()
        {
            if values.len() != nodes.len() {
                return Err(SubsurfaceError::SampleCount {
                    density,
                    given: values.len(),
                    expected: nodes.len(),
                });
            }
            if let Some(i) = values.iter().position(|v| !v.is_finite()) {
                return Err(SubsurfaceError::NotFinite {
                    density,
                    x: nodes[i],
                });
            }
            weighted[k] = rule.weighted(values);
        }
        Ok(Self {
            representation: Representation::Rule {
                rule: Box::new(rule),
                weighted,
            },
        })
    }

    /// From values constant on elements: `edges` (m, N + 1, increasing) and p (Pa), q (Pa),
    /// g (C/m²) on each of the N elements, zero outside them; integrated exactly (a
    /// piecewise-constant density is what the general solver's element states hold,
    /// [`crate::contact::general::GeneralState`]).
    pub fn from_elements(
        edges: &[f64],
        pressure: &[f64],
        traction: &[f64],
        charge: &[f64],
    ) -> Result<Self, SubsurfaceError> {
        let n = edges.len().saturating_sub(1);
        if n == 0 || edges.iter().any(|e| !e.is_finite()) || edges.windows(2).any(|w| w[1] <= w[0])
        {
            return Err(SubsurfaceError::Elements { edges: edges.len() });
        }
        let mut element_values: [Vec<f64>; 3] = Default::default();
        for (k, (density, values)) in [("q", traction), ("p", pressure), ("g", charge)]
            .into_iter()
            .enumerate()
        {
            if values.len() != n {
                return Err(SubsurfaceError::SampleCount {
                    density,
                    given: values.len(),
                    expected: n,
                });
            }
            if let Some(i) = values.iter().position(|v| !v.is_finite()) {
                return Err(SubsurfaceError::NotFinite {
                    density,
                    x: 0.5 * (edges[i] + edges[i + 1]),
                });
            }
            element_values[k] = values.to_vec();
        }
        Ok(Self {
            representation: Representation::Elements {
                edges: edges.to_vec(),
                values: element_values,
            },
        })
    }

    /// From a function of x giving `(p, q, g)` (Pa, Pa, C/m²) on the contact.
    pub fn from_fn(
        rule: SurfaceRule,
        mut loads: impl FnMut(f64) -> (f64, f64, f64),
    ) -> Result<Self, SubsurfaceError> {
        let nodes = rule.nodes();
        let (mut p, mut q, mut g) = (Vec::new(), Vec::new(), Vec::new());
        for &x in &nodes {
            let (pi, qi, gi) = loads(x);
            p.push(pi);
            q.push(qi);
            g.push(gi);
        }
        Self::from_samples(rule, &p, &q, &g)
    }

    /// The loads of a contact state (spectral representation): its contact, cut at
    /// [`state_breakpoints`], with `panels_per_half` panels per half piece
    /// ([`DEFAULT_PANELS_PER_HALF`] unless measured otherwise).
    pub fn of_state(state: &ContactState, panels_per_half: usize) -> Result<Self, SubsurfaceError> {
        let (centre, half_width) = (state.centre, state.half_width);
        let rule = SurfaceRule::new(
            centre,
            half_width,
            &state_breakpoints(state),
            panels_per_half,
        )
        .ok_or(SubsurfaceError::Contact {
            centre,
            half_width,
            panels_per_half,
        })?;
        Self::sampled(state, rule)
    }

    /// The loads of a contact state sampled at the nodes of `rule`: p, q and
    /// `g = k p + w` (the charge split of the conducting punch).
    pub fn sampled(state: &ContactState, rule: SurfaceRule) -> Result<Self, SubsurfaceError> {
        let nodes = rule.nodes();
        let (mut p, mut q, mut w) = (Vec::new(), Vec::new(), Vec::new());
        state.pressures_into(&nodes, &mut p);
        state.tractions_with(&nodes, &p, &mut q);
        state.potential_charges_into(&nodes, &mut w);
        let g: Vec<f64> = p
            .iter()
            .zip(&w)
            .map(|(p, w)| state.split.ratio * p + w)
            .collect();
        Self::from_samples(rule, &p, &q, &g)
    }

    /// The loads of an element state of the general solver ([`Self::from_elements`] on its
    /// mesh).
    pub fn of_elements(
        state: &crate::contact::general::GeneralState,
    ) -> Result<Self, SubsurfaceError> {
        Self::from_elements(
            &state.mesh.edges,
            &state.pressure,
            &state.shear,
            &state.charge,
        )
    }

    /// The rule the loads are sampled on; `None` for element loads.
    pub fn rule(&self) -> Option<&SurfaceRule> {
        match &self.representation {
            Representation::Rule { rule, .. } => Some(rule),
            Representation::Elements { .. } => None,
        }
    }
}

/// `ln(1 + w)` (principal), by its series for `|w| < 1/8` (18 terms: below 1e−17).
fn ln_1p(w: C64) -> C64 {
    if w.norm() >= 0.125 {
        return (w + 1.0).ln();
    }
    let mut power = w;
    let mut sum = w;
    for k in 2..=18 {
        power *= -w;
        sum += power / k as f64;
    }
    sum
}

/// Where the densities of a contact state are not smooth inside the contact: the traction's
/// breakpoints ([`ContactState::traction_breakpoints`]: stick ends, fade ramps, centre kinks)
/// and the kink points of the pressure and of the charge.
pub fn state_breakpoints(state: &ContactState) -> Vec<f64> {
    let mut points = state.traction_breakpoints();
    points.extend(state.pressure_kinks.0.iter().map(|k| k.at));
    points.extend(state.charge_kinks.0.iter().map(|k| k.at));
    points
}

/// The fields at one point below the surface (SI).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SubsurfacePoint {
    /// x (m).
    pub x: f64,
    /// Depth z > 0 (m).
    pub z: f64,
    /// σxx (Pa).
    pub sigma_xx: f64,
    /// σzz (Pa).
    pub sigma_zz: f64,
    /// σxz (Pa).
    pub sigma_xz: f64,
    /// σyy of plane strain (Pa); `None` for a piezoelectric solid of unknown c12.
    pub sigma_yy: Option<f64>,
    /// Dx (C/m²); zero for an elastic solid.
    pub d_x: f64,
    /// Dz (C/m²); zero for an elastic solid.
    pub d_z: f64,
    /// Ex (V/m); zero for an elastic solid.
    pub e_x: f64,
    /// Ez (V/m); zero for an elastic solid.
    pub e_z: f64,
    /// von Mises stress (Pa), with σyy; `None` without it.
    pub von_mises: Option<f64>,
    /// The larger in-plane principal stress σ1 (Pa).
    pub max_principal: f64,
    /// The in-plane maximum shear stress τ_max (Pa).
    pub max_shear: f64,
}

impl SubsurfacePoint {
    fn new(
        (x, z): (f64, f64),
        [sxx, szz, sxz]: [f64; 3],
        sigma_yy: Option<f64>,
        [d_x, d_z, e_x, e_z]: [f64; 4],
    ) -> Self {
        let max_shear = (0.25 * (sxx - szz).powi(2) + sxz * sxz).sqrt();
        let von_mises = sigma_yy.map(|syy| {
            (0.5 * ((sxx - syy).powi(2) + (syy - szz).powi(2) + (szz - sxx).powi(2))
                + 3.0 * sxz * sxz)
                .sqrt()
        });
        Self {
            x,
            z,
            sigma_xx: sxx,
            sigma_zz: szz,
            sigma_xz: sxz,
            sigma_yy,
            d_x,
            d_z,
            e_x,
            e_z,
            von_mises,
            max_principal: 0.5 * (sxx + szz) + max_shear,
            max_shear,
        }
    }
}

/// The uniform state of a bulk stress σB along the surface (`general::Loads::bulk_stress`):
/// `σxx = σB`, `σzz = σxz = 0`, `εyy = 0`, and for a piezoelectric solid open circuit,
/// `Dz = 0` and `Ex = Dx = 0` ([`crate::material::Material::bulk_compliance`]). From
/// `σzz = c13 εxx + c33 εzz − e33 Ez = 0` and `Dz = e31 εxx + e33 εzz + ε33 Ez = 0`,
///
/// ```text
/// εzz = −(ε33 c13 + e33 e31) εxx/Δ,   Ez = (e33 c13 − c33 e31) εxx/Δ,   Δ = c33 ε33 + e33²,
/// σyy = c12 εxx + c13 εzz − e31 Ez                (isotropic: σyy = ν σB, Ez = 0).
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BulkState {
    /// εxx = s̃σB and εzz (–) of a piezoelectric solid (the isotropic state needs none).
    pub strains: Option<(f64, f64)>,
    /// σyy (Pa), when c12 is known.
    pub sigma_yy: Option<f64>,
    /// Ez (V/m).
    pub e_z: f64,
}

impl SubsurfaceKernel {
    /// The uniform state of the bulk stress `sigma_b` (Pa) in this kernel's solid.
    pub fn bulk_state(&self, sigma_b: f64) -> BulkState {
        match &self.kind {
            Kind::Isotropic { poisson_ratio } => BulkState {
                strains: None,
                sigma_yy: Some(poisson_ratio * sigma_b),
                e_z: 0.0,
            },
            Kind::Piezoelectric {
                constants: c, c12, ..
            } => {
                let exx = sigma_b * crate::material::Material::Piezoelectric(*c).bulk_compliance();
                let det = c.c33 * c.eps33 + c.e33 * c.e33;
                let ezz = -(c.eps33 * c.c13 + c.e33 * c.e31) * exx / det;
                let e_z = (c.e33 * c.c13 - c.c33 * c.e31) * exx / det;
                BulkState {
                    strains: Some((exx, ezz)),
                    sigma_yy: c12.map(|c12| c12 * exx + c.c13 * ezz - c.e31 * e_z),
                    e_z,
                }
            }
        }
    }
}

impl SubsurfacePoint {
    /// The point with the uniform state of a bulk stress `sigma_b` added ([`BulkState`]).
    pub fn with_bulk(&self, sigma_b: f64, bulk: &BulkState) -> Self {
        Self::new(
            (self.x, self.z),
            [self.sigma_xx + sigma_b, self.sigma_zz, self.sigma_xz],
            self.sigma_yy.zip(bulk.sigma_yy).map(|(s, b)| s + b),
            [self.d_x, self.d_z, self.e_x, self.e_z + bulk.e_z],
        )
    }
}

/// The fields at each of `points` (x, z) (m, z > 0) under `loads` (module docs).
pub fn subsurface_fields(
    kernel: &SubsurfaceKernel,
    loads: &SurfaceLoads,
    points: &[(f64, f64)],
) -> Result<Vec<SubsurfacePoint>, SubsurfaceError> {
    if let Some(&(x, z)) = points
        .iter()
        .find(|(x, z)| !(x.is_finite() && z.is_finite() && *z > 0.0))
    {
        return Err(SubsurfaceError::NotBelowSurface { x, z });
    }
    Ok(points
        .iter()
        .map(|&point| match &kernel.kind {
            Kind::Isotropic { poisson_ratio } => isotropic_point(*poisson_ratio, loads, point),
            Kind::Piezoelectric {
                modes,
                constants,
                c12,
            } => piezoelectric_point(modes, constants, *c12, loads, point),
        })
        .collect())
}

/// Flamant's kernel (module docs).
fn isotropic_point(nu: f64, loads: &SurfaceLoads, (x, z): (f64, f64)) -> SubsurfacePoint {
    let ([fq, fp], [dq, dp]) = loads.representation.cauchy([0, 1], C64::new(x, z), true);
    let szz = -fp.im + z * dp.re + z * dq.im;
    let sxx = -fp.im - z * dp.re + 2.0 * fq.re - z * dq.im;
    let sxz = z * dp.im - fq.im - z * dq.re;
    SubsurfacePoint::new((x, z), [sxx, szz, sxz], Some(nu * (sxx + szz)), [0.0; 4])
}

/// The modal sums of the Stroh solution (module docs).
fn piezoelectric_point(
    modes: &Modes,
    c: &PiezoConstants,
    c12: Option<f64>,
    loads: &SurfaceLoads,
    (x, z): (f64, f64),
) -> SubsurfacePoint {
    let zero = Vector3::<C64>::zeros();
    let (mut t, mut s, mut dx, mut dz) = (zero, zero, zero, zero);
    for k in 0..3 {
        let pk = modes.roots[k];
        let ([fq, fp, fg], _) = loads.representation.cauchy([0, 1, 2], pk * z + x, false);
        // Cauchy integrals of the z-face traction t0 = −(q, p, g).
        let f = -Vector3::new(fq, fp, fg);
        let tk = modes.traction[k] * f;
        let gk = modes.gradient[k] * f;
        t += tk;
        s -= tk * pk;
        dx += gk;
        dz += gk * pk;
    }
    let (t, s, dx, dz) = (
        t.map(|v| v.im),
        s.map(|v| v.im),
        dx.map(|v| v.im),
        dz.map(|v| v.im),
    );
    let sigma_yy = c12.map(|c12| c12 * dx[0] + c.c13 * dz[1] + c.e31 * dz[2]);
    SubsurfacePoint::new(
        (x, z),
        [s[0], t[1], t[0]],
        sigma_yy,
        [s[2], t[2], -dx[2], -dz[2]],
    )
}

/// σxz from the x face of the Stroh solution, for the symmetry test.
#[cfg(test)]
fn piezoelectric_shear_from_x_face(
    kernel: &SubsurfaceKernel,
    loads: &SurfaceLoads,
    (x, z): (f64, f64),
) -> f64 {
    let Kind::Piezoelectric { modes, .. } = &kernel.kind else {
        panic!("piezoelectric kernel expected")
    };
    let mut s = C64::new(0.0, 0.0);
    for k in 0..3 {
        let pk = modes.roots[k];
        let ([fq, fp, fg], _) = loads.representation.cauchy([0, 1, 2], pk * z + x, false);
        let f = -Vector3::new(fq, fp, fg);
        s -= (modes.traction[k] * f)[1] * pk;
    }
    s.im
}
