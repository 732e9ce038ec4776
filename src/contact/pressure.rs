//! The pressure and charge sub-problems for a given shear traction, shared by every solver
//! state (seed eqs. 24–29, 37–42, 52–57).
//!
//! Pressure (bounded at both contact ends), on `x = c + aτ`:
//!
//! ```text
//! (1/π)⨍ p(θ)/(θ − τ) dθ = −(c + aτ)/(R Y*) − (κ/Y*) q(c + aτ),     ∫ p dx = P
//! ```
//!
//! Writing `p = a ψ₁ + ψ_q` with `ψ₁` the response to `−τ/(RY*)` and `ψ_q` the response to the
//! shear term, the consistency condition (zero discrete Chebyshev mean of the right-hand side)
//! gives `c = R Y* mean(−(κ/Y*) q)` and the resultant gives the quadratic
//! `a² I₁ + a I_q = P` (`I` the integrals of ψ over θ). Because q is sampled at the new points,
//! (a, c) are iterated to a fixed point; without shear coupling one pass is exact.
//!
//! Charge (conducting punch), on the unbounded grid:
//! `(1/π)⨍ w(θ)/(θ − τ) dθ = −(w13/y33) q(c + aτ)`, `∫ w dx = Γ − kP`.

use crate::error::SolveFailure;
use crate::quadrature::{BoundedGrid, BoundedSeries, UnboundedGrid, UnboundedSeries};

use super::{ChargeSplit, ContactModel};

/// The factored collocation matrices of a run (depend only on M).
#[derive(Debug, Clone)]
pub struct Discretisation {
    /// Grid for bounded densities (pressure, stick-zone traction).
    pub bounded: BoundedGrid,
    /// Grid for the inverse-square-root charge.
    pub unbounded: UnboundedGrid,
    /// ψ₁: response to `−τ` (unit `1/(RY*)`), with its integral.
    unit_psi: Vec<f64>,
    unit_integral: f64,
    /// The coarse companion grid ([`COARSE_NODES`] nodes, when M is at least three times
    /// that), on which the tangential solver builds the finite-difference Jacobian of a step.
    coarse: Option<Box<Discretisation>>,
}

/// Nodes of the coarse companion grid ([`Discretisation::coarse`]). Its Jacobian of a
/// tangential step is within 1–3 % of the fine grid's (the two grids' discretisation errors
/// of the derivatives, which do not shrink between 16 and 48 coarse nodes). Of 16, 24 and 32
/// nodes, 24 made the forward step fastest (16 and 24 at M = 96 and 256, all three at
/// M = 128; `docs/performance.md`).
pub const COARSE_NODES: usize = 24;

impl Discretisation {
    /// Build and factor for M collocation nodes.
    pub fn new(m: usize) -> Self {
        let bounded = BoundedGrid::new(m);
        let unbounded = UnboundedGrid::new(m);
        let rhs: Vec<f64> = bounded.collocation.iter().map(|t| -t).collect();
        let mut unit_psi = vec![0.0; m];
        bounded.solve(&rhs, &mut unit_psi);
        let unit_integral = bounded.integral(&unit_psi);
        Self {
            bounded,
            unbounded,
            unit_psi,
            unit_integral,
            coarse: (m >= 3 * COARSE_NODES).then(|| Box::new(Discretisation::new(COARSE_NODES))),
        }
    }

    /// Number of nodes M.
    pub fn nodes(&self) -> usize {
        self.bounded.len()
    }

    /// The density of a bounded series with coefficients `beta` at the bounded collocation
    /// points, then at the unbounded ones, into `out` (2M values, or the first `out.len()`):
    /// the pressure at the points where the tangential solver samples the shear traction
    /// ([`BoundedGrid::densities_at_collocation`],
    /// [`UnboundedGrid::bounded_densities_at_collocation`]).
    pub fn bounded_at_collocation(&self, beta: &[f64], out: &mut [f64]) {
        let m = self.nodes();
        let (at_bounded, at_unbounded) = out.split_at_mut(m + 1);
        self.bounded.densities_at_collocation(beta, at_bounded);
        if !at_unbounded.is_empty() {
            self.unbounded
                .bounded_densities_at_collocation(beta, at_unbounded);
        }
    }

    /// The coarse companion grid, when M is at least three times [`COARSE_NODES`]: on a finer
    /// grid its Jacobian saves time, on a coarser one its evaluations cost as much as the
    /// fine ones they save.
    pub fn coarse(&self) -> Option<&Discretisation> {
        self.coarse.as_deref()
    }
}

/// Solution of the pressure sub-problem.
#[derive(Debug, Clone)]
pub struct PressureSolution {
    /// Half-width a (m).
    pub half_width: f64,
    /// Centre c (m).
    pub centre: f64,
    /// Pressure representation (Pa).
    pub pressure: BoundedSeries,
}

/// Solve the pressure for the shear traction `q(x)` (material coordinates), starting from
/// the guess `(a, c)`. With `symmetric` the centre is held at c = 0 (normal loading, where
/// the mirror symmetry of material and load centres the contact; sampling a traction that
/// changes sign across a tiny stick zone would otherwise make the c-update discontinuous).
pub fn solve_pressure(
    model: &ContactModel,
    disc: &Discretisation,
    split: ChargeSplit,
    normal_load: f64,
    traction: &dyn Fn(f64) -> f64,
    guess: (f64, f64),
    symmetric: bool,
) -> Result<PressureSolution, SolveFailure> {
    let m = disc.nodes();
    let ystar = model.pressure_compliance(split);
    let kappa = model.pressure_shear_coupling(split);
    let scale = model.pressure_scale(split);
    let i1 = disc.unit_integral * scale;
    let (mut a, mut c) = guess;
    if !(a.is_finite() && a > 0.0) {
        a = (normal_load / i1).sqrt();
        c = 0.0;
    }
    let coupled = kappa != 0.0;
    if !coupled {
        let a = (normal_load / i1).sqrt();
        let psi: Vec<f64> = disc.unit_psi.iter().map(|u| a * scale * u).collect();
        let pressure = BoundedSeries::from_nodes(&disc.bounded, &psi);
        return Ok(PressureSolution {
            half_width: a,
            centre: 0.0,
            pressure,
        });
    }
    // G(a, c): the (a, c) that the consistency and resultant conditions give for the shear
    // term sampled at the points of (a, c); solve G(x) = x by Broyden's method started as a
    // plain fixed-point iteration (J = −I). The shear is sampled at moving points, so G is
    // only piecewise smooth; Broyden copes where plain iteration can cycle.
    let mut rhs = vec![0.0; m + 1];
    let mut psi_q = vec![0.0; m];
    let mut evaluate = |a: f64, c: f64, psi_q: &mut Vec<f64>| -> (f64, f64) {
        for (r, &t) in rhs.iter_mut().zip(&disc.bounded.collocation) {
            *r = -kappa / ystar * traction(c + a * t);
        }
        let lambda = disc.bounded.solve(&rhs, psi_q);
        let iq = disc.bounded.integral(psi_q);
        let c_new = if symmetric { 0.0 } else { lambda / scale };
        let a_new = (-iq + (iq * iq + 4.0 * i1 * normal_load).sqrt()) / (2.0 * i1);
        (a_new, c_new)
    };
    let a_scale = a;
    let mut x = [a / a_scale, c / a_scale];
    let g = evaluate(a, c, &mut psi_q);
    let mut f = [g.0 / a_scale - x[0], g.1 / a_scale - x[1]];
    let mut jac = [[-1.0, 0.0], [0.0, -1.0]];
    let max_iter = 200;
    let mut last = f64::INFINITY;
    for _ in 0..max_iter {
        let norm = f[0].hypot(f[1]);
        if !norm.is_finite() {
            return Err(SolveFailure::NonFinite {
                field: "contact half-width",
            });
        }
        last = norm;
        if norm < 1e-13 {
            let (a, c) = (x[0] * a_scale, x[1] * a_scale);
            let psi: Vec<f64> = disc
                .unit_psi
                .iter()
                .zip(&psi_q)
                .map(|(u, q)| a * scale * u + q)
                .collect();
            return Ok(PressureSolution {
                half_width: a,
                centre: c,
                pressure: BoundedSeries::from_nodes(&disc.bounded, &psi),
            });
        }
        let det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
        let mut dx = [
            -(jac[1][1] * f[0] - jac[0][1] * f[1]) / det,
            -(-jac[1][0] * f[0] + jac[0][0] * f[1]) / det,
        ];
        if !(dx[0].is_finite() && dx[1].is_finite()) || det.abs() < 1e-12 {
            jac = [[-1.0, 0.0], [0.0, -1.0]];
            dx = [f[0], f[1]];
        }
        // Keep a positive.
        while x[0] + dx[0] <= 0.0 {
            dx = [0.5 * dx[0], 0.5 * dx[1]];
        }
        let xn = [x[0] + dx[0], x[1] + dx[1]];
        let g = evaluate(xn[0] * a_scale, xn[1] * a_scale, &mut psi_q);
        let fn_ = [g.0 / a_scale - xn[0], g.1 / a_scale - xn[1]];
        if fn_[0].hypot(fn_[1]) > 2.0 * f[0].hypot(f[1]) {
            // Broyden's model went wrong: restart from a plain fixed-point step.
            jac = [[-1.0, 0.0], [0.0, -1.0]];
        }
        let df = [fn_[0] - f[0], fn_[1] - f[1]];
        let dd = dx[0] * dx[0] + dx[1] * dx[1];
        if dd > 0.0 {
            let jdx = [
                jac[0][0] * dx[0] + jac[0][1] * dx[1],
                jac[1][0] * dx[0] + jac[1][1] * dx[1],
            ];
            for i in 0..2 {
                for j in 0..2 {
                    jac[i][j] += (df[i] - jdx[i]) * dx[j] / dd;
                }
            }
        }
        x = xn;
        f = fn_;
        if symmetric {
            x[1] = 0.0;
            f[1] = 0.0;
        }
    }
    Err(SolveFailure::NoConvergence {
        what: "contact half-width and centre",
        iterations: max_iter,
        residual: last,
    })
}

/// Solve the constant-potential charge `w` of a conducting punch on the contact `[c − a, c + a]`
/// with resultant `free_charge = Γ − kP`.
pub fn solve_potential_charge(
    model: &ContactModel,
    disc: &Discretisation,
    half_width: f64,
    centre: f64,
    free_charge: f64,
    traction: &dyn Fn(f64) -> f64,
) -> UnboundedSeries {
    let m = disc.nodes();
    let e = model
        .compliance
        .electric
        .expect("conducting punch needs a piezoelectric half-plane");
    let rhs: Vec<f64> = disc
        .unbounded
        .collocation
        .iter()
        .map(|&t| -e.w13 / e.y33 * traction(centre + half_width * t))
        .collect();
    let mut theta = vec![0.0; m];
    disc.unbounded
        .solve(&rhs, free_charge / half_width, &mut theta);
    UnboundedSeries::from_nodes(&disc.unbounded, &theta)
}

/// `φ0 = (ln(2d/a)/π)(y23 P + y33 Γ) − (w13/π) J_q`, with `J_q = ∫ q(s) arcsin((s − c)/a) ds`
/// supplied by the caller (module docs of [`crate::contact`]).
pub fn contact_potential(
    model: &ContactModel,
    half_width: f64,
    normal_load: f64,
    charge: f64,
    j_q: f64,
) -> f64 {
    let e = model.compliance.electric.expect("piezoelectric half-plane");
    let log = (2.0 * model.reference_distance / half_width).ln();
    log / std::f64::consts::PI * (e.y23 * normal_load + e.y33 * charge)
        - e.w13 / std::f64::consts::PI * j_q
}

/// Inverse of [`contact_potential`] for Γ.
pub fn charge_for_potential(
    model: &ContactModel,
    half_width: f64,
    normal_load: f64,
    potential: f64,
    j_q: f64,
) -> f64 {
    let e = model.compliance.electric.expect("piezoelectric half-plane");
    let log = (2.0 * model.reference_distance / half_width).ln();
    (std::f64::consts::PI * potential + e.w13 * j_q - log * e.y23 * normal_load) / (log * e.y33)
}

/// Γ and φ0 for the model's electrode at half-width a, given the arcsine moment `J_q` of q.
pub fn electric_resultants(
    model: &ContactModel,
    half_width: f64,
    normal_load: f64,
    j_q: f64,
) -> (f64, Option<f64>) {
    use super::Electrode;
    match model.electrode {
        Electrode::None | Electrode::Insulating => (0.0, None),
        Electrode::ConductingCharge { charge } => (
            charge,
            Some(contact_potential(
                model,
                half_width,
                normal_load,
                charge,
                j_q,
            )),
        ),
        Electrode::ConductingPotential { potential } => (
            charge_for_potential(model, half_width, normal_load, potential, j_q),
            Some(potential),
        ),
    }
}
