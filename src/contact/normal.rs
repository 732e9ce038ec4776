//! Normal loading with friction: Spence's self-similar partial-slip state (seed Section 3,
//! eqs. 17–42), the first state of every history.
//!
//! # The state
//! Under proportional loading (P and Γ rise together from zero, which keeps χ and every ratio
//! fixed and makes the contact self-similar), the contact `[−a, a]` has a central stick zone
//! `|x| ≤ b` and two slip zones. A compressible half-plane under a rigid punch is drawn inward,
//! so friction on the half-plane points outward: `q = +η p sign(x)` for `b < |x| ≤ a`
//! (the seed paper's eq. 17 has the other sign because its q acts on the punch). Points in the
//! stick zone keep the strain they had when they stuck; self-similarity makes it
//! `∂ux/∂x = C|x|` (seed eq. 20).
//!
//! # Equations
//! `q = η p S(x) + q̃(x)` with `S = sign(x)` in the slip zones and a smoothstep from −1 to 1
//! with zero end slopes in the stick zone, so that `q̃` vanishes at ±b (the seed paper
//! subtracts the linear `η p(b) x/b`; both are continuous, ours makes q̃ smoother at ±b, see
//! [`super::ContactState::slip_shape`]).
//! In the stick zone eq. (A) gives (seed eqs. 32–33)
//!
//! ```text
//! y11 H'q̃ = C|x| + (w12 + χ w13) p + w13 w − η y11 H'(pS),     |x| ≤ b
//! ```
//!
//! with q̃ bounded at ±b. Two conditions fix the two unknowns: the consistency condition
//! (seed eq. 35) gives C explicitly (the right-hand side is linear in C), and the traction
//! must have no square-root term at the stick ends, `ψ̃(±1) = 0` (seed Section 3, after
//! eq. 42): with a non-zero √ term either `|q| ≤ ηp` fails just inside the stick zone or the
//! slip just outside runs against the friction. b is found by a bracketed secant on `ψ̃(1)`.
//! The pressure (with the shear feedback κq) and the charge are solved by
//! [`super::pressure`]; the three sub-problems are iterated to a fixed point (block
//! Gauss–Seidel, as the seed paper's steps 1–4).
//!
//! # Checks after the solve
//! `p ≥ 0`; `|q| ≤ ηp` in the stick zone; the slip rate has the sign the friction assumes:
//! with `ε(x) = ∂ux/∂x` self-similar, `∂ux/∂a` at fixed x is `(2∫₀ˣ ε − x ε(x))/a`, which must
//! be ≤ 0 for x in the right slip zone (the half-plane slides inward under outward friction).

use serde::Serialize;

use crate::error::SolveFailure;
use crate::quadrature::{BoundedSeries, UnboundedSeries};

use super::pressure::{
    Discretisation, electric_resultants, solve_potential_charge, solve_pressure,
};
use super::{ContactModel, ContactState, StickZone, Traction, ZoneTables};

/// Result of the normal-loading solve.
#[derive(Debug, Clone, Serialize)]
pub struct NormalLoading {
    /// The state at the end of normal loading.
    pub state: ContactState,
    /// Stick-zone half-width b (m); `b = a` means no slip (η large or β = 0 … see docs).
    pub stick_half_width: f64,
    /// Slope C of the locked-in strain `∂ux/∂x = C|x|` in the stick zone (1/m).
    pub strain_slope: f64,
    /// Outer (block) iterations.
    pub iterations: usize,
    /// Final relative change of (a, b, C) between iterations.
    pub residual: f64,
    /// Worst violations of the admissibility checks.
    pub admissibility: Admissibility,
}

/// Options of the iteration.
#[derive(Debug, Clone, Copy)]
pub struct NormalOptions {
    /// Relative tolerance on (a, b, C).
    pub tolerance: f64,
    /// Maximum block iterations.
    pub max_iterations: usize,
    /// Allowed violation of `|q| ≤ ηp` (relative to `η p(centre)`) and of the slip direction
    /// (relative to `|C| b²`). Every converged state measured so far (Spence, aluminium, PZT-4
    /// at η = 0.1–0.8, Γ = 0–9e−7, M = 16–256) has both ≤ 0; 1e−3 leaves room for coarse M.
    pub admissibility: f64,
    /// Which tables the final stick zone may build; it is tabulated when it may
    /// ([`StickZone::tabulate`]: every tangential phase that begins from it evaluates it at
    /// every residual evaluation). All in [`Default`]; none on the reference path of
    /// [`crate::contact::tangential::Accelerations`].
    pub zone_tables: ZoneTables,
}

impl Default for NormalOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-11,
            max_iterations: 200,
            admissibility: 1e-3,
            zone_tables: ZoneTables::default(),
        }
    }
}

/// `J_q = ∫ q(s) arcsin((s − c)/a) ds` over the contact (for the contact potential).
pub fn arcsine_moment(state: &ContactState) -> f64 {
    if state.traction.stick.is_none() {
        return 0.0;
    }
    let (c, a) = (state.centre, state.half_width);
    state.contact_integral(None, &|xs, out| {
        state.tractions_into(xs, out);
        for (q, s) in out.iter_mut().zip(xs) {
            *q *= ((s - c) / a).clamp(-1.0, 1.0).asin();
        }
    })
}

/// Solve the stick sub-problem for a trial b: returns (C, q̃ smooth part, kink amplitude, ψ̃(1)).
///
/// With `x = bu`, `C|x| = Cb(|u| − 2/π) + 2Cb/π`; the first part is inverted in closed form
/// ([`super::kink_density`]), so the collocation only sees the smooth remainder `r0` and keeps
/// its spectral accuracy. Consistency: `2Cb/(π y11) + mean(r0)/y11 = 0`; end condition:
/// `ψ̃(1) = −(2/π)(Cb/y11) + ψ_rest(1) = λ_rest + ψ_rest(1) = 0`.
fn stick_for(
    model: &ContactModel,
    disc: &Discretisation,
    trial: &ContactState,
    b: f64,
) -> (f64, BoundedSeries, f64, f64) {
    let m = disc.nodes();
    let y11 = model.compliance.y11;
    let eta = model.friction;
    let mut state = trial.clone();
    state.traction.stick = Some(StickZone::new(-b, b, BoundedSeries::default(), 0.0));
    // H'(pS) is needed at every collocation point: tabulate its quadrature once.
    state.tabulate_shape();
    let w13 = model.compliance.electric.map_or(0.0, |e| e.w13);
    let local = model.local_pressure_strain(state.split);
    let rhs: Vec<f64> = disc
        .bounded
        .collocation
        .iter()
        .map(|t| {
            let x = b * t;
            (local * state.pressure_at(x) + w13 * state.potential_charge_at(x)
                - eta * y11 * state.shape_cauchy(x))
                / y11
        })
        .collect();
    let mut psi = vec![0.0; m];
    let lambda = disc.bounded.solve(&rhs, &mut psi);
    let series = BoundedSeries::from_nodes(&disc.bounded, &psi);
    let slope = -std::f64::consts::PI * y11 * lambda / (2.0 * b);
    let end = lambda + series.psi(1.0);
    (slope, series, slope * b / y11, end)
}

/// Solve normal loading to `normal_load` with the model's friction and electrode.
///
/// The slip zones are first assumed to carry outward friction (`q = +ηp sign x`, the
/// half-plane drawn inward); if no state of that form exists, inward friction is tried.
pub fn solve_normal(
    model: &ContactModel,
    disc: &Discretisation,
    normal_load: f64,
    options: NormalOptions,
) -> Result<NormalLoading, SolveFailure> {
    let split = model.charge_split(normal_load);
    if model.friction > 0.0
        && !split.conducting
        && model.local_pressure_strain(split).abs() <= 1e-14 * model.compliance.y11
    {
        // Uncoupled (β = 0): the frictionless pressure draws no point sideways, so nothing
        // slips and no traction arises; the whole contact sticks with zero locked-in strain.
        let mut state = super::frictionless::solve_frictionless(model, disc, normal_load)?;
        let a = state.half_width;
        state.traction = Traction {
            friction: model.friction,
            left_sign: 0.0,
            right_sign: 0.0,
            stick: Some(StickZone::new(-a, a, BoundedSeries::default(), 0.0)),
        };
        return Ok(NormalLoading {
            state,
            stick_half_width: a,
            strain_slope: 0.0,
            iterations: 0,
            residual: 0.0,
            admissibility: Admissibility::default(),
        });
    }
    match solve_normal_directed(model, disc, normal_load, options, 1.0) {
        Ok(result) => Ok(result),
        Err(first) => solve_normal_directed(model, disc, normal_load, options, -1.0).map_err(|second| {
            SolveFailure::NoAdmissibleState {
                reason: format!("with outward friction in the slip zones: {first}; with inward friction: {second}"),
            }
        }),
    }
}

fn solve_normal_directed(
    model: &ContactModel,
    disc: &Discretisation,
    normal_load: f64,
    options: NormalOptions,
    outward: f64,
) -> Result<NormalLoading, SolveFailure> {
    let first = super::frictionless::solve_frictionless(model, disc, normal_load)?;
    if model.friction <= 0.0 {
        let b = first.half_width;
        return Ok(NormalLoading {
            state: first,
            stick_half_width: b,
            strain_slope: 0.0,
            iterations: 0,
            residual: 0.0,
            admissibility: Admissibility::default(),
        });
    }
    let eta = model.friction;
    let mut state = first;
    state.traction = Traction {
        friction: eta,
        left_sign: -outward,
        right_sign: outward,
        stick: None,
    };
    let mut b = 0.5 * state.half_width;
    let mut slope = 0.0;
    let mut last_change = f64::INFINITY;
    for iter in 1..=options.max_iterations {
        let a_old = state.half_width;
        // 1. Stick zone for the current p, w: root of ψ̃(1)(b) on (0, a).
        let (b_new, slope_new, correction, kink) = find_stick_zone(model, disc, &state, b)?;
        let previous = state.clone();
        state.traction.stick = Some(StickZone::new(-b_new, b_new, correction, kink));
        // 2. Pressure and charge for the new traction (lagged inside the sub-solvers).
        let lagged = previous_with_stick(&previous, &state);
        let q = |x: f64| lagged.traction_at(x);
        let pressure = solve_pressure(
            model,
            disc,
            state.split,
            normal_load,
            &q,
            (state.half_width, state.centre),
            true,
        )?;
        state.half_width = pressure.half_width;
        state.centre = pressure.centre;
        state.pressure = pressure.pressure;
        let j_q = arcsine_moment(&state);
        let (charge, potential) = electric_resultants(model, state.half_width, normal_load, j_q);
        state.charge = charge;
        state.potential = potential;
        if state.split.conducting {
            let free = charge - model.pressure_charge(normal_load);
            state.potential_charge =
                solve_potential_charge(model, disc, state.half_width, state.centre, free, &q);
        } else {
            state.potential_charge = UnboundedSeries::default();
        }
        let change = ((state.half_width - a_old).abs() + (b_new - b).abs()) / state.half_width
            + (slope_new - slope).abs() / slope_new.abs().max(1e-300);
        b = b_new;
        slope = slope_new;
        last_change = change;
        if !(b.is_finite() && slope.is_finite() && state.half_width.is_finite()) {
            return Err(SolveFailure::NonFinite {
                field: "stick-zone size",
            });
        }
        if change < options.tolerance {
            // Final stick solve with the converged pressure.
            let (b_fin, slope_fin, correction, kink) = find_stick_zone(model, disc, &state, b)?;
            state.traction.stick = Some(StickZone {
                tables: options.zone_tables,
                ..StickZone::new(-b_fin, b_fin, correction, kink)
            });
            // The state is evaluated many times from here on (checks, fields, memory).
            state.tabulate_shape();
            if let Some(zone) = state.traction.stick.as_ref() {
                zone.tabulate(disc.nodes() + 32);
            }
            let admissibility = check_normal_state(model, &state, slope_fin, options.admissibility)
                .map_err(|failure| {
                    if b_fin >= state.half_width {
                        SolveFailure::NoAdmissibleState {
                            reason: format!(
                                "the stick-zone end condition ψ̃(±1) = 0 has no root for 0 < b < a and full stick is \
                                 inadmissible ({failure})"
                            ),
                        }
                    } else {
                        failure
                    }
                })?;
            return Ok(NormalLoading {
                admissibility,
                state,
                stick_half_width: b_fin,
                strain_slope: slope_fin,
                iterations: iter,
                residual: change,
            });
        }
    }
    Err(SolveFailure::NoConvergence {
        what: "normal-loading stick zone (block iteration)",
        iterations: options.max_iterations,
        residual: last_change,
    })
}

/// The traction used to drive the pressure: the new stick zone over the previous pressure.
fn previous_with_stick(previous: &ContactState, new: &ContactState) -> ContactState {
    let mut s = previous.clone();
    s.traction = new.traction.clone();
    s
}

/// Root of `ψ̃(1)` in b ∈ (0, a), starting near `guess`.
fn find_stick_zone(
    model: &ContactModel,
    disc: &Discretisation,
    state: &ContactState,
    guess: f64,
) -> Result<(f64, f64, BoundedSeries, f64), SolveFailure> {
    let a = state.half_width;
    let f = |b: f64| stick_for(model, disc, state, b);
    // A stick zone below 1e−12 a is full slip for every purpose; just below a, full stick.
    let (lo_limit, hi_limit) = (a * 1e-12, a * (1.0 - 1e-9));
    let mut end_condition = |b: f64| f(b).3;
    match super::roots::bracketed_root(
        &mut end_condition,
        guess,
        lo_limit,
        hi_limit,
        0.02 * a,
        1e-14 * a,
    ) {
        Some(b) => {
            let (slope, series, kink, _) = f(b);
            Ok((b, slope, series, kink))
        }
        None => {
            // No root in (0, a): the candidate is full stick, b = a, whose traction may keep a
            // √ term at the contact ends (admissible when |q| ≤ ηp there); the caller checks it.
            let (slope, series, kink, _) = f(a);
            Ok((a, slope, series, kink))
        }
    }
}

/// Worst violations of the admissibility conditions, relative to their scales.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Admissibility {
    /// `max (|q| − ηp)/(η p(centre))` over the stick zone (≤ 0 when admissible).
    pub stick_excess: f64,
    /// Where it occurs (m).
    pub stick_excess_at: f64,
    /// Largest slip rate against the friction, relative to `|C| b²`.
    pub slip_reversal: f64,
    /// Where it occurs (m).
    pub slip_reversal_at: f64,
    /// `min p / p(centre)`.
    pub min_pressure: f64,
}

/// Admissibility of the normal-loading state (module docs).
pub fn assess_normal_state(
    model: &ContactModel,
    state: &ContactState,
    slope: f64,
) -> Admissibility {
    let stick = state.traction.stick.as_ref().expect("frictional state");
    let (a, c, b) = (state.half_width, state.centre, stick.hi);
    let eta = model.friction;
    let p0 = state.pressure_at(c);
    let mut out = Admissibility {
        stick_excess: f64::NEG_INFINITY,
        slip_reversal: f64::NEG_INFINITY,
        min_pressure: 1.0,
        ..Default::default()
    };
    for i in 1..800 {
        let x = c + a * (-1.0 + 2.0 * i as f64 / 800.0);
        let p = state.pressure_at(x);
        out.min_pressure = out.min_pressure.min(p / p0);
        if x.abs() < b {
            let excess = (state.traction_at(x).abs() - eta * p) / (eta * p0);
            if excess > out.stick_excess {
                out.stick_excess = excess;
                out.stick_excess_at = x;
            }
        }
    }
    // Slip direction in the right slip zone: sign(q)·(2∫₀ˣ ε − x ε(x)) ≤ 0.
    let strain = |x: f64| state.strain_at(model, x);
    let mut integral = 0.5 * slope * b * b;
    let n = 400;
    let mut prev_x = b;
    let mut prev_e = strain(b + 1e-9 * a);
    let scale = (slope * b * b).abs().max(1e-30);
    for i in 1..n {
        let x = b + (a - b) * (i as f64 / n as f64);
        let e = strain(x);
        integral += 0.5 * (e + prev_e) * (x - prev_x);
        prev_x = x;
        prev_e = e;
        let rate = state.traction.right_sign * (2.0 * integral - x * e) / scale;
        if rate > out.slip_reversal {
            out.slip_reversal = rate;
            out.slip_reversal_at = x;
        }
    }
    out
}

fn check_normal_state(
    model: &ContactModel,
    state: &ContactState,
    slope: f64,
    tol: f64,
) -> Result<Admissibility, SolveFailure> {
    let adm = assess_normal_state(model, state, slope);
    super::first_violation(&[
        ("p ≥ 0", -adm.min_pressure, tol, adm.min_pressure, f64::NAN),
        (
            "|q| ≤ η p in the stick zone",
            adm.stick_excess,
            tol,
            adm.stick_excess,
            adm.stick_excess_at,
        ),
        (
            "slip in the right slip zone must run against the friction",
            adm.slip_reversal,
            tol,
            adm.slip_reversal,
            adm.slip_reversal_at,
        ),
    ])?;
    Ok(adm)
}
