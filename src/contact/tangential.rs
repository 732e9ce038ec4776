//! One step of a tangential phase: forward slip (`dQ > 0`) or reverse slip (`dQ < 0`) at
//! prescribed Q, with the stored memory (seed Section 4, eqs. 43–63).
//!
//! # Equations
//! In a phase with slip sign `s = ±1` both slip zones carry `q = s η p` (the traction on the
//! half-plane points along the motion of the punch), and on the stick zone `[lo, hi]`
//! `q = s η p + q̃` with q̃ bounded at both ends (seed eqs. 44 and 61: `q** = q − ηp`,
//! `q*** = q + ηp`, here one formula for both signs). Eq. (A) with the remembered strain m(x)
//! gives (seed eqs. 43/60, with N2/N3 written out)
//!
//! ```text
//! y11 H'q̃ = m(x) + (w12 + χ w13) p + w13 w − s η y11 H'p,      lo ≤ x ≤ hi
//! ∫ q̃ dx = Q − s η P                                            (seed eqs. 48/63)
//! ```
//!
//! The stick-zone ends are the unknowns a time-stepping driver needs (the seed paper instead
//! fixes one end and computes Q, eqs. 58–59): for given p and w, a damped Newton iteration on
//! `(lo, hi)` drives the consistency residual (seed eq. 35's analogue, the `(M+1)`-th equation
//! of eq. 58) and the force residual to zero. The pressure (with the eccentric punch,
//! seed eqs. 46, 52, 54) and the charge (eqs. 47, 53, 55) are then re-solved for the new
//! traction, and the three sub-problems iterated to a fixed point, warm-started from the
//! previous step.
//!
//! # Checks
//! `p ≥ 0`; `|q| ≤ ηp` on the stick zone; and in each slip zone the slip increment since the
//! previous step, `Δs(x) = ∫ from the stick end to x of (ε_new − ε_old)`, must oppose the
//! friction on the half-plane: `s Δs ≤ 0`.

use std::sync::Arc;

use serde::Serialize;

use crate::error::SolveFailure;
use crate::quadrature::{BoundedSeries, UnboundedSeries};

use super::memory::Memory;
use super::normal::arcsine_moment;
use super::pressure::{
    Discretisation, electric_resultants, solve_potential_charge, solve_pressure,
};
use super::{ContactModel, ContactState, StickZone, Traction, graded_rule};

/// Options of a tangential step.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct SlipOptions {
    /// Relative tolerance of the block iteration on (a, c, lo, hi), relative to a.
    pub tolerance: f64,
    /// Maximum block iterations.
    pub max_iterations: usize,
    /// Allowed violation of `|q| ≤ ηp` (relative to `η p0`) and of the slip direction
    /// (relative to the largest slip increment).
    pub admissibility: f64,
}

impl Default for SlipOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_iterations: 100,
            admissibility: 1e-3,
        }
    }
}

/// Worst violations of the step's admissibility checks (≤ 0 when admissible).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct StepAdmissibility {
    /// `max (|q| − ηp)/(η p0)` on the stick zone.
    pub stick_excess: f64,
    /// `max s Δs / max |Δs|` over the slip zones.
    pub slip_reversal: f64,
    /// `min p/p0`.
    pub min_pressure: f64,
}

/// A solved step.
#[derive(Debug, Clone, Serialize)]
pub struct SlipStep {
    /// The new state.
    pub state: ContactState,
    /// Block iterations.
    pub iterations: usize,
    /// Newton iterations of the stick-zone ends, summed.
    pub newton_iterations: usize,
    /// Final relative change of the block iteration.
    pub residual: f64,
    /// The checks.
    pub admissibility: StepAdmissibility,
}

struct StickFit {
    lo: f64,
    hi: f64,
    series: BoundedSeries,
    inherited: Option<Arc<StickZone>>,
    iterations: usize,
}

impl StickFit {
    fn zone(&self) -> StickZone {
        StickZone {
            inherited: self.inherited.clone(),
            ..StickZone::new(self.lo, self.hi, self.series.clone(), 0.0)
        }
    }
}

/// Residuals (consistency/(η p0), force/(η P)) of the stick problem for trial ends.
#[allow(clippy::too_many_arguments)]
fn stick_residual(
    model: &ContactModel,
    disc: &Discretisation,
    memory: &Memory,
    base: Option<&Arc<StickZone>>,
    state: &ContactState,
    sign: f64,
    lo: f64,
    hi: f64,
) -> ([f64; 2], BoundedSeries, Option<Arc<StickZone>>) {
    let inherited = base.and_then(|b| b.contained_in(lo, hi));
    let m = disc.nodes();
    let y11 = model.compliance.y11;
    let eta = model.friction;
    let w13 = model.compliance.electric.map_or(0.0, |e| e.w13);
    let local = model.local_pressure_strain(state.split);
    let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    let rhs: Vec<f64> = disc
        .bounded
        .collocation
        .iter()
        .map(|t| {
            let x = mid + half * t;
            let tau = (x - state.centre) / state.half_width;
            let inherited_cauchy = inherited.as_ref().map_or(0.0, |z| z.correction_cauchy(x));
            (memory.strain(model, x)
                + local * state.pressure_at(x)
                + w13 * state.potential_charge.density(tau)
                - sign * eta * y11 * state.pressure_cauchy(x))
                / y11
                - inherited_cauchy
        })
        .collect();
    let mut psi = vec![0.0; m];
    let lambda = disc.bounded.solve(&rhs, &mut psi);
    let force = half * disc.bounded.integral(&psi);
    let p0 = state.pressure_at(state.centre).max(1e-300);
    let target = state.tangential_load
        - sign * eta * state.normal_load
        - inherited.as_ref().map_or(0.0, |z| z.correction_integral());
    let series = BoundedSeries::from_nodes(&disc.bounded, &psi);
    (
        [
            lambda / (eta * p0),
            (force - target) / (eta * state.normal_load),
        ],
        series,
        inherited,
    )
}

/// Newton on (lo, hi) for fixed p and w.
fn fit_stick_zone(
    model: &ContactModel,
    disc: &Discretisation,
    memory: &Memory,
    base: Option<&Arc<StickZone>>,
    state: &ContactState,
    sign: f64,
    guess: (f64, f64),
) -> Result<StickFit, SolveFailure> {
    let (c, a) = (state.centre, state.half_width);
    let (left, right) = (c - a, c + a);
    let valid = |lo: f64, hi: f64| lo > left && hi < right && hi - lo > 1e-9 * a;
    let clamp = |x: f64| x.clamp(left + 1e-12 * a, right - 1e-12 * a);
    let (mut lo, mut hi) = (clamp(guess.0), clamp(guess.1));
    if !valid(lo, hi) {
        lo = c - 0.5 * a;
        hi = c + 0.5 * a;
    }
    let norm = |r: &[f64; 2]| r[0].hypot(r[1]);
    let (mut r, mut series, mut inherited) =
        stick_residual(model, disc, memory, base, state, sign, lo, hi);
    let tol = 1e-12;
    for it in 0..100 {
        if norm(&r) < tol {
            return Ok(StickFit {
                lo,
                hi,
                series,
                inherited,
                iterations: it,
            });
        }
        let d = 1e-7 * a;
        let d_lo = if valid(lo - d, hi) { -d } else { d };
        let d_hi = if valid(lo, hi + d) { d } else { -d };
        let (r_lo, _, _) = stick_residual(model, disc, memory, base, state, sign, lo + d_lo, hi);
        let (r_hi, _, _) = stick_residual(model, disc, memory, base, state, sign, lo, hi + d_hi);
        let j = [
            [(r_lo[0] - r[0]) / d_lo, (r_hi[0] - r[0]) / d_hi],
            [(r_lo[1] - r[1]) / d_lo, (r_hi[1] - r[1]) / d_hi],
        ];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if !(det.is_finite() && det.abs() > 0.0) {
            break;
        }
        let step_lo = -(j[1][1] * r[0] - j[0][1] * r[1]) / det;
        let step_hi = -(-j[1][0] * r[0] + j[0][0] * r[1]) / det;
        let mut alpha = 1.0;
        let mut accepted = false;
        for _ in 0..40 {
            let (nl, nh) = (lo + alpha * step_lo, hi + alpha * step_hi);
            if valid(nl, nh) {
                let (nr, ns, ni) = stick_residual(model, disc, memory, base, state, sign, nl, nh);
                if norm(&nr) < norm(&r) * (1.0 - 1e-4 * alpha) || norm(&nr) < tol {
                    lo = nl;
                    hi = nh;
                    r = nr;
                    series = ns;
                    inherited = ni;
                    accepted = true;
                    break;
                }
            }
            alpha *= 0.5;
        }
        if !accepted {
            break;
        }
    }
    // Newton stalled (the residuals have square-root kinks where a stick end crosses an old
    // stick/slip boundary of the memory): nested bracketed roots, consistency in the centre
    // of the zone for each half-width, force in the half-width.
    nested_fit(model, disc, memory, base, state, sign, (lo, hi))
}

fn nested_fit(
    model: &ContactModel,
    disc: &Discretisation,
    memory: &Memory,
    base: Option<&Arc<StickZone>>,
    state: &ContactState,
    sign: f64,
    guess: (f64, f64),
) -> Result<StickFit, SolveFailure> {
    use super::roots::bracketed_root;
    let (c, a) = (state.centre, state.half_width);
    let mut evaluations = 0usize;
    let centre_for = |half: f64, mid_guess: f64, evaluations: &mut usize| -> Option<f64> {
        let lower = c - a + half * (1.0 + 1e-12);
        let upper = c + a - half * (1.0 + 1e-12);
        if upper <= lower {
            return None;
        }
        let mut f = |mid: f64| {
            *evaluations += 1;
            stick_residual(
                model,
                disc,
                memory,
                base,
                state,
                sign,
                mid - half,
                mid + half,
            )
            .0[0]
        };
        bracketed_root(&mut f, mid_guess, lower, upper, 1e-3 * a, 1e-13 * a)
    };
    let half0 = 0.5 * (guess.1 - guess.0);
    let mid0 = 0.5 * (guess.1 + guess.0);
    let mut last_mid = mid0;
    let mut force = |half: f64| match centre_for(half, last_mid, &mut evaluations) {
        Some(mid) => {
            last_mid = mid;
            stick_residual(
                model,
                disc,
                memory,
                base,
                state,
                sign,
                mid - half,
                mid + half,
            )
            .0[1]
        }
        None => f64::NAN,
    };
    let half = bracketed_root(
        &mut force,
        half0,
        1e-9 * a,
        a * (1.0 - 1e-12),
        1e-3 * a,
        1e-13 * a,
    )
    .ok_or(SolveFailure::NoConvergence {
        what: "stick-zone ends (bracketing)",
        iterations: evaluations,
        residual: f64::NAN,
    })?;
    let mid = centre_for(half, last_mid, &mut evaluations).ok_or(SolveFailure::NoConvergence {
        what: "stick-zone centre (bracketing)",
        iterations: evaluations,
        residual: f64::NAN,
    })?;
    let (r, series, inherited) = stick_residual(
        model,
        disc,
        memory,
        base,
        state,
        sign,
        mid - half,
        mid + half,
    );
    if r[0].hypot(r[1]) < 1e-8 {
        Ok(StickFit {
            lo: mid - half,
            hi: mid + half,
            series,
            inherited,
            iterations: evaluations,
        })
    } else {
        Err(SolveFailure::NoConvergence {
            what: "stick-zone ends (bracketing)",
            iterations: evaluations,
            residual: r[0].hypot(r[1]),
        })
    }
}

/// Solve one step at tangential load `tangential_load` with slip sign `sign`, starting from
/// `start` (the previous step) and the stick-zone guess `guess`.
#[allow(clippy::too_many_arguments)]
pub fn solve_slip(
    model: &ContactModel,
    disc: &Discretisation,
    memory: &Memory,
    base: Option<&Arc<StickZone>>,
    start: &ContactState,
    tangential_load: f64,
    sign: f64,
    guess: (f64, f64),
    options: SlipOptions,
) -> Result<SlipStep, SolveFailure> {
    let eta = model.friction;
    let normal_load = start.normal_load;
    let mut state = start.clone();
    state.tangential_load = tangential_load;
    state.traction = Traction {
        friction: eta,
        left_sign: sign,
        right_sign: sign,
        stick: None,
    };
    let (mut lo, mut hi) = guess;
    let mut newton = 0;
    let mut last_change = f64::INFINITY;
    for iter in 1..=options.max_iterations {
        let fit = fit_stick_zone(model, disc, memory, base, &state, sign, (lo, hi))?;
        newton += fit.iterations;
        let (a_old, c_old) = (state.half_width, state.centre);
        let change_ends = (fit.lo - lo).abs() + (fit.hi - hi).abs();
        lo = fit.lo;
        hi = fit.hi;
        state.traction.stick = Some(fit.zone());
        let lagged = state.clone();
        let q = |x: f64| lagged.traction_at(x);
        let pressure = solve_pressure(
            model,
            disc,
            state.split,
            normal_load,
            &q,
            (a_old, c_old),
            false,
        )?;
        state.half_width = pressure.half_width;
        state.centre = pressure.centre;
        state.pressure = pressure.pressure;
        let j_q = arcsine_moment(&state);
        let (charge, potential) = electric_resultants(model, state.half_width, normal_load, j_q);
        state.charge = charge;
        state.potential = potential;
        state.potential_charge = if state.split.conducting {
            let free = charge - model.pressure_charge(normal_load);
            solve_potential_charge(model, disc, state.half_width, state.centre, free, &q)
        } else {
            UnboundedSeries::default()
        };
        let change =
            (change_ends + (state.half_width - a_old).abs() + (state.centre - c_old).abs())
                / state.half_width;
        last_change = change;
        if change < options.tolerance {
            let fit = fit_stick_zone(model, disc, memory, base, &state, sign, (lo, hi))?;
            newton += fit.iterations;
            state.traction.stick = Some(fit.zone());
            let admissibility = assess_step(model, start, &state);
            check(&admissibility, &state, options.admissibility)?;
            return Ok(SlipStep {
                state,
                iterations: iter,
                newton_iterations: newton,
                residual: change,
                admissibility,
            });
        }
    }
    Err(SolveFailure::NoConvergence {
        what: "tangential step (block iteration)",
        iterations: options.max_iterations,
        residual: last_change,
    })
}

fn check(adm: &StepAdmissibility, state: &ContactState, tol: f64) -> Result<(), SolveFailure> {
    let stick = state.traction.stick.as_ref().expect("slip state");
    if adm.min_pressure < -tol {
        return Err(SolveFailure::Inadmissible {
            check: "p ≥ 0".into(),
            value: adm.min_pressure,
            x: f64::NAN,
        });
    }
    if adm.stick_excess > tol {
        return Err(SolveFailure::Inadmissible {
            check: "|q| ≤ η p in the stick zone".into(),
            value: adm.stick_excess,
            x: stick.mid(),
        });
    }
    if adm.slip_reversal > tol.max(1e-2) {
        return Err(SolveFailure::Inadmissible {
            check: "slip in the slip zones must oppose the friction".into(),
            value: adm.slip_reversal,
            x: f64::NAN,
        });
    }
    Ok(())
}

/// The admissibility measures of a step from `old` to `new` (module docs).
pub fn assess_step(
    model: &ContactModel,
    old: &ContactState,
    new: &ContactState,
) -> StepAdmissibility {
    let stick = new.traction.stick.as_ref().expect("slip state");
    let sign = new.traction.right_sign;
    let eta = model.friction;
    let (c, a) = (new.centre, new.half_width);
    let p0 = new.pressure_at(c);
    let mut out = StepAdmissibility {
        stick_excess: f64::NEG_INFINITY,
        slip_reversal: f64::NEG_INFINITY,
        min_pressure: 1.0,
    };
    for i in 1..400 {
        let x = c + a * (-1.0 + 2.0 * i as f64 / 400.0);
        out.min_pressure = out.min_pressure.min(new.pressure_at(x) / p0);
    }
    for i in 0..=200 {
        let x = stick.lo + (stick.hi - stick.lo) * i as f64 / 200.0;
        let excess = (new.traction_at(x).abs() - eta * new.pressure_at(x)) / (eta * p0);
        out.stick_excess = out.stick_excess.max(excess);
    }
    // Slip increments at points of each slip zone, by graded quadrature from the stick end.
    let (nodes, weights) = graded_rule();
    let d_strain = |s: f64| new.strain_at(model, s) - old.strain_at(model, s);
    let mut slips = Vec::new();
    for (from, to) in [(stick.hi, c + a), (stick.lo, c - a)] {
        for f in [0.25, 0.5, 0.75, 1.0] {
            let x = from + f * (to - from);
            let (mid, half) = (0.5 * (from + x), 0.5 * (x - from));
            let slip: f64 = nodes
                .iter()
                .zip(weights)
                .map(|(u, w)| w * half * d_strain(mid + half * u))
                .sum();
            slips.push(slip);
        }
    }
    let largest = slips.iter().fold(0.0f64, |m, s| m.max(s.abs())).max(1e-300);
    out.slip_reversal = slips
        .iter()
        .map(|s| sign * s / largest)
        .fold(f64::NEG_INFINITY, f64::max);
    out
}
