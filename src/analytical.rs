//! Closed-form reference solutions (the oracles of the tests).
//!
//! - Hertz line contact of a rigid cylinder on a half-plane of plane-strain compliance `Y*`
//!   (`2/E*` for an elastic solid): `a² = 2PRY*/π = 4PR/(πE*)`, `p0 = 2P/(πa)`,
//!   `p(x) = p0 √(1 − x²/a²)`.
//! - Zhou & Lee (2012), frictionless conducting punch on a piezoelectric half-plane, in the
//!   form derived in [`crate::contact`]: Hertz with `Y* = y22 − y23²/y33`, and
//!   `g(x) = k p(x) + (Γ − kP)/(π √(a² − x²))`, `k = −y23/y33`.
//! - McEwen (1949), the stresses below a Hertz line contact and below its sliding traction
//!   ([`mcewen`]).
//! - The flat punch with rounded corners (flat half-width b, corner radius R; Ciavarella,
//!   Hills and Monno 1998, *Proc. IMechE C* 212, 319–328): [`FlatRounded`], its load, peak
//!   pressure and, on an uncoupled half-plane, the Cattaneo-type stick zone.

use std::f64::consts::PI;

/// Hertz line contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hertz {
    /// Half-width a (m).
    pub half_width: f64,
    /// Peak pressure p0 (Pa).
    pub peak_pressure: f64,
}

impl Hertz {
    /// For load P (N/m), radius R (m) and compliance Y* (1/Pa): `a² = 2 P R Y*/π`,
    /// `p0 = 2P/(πa)` (Johnson, *Contact Mechanics*, eqs. 4.43–4.45 with `Y* = 2/E*`).
    ///
    /// ```
    /// use fretsim::analytical::Hertz;
    /// use fretsim::material::ALUMINIUM;
    ///
    /// let e_star = ALUMINIUM.plane_strain_modulus();
    /// let h = Hertz::new(2240.0, 0.01, 2.0 / e_star);
    /// // ∫p dx = π a p0 / 2 = P
    /// assert!((std::f64::consts::PI * h.half_width * h.peak_pressure / 2.0 - 2240.0).abs() < 1e-9);
    /// assert!((h.pressure(0.0) - h.peak_pressure).abs() < 1e-6 && h.pressure(h.half_width) == 0.0);
    /// ```
    pub fn new(normal_load: f64, radius: f64, compliance: f64) -> Self {
        let a = (2.0 * normal_load * radius * compliance / PI).sqrt();
        Self {
            half_width: a,
            peak_pressure: 2.0 * normal_load / (PI * a),
        }
    }

    /// p(x) (Pa), zero outside the contact.
    pub fn pressure(&self, x: f64) -> f64 {
        let r = x / self.half_width;
        if r.abs() >= 1.0 {
            0.0
        } else {
            self.peak_pressure * (1.0 - r * r).sqrt()
        }
    }
}

/// Zhou & Lee's frictionless conducting-punch solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZhouLee {
    /// The Hertzian pressure with the effective compliance.
    pub hertz: Hertz,
    /// k = −y23/y33 (C/N).
    pub charge_per_force: f64,
    /// Γ − kP (C/m).
    pub free_charge: f64,
}

impl ZhouLee {
    /// For P, R, Y* = y22 − y23²/y33, k and Γ.
    pub fn new(
        normal_load: f64,
        radius: f64,
        compliance: f64,
        charge_per_force: f64,
        charge: f64,
    ) -> Self {
        Self {
            hertz: Hertz::new(normal_load, radius, compliance),
            charge_per_force,
            free_charge: charge - charge_per_force * normal_load,
        }
    }

    /// g(x) (C/m²) inside the contact.
    pub fn charge(&self, x: f64) -> f64 {
        let a = self.hertz.half_width;
        self.charge_per_force * self.hertz.pressure(x)
            + self.free_charge / (PI * (a * a - x * x).sqrt())
    }
}

/// Complete elliptic integral of the first kind `K(k) = ∫₀^{π/2} dθ/√(1 − k² sin²θ)` (modulus k),
/// by the arithmetic–geometric mean.
pub fn elliptic_k(k: f64) -> f64 {
    let (mut x, mut y) = (1.0, (1.0 - k * k).sqrt());
    for _ in 0..60 {
        let (xn, yn) = ((x + y) / 2.0, (x * y).sqrt());
        x = xn;
        y = yn;
        if (x - y).abs() < 1e-16 * x {
            break;
        }
    }
    std::f64::consts::PI / (2.0 * x)
}

/// Spence's self-similar stick zone for a Hertzian line contact in Goodman's approximation:
/// `β/η = K'(b/a)/K(b/a)`, with `K'(k) = K(√(1 − k²))`. Returns b/a for a given β/η > 0
/// (bisection on the monotone ratio).
///
/// Derivation (checked independently in the project notes): with Hertzian p, slip traction
/// `η p sign(x)` and the strain `C|x|` in the stick zone, the stick traction is bounded with no
/// square-root term at ±b only if this ratio holds; then
/// `C = −(π η)/(2 R k K(k))` (for `∂ux/∂x` of the half-plane; `k = b/a`).
pub fn spence_stick_ratio(beta_over_eta: f64) -> f64 {
    let ratio = |k: f64| elliptic_k((1.0 - k * k).sqrt()) / elliptic_k(k);
    let (mut lo, mut hi) = (1e-300f64, 1.0 - 1e-16);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        // ratio decreases from ∞ (k → 0) to 0 (k → 1).
        if ratio(mid) > beta_over_eta {
            lo = mid
        } else {
            hi = mid
        }
    }
    0.5 * (lo + hi)
}

/// Spence's slope `C = −π η/(2 R k K(k))` of the locked-in strain (1/m), Goodman's approximation.
pub fn spence_strain_slope(friction: f64, radius: f64, stick_ratio: f64) -> f64 {
    -std::f64::consts::PI * friction / (2.0 * radius * stick_ratio * elliptic_k(stick_ratio))
}

/// Cattaneo–Mindlin and Mindlin–Deresiewicz line contact in the uncoupled limit (β = 0):
/// Hertzian pressure `p0√(1 − x²/a²)`, friction η, normal load P.
///
/// - Loading from 0 to Q: stick zone `|x| ≤ c`, `c/a = √(1 − |Q|/(ηP))`,
///   `q = sign(Q) η p0 [√(1 − x²/a²) − (c/a)√(1 − x²/c²)]` (inner term only for |x| < c).
/// - Unloading from Q* to Q (Masing): `q = q_load(Q*) − 2 q_load((Q* − Q)/2)`, stick zone
///   `c'/a = √(1 − |Q* − Q|/(2ηP))`.
#[derive(Debug, Clone, Copy)]
pub struct CattaneoMindlin {
    /// Contact half-width a (m).
    pub half_width: f64,
    /// Peak pressure p0 (Pa).
    pub peak_pressure: f64,
    /// Friction coefficient η.
    pub friction: f64,
    /// Normal load P (N/m).
    pub normal_load: f64,
}

impl CattaneoMindlin {
    /// From a Hertz solution.
    pub fn new(hertz: Hertz, friction: f64, normal_load: f64) -> Self {
        Self {
            half_width: hertz.half_width,
            peak_pressure: hertz.peak_pressure,
            friction,
            normal_load,
        }
    }

    /// c/a after loading from 0 to Q.
    pub fn stick_ratio(&self, q: f64) -> f64 {
        (1.0 - q.abs() / (self.friction * self.normal_load))
            .max(0.0)
            .sqrt()
    }

    /// Traction after loading from 0 to Q (Pa).
    pub fn loading_traction(&self, q: f64, x: f64) -> f64 {
        let r = x / self.half_width;
        if r.abs() >= 1.0 {
            return 0.0;
        }
        let c = self.stick_ratio(q);
        let inner = if r.abs() < c {
            c * (1.0 - (r / c).powi(2)).sqrt()
        } else {
            0.0
        };
        q.signum() * self.friction * self.peak_pressure * ((1.0 - r * r).sqrt() - inner)
    }

    /// c'/a after unloading from Q* to Q.
    pub fn unloading_stick_ratio(&self, q_star: f64, q: f64) -> f64 {
        self.stick_ratio((q_star - q) / 2.0)
    }

    /// Traction after unloading from Q* to Q (Pa).
    pub fn unloading_traction(&self, q_star: f64, q: f64, x: f64) -> f64 {
        self.loading_traction(q_star, x) - 2.0 * self.loading_traction((q_star - q) / 2.0, x)
    }
}

/// Cattaneo–Mindlin with a bulk stress σB along the surface, for a **rigid** punch on the
/// uncoupled half-plane (only the half-plane strains): after pressing to P, Q and σB raised
/// from zero in proportion (or in one step), the stick zone is `|x − e| ≤ c` with
///
/// ```text
/// c/a = √(1 − |Q|/(ηP)),   e = sign(Q) a s̃ σB/(y11 ηp0) = sign(Q) aσB/(2ηp0),
/// q = sign(Q) η p0 [√(1 − x²/a²) − (c/a)√(1 − (x − e)²/c²)]   (inner term on |x − e| < c)
/// ```
///
/// (`s̃ = (1 − ν²)/E` the bulk compliance, `y11 = 2(1 − ν²)/E`): the q-part of the surface
/// strain on the stick zone is `−sign(Q) y11 ηp0 e/a`, which cancels the bulk strain `s̃σB`.
/// Nowell and Hills' `e = aσB/(4ηp0)` is for two similar elastic bodies, whose tangential
/// compliance is twice the rigid punch's. It needs `|e| + c ≤ a`, and along a proportional
/// path (Q*, σB*) slip that never reverses: nested stick zones and growing slip, which
/// `|σB*|/p0 ≤ |Q*|/P` ensures.
#[derive(Debug, Clone, Copy)]
pub struct BulkStressCattaneo {
    /// The contact without bulk stress.
    pub contact: CattaneoMindlin,
}

impl BulkStressCattaneo {
    /// From the Cattaneo–Mindlin contact.
    pub fn new(contact: CattaneoMindlin) -> Self {
        Self { contact }
    }

    /// The stick zone's centre e (m) under Q (N/m) and σB (Pa).
    pub fn offset(&self, q: f64, bulk_stress: f64) -> f64 {
        let c = &self.contact;
        q.signum() * c.half_width * bulk_stress / (2.0 * c.friction * c.peak_pressure)
    }

    /// The stick zone's half-width c (m) under Q.
    pub fn stick_half_width(&self, q: f64) -> f64 {
        self.contact.half_width * self.contact.stick_ratio(q)
    }

    /// Whether the stick zone lies in the contact, `|e| + c ≤ a`.
    pub fn holds(&self, q: f64, bulk_stress: f64) -> bool {
        self.offset(q, bulk_stress).abs() + self.stick_half_width(q) <= self.contact.half_width
    }

    /// The traction q(x) (Pa).
    pub fn traction(&self, q: f64, bulk_stress: f64, x: f64) -> f64 {
        let cm = &self.contact;
        let a = cm.half_width;
        let r = x / a;
        if r.abs() >= 1.0 {
            return 0.0;
        }
        let (e, c) = (self.offset(q, bulk_stress), self.stick_half_width(q));
        let t = (x - e) / c;
        let inner = if t.abs() < 1.0 {
            (c / a) * (1.0 - t * t).sqrt()
        } else {
            0.0
        };
        q.signum() * cm.friction * cm.peak_pressure * ((1.0 - r * r).sqrt() - inner)
    }
}

impl CattaneoMindlin {
    /// Punch displacement after loading from 0 to Q (m), for tangential compliance `y11 = 2/E*`
    /// and datum distance d (the regularised kernel `−ln(|r|/d)`):
    /// `δ = −(y11 ηP/π)[ln(a/2d) − ½ − (c/a)²(ln(c/2d) − ½)]`, odd in Q. It follows from
    /// `ux(0) = −(y11/π)∫ q(s) ln(|s|/d) ds` and `∫√(a² − s²) ln(|s|/d) ds = (πa²/2)(ln(a/2d) − ½)`.
    pub fn loading_displacement(&self, q: f64, y11: f64, d: f64) -> f64 {
        let limit = self.friction * self.normal_load;
        let a = self.half_width;
        let ratio = 1.0 - q.abs() / limit;
        let c = a * ratio.max(0.0).sqrt();
        let inner = if c > 0.0 {
            ratio * ((c / (2.0 * d)).ln() - 0.5)
        } else {
            0.0
        };
        -q.signum() * y11 * limit / std::f64::consts::PI * (((a / (2.0 * d)).ln() - 0.5) - inner)
    }

    /// Displacement on the branch from a reversal at Q* (Masing): `δ(Q*) − 2 δ_load((Q* − Q)/2)`.
    pub fn unloading_displacement(&self, q_star: f64, q: f64, y11: f64, d: f64) -> f64 {
        self.loading_displacement(q_star, y11, d)
            - 2.0 * self.loading_displacement((q_star - q) / 2.0, y11, d)
    }
}

/// The frictionless flat punch with rounded corners on a half-plane of pressure compliance Y*
/// ([`crate::contact::Profile::FlatRounded`]): with `φ0 = arcsin(b/a)` for a contact
/// `|x| ≤ a`, `a > b`, from `P = (1/Y*)∫ x h'(x)/√(a² − x²) dx` and
/// `p(x) = (√(a² − x²)/(π Y*)) ∫ h'(s)/(√(a² − s²)(s − x)) ds` (bounded at both ends),
///
/// ```text
/// P(a) = a² (π/2 − φ0 − sin φ0 cos φ0)/(R Y*)
/// p(0) = (2a/(π R Y*)) [π/2 − φ0 − sin φ0 ln((1 + cos φ0)/sin φ0)]
/// ```
///
/// Hertz's at b = 0. Under a tangential load Q < ηP from zero at constant P, on an uncoupled
/// half-plane (Dundurs' β = 0), the shear traction is `q = η(p(x; a) − p(x; c))` (Ciavarella's
/// and Jäger's superposition of the same punch's pressures), so the stick zone `|x| < c`
/// carries `P(c) = P − |Q|/η`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlatRounded {
    /// Flat half-width b (m).
    pub half_flat: f64,
    /// Corner radius R (m).
    pub radius: f64,
    /// Pressure compliance Y* (1/Pa).
    pub compliance: f64,
}

impl FlatRounded {
    /// The load P (N/m) that a contact of half-width `a` (m) carries; 0 for `a ≤ b`.
    pub fn load(&self, a: f64) -> f64 {
        if a <= self.half_flat {
            return 0.0;
        }
        let phi = (self.half_flat / a).asin();
        a * a * (PI / 2.0 - phi - phi.sin() * phi.cos()) / (self.radius * self.compliance)
    }

    /// The contact half-width (m) under `load` (N/m): the root of [`Self::load`], which rises
    /// monotonically from b, bracketed and found by bisection to round-off.
    pub fn half_width(&self, load: f64) -> f64 {
        let hertz = Hertz::new(load, self.radius, self.compliance).half_width;
        let (mut lo, mut hi) = (self.half_flat, self.half_flat + hertz);
        while self.load(hi) < load {
            hi = self.half_flat + 2.0 * (hi - self.half_flat);
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if self.load(mid) < load {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// The pressure at the centre (Pa) of a contact of half-width `a`.
    pub fn centre_pressure(&self, a: f64) -> f64 {
        let phi = (self.half_flat / a).asin();
        let log = if phi > 0.0 {
            phi.sin() * ((1.0 + phi.cos()) / phi.sin()).ln()
        } else {
            0.0
        };
        2.0 * a / (PI * self.radius * self.compliance) * (PI / 2.0 - phi - log)
    }

    /// The stick-zone half-width c (m) after a tangential load Q from zero at constant `load`
    /// P with friction η, on an uncoupled half-plane: `P(c) = P − |Q|/η`.
    pub fn stick_half_width(&self, load: f64, friction: f64, q: f64) -> f64 {
        self.half_width(load - q.abs() / friction)
    }
}

/// Wallis's integral `W(n) = ∫₀^{π/2} sinⁿφ dφ` for real n ≥ 1, by 64-point Gauss–Legendre
/// on the smooth integrand (`W(1) = 1`, `W(2) = π/4`, `W(3) = 2/3` to round-off).
pub fn wallis(n: f64) -> f64 {
    let (nodes, weights) = crate::quadrature::gauss_legendre(64);
    let half = PI / 4.0;
    nodes
        .iter()
        .zip(&weights)
        .map(|(x, w)| w * half * (half * (1.0 + x)).sin().powf(n))
        .sum()
}

/// The frictionless contact half-width (m) of the power-law punch `h = A|x|ⁿ` under load P
/// (N/m) on a half-plane of pressure compliance Y*: `P = 2nA aⁿ W(n)/Y*` (from
/// `P = (1/Y*)∫ x h'(x)/√(a² − x²) dx`, x = a sin φ), Hertz's at n = 2, A = 1/(2R).
pub fn power_law_half_width(coefficient: f64, exponent: f64, load: f64, compliance: f64) -> f64 {
    (load * compliance / (2.0 * exponent * coefficient * wallis(exponent))).powf(1.0 / exponent)
}

/// McEwen (1949), Johnson *Contact Mechanics* eqs. (7.5)–(7.7): `(σxx, σzz, σxz)` below a
/// Hertz line contact of half-width 1 and peak pressure 1 (`normal`: `p = √(1 − x²)`) and
/// below the traction `q = √(1 − x²)` along +x on the half-plane (`tangential`, a sliding
/// contact's), at (x, z) in units of the half-width, z ≥ 0 the depth; scale a contact of
/// half-width a and peaks p0, q0 as `p0·normal(x/a, z/a) + q0·tangential(x/a, z/a)`. The
/// normal part's σxz has the sign of Flamant's solution (`σxz = σr xz/r² < 0` for x > 0); the
/// tangential part gives `σxz → −q` and `σxx → −2x` on the surface. With `m² = (root + b)/2`,
/// `n² = (root − b)/2`, `b = 1 − x² + z²`, `root = √(b² + 4x²z²)`, the smaller of m², n² is
/// taken from their product x²z² (no cancellation inside the contact near the surface).
pub fn mcewen(x: f64, z: f64) -> ([f64; 3], [f64; 3]) {
    let b = 1.0 - x * x + z * z;
    let root = (b * b + 4.0 * x * x * z * z).sqrt();
    let (m2, n2) = if b >= 0.0 {
        let m2 = 0.5 * (root + b);
        (m2, x * x * z * z / m2)
    } else {
        let n2 = 0.5 * (root - b);
        (x * x * z * z / n2, n2)
    };
    let (m, n) = (m2.sqrt(), x.signum() * n2.sqrt());
    let d = m * m + n * n;
    let normal = [
        -(m * (1.0 + (z * z + n * n) / d) - 2.0 * z),
        -m * (1.0 - (z * z + n * n) / d),
        -n * (m * m - z * z) / d,
    ];
    let tangential = [
        n * (2.0 - (z * z - m * m) / d) - 2.0 * x,
        -n * (m * m - z * z) / d,
        -(m * (1.0 + (z * z + n * n) / d) - 2.0 * z),
    ];
    (normal, tangential)
}
