//! The search for a step's geometry `(lo, hi, a, c)` (tangential module docs): the attempt
//! plan of `solve_slip` (a recalled step, Masing's return to a remembered turning state, the
//! stick-zone guesses and slip-sign patterns in turn, Newton's fallback, within the step's
//! bound on residual evaluations where one is set), the quasi-Newton iteration of one attempt
//! (`solve_geometry`) and its finite-difference and coarse-grid Jacobians.

use std::cell::{Cell, RefCell};
use std::sync::Arc;

use crate::contact::memory::Memory;
use crate::contact::normal::arcsine_moment;
use crate::contact::pressure::{Discretisation, electric_resultants};
use crate::contact::{ContactModel, ContactState, StickZone};
use crate::error::SolveFailure;

use super::checks::{assess_step, check};
use super::linalg::{SecantDirections, norm, secant_update, solve4};
use super::residual::{
    Geometry, INNER_TOLERANCE, JACOBIAN_INNER_TOLERANCE, LOOSEST_INNER_TOLERANCE, StepProblem,
    inner_tolerance,
};
use super::{
    PhaseStart, Recalled, SlipOptions, SlipPattern, SlipStep, StepAdmissibility, WarmStart,
};

/// Largest first residual with which a recalled step is continued ([`Recalled`]): where the
/// step's problem is the recalled one's, the first residual is the recalled state's own, below
/// the solver's tolerance but for round-off (measured over the 22 runs of
/// the regression runs at the tolerance 1e−11: median 1.1e−12, largest 1.14e−11), while a
/// problem that differs starts
/// at the size of a load step's change of the residuals (1e−4–1e−3). A larger one means the
/// problem differs, and the step's own attempts decide among its sign patterns.
const RECALL_RESIDUAL: f64 = 1e-9;

/// Solve one step at tangential load `tangential_load` with slip sign `sign`, starting from
/// `start` (the previous step), stick-zone guesses tried in turn and the phase's inherited
/// correction chain `base`. `contact`, when given, is the predicted contact half-width and
/// centre `(a, c)` from which the attempts with the first stick-zone guess start (otherwise
/// they start from `start`'s). `recalled`, when given, is tried first (see [`Recalled`]);
/// `last_start`, at a phase start, is how the last phase that began mixed began: its pattern
/// is then tried after the standard one's attempts and before the other mixed ones, from its
/// remembered edge ([`PhaseStart`], [`Accelerations::mixed_start_guesses`](super::Accelerations::mixed_start_guesses)).
#[allow(clippy::too_many_arguments)]
pub fn solve_slip(
    model: &ContactModel,
    disc: &Discretisation,
    memory: &Memory,
    base: Option<&Arc<StickZone>>,
    start: &ContactState,
    tangential_load: f64,
    sign: f64,
    guesses_in: &[(f64, f64)],
    contact: Option<(f64, f64)>,
    warm: Option<&WarmStart>,
    recalled: Option<&Recalled>,
    last_start: Option<&PhaseStart>,
    options: SlipOptions,
) -> Result<SlipStep, SolveFailure> {
    let guess = guesses_in[0];
    // Both slip zones normally follow the load (seed Section 4); right after a reversal in a
    // coupled contact one edge may keep its previous direction while the contact shifts, so
    // the mixed states are tried when the standard one has no solution.
    //
    // The stick ends can also jump: when the load passes an earlier turning point (Masing
    // memory), the part of the zone that is already at the friction limit slips at once and
    // the ends move to an older stick/slip boundary of the memory. So the remembered
    // boundaries inside the current zone are tried as starting points when the warm start fails.
    let remembered = remembered_zones(memory, start, guess);
    let (warm_guesses, jump_guesses) = distinct_guesses(guesses_in, &remembered, start.half_width);
    let mut plan = attempt_plan(sign, warm.is_some(), &warm_guesses, &jump_guesses);
    // At a phase start, the pattern of the last phase that began mixed is tried first among
    // the attempts of its signs, with its stick end next to the edge that slips against the phase
    // where it was then (`PhaseStart`). The standard pattern's attempts still come first: where
    // both converge to states that pass the checks (the edge zone thinner than what the checks
    // resolve), the standard one is the state the step reports.
    let preferred = last_start
        .filter(|_| warm.is_none() && options.accelerations.mixed_start_guesses)
        .map(|last| {
            let from = contact.unwrap_or((start.half_width, start.centre));
            (
                SlipPattern::of_signs(last.signs),
                last.guess(sign, guess, from),
            )
        });
    if let Some(entry) = preferred {
        let at = plan
            .iter()
            .position(|p| p.0 == entry.0)
            .unwrap_or(plan.len());
        plan.insert(at, entry);
    }
    let mut attempts = Attempts::default();
    let scratch = RefCell::default();
    // The step's residual evaluations, which `options.step_evaluations` bounds.
    let spent = Cell::new(0);
    let problem_for = |signs: (f64, f64)| StepProblem {
        model,
        disc,
        memory,
        base,
        signs,
        normal_load: start.normal_load,
        tangential_load,
        scratch: &scratch,
        accelerations: options.accelerations,
        evaluations: Some(&spent),
    };
    if let Some(step) = recalled.and_then(|r| recall(&problem_for, start, r, options)) {
        return Ok(step);
    }
    if let Some(step) = masing_return(&problem_for, start, sign, options, &mut attempts) {
        return Ok(step);
    }
    // Every attempt is made with the fast quasi-Newton iteration first; the jumps above are
    // where it can miss a root that Newton's method finds, so Newton's method is the fallback.
    let rounds: &[bool] = if options.newton_fallback {
        &[false, true]
    } else {
        &[false]
    };
    'attempts: for &newton in rounds {
        for &(pattern, guess) in &plan {
            let signs = pattern.signs();
            if attempts.stalled.is_some() {
                break 'attempts;
            }
            let problem = problem_for(signs);
            // The step's evaluation budget, once an attempt has failed (its failure is the
            // one reported).
            if attempts.first_failure.is_some() && budget_spent(&problem, options) {
                break 'attempts;
            }
            let method = match warm {
                _ if newton => Method::Newton,
                Some(w) if w.signs == signs => Method::Broyden(Some(w.jacobian)),
                Some(_) => Method::Coarse,
                None => Method::Broyden(None),
            };
            // Within a phase the prediction continues the warm start's slip signs only.
            let first = guess == guesses_in[0] || preferred == Some((pattern, guess));
            let contact = contact.filter(|_| first && warm.is_none_or(|w| w.signs == signs));
            let attempt = (guess, contact);
            if let Some(step) =
                try_attempt(&problem, start, attempt, method, options, &mut attempts)
            {
                return Ok(step);
            }
        }
    }
    // No attempt converged: the admissible stalled iterate, if any.
    match attempts.stalled {
        Some(step) => Ok(*step),
        None => Err(attempts.first_failure.expect("at least one attempt")),
    }
}

/// Whether the step's residual evaluations that `problem` counts have reached the step's
/// bound ([`SlipOptions::step_evaluations`]).
fn budget_spent(problem: &StepProblem<'_>, options: SlipOptions) -> bool {
    match (options.step_evaluations, problem.evaluations) {
        (Some(bound), Some(spent)) => spent.get() >= bound,
        _ => false,
    }
}

/// A stick zone's ends `(lo, hi)` (m).
type Zone = (f64, f64);

/// The stick zones of the memory's turning states that lie inside `start`'s contact, as
/// starting guesses (inset by 1e−3 a): the nested pairs of remembered stick/slip boundaries
/// (outermost first), then the other pairs, widest first. Only the boundaries within a of
/// the contact or of the first guess `guess` are used.
fn remembered_zones(memory: &Memory, start: &ContactState, guess: Zone) -> Vec<Zone> {
    let (c, a) = (start.centre, start.half_width);
    let inset = 1e-3 * a;
    let breaks: Vec<f64> = memory
        .breakpoints()
        .into_iter()
        .filter(|&x| x > guess.0.min(c - a) - a && x < guess.1.max(c + a) + a)
        .collect();
    let mut remembered = Vec::new();
    for i in 0..breaks.len() / 2 {
        let (l, r) = (breaks[i], breaks[breaks.len() - 1 - i]);
        if r - l > 2.0 * inset && l > c - a && r < c + a {
            remembered.push((l + inset, r - inset));
        }
    }
    // Other pairs of remembered boundaries (an earlier turning point's zone need not be
    // nested symmetrically in the breakpoint list), widest first.
    let mut pairs: Vec<(f64, f64)> = Vec::new();
    for (i, &l) in breaks.iter().enumerate() {
        for &r in &breaks[i + 1..] {
            if r - l > 2.0 * inset && l > c - a && r < c + a {
                pairs.push((l + inset, r - inset));
            }
        }
    }
    pairs.sort_by(|x, y| (y.1 - y.0).total_cmp(&(x.1 - x.0)));
    remembered.extend(pairs);
    remembered
}

/// The caller's stick-zone guesses (the continuations) and the remembered zones (the jumps),
/// each without the guesses that repeat an earlier one to 1e−12 of the half-width `a`.
fn distinct_guesses(guesses_in: &[Zone], remembered: &[Zone], a: f64) -> (Vec<Zone>, Vec<Zone>) {
    let mut warm_guesses: Vec<(f64, f64)> = Vec::new();
    let mut jump_guesses: Vec<(f64, f64)> = Vec::new();
    for (k, g) in guesses_in.iter().chain(remembered).enumerate() {
        let same = |h: &(f64, f64)| (h.0 - g.0).abs().max((h.1 - g.1).abs()) <= 1e-12 * a;
        if !warm_guesses.iter().chain(&jump_guesses).any(same) {
            if k < guesses_in.len() {
                warm_guesses.push(*g);
            } else {
                jump_guesses.push(*g);
            }
        }
    }
    (warm_guesses, jump_guesses)
}

/// The attempts of a step in phase `sign`, as `(slip pattern, stick-zone guess)`, in order;
/// `warm_start` when the step is not the first of its phase.
///
/// Mixed states: inward friction at both edges ([`SlipPattern::Inward`]) before outward;
/// both patterns are their own mirror images, so the order does not depend on the direction
/// of loading. At the first step of a phase (no warm start) the mixed states are what the
/// reversal needs, and the continuations are tried in every state before the jumps to
/// remembered boundaries; later in a phase the jumps of the standard state come first (test
/// `the_attempt_plan_is_pinned`).
fn attempt_plan(
    sign: f64,
    warm_start: bool,
    warm_guesses: &[Zone],
    jump_guesses: &[Zone],
) -> Vec<(SlipPattern, Zone)> {
    let patterns = [
        SlipPattern::with_load(sign),
        SlipPattern::Inward,
        SlipPattern::Outward,
    ];
    let mut plan = Vec::new();
    if warm_start {
        for pattern in patterns {
            for set in [warm_guesses, jump_guesses] {
                plan.extend(set.iter().map(|&g| (pattern, g)));
            }
        }
    } else {
        for set in [warm_guesses, jump_guesses] {
            for pattern in patterns {
                plan.extend(set.iter().map(|&g| (pattern, g)));
            }
        }
    }
    plan
}

/// One attempt of the plan from the stick ends and the contact `attempt`; its failure goes to
/// `attempts`. A stall from a carried (or coarse) Jacobian is tried once more from a fresh
/// finite-difference one before the stalled iterate is taken (default history at M = 64, 20
/// steps per segment, the step at −0.075 ηP of the second cycle: stalled at 1.4e−6 after 65
/// evaluations, converged in 10, 7e−6 a from the stalled state; the two other stalls of the
/// batch in `docs/performance.md` stay stalled, at 66 and 73 more evaluations).
fn try_attempt(
    problem: &StepProblem<'_>,
    start: &ContactState,
    attempt: ((f64, f64), Option<(f64, f64)>),
    method: Method<'_>,
    options: SlipOptions,
    attempts: &mut Attempts,
) -> Option<SlipStep> {
    match solve_geometry(problem, start, start, attempt, method, options) {
        Ok(step) => Some(step),
        Err(failed) => {
            let retry = failed.stalled.is_some()
                && method.within_phase()
                && !budget_spent(problem, options);
            attempts.record(failed);
            if retry {
                let fresh = Method::Broyden(None);
                solve_geometry(problem, start, start, attempt, fresh, options).ok()
            } else {
                None
            }
        }
    }
}

/// The recalled state's geometry, from its own coefficients and Jacobian; `None` (and nothing
/// recorded: the step's own attempts follow) when its first residual exceeds
/// [`RECALL_RESIDUAL`], i.e. the problem is not the earlier one's.
fn recall<'a>(
    problem_for: &dyn Fn((f64, f64)) -> StepProblem<'a>,
    start: &ContactState,
    recalled: &Recalled,
    options: SlipOptions,
) -> Option<SlipStep> {
    let state = &recalled.state;
    let zone = state.traction.stick.as_ref()?;
    let guess = ((zone.lo, zone.hi), Some((state.half_width, state.centre)));
    let problem = problem_for(recalled.warm.signs);
    let method = Method::Recall(recalled);
    solve_geometry(&problem, start, state, guess, method, options).ok()
}

/// Masing's memory: when the load returns to the load of a remembered turning point whose
/// stick zone lies inside the current one, that turning state solves the step again (inside
/// its zone the memory is the one it stuck with, and outside it the step slips as it did).
/// The stretch between the current stick ends and the remembered ones is then exactly at the
/// friction limit, so the residuals are flat in the stick ends there: the continuation from
/// the previous step lands on an M-dependent point of that stretch (the same p, q and g, with
/// the stretch labelled stuck) or does not converge. The turning state is therefore tried
/// first, from its own geometry; the smallest stick zone is the canonical one. `None` when no
/// remembered turning point applies or none converges (failures go to `attempts`).
fn masing_return<'a>(
    problem_for: &dyn Fn((f64, f64)) -> StepProblem<'a>,
    start: &ContactState,
    sign: f64,
    options: SlipOptions,
    attempts: &mut Attempts,
) -> Option<SlipStep> {
    let (lo0, hi0) = start
        .traction
        .stick
        .as_ref()
        .map_or((f64::NEG_INFINITY, f64::INFINITY), |z| (z.lo, z.hi));
    let probe = problem_for((sign, sign));
    let limit = probe.model.friction * start.normal_load;
    for turning in probe
        .memory
        .states_at_load(probe.tangential_load, 1e-9 * limit)
    {
        let Some(zone) = turning.traction.stick.as_ref() else {
            continue;
        };
        let signs = (turning.traction.left_sign, turning.traction.right_sign);
        if signs != (sign, sign) || zone.lo < lo0 || zone.hi > hi0 {
            continue;
        }
        if budget_spent(&probe, options) {
            break;
        }
        let method = Method::Broyden(None);
        let guess = ((zone.lo, zone.hi), None);
        match solve_geometry(&probe, start, &turning, guess, method, options) {
            Ok(step) => return Some(step),
            Err(failed) => attempts.record(failed),
        }
    }
    None
}

/// Finite-difference Jacobian of the residuals at `g` (the inherited correction of the base
/// point is kept so that the differences do not straddle a switch of the chain).
#[allow(clippy::needless_range_loop)]
fn fd_jacobian(
    problem: &StepProblem<'_>,
    g: &Geometry,
    r: &[f64; 4],
    state: &ContactState,
) -> Result<[[f64; 4]; 4], SolveFailure> {
    // Steps well above evaluation noise, well inside the contact (the residuals have
    // square-root behaviour at its ends).
    let room = (g.lo - (g.c - g.a)).min(g.c + g.a - g.hi);
    let d = (1e-6 * g.a).min(0.1 * room).max(1e-10 * g.a);
    let chosen = state
        .traction
        .stick
        .as_ref()
        .and_then(|z| z.inherited.clone());
    let mut jac = [[0.0; 4]; 4];
    for k in 0..4 {
        let mut gk = *g;
        let step = match k {
            0 => {
                gk.lo += d;
                d
            }
            1 => {
                gk.hi -= d;
                -d
            }
            2 => {
                gk.a += d;
                d
            }
            _ => {
                gk.c += d;
                d
            }
        };
        let (rk, ..) =
            problem.evaluate_with(&gk, state, chosen.clone(), JACOBIAN_INNER_TOLERANCE)?;
        for i in 0..4 {
            jac[i][k] = (rk[i] - r[i]) / step;
        }
    }
    Ok(jac)
}

/// The finite-difference Jacobian of the step's residuals at `g`, on the coarse companion grid
/// ([`Discretisation::coarse`]); `None` without one, or when an evaluation there fails. The
/// residuals are dimensionless and converge in M, and so does their dependence on the
/// geometry: the coarse Jacobian is the fine one to 1–3 % (measured at forward steps of the
/// default history at M = 72 … 512; the test `coarse_jacobian_is_near_the_fine_one` bounds
/// it), where the Jacobian carried from the previous step and updated by Broyden is off by
/// 3–8 % (the fine Jacobian itself moves by 7–9 % from one step to the next, and the
/// quasi-Newton steps, nearly parallel, correct it along one direction only). Its five
/// evaluations: the base point at the full inner tolerance, from `guess`'s traction, and four
/// differences.
fn coarse_jacobian(
    problem: &StepProblem<'_>,
    g: &Geometry,
    guess: &ContactState,
) -> Option<[[f64; 4]; 4]> {
    let maps = RefCell::default();
    let coarse = StepProblem {
        disc: problem.disc.coarse()?,
        scratch: &maps,
        evaluations: None,
        ..*problem
    };
    let (r, state, _) = coarse.evaluate(g, guess, INNER_TOLERANCE).ok()?;
    fd_jacobian(&coarse, g, &r, &state).ok()
}

/// A failed attempt: why, and its best iterate when that is an admissible state whose
/// residual stalled below [`SlipOptions::stall_tolerance`].
struct Failed {
    failure: SolveFailure,
    stalled: Option<Box<SlipStep>>,
}

impl From<SolveFailure> for Failed {
    fn from(failure: SolveFailure) -> Self {
        Self {
            failure,
            stalled: None,
        }
    }
}

/// The outcomes of a step's attempts: the first failure (reported when nothing is accepted)
/// and the first admissible stalled iterate (which ends the search).
#[derive(Default)]
struct Attempts {
    first_failure: Option<SolveFailure>,
    stalled: Option<Box<SlipStep>>,
}

impl Attempts {
    fn record(&mut self, failed: Failed) {
        self.first_failure.get_or_insert(failed.failure);
        if self.stalled.is_none() {
            self.stalled = failed.stalled;
        }
    }
}

/// How the geometry is iterated.
#[derive(Debug, Clone, Copy)]
enum Method<'a> {
    /// Secant updates within the evaluation budget (projected within a phase, Broyden's at a
    /// phase start: [`Method::within_phase`]), from the given Jacobian (the previous step's)
    /// or, with [`Accelerations::coarse_jacobian`](super::Accelerations::coarse_jacobian) and a coarse grid, from the coarse grid's at
    /// the first iterate; without one, from a finite-difference Jacobian.
    Broyden(Option<[[f64; 4]; 4]>),
    /// Secant updates within a phase for slip signs other than the previous step's (whose
    /// Jacobian does not apply): from the coarse grid's Jacobian at the first iterate with
    /// [`Accelerations::coarse_jacobian`](super::Accelerations::coarse_jacobian) and a coarse grid, else a finite-difference one.
    Coarse,
    /// Newton's method with a finite-difference Jacobian at every iterate and five times the
    /// evaluation budget: slower, and the fallback where the quasi-Newton attempts all fail.
    Newton,
    /// Secant updates from a recalled step's Jacobian, the first residual solved at the full
    /// inner tolerance (from the recalled coefficients, a pass or two), and given up at once
    /// when that residual exceeds [`RECALL_RESIDUAL`].
    Recall(&'a Recalled),
}

impl Method<'_> {
    /// Whether the attempt is within a phase and starts from a Jacobian that applies to its
    /// slip signs or from the coarse grid's (not a phase start, not a recalled step, not
    /// Newton's fallback): where the coarse grid's Jacobian is taken and a stall is tried once
    /// more from a finite-difference one.
    fn within_phase(&self) -> bool {
        matches!(self, Method::Broyden(Some(_)) | Method::Coarse)
    }
}

/// Newton's method on the geometry with rank-one secant updates: the Jacobian is taken
/// from the coarse grid or from `hint` (the previous step's, when the sign pattern is the
/// same; see [`Method::Broyden`]) or by finite differences, updated after every accepted
/// step, and recomputed by finite differences only when a quasi-Newton direction fails the
/// line search. The iteration begins with the stick ends `guess` and the half-width, centre
/// and traction of `from`; `start` is the previous step, against which the slip direction is
/// checked.
fn solve_geometry(
    problem: &StepProblem<'_>,
    start: &ContactState,
    from: &ContactState,
    (guess, contact): ((f64, f64), Option<(f64, f64)>),
    method: Method<'_>,
    options: SlipOptions,
) -> Result<SlipStep, Failed> {
    let search = GeometrySearch {
        problem,
        start,
        method,
        options,
    };
    let (hint, quasi_newton) = match method {
        Method::Broyden(hint) => (hint, true),
        Method::Coarse => (None, true),
        Method::Recall(recalled) => (Some(recalled.warm.jacobian), true),
        Method::Newton => (None, false),
    };
    let mut g = search.starting_geometry(from, guess, contact);
    let (mut r, mut state, mut tight) = search.first_residual(&g, from)?;
    let mut evaluations = 1;
    let mut jac = search.starting_jacobian(&g, &state, hint);
    let mut fresh = false;
    // The projected update within a phase; at a phase start Broyden's (there the iteration's
    // path decides which of several admissible states it reaches: tried there too, the first
    // step of a PZT-4 first loading at M = 128 reached another state, 8e−5 a away).
    let projected = options.accelerations.projected_updates
        && (method.within_phase() || matches!(method, Method::Recall(_)));
    let mut directions = SecantDirections::default();
    let mut iterations = 0;
    for iter in 0..options.max_iterations {
        iterations = iter;
        let size = norm(&r);
        if size < options.tolerance && !tight {
            // Converged on a loose inner solve: confirm at the full inner tolerance (from the
            // loose solution, a pass or two).
            (r, state, tight) = search.solve_fully(&g, &state)?;
            evaluations += 1;
            continue;
        }
        if size < options.tolerance {
            return Ok(search.accept(state, &g, (iter, evaluations), size, jac)?);
        }
        if evaluations > search.budget(quasi_newton, size) || budget_spent(problem, options) {
            break;
        }
        let j = match jac {
            Some(j) => j,
            None => {
                evaluations += 4;
                fresh = true;
                directions = SecantDirections::default();
                fd_jacobian(problem, &g, &r, &state)?
            }
        };
        let Some(dx) = solve4(j, r) else {
            if fresh {
                break;
            }
            jac = None;
            continue;
        };
        let trial = search.line_search(&g, &state, dx, size, fresh, &mut evaluations)?;
        let Some(trial) = trial else {
            if fresh {
                break;
            }
            jac = None;
            continue;
        };
        // The secant update with the step taken and the change of the residuals.
        let step = dx.map(|v| trial.alpha * v);
        let direction = if projected {
            directions.direction(step)
        } else {
            step
        };
        let change = std::array::from_fn(|i| trial.r[i] - r[i]);
        jac = quasi_newton.then(|| secant_update(j, step, change, direction));
        fresh = false;
        (g, r, state, tight) = (trial.g, trial.r, trial.state, trial.full);
    }
    Err(search.stalled(g, (r, state, tight), (iterations, evaluations), jac))
}

/// What one attempt of [`solve_geometry`] works with besides its iterates.
struct GeometrySearch<'s> {
    problem: &'s StepProblem<'s>,
    /// The previous step, against which the slip direction is checked.
    start: &'s ContactState,
    method: Method<'s>,
    options: SlipOptions,
}

/// An iterate of the line search that lowered the residual: its geometry, residuals and
/// state, the fraction `alpha` of the direction taken, and whether its inner solve reached
/// the full inner tolerance.
struct Trial {
    g: Geometry,
    r: [f64; 4],
    state: ContactState,
    alpha: f64,
    full: bool,
}

impl GeometrySearch<'_> {
    /// The first iterate: the stick ends `guess` (kept inside the contact) on the contact
    /// `contact`, or `from`'s when not given; the middle half of that contact when the
    /// guess is not a valid geometry.
    fn starting_geometry(
        &self,
        from: &ContactState,
        guess: (f64, f64),
        contact: Option<(f64, f64)>,
    ) -> Geometry {
        let (a0, c0) = contact.unwrap_or((from.half_width, from.centre));
        let clamp_lo = |lo: f64| lo.max(c0 - a0 * (1.0 - 1e-9));
        let clamp_hi = |hi: f64| hi.min(c0 + a0 * (1.0 - 1e-9));
        let mut g = Geometry {
            lo: clamp_lo(guess.0),
            hi: clamp_hi(guess.1),
            a: a0,
            c: c0,
        };
        if !self.problem.valid(&g) {
            g.lo = c0 - 0.5 * a0;
            g.hi = c0 + 0.5 * a0;
        }
        g
    }

    /// The Jacobian the attempt starts from at its first iterate `g` (solved as `state`):
    /// `hint`, or within a phase the coarse grid's Jacobian there (`coarse_jacobian`), which
    /// replaces the carried one. Its evaluations are not counted: they are the coarse grid's.
    /// It saves residual evaluations because within a phase the geometry changes little, so
    /// the coarse Jacobian at the current iterate is closer than the carried one; the states
    /// are the same to the tolerance ([`Accelerations::coarse_jacobian`](super::Accelerations::coarse_jacobian)). At a phase start the
    /// fine one is kept: there a coarse Jacobian can steer the iteration to another admissible
    /// state.
    fn starting_jacobian(
        &self,
        g: &Geometry,
        state: &ContactState,
        hint: Option<[[f64; 4]; 4]>,
    ) -> Option<[[f64; 4]; 4]> {
        if self.options.accelerations.coarse_jacobian && self.method.within_phase() {
            coarse_jacobian(self.problem, g, state).or(hint)
        } else {
            hint
        }
    }

    /// The first residual of the attempt, from `from`'s traction. It is a trial iterate's
    /// whose size is not known yet: it is solved to the loosest inner tolerance (an accepted
    /// residual is solved again at the full tolerance anyway, so this saves inner passes and
    /// leaves the states unchanged). A recalled step's is solved at the full tolerance, and
    /// the attempt is given up when it exceeds [`RECALL_RESIDUAL`].
    fn first_residual(
        &self,
        g: &Geometry,
        from: &ContactState,
    ) -> Result<([f64; 4], ContactState, bool), Failed> {
        let recalled = matches!(self.method, Method::Recall(_));
        let first_tolerance = if recalled {
            INNER_TOLERANCE
        } else {
            LOOSEST_INNER_TOLERANCE
        };
        let (r, state, tight) = self.problem.evaluate(g, from, first_tolerance)?;
        if recalled && norm(&r) > RECALL_RESIDUAL {
            return Err(SolveFailure::NoConvergence {
                what: "recalled step",
                iterations: 1,
                residual: norm(&r),
            }
            .into());
        }
        Ok((r, state, tight))
    }

    /// The residuals at `g` solved at the full inner tolerance from `state`: a residual from
    /// a loose inner solve is solved again so before its iterate can be accepted.
    fn solve_fully(
        &self,
        g: &Geometry,
        state: &ContactState,
    ) -> Result<([f64; 4], ContactState, bool), SolveFailure> {
        self.problem.evaluate(g, state, INNER_TOLERANCE)
    }

    /// Whether a residual of size `size` is within 1e4 of the solver's tolerance: such an
    /// attempt is converging (attempts without a root wander at large residuals).
    fn near(&self, size: f64) -> bool {
        size < 1e4 * self.options.tolerance
    }

    /// The evaluations an attempt may make at the residual `size`. Newton's fallback gets a
    /// larger budget: it needs 5 evaluations per iteration. An attempt that is already within
    /// 1e4 of the tolerance ([`Self::near`]) is converging and may take twice the budget: at
    /// the first step after the reversal of the default history at M = 128 the mixed state
    /// converged linearly to 5e−12 in the 61 evaluations allowed, and the next attempt found
    /// the same state after 38 more.
    fn budget(&self, quasi_newton: bool, size: f64) -> usize {
        let near = self.near(size);
        (if quasi_newton { 1 } else { 5 }) * self.options.max_evaluations * if near { 2 } else { 1 }
    }

    /// The inner tolerance of a trial iterate from a residual of size `size`: the inexact
    /// Newton tolerance ([`inner_tolerance`]), which saves inner passes. Near the tolerance
    /// ([`Self::near`]) the trial is solved fully, so that it can be accepted as it is (a
    /// loose one below the tolerance would be evaluated again, one fine evaluation more).
    /// Either way an iterate is accepted only on a residual solved at the full tolerance.
    fn trial_tolerance(&self, size: f64) -> f64 {
        if self.near(size) {
            INNER_TOLERANCE
        } else {
            inner_tolerance(size)
        }
    }

    /// Backtracking along the direction `dx` from `g` (residual size `size`): the first
    /// fraction, halved from 1 (30 times from a fresh Jacobian, else 6), whose geometry is
    /// valid and lowers the residual by the Armijo factor; `None` when none does. Each
    /// evaluation is counted in `evaluations`.
    fn line_search(
        &self,
        g: &Geometry,
        state: &ContactState,
        dx: [f64; 4],
        size: f64,
        fresh: bool,
        evaluations: &mut usize,
    ) -> Result<Option<Trial>, SolveFailure> {
        let mut alpha = 1.0;
        for _ in 0..if fresh { 30 } else { 6 } {
            let gn = Geometry {
                lo: g.lo + alpha * dx[0],
                hi: g.hi + alpha * dx[1],
                a: g.a + alpha * dx[2],
                c: g.c + alpha * dx[3],
            };
            if self.problem.valid(&gn) {
                let inner = self.trial_tolerance(size);
                let (rn, sn, full) = self.problem.evaluate(&gn, state, inner)?;
                *evaluations += 1;
                if norm(&rn) < (1.0 - 1e-4 * alpha) * size {
                    return Ok(Some(Trial {
                        g: gn,
                        r: rn,
                        state: sn,
                        alpha,
                        full,
                    }));
                }
            }
            alpha *= 0.5;
        }
        Ok(None)
    }

    /// The recalled step and its checks, at an iterate `g` that repeats it ([`Recalled`]):
    /// its charge, potential and checks are then taken instead of evaluated, which saves
    /// those evaluations; the step is the recalled one again to the solver's tolerance.
    fn repeated(&self, g: &Geometry) -> Option<(&Recalled, StepAdmissibility)> {
        match self.method {
            Method::Recall(recalled) => recalled.repeated_at(g).map(|checks| (recalled, checks)),
            _ => None,
        }
    }

    /// The step at an accepted iterate `g`: φ0, the shape table and the checks.
    fn accept(
        &self,
        mut state: ContactState,
        g: &Geometry,
        (iterations, evaluations): (usize, usize),
        residual: f64,
        jac: Option<[[f64; 4]; 4]>,
    ) -> Result<SlipStep, SolveFailure> {
        let model = self.problem.model;
        let repeated = self.repeated(g);
        if state.split.conducting
            && !matches!(
                model.electrode,
                crate::contact::Electrode::ConductingPotential { .. }
            )
        {
            // φ0 of the accepted state (charge control; the moment does not feed back), or
            // the recalled state's when this is that state again.
            (state.charge, state.potential) = match repeated {
                Some((recalled, _)) => (recalled.state.charge, recalled.state.potential),
                None => {
                    let j_q = arcsine_moment(&state);
                    electric_resultants(model, g.a, self.problem.normal_load, j_q)
                }
            };
        }
        // The accepted state is evaluated many times from here on (checks, increments,
        // memory): tabulate its shape quadrature once, and drop an own correction that is
        // round-off (a return to a remembered state inherits that state whole and adds
        // nothing; its own series, about 1e−16 of ηp0, would otherwise cost a Clenshaw sum at
        // every later evaluation of every state whose chain holds it, one more per cycle).
        state.tabulate_shape();
        state.drop_negligible_correction(model.friction);
        let admissibility = match repeated {
            Some((_, checks)) => checks,
            None => assess_step(model, self.start, &state),
        };
        check(&admissibility, self.options.admissibility)?;
        Ok(SlipStep {
            state,
            iterations,
            newton_iterations: evaluations,
            residual,
            admissibility,
            jacobian: jac.unwrap_or([[0.0; 4]; 4]),
            repeated: repeated.is_some(),
        })
    }

    /// The failure of an attempt whose iteration ended at `g` without converging, with its
    /// stalled step when that is admissible. Every accepted iterate lowered the residual, so
    /// the last one is the best. A stalled iterate that may be accepted is first solved at the
    /// full inner tolerance (its inner solve may have stopped at 1e−3 of the residual before
    /// it).
    fn stalled(
        &self,
        g: Geometry,
        (mut r, mut state, tight): ([f64; 4], ContactState, bool),
        (iterations, mut evaluations): (usize, usize),
        jac: Option<[[f64; 4]; 4]>,
    ) -> Failed {
        let mut size = norm(&r);
        if size < self.options.stall_tolerance && !tight {
            (r, state, _) = match self.solve_fully(&g, &state) {
                Ok(solved) => solved,
                Err(failure) => return failure.into(),
            };
            evaluations += 1;
            size = norm(&r);
        }
        let stalled = (size < self.options.stall_tolerance)
            .then(|| {
                self.accept(state, &g, (iterations, evaluations), size, jac)
                    .ok()
            })
            .flatten()
            .map(Box::new);
        Failed {
            failure: SolveFailure::NoConvergence {
                what: "tangential step (Newton on stick ends, a, c)",
                iterations: evaluations,
                residual: size,
            },
            stalled,
        }
    }
}

#[cfg(test)]
mod tests;
