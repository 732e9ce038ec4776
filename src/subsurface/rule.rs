//! The Cauchy integrals of a surface density at points off the surface, by product integration
//! on a composite rule over the contact ([`SurfaceRule`]).
//!
//! # What is computed
//! For a density f on the contact `[c − a, c + a]` and ζ in the upper half-plane,
//!
//! ```text
//! F(ζ)  = (1/π) ∫ f(s)/(s − ζ) ds,        F'(ζ) = (1/π) ∫ f(s)/(s − ζ)² ds.
//! ```
//!
//! As ζ approaches the contact (a field point close to the surface) the kernel becomes nearly
//! singular: `F(x + i0) = H'f(x) + i f(x)`. A fixed quadrature rule would need nodes finer than
//! the depth; here the kernel is integrated exactly against a piecewise-polynomial
//! interpolant of the density instead, so the only error is the interpolation error, at any
//! depth.
//!
//! # The rule
//! Work in the contact variable `t = (s − c)/a` (F is unchanged, F' is scaled by 1/a).
//! The contact is cut at the breakpoints (where the density has a square-root kink: the stick
//! ends and the kinks of fretsim's representation) into pieces; each piece is cut at its
//! midpoint into two halves, and on the half that ends at `e` the substitution
//! `t = e + σ v²` (σ = +1 from a left end, −1 from a right end, `0 ≤ v ≤ V = √(half-length)`)
//! turns each end behaviour the contact has into a smooth function of v:
//!
//! ```text
//! H(v) = 2v f(e + σv²):   f ~ √|t − e|  →  H ~ v²;   f ~ A + B√|t − e|  →  H ~ 2Av + 2Bv²;
//!                         f ~ C/√|t − e| (the charge under a conducting punch)  →  H ~ 2C.
//! ```
//!
//! With `c_ζ = σ(ζ − e)` and `r = √c_ζ`, `ds/(s − ζ) = σ 2v dv/(v² − c_ζ)`, so
//!
//! ```text
//! ∫_half f/(s − ζ) ds  = σ ∫_0^V H(v)/(v² − c_ζ) dv,      ∫_half f/(s − ζ)² ds = ∫_0^V H(v)/(v² − c_ζ)² dv,
//! 1/(v² − c_ζ)  = (1/(2r)) [1/(v − r) − 1/(v + r)],
//! 1/(v² − c_ζ)² = (1/(4r²)) [1/(v − r)² + 1/(v + r)²] − (1/(4r³)) [1/(v − r) − 1/(v + r)].
//! ```
//!
//! Each half is split into equal panels in v (the one at an interior breakpoint further cut
//! geometrically towards it, `GRADED_LEVELS`), each with `PANEL_NODES` Gauss–Legendre nodes.
//! On a
//! panel mapped to `τ ∈ [−1, 1]`, a pole τ0 (`r` or `−r` in panel coordinates) is *far* when
//! the Bernstein ellipse through it has `ρ = |τ0 + √(τ0 − 1)√(τ0 + 1)| ≥ RHO_NEAR`; Gauss–
//! Legendre is then accurate to `O(ρ^{−2n})` and is used as it is. A near pole gets product
//! weights (Helsing & Ojala, J. Comput. Phys. 227, 2008, in a Legendre basis): with the
//! interpolant `H = Σ_k c_k P_k`, `c_k = (k + ½) Σ_l w_l P_k(τ_l) H_l`,
//!
//! ```text
//! ∫ H(τ)/(τ − τ0) dτ  ≈ Σ_l α_l H_l,   α_l = w_l Σ_k (k + ½) P_k(τ_l) m_k,   m_k = ∫ P_k/(τ − τ0) dτ,
//! m_0 = Log((1 − τ0)/(−1 − τ0)),  m_1 = 2 + τ0 m_0,  (k + 1) m_{k+1} = (2k + 1) τ0 m_k − k m_{k−1},
//! ```
//!
//! and `d_k = dm_k/dτ0 = ∫ P_k/(τ − τ0)² dτ` likewise for the double pole. (The principal
//! logarithm of the ratio is the integral along the segment, which does not pass through τ0.)
//! The forward recurrence grows errors like the dominant solution `P_k(τ0) ~ ρ^k`, which the
//! decaying Legendre coefficients of a resolved density keep harmless for `ρ < RHO_NEAR`.
//! Measured accuracy: see the tests (the closed-form Cauchy transforms of `√(1 − t²)`,
//! `1/√(1 − t²)` and a half-ellipse on an interior piece).

use nalgebra::Complex;

use crate::quadrature::gauss_legendre;

type C64 = Complex<f64>;

/// Panels on each half piece unless asked otherwise. Measured on the default scenario against
/// 16: 8e−10 (end of normal loading) and 3e−12 (Q = 0.5 ηP) of the fields' scales; 2 panels
/// give 1e−6 (test `fields_converge_as_the_panels_are_refined`).
pub const DEFAULT_PANELS_PER_HALF: usize = 4;

/// Geometric levels towards each interior breakpoint, and their ratio: the first panel of a
/// half piece that ends at a breakpoint, `[0, Δv]`, is cut at `Δv·GRADING^l`,
/// l = 1 … GRADED_LEVELS. A density with a weaker singularity at a breakpoint than the
/// substitution absorbs (a `t log|t|` term, as the charge has at a kink of the traction: its
/// Hilbert transform) is then resolved down to `Δv·GRADING^GRADED_LEVELS` (measured in the
/// tests).
const GRADED_LEVELS: usize = 4;
const GRADING: f64 = 0.25;

/// Gauss–Legendre nodes per panel.
pub(crate) const PANEL_NODES: usize = 16;
const N: usize = PANEL_NODES;

/// Product weights are used for poles inside the Bernstein ellipse of this parameter:
/// outside it the 16-point Gauss–Legendre error `~ρ^{−32}` is below 1e−15.
const RHO_NEAR: f64 = 3.0;

/// The reference panel: nodes, weights, and the Legendre table of the product weights.
#[derive(Debug, Clone)]
struct Reference {
    nodes: [f64; N],
    weights: [f64; N],
    /// `legendre[l][k] = w_l (k + ½) P_k(τ_l)`.
    legendre: [[f64; N]; N],
}

impl Reference {
    fn new() -> Self {
        let (x, w) = gauss_legendre(N);
        let mut nodes = [0.0; N];
        let mut weights = [0.0; N];
        nodes.copy_from_slice(&x);
        weights.copy_from_slice(&w);
        let mut legendre = [[0.0; N]; N];
        for ((row, &t), &w) in legendre.iter_mut().zip(&nodes).zip(&weights) {
            // P_k(t) by the three-term recurrence.
            let mut p = [0.0; N];
            p[0] = 1.0;
            p[1] = t;
            for k in 1..N - 1 {
                let kf = k as f64;
                p[k + 1] = ((2.0 * kf + 1.0) * t * p[k] - kf * p[k - 1]) / (kf + 1.0);
            }
            for (k, (entry, pk)) in row.iter_mut().zip(p).enumerate() {
                *entry = w * (k as f64 + 0.5) * pk;
            }
        }
        Self {
            nodes,
            weights,
            legendre,
        }
    }

    /// Weights for `∫ H/(τ − τ0) dτ` and, when `double`, `∫ H/(τ − τ0)² dτ` on the panel,
    /// given τ0 and its distances `1 − τ0`, `−1 − τ0` from the panel ends (computed by the
    /// caller without cancellation: they carry the end singularities).
    fn pole_weights(&self, tau0: C64, ends: (C64, C64), double: bool) -> ([C64; N], [C64; N]) {
        let mut single = [C64::new(0.0, 0.0); N];
        let mut second = [C64::new(0.0, 0.0); N];
        if bernstein(tau0) >= RHO_NEAR {
            for l in 0..N {
                let inv = (C64::new(self.nodes[l], 0.0) - tau0).inv();
                single[l] = inv * self.weights[l];
                if double {
                    second[l] = inv * inv * self.weights[l];
                }
            }
            return (single, second);
        }
        let (to_right, to_left) = ends;
        let mut m = [C64::new(0.0, 0.0); N];
        let mut d = [C64::new(0.0, 0.0); N];
        m[0] = (to_right / to_left).ln();
        m[1] = tau0 * m[0] + 2.0;
        d[0] = to_left.inv() - to_right.inv();
        d[1] = m[0] + tau0 * d[0];
        for k in 1..N - 1 {
            let kf = k as f64;
            m[k + 1] = (tau0 * m[k] * (2.0 * kf + 1.0) - m[k - 1] * kf) / (kf + 1.0);
            d[k + 1] = ((m[k] + tau0 * d[k]) * (2.0 * kf + 1.0) - d[k - 1] * kf) / (kf + 1.0);
        }
        for l in 0..N {
            let row = &self.legendre[l];
            single[l] = (0..N).map(|k| m[k] * row[k]).sum();
            if double {
                second[l] = (0..N).map(|k| d[k] * row[k]).sum();
            }
        }
        (single, second)
    }
}

/// `ρ` of the Bernstein ellipse (foci ±1) through τ0.
fn bernstein(tau0: C64) -> f64 {
    let one = C64::new(1.0, 0.0);
    (tau0 + (tau0 - one).sqrt() * (tau0 + one).sqrt()).norm()
}

/// One panel: `t = end + sigma v²` for `v` in `[va, vb]` (`v = centre + half τ`, τ in
/// [−1, 1]), whose ends are `ta = end + sigma va²` and `tb`; `tb` of the panel at a piece's
/// midpoint is the midpoint itself, the same number from both halves.
#[derive(Debug, Clone, Copy)]
struct Panel {
    end: f64,
    sigma: f64,
    va: f64,
    vb: f64,
    ta: f64,
    tb: f64,
}

impl Panel {
    fn centre(&self) -> f64 {
        0.5 * (self.va + self.vb)
    }

    fn half(&self) -> f64 {
        0.5 * (self.vb - self.va)
    }
}

/// A composite rule over the contact `[c − a, c + a]` for densities with square-root or
/// inverse-square-root behaviour at the contact ends and at given breakpoints (module docs).
#[derive(Debug, Clone)]
pub struct SurfaceRule {
    centre: f64,
    half_width: f64,
    breakpoints: Vec<f64>,
    panels_per_half: usize,
    panels: Vec<Panel>,
    /// The nodes in the contact variable t.
    nodes: Vec<f64>,
    /// `2v` at each node: `H = 2v f`.
    jacobians: Vec<f64>,
    reference: Reference,
}

impl SurfaceRule {
    /// The rule on the contact of centre `centre` and half-width `half_width` (m), cut at the
    /// `breakpoints` that lie inside it (m; any order; points closer than 1e−12 a to an end or
    /// to each other are merged), with `panels_per_half` panels of 16 nodes on each half
    /// piece. `None` if the contact is not finite with `half_width > 0` or `panels_per_half`
    /// is zero.
    pub fn new(
        centre: f64,
        half_width: f64,
        breakpoints: &[f64],
        panels_per_half: usize,
    ) -> Option<Self> {
        Self::with_grading(
            centre,
            half_width,
            breakpoints,
            panels_per_half,
            GRADED_LEVELS,
        )
    }

    /// [`Self::new`] with `graded_levels` geometric levels (ratio `GRADING`) in the panel at
    /// each interior breakpoint.
    pub(crate) fn with_grading(
        centre: f64,
        half_width: f64,
        breakpoints: &[f64],
        panels_per_half: usize,
        graded_levels: usize,
    ) -> Option<Self> {
        if !(centre.is_finite() && half_width.is_finite() && half_width > 0.0)
            || panels_per_half == 0
        {
            return None;
        }
        let gap = 1e-12;
        let mut cuts: Vec<f64> = breakpoints
            .iter()
            .map(|x| (x - centre) / half_width)
            .filter(|t| t.is_finite() && t.abs() < 1.0 - gap)
            .collect();
        cuts.sort_by(f64::total_cmp);
        let mut ends = vec![-1.0];
        for t in cuts {
            if t - ends[ends.len() - 1] > gap {
                ends.push(t);
            }
        }
        ends.push(1.0);
        let reference = Reference::new();
        let mut panels = Vec::new();
        for piece in ends.windows(2) {
            let (u, w) = (piece[0], piece[1]);
            let mid = 0.5 * (u + w);
            for (end, sigma) in [(u, 1.0), (w, -1.0)] {
                let length = (sigma * (mid - end)).sqrt();
                let dv = length / panels_per_half as f64;
                // Edges in v: the first panel graded geometrically towards an interior
                // breakpoint (not towards a contact end: there the densities are sampled at
                // x with `a − |x − c|` known only to `ε a`, which a node at `v² ~ 1e−8 a` would
                // magnify into the 1/√ charge).
                let levels = if end.abs() < 1.0 { graded_levels } else { 0 };
                let mut edges: Vec<f64> = (0..=levels)
                    .rev()
                    .map(|l| dv * GRADING.powi(l as i32))
                    .collect();
                edges.insert(0, 0.0);
                edges.extend((2..panels_per_half).map(|j| j as f64 * dv));
                if panels_per_half > 1 {
                    edges.push(length);
                } else {
                    *edges.last_mut().expect("edges") = length;
                }
                let t_at = |v: f64| end + sigma * v * v;
                let last = edges.len() - 2;
                for (j, e) in edges.windows(2).enumerate() {
                    panels.push(Panel {
                        end,
                        sigma,
                        va: e[0],
                        vb: e[1],
                        ta: t_at(e[0]),
                        tb: if j == last { mid } else { t_at(e[1]) },
                    });
                }
            }
        }
        let mut nodes = Vec::with_capacity(panels.len() * N);
        let mut jacobians = Vec::with_capacity(panels.len() * N);
        for p in &panels {
            for &tau in &reference.nodes {
                let v = p.centre() + p.half() * tau;
                nodes.push(p.end + p.sigma * v * v);
                jacobians.push(2.0 * v);
            }
        }
        Some(Self {
            centre,
            half_width,
            breakpoints: ends[1..ends.len() - 1]
                .iter()
                .map(|t| centre + half_width * t)
                .collect(),
            panels_per_half,
            panels,
            nodes,
            jacobians,
            reference,
        })
    }

    /// Contact centre c (m).
    pub fn centre(&self) -> f64 {
        self.centre
    }

    /// Contact half-width a (m).
    pub fn half_width(&self) -> f64 {
        self.half_width
    }

    /// The breakpoints kept, in increasing order (m).
    pub fn breakpoints(&self) -> &[f64] {
        &self.breakpoints
    }

    /// Panels on each half piece.
    pub fn panels_per_half(&self) -> usize {
        self.panels_per_half
    }

    /// The number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the rule has no nodes (never, for a rule that was built).
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The nodes x (m), at which a density is sampled, panel by panel.
    pub fn nodes(&self) -> Vec<f64> {
        self.nodes
            .iter()
            .map(|t| self.centre + self.half_width * t)
            .collect()
    }

    /// `H = 2v f` at the nodes from f at the nodes.
    pub(crate) fn weighted(&self, values: &[f64]) -> Vec<f64> {
        values
            .iter()
            .zip(&self.jacobians)
            .map(|(f, j)| f * j)
            .collect()
    }

    /// `(1/π) ∫ f/(s − ζ) ds` and, when `derivative`, `(1/π) ∫ f/(s − ζ)² ds` (1/m) for each
    /// density, given as [`Self::weighted`] values; ζ in metres, `Im ζ > 0`.
    pub(crate) fn cauchy<const D: usize>(
        &self,
        weighted: [&[f64]; D],
        zeta: C64,
        derivative: bool,
    ) -> ([C64; D], [C64; D]) {
        let zero = C64::new(0.0, 0.0);
        let mut f = [zero; D];
        let mut df = [zero; D];
        let zt = (zeta - self.centre) / self.half_width;
        let r_ref = &self.reference;
        for (j, p) in self.panels.iter().enumerate() {
            let (centre, half) = (p.centre(), p.half());
            let c = (zt - p.end) * p.sigma;
            let r = c.sqrt();
            let tau1 = (r - centre) / half;
            let tau2 = (-r - centre) / half;
            let mut k = [zero; N];
            let mut dk = [zero; N];
            if bernstein(tau1) >= RHO_NEAR && bernstein(tau2) >= RHO_NEAR {
                // Both poles far: Gauss–Legendre on the kernel as it is.
                for l in 0..N {
                    let v = centre + half * r_ref.nodes[l];
                    let inv = (C64::new(v * v, 0.0) - c).inv();
                    let w = half * r_ref.weights[l];
                    k[l] = inv * (w * p.sigma);
                    if derivative {
                        dk[l] = inv * inv * w;
                    }
                }
            } else {
                // Distances of the poles ±r from the panel ends, in panel units: r − vb =
                // σ(ζ − tb)/(r + vb) (Re r ≥ 0, no cancellation), so that a pole next to an
                // end has its distance to full relative precision.
                let to_b = (zt - p.tb) * p.sigma / (r + p.vb);
                let to_a = if p.va > 0.0 {
                    (zt - p.ta) * p.sigma / (r + p.va)
                } else {
                    r
                };
                let ends1 = (-to_b / half, -to_a / half);
                let ends2 = ((r + p.vb) / half, (r + p.va) / half);
                let (a1, b1) = r_ref.pole_weights(tau1, ends1, derivative);
                let (a2, b2) = r_ref.pole_weights(tau2, ends2, derivative);
                let inv_r = r.inv();
                let single = inv_r * 0.5 * p.sigma;
                let cubic = inv_r * inv_r * inv_r * 0.25;
                let square = inv_r * inv_r * (0.25 / half);
                for l in 0..N {
                    k[l] = (a1[l] - a2[l]) * single;
                    if derivative {
                        dk[l] = (b1[l] + b2[l]) * square - (a1[l] - a2[l]) * cubic;
                    }
                }
            }
            let range = j * N..(j + 1) * N;
            for (d, values) in weighted.iter().enumerate() {
                let h = &values[range.clone()];
                f[d] += (0..N).map(|l| k[l] * h[l]).sum::<C64>();
                if derivative {
                    df[d] += (0..N).map(|l| dk[l] * h[l]).sum::<C64>();
                }
            }
        }
        let pi = std::f64::consts::PI;
        for d in 0..D {
            f[d] /= pi;
            df[d] /= pi * self.half_width;
        }
        (f, df)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> C64 {
        C64::new(re, im)
    }

    /// Measured (default panels) worst errors: F 7.0e−12 and z·F' 5.8e−12, both at a contact
    /// end at depth 1e−10 (the pole pair ±√(ζ − e) of the end panel is then 1e−5 apart and
    /// their difference loses `h/|r|` digits); 1e−13 from depth 1e−6 on. Tolerances: 3×.
    const TOL_F: f64 = 2e-11;
    const TOL_DF: f64 = 2e-11;

    /// `√(ζ − u)√(ζ − v)`: the branch analytic off [u, v] that behaves like ζ at infinity.
    fn root(zeta: C64, u: f64, v: f64) -> C64 {
        (zeta - u).sqrt() * (zeta - v).sqrt()
    }

    /// Targets from far away down to 1e−10 above the contact, inside, at and beyond the ends.
    fn targets() -> Vec<C64> {
        let mut out = Vec::new();
        for x in [-1.7, -1.0, -0.999, -0.6, 0.0, 0.31, 0.9999, 1.0, 1.2, 4.0] {
            for y in [1e-10, 1e-6, 1e-3, 0.05, 0.5, 3.0, 40.0] {
                out.push(c(x, y));
            }
        }
        out
    }

    /// Largest errors over the targets against closed forms, for a density of unit scale:
    /// of F relative to `max(|F|, 1)`, and of `Im ζ · F'` (the combination the isotropic
    /// kernel uses, `z F'`) relative to `max(|z F'|, 1)`; with the target where each occurs.
    fn worst(
        rule: &SurfaceRule,
        f: impl Fn(f64) -> f64,
        exact: impl Fn(C64) -> (C64, C64),
        scale: f64,
    ) -> ((f64, C64), (f64, C64)) {
        let values: Vec<f64> = rule.nodes().iter().map(|&x| f(x)).collect();
        let h = rule.weighted(&values);
        let zero = C64::new(0.0, 0.0);
        let (mut e0, mut e1) = ((0.0f64, zero), (0.0f64, zero));
        for t in targets() {
            let z = C64::new(rule.centre() + scale * t.re, scale * t.im);
            let ([got], [dgot]) = rule.cauchy([&h], z, true);
            let (want, dwant) = exact(z);
            let err0 = (got - want).norm() / want.norm().max(scale);
            let err1 = (dgot - dwant).norm() * z.im / (dwant.norm() * z.im).max(scale);
            if err0 > e0.0 {
                e0 = (err0, t);
            }
            if err1 > e1.0 {
                e1 = (err1, t);
            }
        }
        (e0, e1)
    }

    #[test]
    fn joukowski_transform_of_the_semi_ellipse_at_every_depth() {
        // (1/π)∫ √(1 − t²)/(t − ζ) dt = −(ζ − √(ζ²−1)); its ζ-derivative −(1 − ζ/√(ζ²−1)).
        let rule = SurfaceRule::new(0.0, 1.0, &[], DEFAULT_PANELS_PER_HALF).unwrap();
        let (e0, e1) = worst(
            &rule,
            |x| (1.0 - x * x).max(0.0).sqrt(),
            |z| {
                let s = root(z, -1.0, 1.0);
                (-(z - s), -(1.0 - z / s))
            },
            1.0,
        );
        println!("F {e0:?}, z F' {e1:?}");
        assert!(e0.0 < TOL_F && e1.0 < TOL_DF);
    }

    #[test]
    fn transform_of_the_inverse_square_root_density_at_every_depth() {
        // (1/π)∫ 1/(√(1 − t²)(t − ζ)) dt = −1/√(ζ²−1); derivative ζ/(ζ²−1)^{3/2}.
        let rule = SurfaceRule::new(0.0, 1.0, &[], DEFAULT_PANELS_PER_HALF).unwrap();
        let (e0, e1) = worst(
            &rule,
            |x| 1.0 / (1.0 - x * x).sqrt(),
            |z| {
                let s = root(z, -1.0, 1.0);
                (-s.inv(), z / (s * s * s))
            },
            1.0,
        );
        println!("F {e0:?}, z F' {e1:?}");
        assert!(e0.0 < TOL_F && e1.0 < TOL_DF);
    }

    #[test]
    fn half_ellipse_on_an_interior_piece_with_physical_units() {
        // A kink-type density √((t − u)(v − t)) on [u, v] inside the contact (fretsim's
        // stick-end kinks): (1/π)∫ … = −((ζ − m) − √(ζ − u)√(ζ − v)), m = (u + v)/2; on a
        // contact of centre 3e−5 m and half-width 4e−5 m, with u, v as breakpoints.
        let (centre, a) = (3e-5, 4e-5);
        let (u, v) = (centre - 0.35 * a, centre + 0.8 * a);
        let rule = SurfaceRule::new(centre, a, &[v, u, v], DEFAULT_PANELS_PER_HALF).unwrap();
        assert_eq!(rule.breakpoints(), &[u, v]);
        let m = 0.5 * (u + v);
        let (e0, e1) = worst(
            &rule,
            |x| ((x - u) * (v - x)).max(0.0).sqrt(),
            |z| {
                let s = root(z, u, v);
                (-((z - m) - s), -(1.0 - (z - m) / s))
            },
            a,
        );
        println!("F {e0:?}, z F' {e1:?}");
        assert!(e0.0 < TOL_F && e1.0 < TOL_DF);
    }

    #[test]
    fn error_falls_with_panels_for_a_density_singular_near_the_contact() {
        // f = 1/(1.05 − t) on the contact (a pole 0.05 a beyond the end): smooth, but not on
        // the panels' scale; (1/π)∫ f/(t − ζ) dt in closed form by partial fractions. The
        // error must fall geometrically as the panels are refined.
        let b = 1.05;
        let exact = |z: C64| {
            let one = C64::new(1.0, 0.0);
            // 1/((b − t)(t − ζ)) = (1/(b − ζ)) [1/(t − ζ) − 1/(t − b)]
            let l = |w: C64| ((one - w) / (-one - w)).ln();
            let lb = ((b - 1.0_f64) / (b + 1.0)).ln();
            ((l(z) - lb) / (C64::new(b, 0.0) - z)) / std::f64::consts::PI
        };
        let mut errors = Vec::new();
        for k in [1, 2, 4, 8] {
            let rule = SurfaceRule::new(0.0, 1.0, &[], k).unwrap();
            let (e0, _) = worst(
                &rule,
                |x| 1.0 / (b - x),
                |z| (exact(z), C64::new(0.0, 0.0)),
                1.0,
            );
            errors.push(e0.0);
        }
        println!("{errors:?}");
        for pair in errors.windows(2) {
            assert!(pair[1] < pair[0] / 4.0 || pair[1] < 1e-13, "{errors:?}");
        }
    }
}
