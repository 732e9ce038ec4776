//! Contact of a rigid cylindrical punch with the half-plane: the model, the state at one
//! instant, field evaluation, and the surface fields of seed eqs. (64)–(65).
//!
//! # Conventions (fretsim's, physical)
//! - x along the surface in the *material* frame; the punch axis is at x = 0 (its tangential
//!   rigid displacement is of the order of the elastic displacements and is neglected in the
//!   geometry, as in all small-strain contact theory). The contact is `[c − a, c + a]`; the
//!   seed paper's eccentricity (punch axis relative to the contact centre) is `e = −c`.
//! - `p` compressive positive; `q` the shear traction the punch exerts *on the half-plane*
//!   (+x positive), so `∫q = Q` is the tangential force applied to the punch; `g = −Dz(x,0⁺)`
//!   as in the seed paper; `uz` positive into the solid, so the rigid cylinder imposes
//!   `∂uz/∂x = −x/R` on the contact.
//! - The seed paper's `q` is the traction on the punch (`q_paper = −q`): its solution for a given
//!   Q is the mirror image x → −x of ours (see [`crate::halfplane`] for the coefficient map).
//!
//! # Equations on the contact (from (A)–(C) of [`crate::halfplane`])
//! Write the charge as `g = χ p + w`:
//! - conducting punch (φ constant on the contact): `χ = k = −y23/y33` and, from (C),
//!   `y33 H'w = −w13 q`, `∫w = Γ − kP` (seed eqs. 23, 26–29: `g1 = k p` is the part carried by
//!   the pressure, `w = g2` the part held by the constant potential);
//! - insulating punch: `g ≡ 0` (`χ = 0`, `w = 0`). The seed paper says the conducting punch,
//!   unlike the insulating one, puts charge on the contact surface, and its trends confirm this
//!   reading: with `g ≡ 0` we get the smaller stick zone and the larger |C| it reports for the
//!   insulating punch at every η, while the alternative `g = (Γ/P) p` gives the opposite order
//!   (PZT-4, R = 60 mm, P = 2000 N/m, η = 0.3: b/a = 0.954 conducting, 0.343 for `g ≡ 0`,
//!   0.991 for `g = (Γ/P)p`). Γ therefore has no effect under an insulating punch;
//! - elastic half-plane: `χ = 0`, `w = 0`.
//!
//! Eliminating g from (B) gives the pressure equation (seed eqs. 21/46):
//!
//! ```text
//! Y* H'p(x) = −x/R − κ q(x),   Y* = y22 + χ y23,   κ = w12 − y23 w13/y33 (conducting) or w12
//! ```
//!
//! and, from (A), the tangential equation `y11 H'q = ∂ux/∂x + (w12 + χ w13) p + w13 w`.
//! For the frictionless elastic case `Y* = 2/E*` and `p = p0 √(1 − x²/a²)`,
//! `a² = 2PRY*/π` (Hertz). `κ/Y*` is Dundurs' β for an elastic solid.
//!
//! # Zhou & Lee's frictionless conducting solution (derived from seed eqs. 24–29 with q = 0)
//! With q = 0 the pressure equation is Hertz's with compliance `Y*`: `c = 0`,
//! `a² = 2PRY*/π`, `p = (2P/(πa²))√(a² − x²)`. The charge equation `y33 H'w = 0` with
//! `∫w = Γ − kP` has the bounded-at-neither-end solution `w = (Γ − kP)/(π√(a² − x²))`, so
//! `g(x) = k p(x) + (Γ − kP)/(π√(a² − x²))`. With the regularised kernel
//! `∫₀^∞ cos(sr)/s ds → −ln(|r|/d)` (datum distance d) the contact potential is
//! `φ0 = (ln(2d/a)/π)(y23 P + y33 Γ) − (w13/π) ∫ q(s) arcsin((s − c)/a) ds`: the weighted mean of
//! φ over the contact with weight `1/√(a² − x²)`, exact because φ is constant there and
//! `(1/π)∫ ln|x − s| dx/√(a² − x²) = ln(a/2)` for every s in the contact.
//! Under potential control (φ0 given) this relation gives Γ.
//!
//! # Surface in-plane fields (seed eqs. 64–65, re-derived)
//! ```text
//! σxx0 = −Δ1 p − Δ2 g + Δ3 ∂ux/∂x,      ∂ux/∂x = −w12 p − w13 g + y11 H'q
//! Dx0  = −(e15/c44) q − Δ4 ∂φ/∂x,        ∂φ/∂x  =  w13 q + y23 H'p + y33 H'g
//! ```
//! valid on and off the contact (off it p = q = g = 0 and only the Cauchy terms remain).

pub mod frictionless;
pub mod general;
pub mod memory;
pub mod normal;
pub mod pressure;
pub mod profile;
pub mod roots;
pub mod tangential;

use serde::Serialize;

use crate::error::MaterialFailure;
use crate::halfplane::{SurfaceCompliance, SurfaceFieldCoefficients};
use crate::material::Material;
use crate::quadrature::{BoundedSeries, UnboundedSeries};
pub use profile::Profile;

/// How the punch is connected electrically (piezoelectric half-plane only).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Electrode {
    /// Elastic half-plane: no electric field.
    None,
    /// Perfectly conducting punch carrying the resultant charge Γ (C/m); φ0 is computed.
    ConductingCharge {
        /// Γ (C/m).
        charge: f64,
    },
    /// Perfectly conducting punch held at potential φ0 (V) relative to the datum; Γ is computed.
    ConductingPotential {
        /// φ0 (V).
        potential: f64,
    },
    /// Insulating punch: no charge on the contact surface, `g ≡ 0` (module docs).
    Insulating,
}

/// Whether the shear traction is fed back into the pressure equation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Coupling {
    /// Full coupling (κ as derived).
    #[default]
    Full,
    /// Goodman's approximation: κ = 0 in the pressure equation (q does not change p).
    Goodman,
}

/// Everything that defines the contact except the loads and the history.
#[derive(Debug, Clone, Serialize)]
pub struct ContactModel {
    /// The half-plane.
    pub material: Material,
    /// Surface compliance coefficients derived from the material.
    pub compliance: SurfaceCompliance,
    /// Δ1…Δ4 for the surface fields.
    pub field_coefficients: SurfaceFieldCoefficients,
    /// The punch's profile.
    pub profile: Profile,
    /// Coulomb friction coefficient η (–).
    pub friction: f64,
    /// Electric boundary condition of the punch.
    pub electrode: Electrode,
    /// Datum distance d of the regularised log kernel (m), for φ0 and the displacement δ.
    pub reference_distance: f64,
    /// Shear–pressure coupling.
    pub coupling: Coupling,
    /// Whether p and w carry their square-root kinks at the stick ends in closed form
    /// ([`Kinks`]; default on). Off gives the plain series of the seed paper: slower
    /// convergence in M, but it completes two histories that the kinks stop (README).
    pub stick_end_kinks: bool,
}

/// How the charge is split, `g = χ p + w`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ChargeSplit {
    /// χ (C/N).
    pub ratio: f64,
    /// Whether the constant-potential part `w` is present (conducting punch).
    pub conducting: bool,
}

impl ContactModel {
    /// A model with the coefficients derived from `material`, or why the constants give no
    /// surface response ([`SurfaceCompliance::try_of`]).
    pub fn try_new(
        material: Material,
        profile: Profile,
        friction: f64,
        electrode: Electrode,
    ) -> Result<Self, MaterialFailure> {
        Ok(Self {
            compliance: SurfaceCompliance::try_of(&material)?,
            field_coefficients: SurfaceFieldCoefficients::of(&material),
            material,
            profile,
            friction,
            electrode,
            reference_distance: 1e-2,
            coupling: Coupling::Full,
            stick_end_kinks: true,
        })
    }

    /// A model with the coefficients derived from a material known to be sound (the presets,
    /// tests).
    ///
    /// # Panics
    /// If [`Self::try_new`] fails; use that on constants from the user.
    pub fn new(material: Material, profile: Profile, friction: f64, electrode: Electrode) -> Self {
        Self::try_new(material, profile, friction, electrode)
            .unwrap_or_else(|e| panic!("contact model: {e}"))
    }

    /// With the kinks at the stick ends on or off.
    pub fn with_stick_end_kinks(mut self, on: bool) -> Self {
        self.stick_end_kinks = on;
        self
    }

    /// With a datum distance d (m).
    pub fn with_reference_distance(mut self, d: f64) -> Self {
        self.reference_distance = d;
        self
    }

    /// With the given shear–pressure coupling.
    pub fn with_coupling(mut self, coupling: Coupling) -> Self {
        self.coupling = coupling;
        self
    }

    /// χ and the conducting flag at normal load P.
    pub fn charge_split(&self, _normal_load: f64) -> ChargeSplit {
        match self.electrode {
            Electrode::None => ChargeSplit {
                ratio: 0.0,
                conducting: false,
            },
            Electrode::ConductingCharge { .. } | Electrode::ConductingPotential { .. } => {
                ChargeSplit {
                    ratio: self.compliance.charge_per_force(),
                    conducting: true,
                }
            }
            Electrode::Insulating => ChargeSplit {
                ratio: 0.0,
                conducting: false,
            },
        }
    }

    /// `Y* = y22 + χ y23` (1/Pa).
    pub fn pressure_compliance(&self, split: ChargeSplit) -> f64 {
        let y23 = self.compliance.electric.map_or(0.0, |e| e.y23);
        self.compliance.y22 + split.ratio * y23
    }

    /// The pressure per unit of the collocation grid's unit response, `h''/Y*` (1/Pa·m): the
    /// pressure equation's right-hand side for a profile of constant curvature.
    pub fn pressure_scale(&self, split: ChargeSplit) -> f64 {
        self.profile.pressure_scale(self.pressure_compliance(split))
    }

    /// κ of the pressure equation (zero under Goodman's approximation).
    pub fn pressure_shear_coupling(&self, split: ChargeSplit) -> f64 {
        match self.coupling {
            Coupling::Goodman => 0.0,
            Coupling::Full if split.conducting => self.compliance.pressure_shear_coupling(),
            Coupling::Full => self.compliance.w12,
        }
    }

    /// Local coefficient of p in `−∂ux/∂x`: `w12 + χ w13`.
    pub fn local_pressure_strain(&self, split: ChargeSplit) -> f64 {
        self.compliance.w12 + split.ratio * self.compliance.electric.map_or(0.0, |e| e.w13)
    }

    /// Charge Γ1 = kP carried by the pressure under a conducting punch (C/m).
    pub fn pressure_charge(&self, normal_load: f64) -> f64 {
        self.compliance.charge_per_force() * normal_load
    }
}

/// The shear traction on the contact: `q = η p S(x) + q̃(x)` (see module docs of the solvers).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Traction {
    /// Friction coefficient η used in the slip zones.
    pub friction: f64,
    /// Sign of `q/(ηp)` in the left slip zone `[c − a, lo)`.
    pub left_sign: f64,
    /// Sign of `q/(ηp)` in the right slip zone `(hi, c + a]`.
    pub right_sign: f64,
    /// Stick zone and its correction, `None` when the contact is frictionless.
    pub stick: Option<StickZone>,
}

/// The stick zone `[lo, hi]` and the bounded correction `q̃` on it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StickZone {
    /// Left end (m).
    pub lo: f64,
    /// Right end (m).
    pub hi: f64,
    /// Smooth part of `q̃((x − mid)/half)` (Pa).
    pub correction: BoundedSeries,
    /// Amplitude A of the kink part `A·k(u)` of q̃ (Pa), see [`kink_density`]; non-zero only
    /// for the normal-loading state, whose memory `C|x|` has a kink at the centre.
    pub kink: f64,
    /// Correction inherited from the state that began the phase; it carries the exact
    /// square-root structure of the memory at old stick ends (see [`Inherited`]).
    #[serde(skip)]
    pub inherited: Option<std::sync::Arc<Inherited>>,
    /// The square-root coefficients `[k_lo, k_hi]` of the whole q̃ at the ends,
    /// `q̃ ≈ k_lo √(x − lo)` and `q̃ ≈ k_hi √(hi − x)` (Pa/√m): they fix the kinks of p and w
    /// here and, once the zone is remembered, at its ends inside later stick zones. Zero for a
    /// zone solved without kinks (normal loading, uncoupled contacts).
    pub end_roots: [f64; 2],
    /// The slip signs beside the ends when the zone was solved (left, right).
    pub end_signs: [f64; 2],
    /// Closed-form parts of q̃ that carry the kinks of remembered stick ends inside the zone:
    /// `amplitude · √((x − u)(v − x))` on `[u, v]`, as `(u, v, amplitude)` (tangential module
    /// docs, "Kinks at the stick ends").
    pub extras: Vec<(f64, f64, f64)>,
    /// `H'q̃` tabulated once the zone begins a phase ([`StickZone::tabulate`]).
    #[serde(skip)]
    cauchy_table: TableCache,
    /// q̃ tabulated with it.
    #[serde(skip)]
    value_table: TableCache,
    /// `H'q̃` on the two outer pieces alone, `[lo − w, lo]` and `[hi, hi + w]` (w the zone's
    /// width), for a zone without [`Self::tabulate`]'s table whose transform is wanted at many
    /// points of the slip zones (`EXTERIOR_TABLE_POINTS`; the checks and increments of the
    /// steps it ends and begins).
    #[serde(skip)]
    exterior_table: TableCache<[ChainTable; 2]>,
}

/// `H'q̃` of a zone with its whole chain, interpolated piecewise: on each piece between the
/// points where q̃ is not smooth (the zone's ends, its chain's zone ends and ramp points, a
/// centre kink), and on two outer pieces of the zone's width on either side, by a Chebyshev
/// series in the graded variable v (`x = mid + half sin(πv/2)`, which absorbs the square
/// roots at the piece ends). Outside the outer pieces the transform is evaluated directly.
/// The same form holds q̃ itself on the zone's pieces, less its centre kinks
/// (`StickZone::chain_kinks`), for a zone with a chain: one sum of `M + 32` terms instead of
/// one of M terms for every zone of the chain (in a steady cycle, four).
#[derive(Debug, Clone, Default)]
struct ChainTable {
    /// Piece ends, increasing.
    ends: Vec<f64>,
    /// Chebyshev coefficients in v, one series per piece.
    coefficients: Vec<Vec<f64>>,
}

impl ChainTable {
    /// The table of f on the pieces between `ends`, `nodes` Chebyshev points per piece in the
    /// graded variable.
    fn interpolating(ends: Vec<f64>, nodes: usize, f: impl Fn(f64) -> f64) -> Self {
        Self::interpolating_batch(ends, nodes, |xs, out| out.extend(xs.iter().map(|&x| f(x))))
    }

    /// [`Self::interpolating`] with f evaluated at all the pieces' points in one call
    /// (`f(xs, out)` pushes the values onto `out`, passed empty).
    fn interpolating_batch(
        ends: Vec<f64>,
        nodes: usize,
        f: impl FnOnce(&[f64], &mut Vec<f64>),
    ) -> Self {
        let ChebyshevPoints { v, transforms } = ChebyshevPoints::of(nodes);
        let points: Vec<f64> = ends
            .windows(2)
            .flat_map(|w| {
                let (mid, half) = (0.5 * (w[0] + w[1]), 0.5 * (w[1] - w[0]));
                v.iter()
                    .map(move |v| mid + half * (std::f64::consts::FRAC_PI_2 * v).sin())
            })
            .collect();
        let mut all = Vec::with_capacity(points.len());
        f(&points, &mut all);
        // The coefficients `c_j = (2 − δ_j0)/N Σ_k f_k cos(j θ_k)`: a discrete cosine transform.
        let coefficients = all
            .chunks_exact(nodes)
            .map(|values| {
                let mut c = vec![0.0; nodes];
                c[0] = transforms.cosines(values, &mut c[1..]) / nodes as f64;
                for cj in &mut c[1..] {
                    *cj *= 2.0 / nodes as f64;
                }
                c
            })
            .collect();
        Self { ends, coefficients }
    }

    /// The interpolated value at x, `None` outside the tabulated range.
    fn at(&self, x: f64) -> Option<f64> {
        let k = self.piece(x)?;
        Some(crate::quadrature::chebyshev_t_sum(
            &self.coefficients[k],
            self.graded(k, x),
        ))
    }

    /// The piece that holds x, `None` outside the tabulated range.
    fn piece(&self, x: f64) -> Option<usize> {
        let (first, last) = (*self.ends.first()?, *self.ends.last()?);
        if !(x >= first && x <= last) {
            return None;
        }
        Some(
            self.ends
                .partition_point(|e| *e <= x)
                .clamp(1, self.ends.len() - 1)
                - 1,
        )
    }

    /// The graded variable v of x on piece k.
    fn graded(&self, k: usize, x: f64) -> f64 {
        let (mid, half) = (
            0.5 * (self.ends[k] + self.ends[k + 1]),
            0.5 * (self.ends[k + 1] - self.ends[k]),
        );
        ((x - mid) / half).clamp(-1.0, 1.0).asin() / std::f64::consts::FRAC_PI_2
    }

    /// [`Self::at`] at each of `xs` into `out`, `fallback(x)` outside the table (bit-identical;
    /// eight, else four, consecutive points on one piece share one sum, their recurrences
    /// interleaved, because the recurrences are latency-bound; each point's piece is found
    /// once).
    fn values_into(&self, xs: &[f64], fallback: impl Fn(f64) -> f64, out: &mut Vec<f64>) {
        let pieces: Vec<Option<usize>> = xs.iter().map(|&x| self.piece(x)).collect();
        let run = |k: usize, len: usize| {
            pieces[k].is_some()
                && k + len <= xs.len()
                && pieces[k + 1..k + len].iter().all(|p| *p == pieces[k])
        };
        let mut k = 0;
        while k < xs.len() {
            match pieces[k] {
                Some(p) if run(k, 8) => {
                    let v: [f64; 8] = std::array::from_fn(|l| self.graded(p, xs[k + l]));
                    out.extend(crate::quadrature::chebyshev_t_sums(
                        &self.coefficients[p],
                        v,
                    ));
                    k += 8;
                }
                Some(p) if run(k, 4) => {
                    let v: [f64; 4] = std::array::from_fn(|l| self.graded(p, xs[k + l]));
                    out.extend(crate::quadrature::chebyshev_t_sums(
                        &self.coefficients[p],
                        v,
                    ));
                    k += 4;
                }
                _ => {
                    out.push(self.at(xs[k]).unwrap_or_else(|| fallback(xs[k])));
                    k += 1;
                }
            }
        }
    }
}

/// The Chebyshev points `v_k = cos θ_k`, `θ_k = (2k+1)π/(2N)`, of a [`ChainTable`]'s pieces
/// and the fast transform of its cosine sums, built once per N: computing the N² cosines for
/// every table would cost far more than the transform that uses them.
struct ChebyshevPoints {
    v: Vec<f64>,
    transforms: crate::transforms::HalfAngleTransforms,
}

impl ChebyshevPoints {
    fn of(nodes: usize) -> &'static Self {
        static POINTS: SizeTables<ChebyshevPoints> = std::sync::Mutex::new(Vec::new());
        thread_local! {
            static KNOWN: KnownSizes<ChebyshevPoints> =
                const { std::cell::RefCell::new(Vec::new()) };
        }
        built_once(&POINTS, &KNOWN, nodes, |n| {
            let theta = |k: usize| (2 * k + 1) as f64 * std::f64::consts::PI / (2 * n) as f64;
            Self {
                v: (0..n).map(|k| theta(k).cos()).collect(),
                transforms: crate::transforms::HalfAngleTransforms::new(n),
            }
        })
    }
}

/// A cache filled at most once that takes no part in comparisons.
#[derive(Debug, Clone)]
struct TableCache<T = ChainTable>(std::sync::OnceLock<T>);

impl<T> Default for TableCache<T> {
    fn default() -> Self {
        Self(std::sync::OnceLock::new())
    }
}

impl<T> PartialEq for TableCache<T> {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// An earlier stick zone's correction carried into a new zone, faded out smoothly where the
/// new zone ends inside it: `χ(x) q̃_E(x)` with `χ` rising from 0 at `ramp_lo.0` to 1 at
/// `ramp_lo.1` and falling from 1 at `ramp_hi.0` to 0 at `ramp_hi.1` (C² quintic ramps).
/// The memory inside the new zone has square-root kinks at the old zone's ends, which the old
/// correction reproduces exactly; the fade only matters near the new ends, where q̃ must vanish.
#[derive(Debug, Clone)]
pub struct Inherited {
    /// The earlier zone (with its own chain).
    pub zone: std::sync::Arc<StickZone>,
    /// Left ramp `(start, end)`, or `None` when the earlier zone lies inside on that side.
    pub ramp_lo: Option<(f64, f64)>,
    /// Right ramp `(start, end)`.
    pub ramp_hi: Option<(f64, f64)>,
    /// Quadrature table of the fade integral, built on first use.
    table: std::sync::OnceLock<FadeTable>,
}

/// Quadrature nodes `(t, w q̃_E(t), χ(t))` of the fade integral of an [`Inherited`], all of
/// them and, in the same order, those with χ ≠ 1 and those with χ ≠ 0: at a point x where
/// χ(x) is 1 (or 0) the nodes with the same χ contribute exactly zero to the sum of
/// [`Inherited::cauchy`] and are skipped.
#[derive(Debug, Clone, Default)]
struct FadeTable {
    all: Vec<(f64, f64, f64)>,
    not_one: Vec<(f64, f64, f64)>,
    not_zero: Vec<(f64, f64, f64)>,
    /// The ramps `(ramp_lo, ramp_hi)` whose points end the pieces of the nodes.
    ramps: [Option<(f64, f64)>; 2],
}

impl FadeTable {
    /// The table of the nodes `(t, w q̃_E(t), χ(t))` in increasing t, on pieces ended by
    /// `ramps`' points.
    fn new(all: Vec<(f64, f64, f64)>, ramps: [Option<(f64, f64)>; 2]) -> Self {
        // `FadeSums` finds the nodes near a point by bisection.
        debug_assert!(all.is_sorted_by(|a, b| a.0 <= b.0), "nodes in increasing t");
        let except = |v: f64| {
            all.iter()
                .copied()
                .filter(|e| (e.2 - v).abs() > 0.0)
                .collect()
        };
        Self {
            not_one: except(1.0),
            not_zero: except(0.0),
            all,
            ramps,
        }
    }

    /// The nodes whose terms can be non-zero at a point where χ is `cx`.
    fn nodes_for(&self, cx: f64) -> &[(f64, f64, f64)] {
        // χ is exactly 1 (or 0) away from the ramps; only exact zeros are skipped.
        if (cx - 1.0).abs() <= 0.0 {
            &self.not_one
        } else if cx.abs() <= 0.0 {
            &self.not_zero
        } else {
            &self.all
        }
    }
}

/// [`fade_sum`] at each point `x` (with χ there `cx`) into `sums` (which start at −0), the
/// points in SIMD lanes chosen at run time by `pulp` (four-wide AVX2 where the processor has
/// it, else two-wide SSE2: the 256-bit divisions that bound these sums halve their time;
/// points left over from the lanes by [`fade_sum`] itself). Each lane adds the same terms in
/// the same order as [`fade_sum`], with the same operations, so the sums are its own to the
/// bit on every processor: a group of nodes none of which lies within twice `tiny` of a
/// lane's point (the nodes increase, so the others are found by bisection; a point rarely has
/// any) skips nothing, and its terms are summed without the masks of the skipped nodes, which
/// give the same bits where nothing is skipped.
struct FadeSums<'a> {
    nodes: &'a [(f64, f64, f64)],
    x: &'a [f64],
    cx: &'a [f64],
    tiny: f64,
    sums: &'a mut [f64],
}

impl pulp::WithSimd for FadeSums<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> Self::Output {
        let (x_lanes, x_tail) = S::as_simd_f64s(self.x);
        let (cx_lanes, cx_tail) = S::as_simd_f64s(self.cx);
        let (sum_lanes, sum_tail) = S::as_mut_simd_f64s(self.sums);
        let tiny = simd.splat_f64s(self.tiny);
        let (zero, one) = (simd.splat_f64s(0.0), simd.splat_f64s(1.0));
        let groups = self.nodes.chunks_exact(FADE_GROUP);
        let (count, single) = (groups.len(), groups.remainder());
        let mul = |a, b| simd.mul_f64s(a, b);
        let add = |a, b| simd.add_f64s(a, b);
        // The (vector, group) pairs with a node within twice `tiny` of one of the vector's
        // points, increasing (a point rarely has any). The nodes increase; for points in
        // order (the stick points, the rules' nodes) one walk along both finds each point's
        // first node at or beyond `x − 2 tiny`, otherwise a bisection per point does (the
        // bisections took 1.8 % of the bench's forward step at M = 128).
        let lanes = S::F64_LANES;
        let reach = 2.0 * self.tiny;
        let points = &self.x[..x_lanes.len() * lanes];
        let mut near_all: Vec<(usize, usize)> = Vec::new();
        let mut mark_from = |i: usize, from: usize| {
            for (k, node) in self.nodes.iter().enumerate().skip(from) {
                if node.0 > points[i] + reach {
                    break;
                }
                if k / FADE_GROUP < count {
                    near_all.push((i / lanes, k / FADE_GROUP));
                }
            }
        };
        let increasing = points.is_sorted();
        if increasing || points.iter().rev().is_sorted() {
            let mut from = 0;
            for j in 0..points.len() {
                let i = if increasing { j } else { points.len() - 1 - j };
                while from < self.nodes.len() && self.nodes[from].0 < points[i] - reach {
                    from += 1;
                }
                mark_from(i, from);
            }
        } else {
            for (i, &xi) in points.iter().enumerate() {
                mark_from(i, self.nodes.partition_point(|n| n.0 < xi - reach));
            }
        }
        near_all.sort_unstable();
        near_all.dedup();
        let mut near_rest = near_all.as_slice();
        for (v, ((x, cx), sum)) in x_lanes.iter().zip(cx_lanes).zip(sum_lanes).enumerate() {
            let here = near_rest.iter().take_while(|n| n.0 == v).count();
            let (near, rest) = near_rest.split_at(here);
            near_rest = rest;
            // A node's numerator and distance; masked, a skipped node's as 0 and 1. (Macros,
            // not closures: a closure that is not inlined is compiled without the lanes'
            // instruction set, and each SIMD operation becomes a call.)
            macro_rules! term {
                ($node:expr) => {{
                    let (t, wq, chi) = $node;
                    let d = simd.sub_f64s(simd.splat_f64s(t), *x);
                    let weight = simd.sub_f64s(simd.splat_f64s(chi), *cx);
                    (simd.mul_f64s(simd.splat_f64s(wq), weight), d)
                }};
                ($node:expr, masked) => {{
                    let (n, d) = term!($node);
                    let keep = simd.greater_than_f64s(simd.abs_f64s(d), tiny);
                    (
                        simd.select_f64s(keep, n, zero),
                        simd.select_f64s(keep, d, one),
                    )
                }};
            }
            let mut acc = *sum;
            // The groups up to the next near one without masks, that one with them (two loops:
            // one with a branch between the two forms is compiled with the masks in both).
            let (mut first, mut near) = (0, near.iter());
            loop {
                let stop = near.next().map_or(count, |&(_, g)| g);
                for group in
                    self.nodes[first * FADE_GROUP..stop * FADE_GROUP].chunks_exact(FADE_GROUP)
                {
                    let (num, den) = group_quotient!([term!(group[0]), term!(group[1])], mul, add);
                    acc = simd.add_f64s(acc, simd.div_f64s(num, den));
                }
                if stop == count {
                    break;
                }
                let group = &self.nodes[stop * FADE_GROUP..(stop + 1) * FADE_GROUP];
                let terms = [term!(group[0], masked), term!(group[1], masked)];
                let (num, den) = group_quotient!(terms, mul, add);
                acc = simd.add_f64s(acc, simd.div_f64s(num, den));
                first = stop + 1;
            }
            for &node in single {
                let (n, d) = term!(node, masked);
                acc = simd.add_f64s(acc, simd.div_f64s(n, d));
            }
            *sum = acc;
        }
        for ((&x, &cx), sum) in x_tail.iter().zip(cx_tail).zip(sum_tail) {
            *sum = fade_sum(self.nodes, x, cx, self.tiny);
        }
    }
}

/// Nodes over one denominator in the fade sums ([`fade_sum`]).
const FADE_GROUP: usize = 2;

/// `n₁/d₁ + n₂/d₂` of two terms `[(n_k, d_k)]` as one numerator and denominator,
/// `(n₁d₂ + n₂d₁, d₁d₂)`, in a fixed order of multiplications and additions (`mul`, `add`),
/// written out where it is used (the one-point and the SIMD sums of [`fade_sum`]).
macro_rules! group_quotient {
    ($terms:expr, $mul:expr, $add:expr) => {{
        let [(n1, d1), (n2, d2)] = $terms;
        ($add($mul(n1, d2), $mul(n2, d1)), $mul(d1, d2))
    }};
}
use group_quotient;

/// `Σ w q̃_E(t) (χ(t) − χ(x))/(t − x)` over `nodes`, skipping a node within `tiny` of x.
///
/// The divisions bound these sums, so the nodes are taken in pairs over a common
/// denominator (`group_quotient`; a skipped node as `n = 0, d = 1`): one division for two
/// terms, with a rounding error of the same order as the two quotients' (the distances are at
/// least `tiny`, so their products stay far above f64's smallest normal number). Where no
/// node is near, the SIMD sums (`FadeSums`) run without the skipped nodes' masks. Pairs are
/// the sweet spot: groups of four over one denominator save no further time.
#[inline(always)]
fn fade_sum(nodes: &[(f64, f64, f64)], x: f64, cx: f64, tiny: f64) -> f64 {
    let term = |&(t, wq, chi): &(f64, f64, f64)| {
        let d = t - x;
        if d.abs() > tiny {
            (wq * (chi - cx), d)
        } else {
            (0.0, 1.0)
        }
    };
    let groups = nodes.chunks_exact(FADE_GROUP);
    let single = groups.remainder();
    let mut acc = -0.0;
    for group in groups {
        let terms: [_; FADE_GROUP] = std::array::from_fn(|k| term(&group[k]));
        let (num, den) = group_quotient!(terms, |a: f64, b| a * b, |a: f64, b| a + b);
        acc += num / den;
    }
    for node in single {
        let (n, d) = term(node);
        acc += n / d;
    }
    acc
}

impl PartialEq for Inherited {
    fn eq(&self, other: &Self) -> bool {
        self.zone == other.zone && self.ramp_lo == other.ramp_lo && self.ramp_hi == other.ramp_hi
    }
}

/// The slip shape between the signs `[left, right]` beside a stick zone `[lo, hi]`:
/// `s_L + (s_R − s_L)(3v² − 2v³)`, `v = (x − lo)/(hi − lo)` clamped to [0, 1].
fn sign_blend([left, right]: [f64; 2], lo: f64, hi: f64, x: f64) -> f64 {
    let v = ((x - lo) / (hi - lo)).clamp(0.0, 1.0);
    left + (right - left) * v * v * (3.0 - 2.0 * v)
}

pub(crate) fn smootherstep(v: f64) -> f64 {
    let v = v.clamp(0.0, 1.0);
    v * v * v * (v * (6.0 * v - 15.0) + 10.0)
}

impl Inherited {
    /// The earlier zone carried whole or faded by the given ramps.
    pub fn new(
        zone: std::sync::Arc<StickZone>,
        ramp_lo: Option<(f64, f64)>,
        ramp_hi: Option<(f64, f64)>,
    ) -> Self {
        Self {
            zone,
            ramp_lo,
            ramp_hi,
            table: std::sync::OnceLock::new(),
        }
    }

    fn table(&self) -> &FadeTable {
        self.table.get_or_init(|| {
            let rule = graded_rule_with(FADE_RULE_NODES);
            let (nodes, weights) = (&rule.nodes, &rule.weights);
            let mut points = Vec::new();
            let mut scaled_weights = Vec::new();
            // In increasing t: the pieces increase, the rule's nodes decrease.
            for w in self.pieces().windows(2) {
                let (mid, half) = (0.5 * (w[0] + w[1]), 0.5 * (w[1] - w[0]));
                for (u, wt) in nodes.iter().zip(weights).rev() {
                    points.push(mid + half * u);
                    scaled_weights.push(wt * half);
                }
            }
            let mut values = Vec::with_capacity(points.len());
            self.zone.corrections_into(&points, &mut values);
            let all: Vec<(f64, f64, f64)> = points
                .iter()
                .zip(&scaled_weights)
                .zip(&values)
                .map(|((&t, &w), &q)| (t, w * q, self.chi(t)))
                .collect();
            FadeTable::new(all, [self.ramp_lo, self.ramp_hi])
        })
    }

    /// This link with the nodes and `w q̃_E` of `built`'s fade table (χ at the nodes its own),
    /// when `built` fades the same zone on the same sides by ramps whose points lie within
    /// `FADE_TABLE_REUSE` of a ramp's length of this link's, and has its table. A step's
    /// evaluations near convergence move the ramps by far less (and the coarse grid's first
    /// evaluation, at the fine grid's first iterate, not at all), while the table's values,
    /// sums of `M` terms at a few hundred points, are a noticeable part of an evaluation.
    /// The pieces then end up to that distance from the ramps' ends, where χ has a jump in its
    /// third derivative; the transform changes by about `2.4e−6 (δ/r)²` of its largest value
    /// (δ the distance, r the ramp's length; measured from δ/r = 9e−5 to 1e−3, test
    /// `a_fade_table_is_reused_for_ramps_that_hardly_moved`), round-off at the largest reuse.
    pub fn reusing_table_of(self, built: &Inherited) -> Self {
        let near = |a: Option<(f64, f64)>, b: Option<(f64, f64)>| match (a, b) {
            (None, None) => true,
            (Some(a), Some(b)) => {
                let slack = FADE_TABLE_REUSE * (a.1 - a.0);
                (a.0 - b.0).abs() <= slack && (a.1 - b.1).abs() <= slack
            }
            _ => false,
        };
        let Some(table) = built.table.get() else {
            return self;
        };
        let [lo, hi] = table.ramps;
        if !std::sync::Arc::ptr_eq(&self.zone, &built.zone)
            || !self.faded()
            || !near(self.ramp_lo, lo)
            || !near(self.ramp_hi, hi)
        {
            return self;
        }
        let all = table
            .all
            .iter()
            .map(|&(t, wq, _)| (t, wq, self.chi(t)))
            .collect();
        // A fresh link's table is empty, so the set cannot fail.
        let _ = self.table.set(FadeTable::new(all, table.ramps));
        self
    }

    /// The fade factor χ(x).
    pub fn chi(&self, x: f64) -> f64 {
        let up = self
            .ramp_lo
            .map_or(1.0, |(a, b)| smootherstep((x - a) / (b - a)));
        let down = self
            .ramp_hi
            .map_or(1.0, |(a, b)| 1.0 - smootherstep((x - a) / (b - a)));
        up * down
    }

    /// The start and end points of the fade ramps.
    fn ramp_points(&self) -> impl Iterator<Item = f64> + use<> {
        [self.ramp_lo, self.ramp_hi]
            .into_iter()
            .flatten()
            .flat_map(|r| [r.0, r.1])
    }

    fn faded(&self) -> bool {
        self.ramp_lo.is_some() || self.ramp_hi.is_some()
    }

    /// `χ q̃_E` at x.
    pub fn value(&self, x: f64) -> f64 {
        if self.faded() {
            let chi = self.chi(x);
            if chi.abs() > 0.0 {
                chi * self.zone.correction_at(x)
            } else {
                0.0
            }
        } else {
            self.zone.correction_at(x)
        }
    }

    /// [`Self::value`] at each of `xs` into `out` (bit-identical, the zone's values in a batch,
    /// [`StickZone::corrections_into`], at the points where χ ≠ 0 only).
    pub fn values_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        if !self.faded() {
            self.zone.corrections_into(xs, out);
            return;
        }
        let chis: Vec<f64> = xs.iter().map(|&x| self.chi(x)).collect();
        *out = faded(xs, &chis, |points, values| {
            self.zone.corrections_into(points, values)
        });
    }

    /// The remembered stick ends strictly inside `(lo, hi)` where this link's q̃ (with its
    /// chain) starts like a square root ([`RememberedRoot`]). A point already listed by an
    /// outer zone (a return to a remembered end) is not repeated.
    pub fn interior_roots(&self, lo: f64, hi: f64) -> Vec<RememberedRoot> {
        let mut out: Vec<RememberedRoot> = Vec::new();
        let slack = 1e-9 * (hi - lo);
        let outer = &self.zone;
        let mut factors: Vec<&Inherited> = Vec::new();
        let mut link = Some(self);
        while let Some(l) = link {
            factors.push(l);
            let z = &l.zone;
            for (j, (x0, side)) in [(z.lo, -1.0), (z.hi, 1.0)].into_iter().enumerate() {
                let root = z.end_roots[j] * factors.iter().map(|f| f.chi(x0)).product::<f64>();
                if x0 > lo + slack
                    && x0 < hi - slack
                    && root.abs() > 0.0
                    && out.iter().all(|o| (o.at - x0).abs() > slack)
                {
                    out.push(RememberedRoot {
                        at: x0,
                        side,
                        root,
                        sign: z.end_signs[j],
                        carried_sign: if factors.len() == 1 {
                            z.end_signs[j]
                        } else {
                            outer.end_sign_shape(x0)
                        },
                    });
                }
            }
            link = z.inherited.as_deref();
        }
        out
    }

    /// Breakpoints of the quadrature over the earlier zone.
    fn pieces(&self) -> Vec<f64> {
        let mut pts = vec![self.zone.lo];
        let mut inner = self.zone.chain_points();
        inner.extend(self.ramp_points());
        let (lo, hi) = (self.zone.lo, self.zone.hi);
        let gap = 1e-9 * (hi - lo);
        for v in inner {
            if v > lo + gap && v < hi - gap {
                pts.push(v);
            }
        }
        pts.push(self.zone.hi);
        pts.sort_by(f64::total_cmp);
        pts.dedup_by(|x, y| (*x - *y).abs() <= gap);
        pts
    }

    /// `H'(χ q̃_E)(x) = χ(x) H'q̃_E(x) + (1/π)∫ (χ(t) − χ(x)) q̃_E(t)/(t − x) dt`.
    pub fn cauchy(&self, x: f64) -> f64 {
        if !self.faded() {
            return self.zone.correction_cauchy(x);
        }
        let cx = self.chi(x);
        let sum = fade_sum(self.table().nodes_for(cx), x, cx, self.fade_tiny());
        let own = if cx.abs() > 0.0 {
            cx * self.zone.correction_cauchy(x)
        } else {
            0.0
        };
        own + sum / std::f64::consts::PI
    }

    /// Nodes closer than this to a point are left out of its fade sum.
    fn fade_tiny(&self) -> f64 {
        1e-14 * (self.zone.hi - self.zone.lo)
    }

    /// [`Self::cauchy`] at each of `xs` into `out` (bit-identical: the points whose χ picks
    /// the same node list share one pass over it in SIMD lanes, `FadeSums`, each point's
    /// terms summed in the same order; a skipped node adds −0, which leaves any sum
    /// unchanged; the test `batched_fields_equal_the_one_point_fields` compares the bits).
    pub fn cauchy_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        out.clear();
        if !self.faded() {
            self.zone.correction_cauchys_into(xs, out);
            return;
        }
        let (tiny, table) = (self.fade_tiny(), self.table());
        let chis: Vec<f64> = xs.iter().map(|&x| self.chi(x)).collect();
        // The fade sums first (left in `out`): the points grouped by the node list their χ
        // picks, each group's sums in SIMD lanes (`FadeSums`), ...
        out.resize(xs.len(), 0.0);
        let arch = pulp::Arch::new();
        for list in [&table.not_one, &table.not_zero, &table.all] {
            let members: Vec<usize> = (0..xs.len())
                .filter(|&k| std::ptr::eq(table.nodes_for(chis[k]), list.as_slice()))
                .collect();
            if members.is_empty() {
                continue;
            }
            let x: Vec<f64> = members.iter().map(|&k| xs[k]).collect();
            let cx: Vec<f64> = members.iter().map(|&k| chis[k]).collect();
            let mut sums = vec![-0.0; members.len()];
            arch.dispatch(FadeSums {
                nodes: list,
                x: &x,
                cx: &cx,
                tiny,
                sums: &mut sums,
            });
            for (&k, sum) in members.iter().zip(sums) {
                out[k] = sum;
            }
        }
        // ... then χ H'q̃_E where χ ≠ 0, the zone's transform in one batch.
        let own = faded(xs, &chis, |points, transforms| {
            self.zone.correction_cauchys_into(points, transforms)
        });
        for (sum, own) in out.iter_mut().zip(own) {
            *sum = own + *sum / std::f64::consts::PI;
        }
    }

    /// `∫ χ q̃_E dx`.
    pub fn integral(&self) -> f64 {
        if !self.faded() {
            return self.zone.correction_integral();
        }
        // The fade table holds `w q̃_E` and χ on the same graded nodes.
        self.table().all.iter().map(|(_, wq, chi)| wq * chi).sum()
    }
}

/// `χ f` at each of `xs` (with χ there `chis`): `zone(points, out)`, a batch evaluation of
/// the zone's part, is called once with the points where χ ≠ 0; elsewhere the value is zero.
fn faded(xs: &[f64], chis: &[f64], zone: impl FnOnce(&[f64], &mut Vec<f64>)) -> Vec<f64> {
    let points: Vec<f64> = xs
        .iter()
        .zip(chis)
        .filter(|(_, chi)| chi.abs() > 0.0)
        .map(|(&x, _)| x)
        .collect();
    let mut values = Vec::with_capacity(points.len());
    zone(&points, &mut values);
    let mut values = values.into_iter();
    chis.iter()
        .map(|&chi| {
            if chi.abs() > 0.0 {
                chi * values.next().expect("one value per point with χ ≠ 0")
            } else {
                0.0
            }
        })
        .collect()
}

/// A remembered stick end inside a new stick zone, where q̃ starts like a square root (the
/// tangential module docs, "Kinks at the stick ends").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RememberedRoot {
    /// The point (m).
    pub at: f64,
    /// −1 at a remembered zone's left end (`q̃ ≈ root √(x − at)`), +1 at its right end.
    pub side: f64,
    /// The root coefficient (Pa/√m), times the fades of the links in between.
    pub root: f64,
    /// The slip sign beside the end when the root formed.
    pub sign: f64,
    /// The slip sign S at the point of the outermost inherited zone, whose q̃ already carries
    /// the root `(sign − S) η A` of p's kink beyond the point.
    pub carried_sign: f64,
}

/// `k(u) = −(2u/π) artanh √(1 − u²)`: the bounded solution of
/// `(1/π)⨍ k(t)/(t − u) dt = |u| − 2/π` on (−1, 1). Its U-series coefficients decay only like
/// n⁻², so it is kept in closed form; `k(u)/√(1−u²) → −2/π` at u = ±1.
pub fn kink_density(u: f64) -> f64 {
    // k(u) ≈ −(2u/π) ln(2/|u|) → 0 as u → 0: below 1e−300 it is 0 to f64's resolution of
    // k's values (at most 0.47), and the quotient below would overflow.
    if u.abs() >= 1.0 || u.abs() < 1e-300 {
        return 0.0;
    }
    // artanh √(1 − u²) = ln((1 + √(1 − u²))/|u|): one logarithm of the quotient rather than
    // two (of the numerator and of |u|), on a hot path.
    -2.0 * u / std::f64::consts::PI * ((1.0 + (1.0 - u * u).sqrt()) / u.abs()).ln()
}

/// `(1/π)⨍ k(t)/(t − u) dt`: `|u| − 2/π` inside, `(2/π)((|z| + 1/|z|) arctan|z| − 1)` outside,
/// `z = u − sgn(u)√(u² − 1)`.
pub fn kink_cauchy(u: f64) -> f64 {
    let two_over_pi = 2.0 / std::f64::consts::PI;
    if u.abs() <= 1.0 {
        u.abs() - two_over_pi
    } else {
        let z = (u.abs() - (u * u - 1.0).sqrt()).max(1e-300);
        two_over_pi * ((z + 1.0 / z) * z.atan() - 1.0)
    }
}

/// Chebyshev points per piece of a zone's exterior tables ([`StickZone::correction_cauchys_into`])
/// for series of M terms: near a stick end the transform of an M-term series varies on a
/// scale of about 1/M² of the zone, so the points grow with M. Measured against the direct
/// sums on every accepted zone of four coupled histories (test
/// `exterior_tables_match_the_direct_transform`): 64 points 1e−9 at M = 128 and 3e−8 at
/// M = 256; M/2 + 32 points 2e−12 (1.2e−11 at worst), which still moved two step dissipations
/// of the Figure-3 history at η = 0.2 by 2.2e−8 of themselves (the pair's sum unchanged: a
/// state's strain enters one step as the new state and the next as the old); 3M/4 + 32 points
/// 1.0e−9 of them (1.4e−10 of the largest step's), at 1.5 % of a forward step at M = 128.
fn exterior_table_nodes(terms: usize) -> usize {
    terms * 3 / 4 + 32
}

/// Points on the exterior pieces that make a batch of [`StickZone::correction_cauchys_into`]
/// tabulate the transform there. A step's slip check asks for about 300 at M = 128, its
/// dissipation about 500, and the next step's as many again of the same zone as the old
/// state; the tables cost `2 exterior_table_nodes(M)` direct sums (256 at M = 128), so below
/// this many points direct sums are cheaper and above it the table pays for itself.
const EXTERIOR_TABLE_POINTS: usize = 128;

/// The largest move of a fade ramp's points, relative to its length, over which an evaluation
/// reuses a fade table built for the earlier ramps ([`Inherited::reusing_table_of`]).
const FADE_TABLE_REUSE: f64 = 1e-5;

/// Collocation points a fade ramp over a short overlap must hold ([`StickZone::inheritance_for`]):
/// enough for the series to absorb the ramp's shape. At M = 48 a quarter-overlap ramp with about
/// five points made steps worse than leaving the remembered kink to the series.
const FADE_POINTS: f64 = 6.0;

/// Points whose Chebyshev sums are interleaved in the batched evaluations of a zone's own part
/// ([`StickZone::own_parts_into`]) and of the contact's series
/// ([`ContactState::pressures_into`] and the like): the Clenshaw recurrences are
/// latency-bound, so eight independent points keep more of them in flight than four (sixteen
/// gain nothing more), with the same bits.
const OWN_LANES: usize = 8;

/// A zone's own part in one form (density or Cauchy transform): the series at
/// [`OWN_LANES`] points, at one point, and the kink term ([`StickZone::own_parts_into`]).
type OwnForms = (
    fn(&BoundedSeries, [f64; OWN_LANES]) -> [f64; OWN_LANES],
    fn(&BoundedSeries, f64) -> f64,
    fn(f64) -> f64,
);

/// `f` at each of `xs` into `out`, L points at a time by `fl`, which must give `f`'s values
/// bit for bit (the L-point Chebyshev sums of [`crate::quadrature`]).
fn in_chunks<const L: usize>(
    xs: &[f64],
    fl: impl Fn([f64; L]) -> [f64; L],
    f: impl Fn(f64) -> f64,
    out: &mut Vec<f64>,
) {
    out.clear();
    let mut chunks = xs.chunks_exact(L);
    for c in chunks.by_ref() {
        out.extend(fl(std::array::from_fn(|l| c[l])));
    }
    out.extend(chunks.remainder().iter().map(|&x| f(x)));
}

impl StickZone {
    /// A zone with its own correction only.
    pub fn new(lo: f64, hi: f64, correction: BoundedSeries, kink: f64) -> Self {
        Self {
            lo,
            hi,
            correction,
            kink,
            inherited: None,
            end_roots: [0.0; 2],
            end_signs: [0.0; 2],
            extras: Vec::new(),
            cauchy_table: TableCache::default(),
            value_table: TableCache::default(),
            exterior_table: TableCache::default(),
        }
    }

    /// The slip-shape S at x from the slip signs beside the ends when the zone was solved
    /// (the smoothstep of [`ContactState::slip_shape`]).
    pub fn end_sign_shape(&self, x: f64) -> f64 {
        sign_blend(self.end_signs, self.lo, self.hi, x)
    }

    /// Tabulate `H'q̃` and q̃ (see `ChainTable`) for a zone that will be evaluated many times
    /// (one that a phase inherits from), with `nodes` Chebyshev points per piece. No-op if
    /// already done.
    pub fn tabulate(&self, nodes: usize) {
        let width = self.hi - self.lo;
        let slack = 1e-12 * width;
        let mut inner = self.chain_points();
        inner.retain(|&x| x > self.lo + slack && x < self.hi - slack);
        self.cauchy_table.0.get_or_init(|| {
            let mut points = vec![self.lo - width, self.lo, self.hi, self.hi + width];
            points.extend(&inner);
            ChainTable::interpolating(piece_ends(points), nodes, |x| self.direct_cauchy(x))
        });
        // A zone without a chain sums its own series faster than a table of more terms.
        if self.inherited.is_none() {
            return;
        }
        self.value_table.0.get_or_init(|| {
            let mut points = vec![self.lo, self.hi];
            points.extend(&inner);
            let smooth = |x| self.direct_correction(x) - self.chain_kinks(x);
            ChainTable::interpolating(piece_ends(points), nodes, smooth)
        });
    }

    /// q̃ at x (Pa), including the inherited chain; zero outside the zone (the zones a chain
    /// carries whole lie inside it, and the faded ones are faded out at its ends).
    pub fn correction_at(&self, x: f64) -> f64 {
        if !(x > self.lo && x < self.hi) {
            return 0.0;
        }
        match self.value_table.0.get() {
            Some(table) => table.at(x).unwrap_or(0.0) + self.chain_kinks(x),
            None => self.direct_correction(x),
        }
    }

    /// The centre kinks' part of q̃ at x inside the zone: `kink · k(u)` of every zone of the
    /// chain that carries one, times the fades of the links above it. Its `u ln|u|` at the
    /// kink point is left out of the value table, which interpolates the smooth rest (with it
    /// the table was off by 1e−8 of the largest q̃ at the kink point, 2e−10 at 1e−3 of the
    /// zone's width from it).
    fn chain_kinks(&self, x: f64) -> f64 {
        let own = |zone: &StickZone| {
            if zone.kink.abs() > 0.0 && x > zone.lo && x < zone.hi {
                zone.kink * kink_density((x - zone.mid()) / zone.half())
            } else {
                0.0
            }
        };
        let mut total = own(self);
        let mut fade = 1.0;
        for link in self.links() {
            if link.faded() {
                fade *= link.chi(x);
            }
            total += fade * own(&link.zone);
        }
        total
    }

    /// [`Self::correction_at`] inside the zone from the series and the chain.
    fn direct_correction(&self, x: f64) -> f64 {
        self.own_part(x, BoundedSeries::density, kink_density)
            + self.inherited.as_ref().map_or(0.0, |z| z.value(x))
            + self.extras_with(|u, v| half_ellipse(x, u, v))
    }

    /// [`Self::correction_at`] at each of `xs` into `out` (bit-identical; the own series is
    /// summed eight (`OWN_LANES`) points at a time, [`BoundedSeries::densities`], and the
    /// chain in batches). q̃ is zero outside the zone, so only the points inside are
    /// evaluated (the slip zones' points of a step's checks and integrals, the sample points
    /// beyond the stick ends).
    pub fn corrections_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        let inside = |x: f64| x > self.lo && x < self.hi;
        if xs.iter().all(|&x| inside(x)) {
            self.corrections_inside(xs, out);
            return;
        }
        let points: Vec<f64> = xs.iter().copied().filter(|&x| inside(x)).collect();
        let mut values = Vec::with_capacity(points.len());
        self.corrections_inside(&points, &mut values);
        let mut values = values.into_iter();
        out.clear();
        out.extend(xs.iter().map(|&x| {
            if inside(x) {
                values.next().expect("one value per point inside")
            } else {
                0.0
            }
        }));
    }

    /// [`Self::corrections_into`] at points that all lie inside the zone.
    fn corrections_inside(&self, xs: &[f64], out: &mut Vec<f64>) {
        if let Some(table) = self.value_table.0.get() {
            table.values_into(xs, |_| 0.0, out);
            for (o, &x) in out.iter_mut().zip(xs) {
                *o = if x > self.lo && x < self.hi {
                    *o + self.chain_kinks(x)
                } else {
                    0.0
                };
            }
            return;
        }
        let many = BoundedSeries::densities::<OWN_LANES>;
        self.own_parts_into(xs, (many, BoundedSeries::density, kink_density), out);
        if let Some(link) = &self.inherited {
            let mut inner = Vec::with_capacity(xs.len());
            link.values_into(xs, &mut inner);
            for (o, v) in out.iter_mut().zip(inner) {
                *o += v;
            }
        }
        for (o, &x) in out.iter_mut().zip(xs) {
            *o = if x > self.lo && x < self.hi {
                *o + self.extras_with(|u, v| half_ellipse(x, u, v))
            } else {
                0.0
            };
        }
    }

    /// [`Self::own_part`] at each of `xs` into `out` (bit-identical: the series [`OWN_LANES`]
    /// points at a time by `many`, the rest by `one`; the kink term through `kink`).
    fn own_parts_into(&self, xs: &[f64], (many, one, kink): OwnForms, out: &mut Vec<f64>) {
        let (mid, half) = (self.mid(), self.half());
        let own_many = |x: [f64; OWN_LANES]| {
            let u = x.map(|x| (x - mid) / half);
            let series = (!self.correction.beta.is_empty()).then(|| many(&self.correction, u));
            std::array::from_fn(|l| self.own_with(u[l], series.map(|s| s[l]), kink))
        };
        in_chunks(xs, own_many, |x| self.own_part(x, one, kink), out);
    }

    /// [`Self::own_part`] at u from the series' term there (`None` when the zone has no
    /// series) and the kink term through `kink`.
    fn own_with(&self, u: f64, series: Option<f64>, kink: fn(f64) -> f64) -> f64 {
        let mut own = 0.0;
        if let Some(s) = series {
            own += s;
        }
        if self.kink.abs() > 0.0 {
            own += self.kink * kink(u);
        }
        own
    }

    /// `Σ amplitude · f(u, v)` over the closed-form extras.
    fn extras_with(&self, f: impl Fn(f64, f64) -> f64) -> f64 {
        self.extras.iter().map(|&(u, v, amp)| amp * f(u, v)).sum()
    }

    /// `H'q̃(x)` (Pa), including the inherited chain (from [`Self::tabulate`]'s table or the
    /// exterior tables of [`Self::correction_cauchys_into`] when the zone has them).
    pub fn correction_cauchy(&self, x: f64) -> f64 {
        let table = match self.cauchy_table.0.get() {
            Some(table) => table.at(x),
            None => self
                .exterior_table
                .0
                .get()
                .and_then(|tables| tables.iter().find_map(|t| t.at(x))),
        };
        table.unwrap_or_else(|| self.direct_cauchy(x))
    }

    /// [`Self::correction_cauchy`] at each of `xs` into `out`, bit-identical (the own series
    /// eight (`OWN_LANES`) points at a time, [`BoundedSeries::cauchys`], and the chain's fade
    /// integrals in batches, [`Inherited::cauchy_into`]). A zone without [`Self::tabulate`]'s
    /// table tabulates its transform on the outer pieces `[lo − w, lo]` and `[hi, hi + w]` (w
    /// the zone's width) at the first call with at least `EXTERIOR_TABLE_POINTS` points there
    /// (the slip zones' points of a step's checks and increments); from then on both forms
    /// interpolate it on those pieces.
    pub fn correction_cauchys_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        out.clear();
        if let Some(table) = self.cauchy_table.0.get() {
            table.values_into(xs, |x| self.direct_cauchy(x), out);
            return;
        }
        let Some(tables) = self.exterior_tables(xs) else {
            self.direct_cauchys_into(xs, out);
            return;
        };
        // The points on the tables' pieces from the tables, the rest directly, each in one
        // batch.
        let mut on_table: [(Vec<usize>, Vec<f64>); 2] = Default::default();
        let mut direct: (Vec<usize>, Vec<f64>) = Default::default();
        for (k, &x) in xs.iter().enumerate() {
            let into = match tables.iter().position(|t| t.piece(x).is_some()) {
                Some(side) => &mut on_table[side],
                None => &mut direct,
            };
            into.0.push(k);
            into.1.push(x);
        }
        out.resize(xs.len(), 0.0);
        let mut values = Vec::with_capacity(xs.len());
        for (table, (at, points)) in tables.iter().zip(&on_table) {
            values.clear();
            table.values_into(
                points,
                |_| unreachable!("a point on the table"),
                &mut values,
            );
            for (&k, &v) in at.iter().zip(&values) {
                out[k] = v;
            }
        }
        values.clear();
        self.direct_cauchys_into(&direct.1, &mut values);
        for (&k, &v) in direct.0.iter().zip(&values) {
            out[k] = v;
        }
    }

    /// The exterior tables (`exterior_table`), built here when `xs` has enough points on
    /// their pieces; `None` without them.
    fn exterior_tables(&self, xs: &[f64]) -> Option<&[ChainTable; 2]> {
        if let Some(tables) = self.exterior_table.0.get() {
            return Some(tables);
        }
        let width = self.hi - self.lo;
        let outer =
            |x: f64| (x >= self.lo - width && x < self.lo) || (x > self.hi && x <= self.hi + width);
        if xs.iter().filter(|&&x| outer(x)).count() < EXTERIOR_TABLE_POINTS {
            return None;
        }
        Some(self.exterior_table.0.get_or_init(|| {
            let nodes = exterior_table_nodes(self.series_terms());
            let table = |from: f64, to: f64| {
                ChainTable::interpolating_batch(vec![from, to], nodes, |xs, out| {
                    self.direct_cauchys_into(xs, out)
                })
            };
            [
                table(self.lo - width, self.lo),
                table(self.hi, self.hi + width),
            ]
        }))
    }

    /// [`Self::correction_cauchys_into`] from the series and the chain (no table).
    fn direct_cauchys_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        out.clear();
        let many = BoundedSeries::cauchys::<OWN_LANES>;
        self.own_parts_into(xs, (many, BoundedSeries::cauchy, kink_cauchy), out);
        if let Some(link) = &self.inherited {
            let mut inner = Vec::with_capacity(xs.len());
            link.cauchy_into(xs, &mut inner);
            for (o, v) in out.iter_mut().zip(inner) {
                *o += v;
            }
        }
        for (o, &x) in out.iter_mut().zip(xs) {
            *o += self.extras_with(|u, v| half_ellipse_cauchy(x, u, v));
        }
    }

    /// `H'q̃(x)` from the series and the chain.
    fn direct_cauchy(&self, x: f64) -> f64 {
        self.own_part(x, BoundedSeries::cauchy, kink_cauchy)
            + self.inherited.as_ref().map_or(0.0, |z| z.cauchy(x))
            + self.extras_with(|u, v| half_ellipse_cauchy(x, u, v))
    }

    /// The zone's own series and kink term through `series` and `kink` (density or Cauchy
    /// transform); terms that are absent (no coefficients, no kink) are not evaluated.
    fn own_part(
        &self,
        x: f64,
        series: fn(&BoundedSeries, f64) -> f64,
        kink: fn(f64) -> f64,
    ) -> f64 {
        let u = (x - self.mid()) / self.half();
        let series = (!self.correction.beta.is_empty()).then(|| series(&self.correction, u));
        self.own_with(u, series, kink)
    }

    /// Whether the zone carries nothing of its own: q̃ is exactly its inherited link's.
    fn carries_nothing(&self) -> bool {
        self.correction.beta.is_empty() && self.kink.abs() <= 0.0 && self.extras.is_empty()
    }

    /// `∫ q̃ dx` (N/m), including the inherited chain (the kink part is odd).
    pub fn correction_integral(&self) -> f64 {
        self.half() * self.correction.integral()
            + self.inherited.as_ref().map_or(0.0, |z| z.integral())
            + self.extras_with(half_ellipse_integral)
    }

    /// What a new zone `[lo, hi]` (solved on `nodes` collocation points) inherits from this
    /// chain. The memory inside the new zone has square-root kinks exactly at the ends of
    /// earlier zones that lie inside it (and a `|x|` kink at the centre of the normal-loading
    /// zone): the outermost earlier zone that lies inside is inherited whole; one with a
    /// single end inside is inherited faded out beyond the new zone's end; one that contains
    /// the new zone is passed over for its inner zones, unless its own centre kink lies
    /// inside.
    ///
    /// The fade ramps over a quarter of the overlap of the two zones while the overlap is at
    /// least a tenth of the new zone. Below that, the ramp covers the whole overlap (from the
    /// new end to the remembered one), provided at least `FADE_POINTS` of the new zone's
    /// collocation points fall within it; otherwise the earlier zone is passed over and its
    /// kink is left to the series.
    ///
    /// Why: where a remembered end lies within a tenth of the zone of the new one (the
    /// insulating Figure-3 history at η = 0.2, steps 57–60), leaving its kink to the series
    /// makes those steps' stick ends and dissipations several times less accurate than the
    /// rest of the history; the ramp brings them back in line.
    pub fn inheritance_for(
        self: &std::sync::Arc<Self>,
        lo: f64,
        hi: f64,
        nodes: usize,
    ) -> Option<std::sync::Arc<Inherited>> {
        let slack = 1e-12 * (hi - lo);
        let inside = |x: f64| x > lo + slack && x < hi - slack;
        // Collocation points of the new zone within `length` of one of its ends (about: the
        // points are `cos((2r − 1)π/(2(M + 1)))` in the zone's variable).
        let points_within = |length: f64| {
            (nodes + 1) as f64 * (1.0 - 2.0 * length / (hi - lo)).clamp(-1.0, 1.0).acos()
                / std::f64::consts::PI
        };
        let mut zone = Some(self.clone());
        while let Some(z) = zone {
            let overlap = z.hi.min(hi) - z.lo.max(lo);
            let wide = overlap >= 0.1 * (hi - lo);
            let short = !wide && points_within(overlap) >= FADE_POINTS;
            let ramp = if wide { 0.25 * overlap } else { overlap };
            let candidate = if z.lo >= lo - slack && z.hi <= hi + slack {
                Some(Inherited::new(z.clone(), None, None))
            } else if (wide || short) && (inside(z.lo) != inside(z.hi)) {
                let ramp_lo = (!inside(z.lo)).then_some((lo, lo + ramp));
                let ramp_hi = (!inside(z.hi)).then_some((hi - ramp, hi));
                Some(Inherited::new(z.clone(), ramp_lo, ramp_hi))
            } else if z.kink.abs() > 0.0 && inside(z.mid()) && overlap >= 0.1 * (hi - lo) {
                Some(Inherited::new(
                    z.clone(),
                    Some((lo, lo + ramp)),
                    Some((hi - ramp, hi)),
                ))
            } else {
                None
            };
            if let Some(mut c) = candidate {
                // A zone that carries nothing of its own and inherits an earlier zone whole
                // has exactly that zone's q̃ (a return to a remembered state, once per cycle):
                // carry the earlier zone instead, so that chains do not grow with the cycles.
                while let Some(inner) = c
                    .zone
                    .inherited
                    .as_ref()
                    .filter(|i| c.zone.carries_nothing() && !i.faded())
                {
                    c.zone = inner.zone.clone();
                }
                return Some(std::sync::Arc::new(c));
            }
            zone = z.inherited.as_ref().map(|i| i.zone.clone());
        }
        None
    }

    /// The most terms of a series in the zone or its chain (M).
    fn series_terms(&self) -> usize {
        std::iter::once(self)
            .chain(self.links().map(|l| l.zone.as_ref()))
            .map(|z| z.correction.beta.len())
            .max()
            .unwrap_or(0)
    }

    /// Number of zones in the chain.
    pub fn chain_len(&self) -> usize {
        1 + self.links().count()
    }

    /// The inherited corrections of the chain, outermost first.
    pub fn links(&self) -> impl Iterator<Item = &Inherited> {
        std::iter::successors(self.inherited.as_deref(), |i| i.zone.inherited.as_deref())
    }

    /// Where q̃ may fail to be smooth besides the zone's ends: the ends of the zones in its
    /// chain (square roots), their fade ramps, and centre kinks (see [`kink_density`]); not
    /// filtered to the zone.
    fn chain_points(&self) -> Vec<f64> {
        let mut points: Vec<f64> = self.kink_point().into_iter().collect();
        for i in self.links() {
            points.extend([i.zone.lo, i.zone.hi]);
            points.extend(i.zone.kink_point());
            points.extend(i.ramp_points());
        }
        points
    }

    /// The zone's centre when it carries a centre kink (see [`kink_density`]).
    fn kink_point(&self) -> Option<f64> {
        (self.kink.abs() > 0.0).then_some(self.mid())
    }
}

impl StickZone {
    /// Centre of the zone (m).
    pub fn mid(&self) -> f64 {
        0.5 * (self.lo + self.hi)
    }
    /// Half-width (m).
    pub fn half(&self) -> f64 {
        0.5 * (self.hi - self.lo)
    }
}

/// One square-root kink of a density (the pressure p or the charge w): the term
/// `amplitude · e(x)/a` with the half-ellipse `e(x; u, v) = √((x − u)(v − x))` ([`half_ellipse`])
/// on the slip-side stretch from the kink point `at` to the contact end on `side` (`[at, c + a]`
/// for side +1, `[c − a, at]` for side −1). It starts like a square root at `at`, vanishes like
/// one at the contact end and has a Cauchy transform in closed form ([`half_ellipse_cauchy`]).
/// See the tangential module docs ("Kinks at the stick ends") for where the kinks come from
/// and how the amplitudes are fixed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Kink {
    /// Kink point (m).
    pub at: f64,
    /// +1: the term lies right of the kink point; −1: left.
    pub side: f64,
    /// Amplitude (the density's unit).
    pub amplitude: f64,
}

/// The kinks of a density; empty unless it is coupled to a stick traction.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Kinks(pub Vec<Kink>);

/// The stretch `[u, v]` of a kink term at `at` on `side` of a contact `[c − a, c + a]`.
pub fn kink_domain(at: f64, side: f64, centre: f64, half_width: f64) -> (f64, f64) {
    if side > 0.0 {
        (at, centre + half_width)
    } else {
        (centre - half_width, at)
    }
}

/// `√((x − u)(v − x))` on `[u, v]`, zero outside (m).
pub fn half_ellipse(x: f64, u: f64, v: f64) -> f64 {
    if x <= u || x >= v {
        0.0
    } else {
        ((x - u) * (v - x)).sqrt()
    }
}

/// `(1/π)⨍ e(t)/(t − x) dt` of [`half_ellipse`] (m): `−(x − m)` on `[u, v]` and
/// `−(x − m) + sgn(x − m)√((x − u)(x − v))` outside, `m = (u + v)/2` (the n = 1 term of a
/// bounded series, `−h T_1` inside and `−h z` outside; it decays like `−h²/(2(x − m))`).
pub fn half_ellipse_cauchy(x: f64, u: f64, v: f64) -> f64 {
    let m = 0.5 * (u + v);
    if x >= u && x <= v {
        -(x - m)
    } else {
        -(x - m) + (x - m).signum() * ((x - u) * (x - v)).sqrt()
    }
}

/// `∫ e dx = π (v − u)²/8` of [`half_ellipse`] (m²).
pub fn half_ellipse_integral(u: f64, v: f64) -> f64 {
    std::f64::consts::PI * (v - u) * (v - u) / 8.0
}

/// The solution at one instant.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactState {
    /// Normal load P (N/m).
    pub normal_load: f64,
    /// Tangential load Q (N/m).
    pub tangential_load: f64,
    /// Resultant charge Γ on the punch (C/m).
    pub charge: f64,
    /// Contact potential φ0 relative to the datum (V), conducting punch only.
    pub potential: Option<f64>,
    /// Contact half-width a (m).
    pub half_width: f64,
    /// Contact centre c in the material frame (m); eccentricity e = −c.
    pub centre: f64,
    /// Pressure on the contact, `p(x) = density((x − c)/a) + kinks` (Pa): the series part.
    pub pressure: BoundedSeries,
    /// The pressure's square-root kinks at the stick ends ([`Kinks`]).
    pub pressure_kinks: Kinks,
    /// Charge split.
    pub split: ChargeSplit,
    /// Constant-potential charge `w(x) = density((x − c)/a) + kinks` (C/m²): the series part;
    /// empty unless conducting.
    pub potential_charge: UnboundedSeries,
    /// The square-root kinks of w at the stick ends ([`Kinks`]).
    pub charge_kinks: Kinks,
    /// Shear traction.
    pub traction: Traction,
    /// Quadrature table `(t, w p(t), S(t))` of [`ContactState::shape_cauchy`] for a stored
    /// state whose slip zones have opposite signs (built by [`ContactState::frozen`]).
    #[serde(skip)]
    pub shape_table: Option<std::sync::Arc<Vec<(f64, f64, f64)>>>,
}

impl ContactState {
    /// Normalised position on the contact.
    fn tau(&self, x: f64) -> f64 {
        (x - self.centre) / self.half_width
    }

    /// Whether x lies inside the contact.
    pub fn in_contact(&self, x: f64) -> bool {
        self.tau(x).abs() < 1.0
    }

    /// Pressure p(x) (Pa).
    pub fn pressure_at(&self, x: f64) -> f64 {
        self.pressure.density(self.tau(x)) + self.kinks_at(&self.pressure_kinks, x)
    }

    /// The part `w` of the charge held by the constant potential (C/m²).
    pub fn potential_charge_at(&self, x: f64) -> f64 {
        self.potential_charge.density(self.tau(x)) + self.kinks_at(&self.charge_kinks, x)
    }

    /// `Σ amplitude · f(u, v)/a` over the kink terms (stretches `[u, v]`, [`kink_domain`]):
    /// with the half-ellipse, its transform or its integral as f.
    fn kinks_with(&self, kinks: &Kinks, f: impl Fn(f64, f64) -> f64) -> f64 {
        kinks
            .0
            .iter()
            .map(|k| {
                let (u, v) = kink_domain(k.at, k.side, self.centre, self.half_width);
                k.amplitude * f(u, v)
            })
            .sum::<f64>()
            / self.half_width
    }

    fn kinks_at(&self, kinks: &Kinks, x: f64) -> f64 {
        self.kinks_with(kinks, |u, v| half_ellipse(x, u, v))
    }

    /// `∫ p dx` over the contact (N/m).
    pub fn pressure_force(&self) -> f64 {
        self.half_width * self.pressure.integral()
            + self.kinks_with(&self.pressure_kinks, half_ellipse_integral)
    }

    /// `∫ w dx` over the contact (C/m).
    pub fn potential_charge_force(&self) -> f64 {
        self.half_width * self.potential_charge.integral()
            + self.kinks_with(&self.charge_kinks, half_ellipse_integral)
    }

    /// Charge g(x) = χ p + w (C/m²).
    pub fn charge_at(&self, x: f64) -> f64 {
        self.split.ratio * self.pressure_at(x) + self.potential_charge_at(x)
    }

    /// The slip-direction function S(x): the left/right signs outside the stick zone and the
    /// smoothstep `s_L + (s_R − s_L)(3v² − 2v³)`, `v = (x − lo)/(hi − lo)`, inside it. Its zero
    /// slope at the stick ends makes `q̃ = q − ηpS` vanish like `(b − x)^{3/2}` there (a linear
    /// blend, as in the seed paper's eq. 17, leaves a `(b − x)` term whose square-root quotient
    /// limits the end condition to first order in 1/M).
    pub fn slip_shape(&self, x: f64) -> f64 {
        let t = &self.traction;
        match &t.stick {
            None => 0.0,
            Some(s) if x <= s.lo => t.left_sign,
            Some(s) if x >= s.hi => t.right_sign,
            Some(s) => sign_blend([t.left_sign, t.right_sign], s.lo, s.hi, x),
        }
    }

    /// Shear traction q(x) (Pa).
    pub fn traction_at(&self, x: f64) -> f64 {
        let t = &self.traction;
        let Some(stick) = &t.stick else { return 0.0 };
        let base = t.friction * self.pressure_at(x) * self.slip_shape(x);
        base + stick.correction_at(x)
    }

    /// A series in the contact variable τ plus `extra(x)` at each of `xs` into `out`: the
    /// series [`OWN_LANES`] points at a time by `many`, which must give `one`'s values bit for
    /// bit.
    fn contact_series_into(
        &self,
        xs: &[f64],
        many: impl Fn([f64; OWN_LANES]) -> [f64; OWN_LANES],
        one: impl Fn(f64) -> f64,
        extra: impl Fn(f64) -> f64,
        out: &mut Vec<f64>,
    ) {
        in_chunks(
            xs,
            |x| many(x.map(|x| self.tau(x))),
            |x| one(self.tau(x)),
            out,
        );
        for (o, &x) in out.iter_mut().zip(xs) {
            *o += extra(x);
        }
    }

    /// [`Self::pressure_at`] at each of `xs` into `out` (bit-identical, the series
    /// eight (`OWN_LANES`) points at a time).
    pub fn pressures_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        let (series, kinks) = (&self.pressure, &self.pressure_kinks);
        let many = |t| series.densities(t);
        let one = |t| series.density(t);
        self.contact_series_into(xs, many, one, |x| self.kinks_at(kinks, x), out);
    }

    /// [`Self::potential_charge_at`] at each of `xs` into `out` (bit-identical).
    pub fn potential_charges_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        let (series, kinks) = (&self.potential_charge, &self.charge_kinks);
        let many = |t| series.densities(t);
        let one = |t| series.density(t);
        self.contact_series_into(xs, many, one, |x| self.kinks_at(kinks, x), out);
    }

    /// [`Self::pressure_cauchy`] at each of `xs` into `out` (bit-identical; the transform of
    /// [`Self::pressures_and_cauchys_into`], one code path for both).
    pub fn pressure_cauchys_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        self.pressures_and_cauchys_into(xs, &mut Vec::new(), out);
    }

    /// [`Self::pressures_into`] and [`Self::pressure_cauchys_into`] at once (bit-identical to
    /// each), the series' sums from one run of their chains
    /// ([`BoundedSeries::densities_and_cauchys`]).
    pub fn pressures_and_cauchys_into(&self, xs: &[f64], p: &mut Vec<f64>, h: &mut Vec<f64>) {
        let (series, kinks) = (&self.pressure, &self.pressure_kinks);
        p.clear();
        h.clear();
        let mut chunks = xs.chunks_exact(OWN_LANES);
        for c in chunks.by_ref() {
            let tau: [f64; OWN_LANES] = std::array::from_fn(|l| self.tau(c[l]));
            let (density, cauchy) = series.densities_and_cauchys(tau);
            p.extend(density);
            h.extend(cauchy);
        }
        for &x in chunks.remainder() {
            let ([density], [cauchy]) = series.densities_and_cauchys([self.tau(x)]);
            p.push(density);
            h.push(cauchy);
        }
        for ((p, h), &x) in p.iter_mut().zip(h.iter_mut()).zip(xs) {
            *p += self.kinks_at(kinks, x);
            *h += self.kinks_with(kinks, |u, v| half_ellipse_cauchy(x, u, v));
        }
    }

    /// [`Self::traction_at`] at each of `xs` into `out` (bit-identical, in batches).
    pub fn tractions_into(&self, xs: &[f64], out: &mut Vec<f64>) {
        let mut p = Vec::new();
        self.pressures_into(xs, &mut p);
        self.tractions_with(xs, &p, out);
    }

    /// [`Self::tractions_into`] given the pressure `p` at `xs` (as from
    /// [`Self::pressures_into`]).
    pub fn tractions_with(&self, xs: &[f64], p: &[f64], out: &mut Vec<f64>) {
        out.clear();
        let t = &self.traction;
        let Some(stick) = &t.stick else {
            out.resize(xs.len(), 0.0);
            return;
        };
        let mut chain = Vec::new();
        stick.corrections_into(xs, &mut chain);
        for ((&x, p), c) in xs.iter().zip(p).zip(chain) {
            let base = t.friction * p * self.slip_shape(x);
            out.push(base + c);
        }
    }

    /// `H'p(x) = (1/π)⨍ p(s)/(s − x) ds` from the representation (Pa), any x off the ends.
    pub fn pressure_cauchy(&self, x: f64) -> f64 {
        self.pressure.cauchy(self.tau(x))
            + self.kinks_with(&self.pressure_kinks, |u, v| half_ellipse_cauchy(x, u, v))
    }

    /// `H'g(x)` (C/m²).
    pub fn charge_cauchy(&self, x: f64) -> f64 {
        self.split.ratio * self.pressure_cauchy(x)
            + self.potential_charge.cauchy(self.tau(x))
            + self.kinks_with(&self.charge_kinks, |u, v| half_ellipse_cauchy(x, u, v))
    }

    /// `H'(pS)(x) = S(x) H'p(x) + (1/π)∫ p(t)(S(t) − S(x))/(t − x) dt`: the Cauchy transform of
    /// the friction-limited part of the traction per unit η. The integrand is a bounded
    /// difference quotient; it is integrated piecewise over the slip and stick intervals with
    /// sine-graded Gauss–Legendre rules (which also absorb the √ at the contact ends). When
    /// both slip zones have the same sign S is constant and the integral vanishes.
    pub fn shape_cauchy(&self, x: f64) -> f64 {
        let Some(stick) = &self.traction.stick else {
            return 0.0;
        };
        self.shape_cauchy_with(stick, x, self.pressure_cauchy(x))
    }

    /// [`Self::shape_cauchy`] at x in the stick zone `stick`'s state, given `H'p(x)`.
    fn shape_cauchy_with(&self, stick: &StickZone, x: f64, pressure_cauchy: f64) -> f64 {
        let t = &self.traction;
        let sx = self.slip_shape(x);
        let value = sx * pressure_cauchy;
        if (t.left_sign - t.right_sign).abs() <= 0.0 && self.shape_table.is_none() {
            return value;
        }
        let built;
        let table = match &self.shape_table {
            Some(table) => table.as_slice(),
            None => {
                built = self.shape_nodes(stick);
                built.as_slice()
            }
        };
        let sum: f64 = table
            .iter()
            .filter(|(tt, _, _)| (tt - x).abs() > 1e-14 * self.half_width)
            .map(|(tt, wp, st)| wp * (st - sx) / (tt - x))
            .sum();
        value + sum / std::f64::consts::PI
    }

    /// Quadrature nodes `(t, w p(t), S(t))` over the left slip, stick and right slip pieces.
    fn shape_nodes(&self, stick: &StickZone) -> Vec<(f64, f64, f64)> {
        let mut table = self.shape_quadrature(stick);
        for (t, w, _) in table.iter_mut() {
            *w *= self.pressure_at(*t);
        }
        table
    }

    /// The nodes `(t, w, S(t))` of [`Self::shape_nodes`] without the pressure factor.
    pub(crate) fn shape_quadrature(&self, stick: &StickZone) -> Vec<(f64, f64, f64)> {
        let ends = [
            self.centre - self.half_width,
            stick.lo,
            stick.hi,
            self.centre + self.half_width,
        ];
        let (nodes, weights) = graded_rule();
        let mut table = Vec::with_capacity(3 * nodes.len());
        for seg in ends.windows(2) {
            let (mid, half) = (0.5 * (seg[0] + seg[1]), 0.5 * (seg[1] - seg[0]));
            for (u, w) in nodes.iter().zip(weights) {
                let tt = mid + half * u;
                table.push((tt, w * half, self.slip_shape(tt)));
            }
        }
        table
    }

    /// This state with the quadrature of [`Self::shape_cauchy`] tabulated, for states that
    /// are stored and evaluated many times (the memory).
    pub fn frozen(mut self) -> Self {
        self.tabulate_shape();
        self
    }

    /// (Re)build the shape quadrature table for the current pressure and stick zone (no-op
    /// when both slip zones have the same sign).
    pub fn tabulate_shape(&mut self) {
        self.shape_table = None;
        let t = &self.traction;
        if let (Some(stick), true) = (&t.stick, (t.left_sign - t.right_sign).abs() > 0.0) {
            self.shape_table = Some(std::sync::Arc::new(self.shape_nodes(stick)));
        }
    }

    /// Replace the stick zone's own correction by none when all its coefficients are below
    /// 1e−14 of `η p(c)`, i.e. far below the residual tolerance of a step (1e−13): the traction
    /// changes by less than that, and every later evaluation of the chain skips the series.
    pub fn drop_negligible_correction(&mut self, friction: f64) {
        let scale = 1e-14 * friction * self.pressure_at(self.centre).abs();
        if let Some(stick) = self.traction.stick.as_mut()
            && stick.kink.abs() <= 0.0
            && stick.correction.beta.iter().all(|b| b.abs() <= scale)
        {
            stick.correction = BoundedSeries::default();
        }
    }

    /// `H'q(x) = η H'(pS)(x) + H'q̃(x)` (Pa), on and off the contact.
    pub fn traction_cauchy(&self, x: f64) -> f64 {
        let t = &self.traction;
        let Some(stick) = &t.stick else { return 0.0 };
        t.friction * self.shape_cauchy(x) + stick.correction_cauchy(x)
    }

    /// Surface strain `∂ux/∂x` from eq. (A): `−(w12 + χ w13) p − w13 w + y11 H'q`.
    pub fn strain_at(&self, model: &ContactModel, x: f64) -> f64 {
        let w13 = model.compliance.electric.map_or(0.0, |e| e.w13);
        -model.local_pressure_strain(self.split) * self.pressure_at(x)
            - w13 * self.potential_charge_at(x)
            + model.compliance.y11 * self.traction_cauchy(x)
    }

    /// [`Self::strain_at`] at each of `xs` into `out` (bit-identical; `H'q̃` of the stick
    /// zone's chain in a batch, [`StickZone::correction_cauchys_into`]).
    pub fn strains_into(&self, model: &ContactModel, xs: &[f64], out: &mut Vec<f64>) {
        let (mut p, mut p_cauchy) = (Vec::new(), Vec::new());
        self.pressures_and_cauchys_into(xs, &mut p, &mut p_cauchy);
        self.strains_with(model, xs, (&p, &p_cauchy), out);
    }

    /// [`Self::strains_into`] given the pressure and its Cauchy transform at `xs` (as from
    /// [`Self::pressures_and_cauchys_into`]).
    pub fn strains_with(
        &self,
        model: &ContactModel,
        xs: &[f64],
        (p, p_cauchy): (&[f64], &[f64]),
        out: &mut Vec<f64>,
    ) {
        out.clear();
        let mut w = Vec::new();
        self.potential_charges_into(xs, &mut w);
        let mut chain = Vec::new();
        if let Some(stick) = &self.traction.stick {
            stick.correction_cauchys_into(xs, &mut chain);
        }
        let w13 = model.compliance.electric.map_or(0.0, |e| e.w13);
        let local = model.local_pressure_strain(self.split);
        for (k, &x) in xs.iter().enumerate() {
            // `traction_cauchy` with its parts from the batches.
            let traction_cauchy = match &self.traction.stick {
                None => 0.0,
                Some(stick) => {
                    let shape = self.shape_cauchy_with(stick, x, p_cauchy[k]);
                    self.traction.friction * shape + chain[k]
                }
            };
            out.push(-local * p[k] - w13 * w[k] + model.compliance.y11 * traction_cauchy);
        }
    }

    /// The strain change from `old` to this state, `ε − ε_old`, at each of `xs` into `out`
    /// ([`Self::strains_into`] of both).
    pub fn strain_changes_into(
        &self,
        model: &ContactModel,
        old: &ContactState,
        xs: &[f64],
        out: &mut Vec<f64>,
    ) {
        let mut before = Vec::with_capacity(xs.len());
        self.strains_into(model, xs, out);
        old.strains_into(model, xs, &mut before);
        for (n, o) in out.iter_mut().zip(before) {
            *n -= o;
        }
    }
}

/// Where the strain change between two states is not smooth: both states' traction
/// breakpoints and both contact ends (the old end lies inside a slip zone of the new state
/// when the contact grows or shifts).
pub fn step_breakpoints(old: &ContactState, new: &ContactState) -> Vec<f64> {
    let mut breaks = new.traction_breakpoints();
    breaks.extend(old.traction_breakpoints());
    for s in [old, new] {
        breaks.extend([s.centre - s.half_width, s.centre + s.half_width]);
    }
    breaks
}

/// The ends of the quadrature pieces: `points` sorted and deduplicated, then every piece more
/// than three times as long as a neighbour halved until none is. A singular point at the end
/// of a short piece lies just outside its long neighbour, at a distance small against that
/// neighbour's length, where a fixed rule converges slowly (measured: 1.6e−3 between the 32-
/// and 96-node rules on such a piece of the dissipation integral, 0.048a long with the
/// neighbouring stick end 0.003a beyond it); after halving, every singular point is at least
/// about a third of a piece length away from the pieces it does not end.
fn piece_ends(points: Vec<f64>) -> Vec<f64> {
    balanced_ends(points).into_iter().map(|(x, _)| x).collect()
}

/// [`piece_ends`], each end with whether it was made by the halving (`true`) rather than
/// given.
fn balanced_ends(points: Vec<f64>) -> Vec<(f64, bool)> {
    let mut points: Vec<(f64, bool)> = points.into_iter().map(|x| (x, false)).collect();
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    points.dedup_by(|a, b| (a.0 - b.0).abs() <= 0.0);
    loop {
        let lengths: Vec<f64> = points.windows(2).map(|w| w[1].0 - w[0].0).collect();
        let too_long = |i: usize| {
            let neighbour = [i.checked_sub(1), (i + 1 < lengths.len()).then_some(i + 1)]
                .into_iter()
                .flatten()
                .map(|j| lengths[j])
                .fold(f64::INFINITY, f64::min);
            lengths[i] > 3.0 * neighbour
        };
        let split: Vec<(f64, bool)> = (0..lengths.len())
            .filter(|&i| too_long(i))
            .map(|i| (0.5 * (points[i].0 + points[i + 1].0), true))
            .collect();
        if split.is_empty() {
            return points;
        }
        points.extend(split);
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
}

/// A function tabulated on the nodes of a graded rule's pieces, with running integrals.
#[derive(Debug, Clone, Default)]
pub struct GradedTable {
    /// `(x, weight, f(x), ∫ f from the first point to x)` for every node, in increasing x.
    pub nodes: Vec<(f64, f64, f64, f64)>,
    /// `∫ f` over all pieces.
    pub total: f64,
}

/// The most nodes a piece of the contact integrals' rule takes (δ, δn, the arcsine moment, the
/// shape force of mixed states; `contact_piece_nodes` gives short pieces fewer):
/// `max(32, M/2)`, since a piece holds a share of the M-term series and the stick zone, one
/// long piece, holds q̃'s whole series. Measured on the default history, M = 64 … 512, against
/// four times the nodes: δ within 9e−11 of its range (over the 22-run regression batch 1.5e−6,
/// in the insulating Figure-3 histories at M = 64). A fixed 32-node rule let δ err by 3e−7 of
/// its range at M = 128 and 1e−5 at M = 256, as much as the discretisation error of δ there.
pub fn field_rule_nodes(m: usize) -> usize {
    32.max(m / 2)
}

/// Nodes of the contact integrals' rule on the piece `[x0, x1]` of the contact `(c, a)`: in
/// proportion to the piece's share s of the contact in θ (`x = c + a cos θ`, the variable in
/// which the M-term series oscillate evenly), `8 s field_rule_nodes(M)` rounded up to a
/// multiple of 8, at least `CONTACT_PIECE_MIN_NODES` and at most `field_rule_nodes(M)`. The
/// long pieces and those at the contact ends keep the whole rule; the short pieces between
/// the chain's points get fewer. Measured over the 22-run regression batch against four
/// times [`field_rule_nodes`] on every piece (itself within 8.4e−12 of δ's range of eight
/// times): δ within 1.5e−8 of its range at M ≥ 96 (the whole rule: 4.3e−11), the geometry
/// (through φ0's arcsine moment) within 2.4e−11 a and the dissipation within 4e−9 of the
/// largest step dissipation, as with the whole rule (the stalled step 47 of the insulating
/// Figure-3 history at η = 0.4 aside, which moves with any change of round-off), for fewer
/// nodes on the pieces far from the contact ends.
fn contact_piece_nodes(x0: f64, x1: f64, (c, a): (f64, f64), m: usize) -> usize {
    let most = field_rule_nodes(m);
    let theta = |x: f64| ((x - c) / a).clamp(-1.0, 1.0).acos();
    let share = (theta(x0) - theta(x1)).abs() / std::f64::consts::PI;
    ((8.0 * share * most as f64).ceil() as usize)
        .next_multiple_of(8)
        .clamp(CONTACT_PIECE_MIN_NODES.min(most), most)
}

/// The fewest nodes of a piece of the contact integrals' rule ([`contact_piece_nodes`]): a
/// short piece still carries square-root and logarithmic behaviour at its ends, so the rule
/// changes nothing at M ≤ 64. Measured over the regression batch against four times the whole
/// rule: with 16, δ erred by up to 2.2e−5 of its range (the insulating Figure-3 history at
/// M = 64) whatever the proportion (4, 8 or 16 × the share); with 24, by up to 6.1e−8 in
/// runs where the whole rule errs by 4.3e−11 or less; with 32, by up to 1.5e−8 (at M = 256;
/// 9.6e−9 at M = 128). δ's discretisation error is 1.5e−6 of its range at M = 128 (the
/// default history against M = 256).
const CONTACT_PIECE_MIN_NODES: usize = 32;

/// Nodes per piece of the graded rule over the slip zones (the dissipation):
/// `max(32, M/4)`; the slip zones are split into shorter pieces than the contact. Measured on
/// the default history, M = 64 … 512, against four times the nodes: step dissipations within
/// 5e−9 of themselves (the cycle's friction work the same to ten digits).
pub fn slip_zone_rule_nodes(m: usize) -> usize {
    32.max(m / 4)
}

/// Nodes of the plain Gauss–Legendre rule on the smooth pieces of the dissipation's rule (both
/// ends made by the balancing, [`graded_cumulative`]): half of [`slip_zone_rule_nodes`], 16
/// at M ≤ 128.
pub fn slip_zone_smooth_nodes(m: usize) -> usize {
    smooth_piece_nodes(slip_zone_rule_nodes(m))
}

/// Nodes per piece of the slip check's rule (the slip increments whose sign the step's check
/// reads, [`tangential::assess_step`]): a quarter of [`slip_zone_rule_nodes`], 8 at M ≤ 128.
/// The check only needs the sign, to 1e−2 of the largest slip of the step. Measured over the
/// 22 scenarios of the regression batch (M = 64 … 256, coupled and uncoupled, many cycles and
/// variable amplitude) against eight times the nodes: the worst check measure within 1.2e−4,
/// every state unchanged; half of [`slip_zone_rule_nodes`] gave 1.3e−7 at 8 % more of a
/// forward step's solve at M = 128 (test `the_slip_check_rule_reads_the_sign_to_a_small_error`).
pub fn slip_check_rule_nodes(m: usize) -> usize {
    slip_zone_rule_nodes(m) / 4
}

/// The nodes and weights of a graded rule over the balanced pieces between `points` (none more
/// than three times as long as a neighbour, `piece_ends`), in increasing x, so that
/// `∫ f ≈ Σ weight f(node)` from the smallest to the largest of `points`: each piece `[x0, x1]`
/// by a `nodes(x0, x1)`-point sine-graded Gauss–Legendre rule (nodes clustered like Chebyshev
/// points at both ends, which absorbs square-root and logarithmic behaviour there: every point
/// where f is not smooth must be among `points`); a piece whose two ends the balancing made
/// by the plain rule of `smooth_piece_nodes` (as in [`graded_cumulative`]). Measured over
/// the regression batch against eight times the nodes on every piece: δ unchanged to two
/// digits in every run (1.5e−6 of its range at worst, the insulating Figure-3 histories at
/// M = 64; 9.6e−9 at M = 128); test `the_contact_rule_gives_the_displacements_to_a_small_error`.
pub fn graded_nodes(points: Vec<f64>, nodes: impl Fn(f64, f64) -> usize) -> (Vec<f64>, Vec<f64>) {
    let (mut at, mut weights) = (Vec::new(), Vec::new());
    for w in balanced_ends(points).windows(2) {
        let n = nodes(w[0].0, w[1].0);
        let rule = if w[0].1 && w[1].1 {
            plain_rule_with(smooth_piece_nodes(n))
        } else {
            graded_rule_with(n)
        };
        let (mid, half) = (0.5 * (w[0].0 + w[1].0), 0.5 * (w[1].0 - w[0].0));
        at.extend(rule.nodes.iter().map(|u| mid + half * u));
        weights.extend(rule.weights.iter().map(|wt| half * wt));
    }
    (at, weights)
}

/// Tabulate f on the `nodes`-point graded rule over the balanced pieces between `points` (as
/// [`graded_nodes`]) together with the running integral up to each node, from the
/// cumulative Gauss–Legendre matrix in the graded variable
/// ([`crate::quadrature::gauss_legendre_cumulative`]). Nested integrals such as
/// `∫ g(t) ∫_t^R f ds dt` then cost one evaluation of f per node: f is evaluated at all the
/// pieces' nodes in one call, `f(xs, out)` pushing the values at `xs` onto `out` (passed
/// empty).
///
/// With `smooth_nodes`, a piece whose two ends were both made by the balancing (`piece_ends`)
/// takes a plain Gauss–Legendre rule of that many nodes instead: no point where f is not
/// smooth ends it, and after the balancing every such point lies at least a third of the
/// piece's length beyond its ends (two thirds of its half-length), so f is analytic inside
/// the Bernstein ellipse with `ρ ≥ 5/3 + √(25/9 − 1) = 3` about the piece, and the n-point
/// rule errs by about `ρ^(−2n)` (5e−16 for 16 nodes). The sine-graded rule, whose clustering
/// at both ends pulls such a point towards the piece in its variable, needs more
/// (`piece_ends`' test: 1.3e−8 with 32 nodes for a logarithm at a third of the length).
pub fn graded_cumulative(
    points: Vec<f64>,
    nodes: usize,
    smooth_nodes: Option<usize>,
    f: &mut dyn FnMut(&[f64], &mut Vec<f64>),
) -> GradedTable {
    let graded = graded_rule_with(nodes);
    let pieces: Vec<(f64, f64, &GradedRule)> = balanced_ends(points)
        .windows(2)
        .map(|w| {
            let rule = match smooth_nodes {
                Some(n) if w[0].1 && w[1].1 => plain_rule_with(n),
                _ => graded,
            };
            (0.5 * (w[0].0 + w[1].0), 0.5 * (w[1].0 - w[0].0), rule)
        })
        .collect();
    let at: Vec<f64> = pieces
        .iter()
        .flat_map(|&(mid, half, rule)| rule.nodes.iter().map(move |u| mid + half * u))
        .collect();
    let mut all = Vec::with_capacity(at.len());
    f(&at, &mut all);
    let mut table = GradedTable::default();
    let mut values = all.as_slice();
    for &(mid, half, rule) in &pieces {
        let n = rule.nodes.len();
        let (here, rest) = values.split_at(n);
        values = rest;
        for k in 0..n {
            let row = &rule.cumulative[k * n..(k + 1) * n];
            let before: f64 = half * row.iter().zip(here).map(|(c, v)| c * v).sum::<f64>();
            table.nodes.push((
                mid + half * rule.nodes[k],
                rule.weights[k] * half,
                here[k],
                table.total + before,
            ));
        }
        table.total += half
            * rule
                .weights
                .iter()
                .zip(here)
                .map(|(w, v)| w * v)
                .sum::<f64>();
    }
    table
}

/// The graded rule with `nodes` points and its cumulative matrix, built once per size.
fn graded_rule_with(nodes: usize) -> &'static GradedRule {
    static RULES: SizeTables<GradedRule> = std::sync::Mutex::new(Vec::new());
    thread_local! {
        static KNOWN: KnownSizes<GradedRule> = const { std::cell::RefCell::new(Vec::new()) };
    }
    built_once(&RULES, &KNOWN, nodes, GradedRule::new)
}

/// Nodes of the plain rule on a smooth piece (both ends made by the balancing) of a rule that
/// gives its graded pieces `graded` nodes: half, at least 16 ([`graded_nodes`],
/// [`slip_zone_smooth_nodes`]).
fn smooth_piece_nodes(graded: usize) -> usize {
    (graded / 2).max(16)
}

/// The plain Gauss–Legendre rule with `nodes` points and its cumulative matrix (the smooth
/// pieces of [`graded_nodes`] and [`graded_cumulative`]), built once per size.
fn plain_rule_with(nodes: usize) -> &'static GradedRule {
    static RULES: SizeTables<GradedRule> = std::sync::Mutex::new(Vec::new());
    thread_local! {
        static KNOWN: KnownSizes<GradedRule> = const { std::cell::RefCell::new(Vec::new()) };
    }
    built_once(&RULES, &KNOWN, nodes, GradedRule::plain)
}

/// Tables of one kind built once per size for the whole run: `(size, table)`.
type SizeTables<T> = std::sync::Mutex<Vec<(usize, &'static T)>>;

/// A thread's copy of the entries of a [`SizeTables`] it has used.
type KnownSizes<T> = std::cell::RefCell<Vec<(usize, &'static T)>>;

/// The table of `size` from `shared`, built by `make` on first use and kept for the run. Each
/// thread keeps the tables it has used in `known`: the two threads of a history (steps and
/// their increments) look tables up thousands of times per run, and contended locks of the
/// shared list cost 3 % of the default run in futex calls.
fn built_once<T: Sync + 'static>(
    shared: &'static SizeTables<T>,
    known: &'static std::thread::LocalKey<KnownSizes<T>>,
    size: usize,
    make: impl FnOnce(usize) -> T,
) -> &'static T {
    let find = |tables: &Vec<(usize, &'static T)>| {
        tables.iter().find(|(n, _)| *n == size).map(|(_, t)| *t)
    };
    if let Some(table) = known.with_borrow(find) {
        return table;
    }
    let mut tables = shared
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let table = find(&tables).unwrap_or_else(|| {
        let table: &'static T = Box::leak(Box::new(make(size)));
        tables.push((size, table));
        table
    });
    known.with_borrow_mut(|k| k.push((size, table)));
    table
}

/// Nodes per piece of the graded rule of [`graded_rule`].
const GRADED_NODES: usize = 96;

/// Nodes per piece of the fade integral's graded rule ([`Inherited::cauchy`]), whose table is
/// rebuilt at every residual evaluation (its pieces end at the fade ramps, which move with the
/// stick ends). Measured on the regression batch of `docs/performance.md` against 192 nodes:
/// 64 nodes move the stick ends by at most 1.5e−9 a at M = 128 and 1.4e−8 a at M = 256
/// (the first loading, whose base zone carries the normal-loading centre kink), every other
/// phase by at most 1e−8 a, and the histories' dissipation by at most 5e−9 of itself; 96 nodes
/// (the other graded rules') 6.5e−9 a at M = 256 and 0 at M = 128. 48 nodes: 8e−8 a at
/// M = 128 and 4e−7 a where a remembered stick end lies close to the new one; 32 nodes
/// changed the dissipation of the insulating Figure-3 history by 7.6e−4. The stall of step 47
/// of its η = 0.4 variant moves with any change of round-off and is left out of these figures.
/// 64 nodes are therefore the fewest that keep the errors below the discretisation's.
const FADE_RULE_NODES: usize = 64;

/// A sine-graded Gauss–Legendre rule on [−1, 1] (`u = sin(πv/2)`, see [`graded_rule`]) with
/// its cumulative matrix.
struct GradedRule {
    nodes: Vec<f64>,
    weights: Vec<f64>,
    /// Row k: the weights of `∫_{-1}^{u_k}` in the graded variable, row-major n × n.
    cumulative: Vec<f64>,
}

impl GradedRule {
    fn new(n: usize) -> Self {
        let (v, w) = crate::quadrature::gauss_legendre(n);
        let s = crate::quadrature::gauss_legendre_cumulative(n);
        let half_pi = std::f64::consts::FRAC_PI_2;
        // Row k: ∫_{-1}^{v_k} h(v) dv with h = f(x(v)) x'(v), x'(v) = half (π/2) cos(πv/2).
        let cumulative = (0..n * n)
            .map(|kj| s[kj] * half_pi * (half_pi * v[kj % n]).cos())
            .collect();
        Self {
            nodes: v.iter().map(|v| (half_pi * v).sin()).collect(),
            weights: v
                .iter()
                .zip(&w)
                .map(|(v, w)| w * half_pi * (half_pi * v).cos())
                .collect(),
            cumulative,
        }
    }

    /// The plain n-point Gauss–Legendre rule with its cumulative matrix (no grading).
    fn plain(n: usize) -> Self {
        let (nodes, weights) = crate::quadrature::gauss_legendre(n);
        Self {
            nodes,
            weights,
            cumulative: crate::quadrature::gauss_legendre_cumulative(n),
        }
    }
}

/// One admissibility check: `(name, measure, allowed, reported value, x)`; it fails when
/// `measure > allowed`.
pub(crate) type Check<'a> = (&'a str, f64, f64, f64, f64);

/// The first failed check as an [`SolveFailure::Inadmissible`] error.
pub(crate) fn first_violation(checks: &[Check<'_>]) -> Result<(), crate::error::SolveFailure> {
    match checks.iter().find(|c| c.1 > c.2) {
        Some(&(name, _, _, value, x)) => Err(crate::error::SolveFailure::Inadmissible {
            check: name.to_string(),
            value,
            x,
        }),
        None => Ok(()),
    }
}

/// Sine-graded Gauss–Legendre rule on [−1, 1] with `GRADED_NODES` nodes: `u = sin(πv/2)`,
/// nodes clustered like Chebyshev points at both ends (resolves √ end behaviour and
/// near-singular quotients). Returns `(nodes, weights)`.
pub fn graded_rule() -> (&'static [f64], &'static [f64]) {
    let rule = graded_rule_with(GRADED_NODES);
    (&rule.nodes, &rule.weights)
}

/// Surface fields at one point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SurfacePoint {
    /// x (m).
    pub x: f64,
    /// p (Pa).
    pub pressure: f64,
    /// q (Pa).
    pub traction: f64,
    /// g (C/m²).
    pub charge: f64,
    /// σxx0 (Pa).
    pub sigma_xx: f64,
    /// Dx0 (C/m²).
    pub d_x: f64,
}

impl ContactModel {
    /// p, q, g, σxx0 and Dx0 at x (seed eqs. 64–65, module docs).
    pub fn surface_point(&self, state: &ContactState, x: f64) -> SurfacePoint {
        let c = &self.compliance;
        let d = &self.field_coefficients;
        let (y23, y33, w13) = c
            .electric
            .map_or((0.0, 0.0, 0.0), |e| (e.y23, e.y33, e.w13));
        let p = state.pressure_at(x);
        let q = state.traction_at(x);
        let g = state.charge_at(x);
        let dux = state.strain_at(self, x);
        let dphi = w13 * q + y23 * state.pressure_cauchy(x) + y33 * state.charge_cauchy(x);
        SurfacePoint {
            x,
            pressure: p,
            traction: q,
            charge: g,
            sigma_xx: -d.delta1 * p - d.delta2 * g + d.delta3 * dux,
            d_x: -d.e15_over_c44 * q - d.delta4 * dphi,
        }
    }
}

/// The true gap just outside the contact ends (seed model check, formulation §7).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GapReport {
    /// Smallest gap found within one half-width outside either end (m); negative means the
    /// surface interpenetrates the punch.
    pub min_gap: f64,
    /// Where (m).
    pub at: f64,
    /// The Hertzian scale `a²/(2R)` (m), for comparison.
    pub scale: f64,
}

impl ContactModel {
    /// Gap `g(x) = uz(x) − (δ0 − x²/(2R))` outside the contact, from
    /// `g' = w12 q + y22 H'p + y23 H'g + x/R` (eq. B; q = 0 outside) integrated from each contact
    /// end with `x = end ± v²` (which absorbs the inverse square root of a conducting punch's
    /// charge), sampled at 60 points, clustered quadratically towards the end, up to one
    /// half-width away.
    pub fn outside_gap(&self, state: &ContactState) -> GapReport {
        let y23 = self.compliance.electric.map_or(0.0, |e| e.y23);
        let slope = |x: f64| {
            self.compliance.y22 * state.pressure_cauchy(x)
                + y23 * state.charge_cauchy(x)
                + self.profile.slope(x)
        };
        let (c, a) = (state.centre, state.half_width);
        let (nodes, weights) = crate::quadrature::gauss_legendre(64);
        let mut report = GapReport {
            min_gap: f64::INFINITY,
            at: f64::NAN,
            scale: self.profile.gap(a),
        };
        for dir in [1.0, -1.0] {
            let end = c + dir * a;
            for k in 1..=60 {
                let reach = a * (k as f64 / 60.0).powi(2);
                let vmax = reach.sqrt();
                // ∫_0^{vmax} g'(end + dir v²) 2v dv · dir
                let gap: f64 = nodes
                    .iter()
                    .zip(&weights)
                    .map(|(u, w)| {
                        let v = 0.5 * vmax * (u + 1.0);
                        0.5 * vmax * w * slope(end + dir * v * v) * 2.0 * v
                    })
                    .sum::<f64>()
                    * dir;
                if gap < report.min_gap {
                    report.min_gap = gap;
                    report.at = end + dir * reach;
                }
            }
        }
        report
    }
}

impl ContactState {
    /// `∫ f dt` over the contact by the contact integrals' rule (`contact_piece_nodes` on
    /// the pieces of [`graded_nodes`]), split at the traction's breakpoints
    /// and at `split` (if inside). With the centre kink of a normal-loading zone among the
    /// breakpoints (it was missing before), the arcsine moment's φ0 over the default history
    /// agrees with a 256-node rule to 1e−10 V of 17 V (the 96-node rule without the kink point:
    /// 8e−7 V).
    pub fn contact_integral(&self, split: Option<f64>, f: &dyn Fn(&[f64], &mut Vec<f64>)) -> f64 {
        let (at, weights) = graded_nodes(self.contact_points(split), self.contact_rule());
        let mut values = Vec::with_capacity(at.len());
        f(&at, &mut values);
        weights.iter().zip(&values).map(|(w, v)| w * v).sum()
    }

    /// The nodes of the contact integrals' rule on a piece `[x0, x1]` of this contact
    /// ([`contact_piece_nodes`]), for [`graded_nodes`].
    fn contact_rule(&self) -> impl Fn(f64, f64) -> usize + use<> {
        let (contact, m) = ((self.centre, self.half_width), self.pressure.beta.len());
        move |x0, x1| contact_piece_nodes(x0, x1, contact, m)
    }

    /// The contact ends, the traction's breakpoints inside the contact and `split` (if inside).
    fn contact_points(&self, split: Option<f64>) -> Vec<f64> {
        let (c, a) = (self.centre, self.half_width);
        let mut pts = vec![c - a, c + a];
        pts.extend(
            self.traction_breakpoints()
                .into_iter()
                .filter(|x| *x >= c - a && *x <= c + a),
        );
        if let Some(x) = split.filter(|x| *x > c - a && *x < c + a) {
            pts.push(x);
        }
        pts
    }

    /// The surface tangential displacement `ux(x)` and the normal approach δn of the punch.
    ///
    /// `ux` with the regularised kernel of seed eq. (4), `∫₀^∞ cos(sr)/s ds → −ln(|r|/d)`:
    /// `ux(x) = −½ ∫ ((w12 + χ w13) p + w13 w)(s) sign(x − s) ds − (y11/π) ∫ q(s) ln(|x − s|/d) ds`.
    /// The datum d adds `(y11/π) ln(d) Q`, a term linear in Q.
    ///
    /// `δn = uz(x) + x²/(2R)` (any x in the contact; evaluated at the contact centre), with
    /// `uz(x) = ½∫ w12 q(s) sign(x − s) ds − (1/π)∫ (y22 p + y23 g)(s) ln(|x − s|/d) ds`
    /// (eq. B integrated with the regularised kernel).
    ///
    /// Both from one evaluation of p, w and q on the nodes of [`Self::contact_integral`]'s
    /// rule, split at both x and the contact centre. Each logarithm's singularity is taken out,
    /// `∫ (f(s) − f(x)) ln(|x − s|/d) ds + f(x) ∫ ln(|x − s|/d) ds` (the second integral in
    /// closed form), so that the rule suffices. Measured on the default history (M = 64, 32
    /// nodes per piece): δ within 1e−18 m (1e−10 of its range) of a 256-node rule, where the
    /// 96-node rule without the subtraction was within 1.3e−17 m and the 32-node rule without
    /// it 6.4e−16 m. With both split points in one rule (before, each integral had its own),
    /// the records' δ against four times the nodes: 8.5e−12 of its range (default history,
    /// M = 32; 8.5e−11 before) and 5.2e−10 (Figure-3 history with Γ = 4e−7 C/m; 1.5e−9).
    pub fn displacement_and_approach(&self, model: &ContactModel, x: f64) -> (f64, f64) {
        self.displacement_and_approach_with(model, x, self.contact_rule())
    }

    /// [`Self::displacement_and_approach`] with `nodes(x0, x1)` nodes on the piece `[x0, x1]`
    /// instead of the contact integrals' rule.
    pub(crate) fn displacement_and_approach_with(
        &self,
        model: &ContactModel,
        x: f64,
        nodes: impl Fn(f64, f64) -> usize,
    ) -> (f64, f64) {
        let centre = self.centre;
        let mut points = self.contact_points(Some(x));
        points.push(centre);
        let (at, weights) = graded_nodes(points, nodes);
        // p, w and q at the nodes, then at x and the centre.
        let fields = |xs: &[f64]| {
            let (mut p, mut w, mut q) = (Vec::new(), Vec::new(), Vec::new());
            self.pressures_into(xs, &mut p);
            self.potential_charges_into(xs, &mut w);
            self.tractions_with(xs, &p, &mut q);
            (p, w, q)
        };
        let (p, w, q) = fields(&at);
        let (p0, w0, q0) = fields(&[x, centre]);
        let c = &model.compliance;
        let w13 = c.electric.map_or(0.0, |e| e.w13);
        let y23 = c.electric.map_or(0.0, |e| e.y23);
        let local = model.local_pressure_strain(self.split);
        // The densities of ux's sign integral and of uz's logarithmic one.
        let tangential = |p: f64, w: f64| local * p + w13 * w;
        let normal = |p: f64, w: f64| c.y22 * p + y23 * (self.split.ratio * p + w);
        let d = model.reference_distance;
        let log_distance = |from: f64, s: f64| {
            if (from - s).abs() > 0.0 {
                ((from - s).abs() / d).ln()
            } else {
                0.0
            }
        };
        let (q_x, normal_centre) = (q0[0], normal(p0[1], w0[1]));
        let mut sums = [0.0; 4];
        for k in 0..at.len() {
            let (s, wt) = (at[k], weights[k]);
            sums[0] += wt * tangential(p[k], w[k]) * (x - s).signum();
            sums[1] += wt * (q[k] - q_x) * log_distance(x, s);
            sums[2] += wt * q[k] * (centre - s).signum();
            sums[3] += wt * (normal(p[k], w[k]) - normal_centre) * log_distance(centre, s);
        }
        let (lo, hi) = (centre - self.half_width, centre + self.half_width);
        let pi = std::f64::consts::PI;
        let ux = -0.5 * sums[0] - c.y11 / pi * (sums[1] + q_x * log_moment(lo, hi, x, d));
        let uz =
            0.5 * c.w12 * sums[2] - (sums[3] + normal_centre * log_moment(lo, hi, centre, d)) / pi;
        (ux, uz + model.profile.gap(centre))
    }

    /// Where the traction is not smooth: the stick ends, and the ends, fade ramps and centre
    /// kinks of the zones in the chain.
    pub fn traction_breakpoints(&self) -> Vec<f64> {
        let Some(stick) = self.traction.stick.as_ref() else {
            return Vec::new();
        };
        let mut pts = vec![stick.lo, stick.hi];
        pts.extend(stick.chain_points());
        pts
    }
}

/// `∫ ln(|x − s|/d) ds` from `lo` to `hi`, in closed form (any x).
fn log_moment(lo: f64, hi: f64, x: f64, d: f64) -> f64 {
    // F(r) = r ln(|r|/d) − r is an antiderivative of ln(|r|/d) in r = s − x.
    let antiderivative = |r: f64| {
        if r.abs() > 0.0 {
            r * (r.abs() / d).ln() - r
        } else {
            0.0
        }
    };
    antiderivative(hi - x) - antiderivative(lo - x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The series `scale Σ (−1)^k U_{k−1}/k²`, k = 1..n: coefficients decaying only like
    /// 1/k², the tables' hard case.
    fn alternating_series(n: usize, scale: f64) -> BoundedSeries {
        BoundedSeries {
            beta: (1..=n)
                .map(|k| scale * (-1f64).powi(k as i32) / (k * k) as f64)
                .collect(),
        }
    }

    /// The tests' chain: a normal-loading-like zone (`alternating_series` of `terms` terms and a
    /// centre kink) on [−0.95, 0.95], faded into the zone [−0.8, 0.4] with a series of its own
    /// and the given extras, as in the first tangential phase; the base tabulated with
    /// `base_nodes` points per piece when given.
    fn faded_chain(
        terms: usize,
        base_nodes: Option<usize>,
        extras: Vec<(f64, f64, f64)>,
    ) -> StickZone {
        let base = std::sync::Arc::new(StickZone::new(
            -0.95,
            0.95,
            alternating_series(terms, 1.0),
            -0.3,
        ));
        if let Some(nodes) = base_nodes {
            base.tabulate(nodes);
        }
        let link = Inherited::new(base, Some((-0.8, -0.55)), Some((0.1, 0.4)));
        StickZone {
            inherited: Some(std::sync::Arc::new(link)),
            extras,
            ..StickZone::new(-0.8, 0.4, alternating_series(terms, 0.5), 0.0)
        }
    }

    /// The largest `|got − want|` over `points`, relative to the largest `|want|`.
    fn worst_relative(points: &[f64], got: impl Fn(f64) -> f64, want: impl Fn(f64) -> f64) -> f64 {
        let scale = points.iter().map(|&x| want(x).abs()).fold(0.0, f64::max);
        points
            .iter()
            .map(|&x| (got(x) - want(x)).abs() / scale)
            .fold(0.0, f64::max)
    }

    #[test]
    fn tabulated_cauchy_transform_matches_the_direct_one() {
        // A normal-loading-like zone (centre kink) faded into a narrower zone with a series of
        // its own, as in the first tangential phase; the table against the series and chain,
        // inside, next to every breakpoint, outside within the table and beyond it.
        let zone = faded_chain(64, Some(96), Vec::new());
        let direct = zone.clone();
        zone.tabulate(96);
        let mut points: Vec<f64> = (0..=2000).map(|i| -2.1 + 3.7 * i as f64 / 2000.0).collect();
        for b in [-2.0, -0.8, -0.55, 0.0, 0.1, 0.4, 1.6] {
            points.extend([b - 1e-9, b - 1e-4, b + 1e-4, b + 1e-9]);
        }
        let worst = worst_relative(
            &points,
            |x| zone.correction_cauchy(x),
            |x| direct.correction_cauchy(x),
        );
        // Measured 3.6e−12 (1e−9 outside the zone's left end, where the exterior transform
        // has its square root); the bound is 1e−11.
        assert!(worst < 1e-11, "worst relative difference {worst:e}");
        // The batched lookup (four points of a piece at a time, direct beyond the table) is
        // the one-point lookup bit for bit.
        let mut batch = Vec::new();
        zone.correction_cauchys_into(&points, &mut batch);
        for (v, &x) in batch.iter().zip(&points) {
            assert_eq!(v.to_bits(), zone.correction_cauchy(x).to_bits(), "at {x}");
        }
    }

    /// A zone without `tabulate`'s table (a step's accepted zone: a series of its own, the
    /// normal-loading-like zone faded into it, a half-ellipse extra) tabulates its transform on
    /// the outer pieces at a batch with enough points there, not before; the tables against
    /// the series and chain on both pieces, next to the stick ends (where the transform has
    /// its square root) and beyond the tables (direct); the one-point form is the batch's to
    /// the bit before and after.
    #[test]
    fn exterior_tables_match_the_direct_transform() {
        let zone = faded_chain(128, Some(160), vec![(-0.55, 0.4, 0.2)]);
        let direct = zone.clone();
        let (w, mut out) = (zone.hi - zone.lo, Vec::new());
        let few: Vec<f64> = (1..=20)
            .map(|i| zone.hi + 0.01 * w * f64::from(i))
            .collect();
        zone.correction_cauchys_into(&few, &mut out);
        assert!(
            zone.exterior_table.0.get().is_none(),
            "{} points",
            few.len()
        );
        // Both outer pieces, graded towards the stick ends, and points beyond the tables.
        let mut points: Vec<f64> = Vec::new();
        for i in 1..=400 {
            let r = w * (f64::from(i) / 400.0).powi(3);
            points.extend([zone.lo - r, zone.hi + r]);
        }
        points.extend([zone.lo - 1.5 * w, zone.hi + 2.0 * w]);
        let mut batch = Vec::new();
        zone.correction_cauchys_into(&points, &mut batch);
        assert!(zone.exterior_table.0.get().is_some());
        let worst = worst_relative(
            &points,
            |x| zone.correction_cauchy(x),
            |x| direct.correction_cauchy(x),
        );
        // Measured 5.7e−13, next to the stick ends (the closest points 2e−8 w from them; at
        // 1e−12 w the direct sums themselves are off, by 5e−10 against the table's limit). On
        // every accepted zone of the Figure-3 histories (η = 0.2, 0.3, insulating at 0.4) and
        // the variable-amplitude history, M = 64 … 512, at 800 points from 1.6e−8 w to w on
        // both sides: 2.5e−12, and 1.6e−11 for one variable-amplitude zone at M = 128. The
        // bound is 1e−12.
        assert!(worst < 1e-12, "worst relative difference {worst:e}");
        for (v, &x) in batch.iter().zip(&points) {
            assert_eq!(v.to_bits(), zone.correction_cauchy(x).to_bits(), "at {x}");
        }
    }

    /// A link whose ramps moved by up to `FADE_TABLE_REUSE` of their length from those of a
    /// link with a built table takes its nodes, and its transform and integral agree with a
    /// fresh table's to round-off; a larger move, another zone or another side builds its own.
    #[test]
    fn a_fade_table_is_reused_for_ramps_that_hardly_moved() {
        let base = std::sync::Arc::new(StickZone::new(
            -0.95,
            0.95,
            alternating_series(64, 1.0),
            -0.3,
        ));
        base.tabulate(96);
        let link = |shift: f64| {
            Inherited::new(
                base.clone(),
                Some((-0.8 + shift, -0.55 + shift)),
                Some((0.1 - shift, 0.4 - shift)),
            )
        };
        let built = link(0.0);
        let points: Vec<f64> = (0..=300)
            .map(|i| -1.2 + 2.4 * f64::from(i) / 300.0)
            .collect();
        built.cauchy_into(&points, &mut Vec::new());
        // 0.9 of the largest move (the ramps are 0.25 and 0.3 long).
        let (reused, fresh) = (
            link(0.9e-5 * 0.25).reusing_table_of(&built),
            link(0.9e-5 * 0.25),
        );
        assert!(reused.table.get().is_some() && fresh.table.get().is_none());
        let (mut a, mut b) = (Vec::new(), Vec::new());
        reused.cauchy_into(&points, &mut a);
        fresh.cauchy_into(&points, &mut b);
        let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
            / scale;
        // Measured 3.7e−15 at this move (2.4e−15 at 1e−10 of the ramp, round-off), growing
        // like the move squared beyond: 2.8e−14 at 9e−5, 2.1e−13 at 3e−4, 2.4e−12 at 1e−3
        // (the pieces end that far from the jumps in χ'''). The bound is 1e−14.
        assert!(worst < 1e-14, "transform {worst:e}");
        assert!((reused.integral() - fresh.integral()).abs() < 1e-14 * fresh.integral().abs());
        let other = std::sync::Arc::new(StickZone::new(
            -0.95,
            0.95,
            alternating_series(64, 1.0),
            -0.3,
        ));
        for not in [
            link(2e-5 * 0.25),
            Inherited::new(other, built.ramp_lo, built.ramp_hi),
            Inherited::new(base.clone(), None, built.ramp_hi),
        ] {
            assert!(not.reusing_table_of(&built).table.get().is_none());
        }
    }

    #[test]
    fn tabulated_values_match_the_direct_ones() {
        // The chain of the test above (a centre kink, `u ln|u|` at the base's centre, faded
        // into a narrower zone, here with a half-ellipse extra), tabulated, against the same
        // chain untabulated: inside, next to every breakpoint, and outside (zero). Only the
        // zone with a link gets a value table.
        let chain = |tabulated: bool| {
            let zone = faded_chain(64, tabulated.then_some(96), vec![(-0.55, 0.4, 0.2)]);
            if tabulated {
                zone.tabulate(96);
            }
            zone
        };
        let (zone, direct) = (chain(true), chain(false));
        let mut points: Vec<f64> = (0..=2000).map(|i| -1.1 + 2.2 * i as f64 / 2000.0).collect();
        for b in [-0.95, -0.8, -0.55, 0.0, 0.1, 0.4, 0.95] {
            points.extend([b - 1e-9, b - 1e-4, b, b + 1e-4, b + 1e-9]);
        }
        let worst = worst_relative(
            &points,
            |x| zone.correction_at(x),
            |x| direct.correction_at(x),
        );
        // Measured 2.5e−12, next to the zone's left end (the series' 1/k² tail: 7.0e−12 with
        // 128 terms and 160 nodes, 1.5e−11 with 256 and 288); 1e−8 at the centre kink before
        // `chain_kinks` was taken out of the table. The bound is 1e−11.
        assert!(worst < 1e-11, "worst relative difference {worst:e}");
        for x in [-1.0, -0.8, 0.4, 0.5] {
            assert_eq!(zone.correction_at(x).to_bits(), 0, "outside, at {x}");
        }
        let mut batch = Vec::new();
        zone.corrections_into(&points, &mut batch);
        for (v, &x) in batch.iter().zip(&points) {
            assert_eq!(v.to_bits(), zone.correction_at(x).to_bits(), "at {x}");
        }
    }

    /// The half-ellipse on `[u, v]` is the n = 1 term of a bounded series on that interval
    /// (β_1 = h, τ = (x − m)/h): its values, Cauchy transform (inside and on both sides
    /// outside) and integral (h times the series' ∫ dτ) against the series' own formulas,
    /// which the quadrature module tests against brute-force quadrature.
    #[test]
    fn half_ellipse_is_the_first_bounded_term() {
        let (u, v) = (-0.3, 0.9);
        let (m, h) = (0.5 * (u + v), 0.5 * (v - u));
        let series = BoundedSeries { beta: vec![h] };
        for x in [-2.0, -0.31, -0.2, 0.1, 0.5, 0.89, 0.95, 3.0] {
            let t = (x - m) / h;
            assert!(
                (half_ellipse(x, u, v) - series.density(t)).abs() < 1e-15,
                "{x}"
            );
            assert!(
                (half_ellipse_cauchy(x, u, v) - series.cauchy(t)).abs() < 1e-15,
                "{x}"
            );
        }
        assert!((half_ellipse_integral(u, v) - h * series.integral()).abs() < 1e-15);
    }

    #[test]
    fn log_moment_matches_hand_integrals() {
        // ∫_{−1}^{1} ln|s| ds = −2; ∫_{−1}^{1} ln(2 − s) ds = ∫_1^3 ln r dr = 3 ln 3 − 2;
        // the datum d subtracts (hi − lo) ln d; x = lo gives ∫_0^2 ln r dr = 2 ln 2 − 2.
        let cases = [
            (0.0, 1.0, -2.0),
            (2.0, 1.0, 3.0 * 3f64.ln() - 2.0),
            (-2.0, 1.0, 3.0 * 3f64.ln() - 2.0),
            (0.0, 0.01, -2.0 - 2.0 * 0.01f64.ln()),
            (-1.0, 1.0, 2.0 * 2f64.ln() - 2.0),
        ];
        for (x, d, expected) in cases {
            let got = log_moment(-1.0, 1.0, x, d);
            assert!(
                (got - expected).abs() < 1e-14,
                "x = {x}, d = {d}: {got} vs {expected}"
            );
        }
    }

    /// `k(u)` with one logarithm equals the definition `−(2u/π)(ln(1 + √(1−u²)) − ln|u|)`
    /// to round-off across (−1, 1) (measured 1.1e−16 at worst, k being at most 0.47; bound
    /// 1e−15), and is 0 at and beyond the ends, at 0, and below 1e−300, where the definition
    /// is at most 4.4e−298 and the quotient would overflow.
    #[test]
    fn kink_density_with_one_logarithm_is_the_definition() {
        let two_logs = |u: f64| {
            -2.0 * u / std::f64::consts::PI * ((1.0 + (1.0 - u * u).sqrt()).ln() - u.abs().ln())
        };
        let mut worst: f64 = 0.0;
        for k in 1..2000 {
            let u = -1.0 + k as f64 / 1000.0;
            for u in [u, u * 1e-3, u * 1e-9, u * 1e-150, u * 1e-299] {
                worst = worst.max((kink_density(u) - two_logs(u)).abs());
            }
        }
        assert!(worst < 1e-15, "{worst:e}");
        for u in [-1.0, 1.0, 1.5, 0.0, 1e-301, -3e-310, 5e-324] {
            assert!(kink_density(u).abs() <= 0.0, "at {u:e}");
        }
    }

    /// The fade sums in SIMD lanes are the one-point sums to the bit, with points that lie on
    /// a node, within `tiny` of one, within twice `tiny` (the masked groups) and elsewhere, in
    /// vectors and in the lanes' tail, in no order and in increasing and decreasing order (the
    /// two ways of finding the near nodes); a node on a point is left out (the sum stays
    /// finite).
    #[test]
    fn fade_sums_in_lanes_equal_the_one_point_sums() {
        let tiny = 1e-14;
        let nodes: Vec<(f64, f64, f64)> = (0..37)
            .map(|k| {
                let t = -1.0 + 2.0 * (k as f64 + 0.5) / 37.0;
                (t, 0.05 * (1.0 + t * t), 0.5 + 0.5 * (2.0 * t).sin())
            })
            .collect();
        let on = |k: usize| nodes[k].0;
        let x = vec![
            on(3),
            on(10) + 0.5 * tiny,
            on(11) - 1.5 * tiny,
            0.123,
            on(36),
            on(0) - 0.7 * tiny,
            -0.45,
            0.9,
            on(20) + 3.0 * tiny,
            0.31,
            on(17),
        ];
        let chi = |t: f64| 0.4 + 0.3 * t;
        let lanes = |x: &[f64]| {
            let cx: Vec<f64> = x.iter().map(|&t| chi(t)).collect();
            let mut sums = vec![-0.0; x.len()];
            pulp::Arch::new().dispatch(FadeSums {
                nodes: &nodes,
                x,
                cx: &cx,
                tiny,
                sums: &mut sums,
            });
            sums
        };
        // In no order (a bisection per point), increasing and decreasing (one walk).
        let mut increasing = x.clone();
        increasing.sort_by(f64::total_cmp);
        let decreasing: Vec<f64> = increasing.iter().rev().copied().collect();
        for points in [&x, &increasing, &decreasing] {
            for (&xi, &sum) in points.iter().zip(&lanes(points)) {
                let one = fade_sum(&nodes, xi, chi(xi), tiny);
                assert_eq!(sum.to_bits(), one.to_bits(), "at {xi}: {sum} vs {one}");
                assert!(sum.is_finite(), "at {xi}");
            }
        }
        // The skipped node is really left out: against the sum without it.
        let rest: Vec<_> = [&nodes[..3], &nodes[4..]].concat();
        let without = fade_sum(&rest, x[0], chi(x[0]), tiny);
        let with_lanes = lanes(&x)[0];
        assert!(
            (with_lanes - without).abs() < 1e-13 * without.abs(),
            "{with_lanes} vs {without}"
        );
    }

    #[test]
    fn inherited_corrections_vanish_outside_the_new_zone() {
        // `correction_at` returns zero outside its zone without walking the chain; that is
        // exact only if every link `inheritance_for` builds is zero there: a link carried
        // whole lies inside the new zone, a faded one has χ = 0 beyond the new zone's ends.
        let series = BoundedSeries {
            beta: (1..=16).map(|k| 1.0 / (k * k) as f64).collect(),
        };
        let old = std::sync::Arc::new(StickZone::new(-0.9, 0.9, series.clone(), -0.3));
        let inner = std::sync::Arc::new(StickZone {
            inherited: old.inheritance_for(-0.7, 0.5, 64),
            ..StickZone::new(-0.7, 0.5, series, 0.0)
        });
        // New zones inside, across either end, and around the older zones.
        let cases = [
            (-0.6, 0.4),
            (-0.8, 0.2),
            (-0.2, 0.7),
            (-0.95, 0.95),
            (-0.5, 0.45),
        ];
        let mut links = 0;
        for base in [&old, &inner] {
            for (lo, hi) in cases {
                let Some(link) = base.inheritance_for(lo, hi, 64) else {
                    continue;
                };
                links += 1;
                for i in 0..=400 {
                    let x = -1.2 + 2.4 * i as f64 / 400.0;
                    if x > lo && x < hi {
                        continue;
                    }
                    let outside_link = !(x > link.zone.lo && x < link.zone.hi);
                    assert!(
                        outside_link || link.chi(x).abs() <= 0.0,
                        "zone [{lo}, {hi}], link [{}, {}]: χ({x}) = {}",
                        link.zone.lo,
                        link.zone.hi,
                        link.chi(x)
                    );
                }
            }
        }
        assert!(links >= 8, "{links} links built");
    }

    #[test]
    fn piece_ends_keep_every_point_and_balance_neighbours() {
        // A long piece next to a short one (a stick end 0.003 beyond a ramp end) is halved
        // until no piece is more than three times as long as a neighbour.
        let given = vec![-0.569840, -0.522144, -0.518976, 0.4, 0.4, -0.988128];
        let ends = piece_ends(given.clone());
        for p in &given {
            assert!(ends.contains(p), "{p} kept");
        }
        assert!(
            ends.windows(2).all(|w| w[1] > w[0]),
            "sorted, no duplicates"
        );
        let lengths: Vec<f64> = ends.windows(2).map(|w| w[1] - w[0]).collect();
        for pair in lengths.windows(2) {
            assert!(
                pair[0] <= 3.0 * pair[1] && pair[1] <= 3.0 * pair[0],
                "{pair:?}"
            );
        }
        // Halving only: a few extra points per decade of length ratio, not a uniform grid.
        assert!(ends.len() < 30, "{} ends", ends.len());
        // What the balance is for: ∫ ln|x − x0| over the pieces, x0 the end of the short piece
        // and so just outside the long one. 32-node rule: relative error 1.3e−8 balanced,
        // 1.1e−6 with the given pieces (measured); the bound is 1e−7.
        let x0 = -0.518976;
        let primitive = |x: f64| (x - x0) * (x - x0).abs().ln() - (x - x0);
        let want = primitive(0.4) - primitive(-0.988128);
        let mut log = |xs: &[f64], out: &mut Vec<f64>| {
            out.extend(xs.iter().map(|x| (x - x0).abs().ln()));
        };
        let table = graded_cumulative(given, 32, None, &mut log);
        let error = ((table.total - want) / want).abs();
        assert!(error < 1e-7, "relative error {error:e}");
    }
}
