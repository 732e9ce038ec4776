//! The end of normal loading, the first state of every history ([`NormalEnd`]).
//!
//! P and the electric load (Γ of a charged conducting punch, φ0 of one held at a potential)
//! rise together from zero in proportion, `P f²` and the electric load times `f²`: the path
//! along which the contact is self-similar, `a ∝ f` (seed Section 3; the charge and the
//! potential scale as the pressure does).
//!
//! # Spence's state, or the general solver's
//! The spectral solver gives Spence's self-similar state directly
//! ([`crate::contact::normal::solve_normal`]: one central stick zone between two slip zones).
//! Where that form holds no admissible state, and the choice of solver is not
//! [`SolverChoice::Spectral`], the general solver loads the contact by steps along the same
//! path ([`load_by_steps`]) and the history starts from its state; so it does for a punch
//! that is not a cylinder (the flat punch with rounded corners, [`crate::contact::Profile`]),
//! whose contact is not self-similar. That happens at small η
//! in a coupled contact: PZT-4 under a conducting punch with Γ = 2e−7 C/m (below Γ1) and
//! η = 0.1 ends with the slip near each contact end running the other way, beyond a second
//! stick zone (five zones in all, two changes of the slip direction on each side). Every step
//! of such a history is the general solver's ([`HistoryState::driver`] is `None`): the spectral
//! solver's memory cannot describe that past.
//!
//! # Loading by steps
//! The first step goes from the unloaded state to `f = START`; then f grows by a fixed factor
//! a step, up to 1. The state is path-dependent: its stick zones converge at first order in
//! the step (Spence's aluminium case, Goodman's approximation: b/a 2.6e−3 below the closed form
//! at 2 % steps and 1.4e−3 at 1 %; test
//! `contact::general::tests::spence_stick_ratio_goodman_and_full_coupling`). Two passes: the
//! first, with steps of [`COARSE_RATIO`] on a mesh graded towards the frictionless contact
//! ends ([`Solver::first_half_width`]), finds the contact and its zone ends; the second, with
//! steps of [`RATIO`], on a mesh graded as a handover's is (elements of
//! [`END_SIZE`]·a at the contact ends, [`STICK_SIZE`]·a at every zone end, band `±1.25a`),
//! gives the state. The mesh is symmetric about the punch axis, as the loading is.
//!
//! # From the unloaded punch
//! A scenario with `normal_load` 0 has no normal loading: its history starts from the punch
//! touching the undeformed surface with no load ([`NormalEnd::solve`] gives the general
//! solver's state without contact, [`crate::contact::general::Solver::separated`]), and the
//! history's own steps press it, in the history's steps (uniform in P along a segment) rather
//! than the geometric ones above, with the state carried from each step's mesh to the next.
//! The spectral solver has no state to offer there, so the general solver holds every step.
//! Under proportional P and Γ the stick zone converges to Spence's at first order in the step
//! (test `normal_loading_from_the_unloaded_punch_converges_to_spences_state`).

use std::sync::Arc;

use crate::contact::ContactModel;
use crate::contact::general::{ElementState, Focus, GeneralState, Loads, Mesh, Options, Solver};
use crate::contact::normal::{NormalLoading, NormalOptions, solve_normal};
use crate::contact::pressure::Discretisation;
use crate::error::SolveFailure;

use super::driver::{DriverState, record};
use super::general::{END_SIZE, GROWTH, GeneralRun, STICK_SIZE, SolverChoice, loads_of};
use super::record::{SolvedState, StateView, StepRecord};
use super::regime::Regime;
use super::state::HistoryState;

/// The load fraction f of the first step from the unloaded state.
pub const START: f64 = 0.1;
/// The growth of f per step of the first pass.
pub const COARSE_RATIO: f64 = 1.05;
/// The growth of f per step of the second pass.
pub const RATIO: f64 = 1.01;

/// The state at the end of normal loading.
#[derive(Debug, Clone)]
pub enum NormalEnd {
    /// Spence's self-similar state, from the spectral solver.
    Spectral(Box<NormalLoading>),
    /// The general solver's state after loading by steps, and how it was reached.
    General(Box<GeneralRun>, Loading),
}

/// How the general solver's normal loading went.
#[derive(Debug, Clone, PartialEq)]
pub struct Loading {
    /// Load steps of the final pass.
    pub steps: usize,
    /// Outer (normal–tangential) iterations over those steps.
    pub iterations: usize,
    /// Why the spectral solver did not give the state.
    pub spectral_failure: String,
}

impl NormalEnd {
    /// The end of normal loading to `normal_load` (and the model's electric load): Spence's
    /// state from the spectral solver on `disc`, or, where it has none and `solver` is not
    /// [`SolverChoice::Spectral`], the general solver's by steps (largest elements `inner`·a).
    /// The spectral solver's failure when neither gives a state.
    pub fn solve(
        model: &ContactModel,
        disc: &Discretisation,
        normal_load: f64,
        solver: SolverChoice,
        inner: f64,
    ) -> Result<Self, SolveFailure> {
        if normal_load == 0.0 {
            return match solver {
                SolverChoice::Spectral => Err(SolveFailure::NoAdmissibleState {
                    reason: "the spectral solver's history starts from its normal loading; a \
                             history from the unloaded punch (P = 0) needs the general solver"
                        .into(),
                }),
                _ => Ok(Self::unloaded(model, inner)),
            };
        }
        let failure = if !model.profile.is_cylinder() {
            SolveFailure::NoAdmissibleState {
                reason: "the spectral solver takes a cylindrical punch only".into(),
            }
        } else {
            match solve_normal(model, disc, normal_load, NormalOptions::default()) {
                Ok(normal) => return Ok(Self::Spectral(Box::new(normal))),
                Err(failure) => failure,
            }
        };
        if solver == SolverChoice::Spectral {
            return Err(failure);
        }
        let (run, mut loading) = load_by_steps(model, normal_load, inner).map_err(|general| {
            SolveFailure::NeitherSolver {
                spectral: Box::new(failure.clone()),
                general: Box::new(general),
            }
        })?;
        loading.spectral_failure = failure.to_string();
        Ok(Self::General(Box::new(run), loading))
    }

    /// The unloaded punch touching the undeformed surface, the start of a history from P = 0
    /// (`normal_load` 0): the general solver's state without contact
    /// ([`Solver::separated`]); the history's first step that raises P presses the punch,
    /// on a mesh made for the frictionless contact of its loads
    /// ([`super::general::mesh_for_loads`]), and the general solver holds every step.
    fn unloaded(model: &ContactModel, inner: f64) -> Self {
        let solver = Solver::new(model, Mesh::uniform(-1.0, 1.0, 2), Options::default());
        let state = solver.separated(loads_of(model, 0.0, 0.0), 0.0);
        let loading = Loading {
            steps: 0,
            iterations: 0,
            spectral_failure: "the history starts from the unloaded punch (normal_load 0)".into(),
        };
        Self::General(
            Box::new(GeneralRun::loaded(Arc::new(solver), state, inner)),
            loading,
        )
    }

    /// The state a history starts from.
    pub fn history_state(&self) -> HistoryState {
        match self {
            Self::Spectral(normal) => HistoryState::new(DriverState::after_normal_loading(normal)),
            Self::General(run, _) => HistoryState {
                driver: None,
                turnings: super::turnings::Turnings::new(run.state.loads.tangential, None),
                general: Some((**run).clone()),
            },
        }
    }

    /// The record of the end of normal loading (step 0, at time `t`).
    pub fn record(&self, t: f64) -> StepRecord {
        match self {
            Self::Spectral(normal) => record(
                0,
                t,
                &DriverState::after_normal_loading(normal),
                Regime::NormalLoading,
                None,
            ),
            Self::General(run, _) => run.record(0, t, Regime::NormalLoading, None),
        }
    }

    /// The solved state, borrowed.
    pub fn view(&self) -> StateView<'_> {
        match self {
            Self::Spectral(normal) => StateView::Spectral(&normal.state),
            Self::General(run, _) => StateView::General(run.solver(), &run.state),
        }
    }

    /// The solved state.
    pub fn solved_state(&self) -> SolvedState {
        self.view().to_owned()
    }

    /// The spectral state, if the spectral solver gave it.
    pub fn spectral(&self) -> Option<&NormalLoading> {
        match self {
            Self::Spectral(normal) => Some(normal),
            Self::General(..) => None,
        }
    }
}

/// Load the contact by steps with the general solver (module docs): its run at the end of
/// normal loading, with the punch displacement δ counted from there, and how it went.
pub fn load_by_steps(
    model: &ContactModel,
    normal_load: f64,
    inner: f64,
) -> Result<(GeneralRun, Loading), SolveFailure> {
    let full = loads_of(model, normal_load, 0.0);
    // First pass: the contact and its zones, on a band widened until it holds the contact.
    let probe = Solver::new(model, Mesh::uniform(-1.0, 1.0, 2), Options::default());
    let a = probe.first_half_width(full);
    let mut half = 1.6;
    let first = loop {
        if !(a.is_normal() && (half * a).is_normal() && (END_SIZE * a).is_normal()) {
            return Err(SolveFailure::NoAdmissibleState {
                reason: format!(
                    "the contact half-width of P = {normal_load:e} N/m ({a:e} m, frictionless) is \
                     out of the range of floating-point numbers"
                ),
            });
        }
        let focus = [Focus {
            at: a,
            size: 2e-3 * a,
        }];
        let mesh = Mesh::symmetric(half * a, &focus, 1.1, 2e-2 * a);
        let solver = Solver::new(model, mesh, Options::default());
        let (state, _) = steps(&solver, full, COARSE_RATIO)?;
        let (lo, _) = state.contact_extent().expect("a loaded contact");
        let edge = state.mesh.edges[1] - state.mesh.edges[0];
        if lo - state.mesh.edges[0] > 2.0 * edge {
            break state;
        }
        if half > 6.0 {
            return Err(SolveFailure::NoAdmissibleState {
                reason: format!(
                    "the contact reaches the edge of a band of {half} times its frictionless \
                     half-width {a:e} m"
                ),
            });
        }
        half *= 2.0;
    };
    // Second pass, on the mesh of the first pass's zones.
    let solver = Arc::new(Solver::new(
        model,
        mesh_of_zones(&first, model.profile.flat_half_width(), inner),
        Options::default(),
    ));
    let (state, loading) = steps(&solver, full, RATIO)?;
    Ok((GeneralRun::loaded(solver, state, inner), loading))
}

/// A symmetric mesh for the state of a normal loading: band `±1.25a`, elements of
/// [`END_SIZE`]·a at the contact ends and [`STICK_SIZE`]·a at the ends of its zones (those
/// more than one element long) and at the corners `±flat` of a flat punch (where h'' jumps),
/// growing by [`GROWTH`] up to `inner`·a.
fn mesh_of_zones(state: &GeneralState, flat: f64, inner: f64) -> Mesh {
    let (lo, hi) = state.contact_extent().expect("a loaded contact");
    let a = 0.5 * (hi - lo);
    let mut focus = vec![Focus {
        at: a,
        size: END_SIZE * a,
    }];
    if flat > 0.0 && flat < a {
        focus.push(Focus {
            at: flat,
            size: STICK_SIZE * a,
        });
    }
    let zones = state.zones();
    for pair in zones.windows(2) {
        let at = pair[0].2.abs();
        let inside = at > 0.0 && at < a;
        let resolved = pair
            .iter()
            .all(|z| z.2 - z.1 > 1.5 * state.mesh.width_at(z.1));
        if inside && resolved {
            focus.push(Focus {
                at,
                size: STICK_SIZE * a,
            });
        }
    }
    Mesh::symmetric(1.25 * a, &focus, GROWTH, inner * a)
}

/// The loading from zero on `solver`'s mesh: `f = START`, then `f × ratio` a step up to 1.
fn steps(
    solver: &Solver,
    full: Loads,
    ratio: f64,
) -> Result<(GeneralState, Loading), SolveFailure> {
    let mut state = GeneralState::unloaded(solver.mesh().clone());
    let count = ((1.0 / START).ln() / ratio.ln()).ceil() as usize;
    let mut iterations = 0;
    for k in 0..=count {
        let f = (START * ratio.powi(k as i32)).min(1.0);
        let loads = Loads {
            normal: full.normal * f * f,
            tangential: 0.0,
            electric: full.electric * f * f,
            bulk_stress: 0.0,
        };
        let (next, report) = solver.step(&state, loads)?;
        iterations += report.outer_iterations;
        state = next;
    }
    let loading = Loading {
        steps: count + 1,
        iterations,
        spectral_failure: String::new(),
    };
    Ok((state, loading))
}

/// The slope C of the locked-in strain `∂ux/∂x = C|x|` of the longest stick zone of a state
/// (1/m): the least-squares fit of `ux = u0 + C x|x|/2` to its elements (in a stick zone ux is
/// the displacement each point had when it stuck); 0 without a stick zone of three elements.
pub fn locked_in_strain_slope(state: &GeneralState) -> f64 {
    let Some((_, lo, hi)) = state
        .zones()
        .into_iter()
        .filter(|z| z.0 == ElementState::Stick)
        .max_by(|x, y| (x.2 - x.1).total_cmp(&(y.2 - y.1)))
    else {
        return 0.0;
    };
    let (mut n, mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for i in 0..state.mesh.len() {
        let x = state.mesh.centre(i);
        if x > lo && x < hi {
            let (v, u) = (0.5 * x * x.abs(), state.displacement[i]);
            n += 1.0;
            sx += v;
            sy += u;
            sxx += v * v;
            sxy += v * u;
        }
    }
    let det = n * sxx - sx * sx;
    if n < 3.0 || det <= 0.0 {
        return 0.0;
    }
    (n * sxy - sx * sy) / det
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::general::ElementState::{Exterior, SlipNegative, SlipPositive, Stick};
    use crate::history::{
        LoadHistory, NoObserver, RunOptions, SolverKind, ZoneCount, default_scenario_with,
        general::INNER_SIZE, run_history,
    };

    /// Where the spectral solver has Spence's state, the general solver's loading by steps
    /// gives it too: PZT-4 at Γ = 2e−7 C/m (below Γ1: friction inward in the slip zones, and
    /// the general solver's smooth-end rule for the contact) and η = 0.3.
    #[test]
    fn the_general_loading_by_steps_gives_spences_state_where_the_spectral_solver_has_one() {
        let sc = default_scenario_with(0.3, 2e-7);
        let spectral = solve_normal(
            &sc.model,
            &Discretisation::new(64),
            2000.0,
            NormalOptions::default(),
        )
        .unwrap();
        let (run, loading) = load_by_steps(&sc.model, 2000.0, INNER_SIZE).unwrap();
        let rec = run.record(0, 0.0, Regime::NormalLoading, None);
        let a = spectral.state.half_width;
        let b = 0.5 * (rec.stick_hi - rec.stick_lo);
        let c = locked_in_strain_slope(&run.state);
        eprintln!(
            "a {:.6e} m (spectral {a:.6e}), b/a {:.5} ({:.5}), C {c:.5e} 1/m ({:.5e}), {} steps",
            rec.half_width,
            b / a,
            spectral.stick_half_width / a,
            spectral.strain_slope,
            loading.steps
        );
        // Measured: Δa = 2.5e−4 a (end elements 5e−4 a), Δ(b/a) = −5.0e−4 (elements of
        // 1e−3 a at b; first order in the step: 1 % steps), ΔC/C = −3.3e−3. One central
        // stick zone between the slip zones with friction inward (q = −ηp at the right), as
        // Spence's. (With the slip of the entering elements counted from the step's start:
        // −7.0e−5 a, −1.1e−3, −4.3e−3, and a layer of one element at each end slipping the
        // other way.)
        let end = run.state.mesh.width_at(a);
        assert!((rec.half_width - a).abs() <= end);
        assert!((b - spectral.stick_half_width).abs() <= 2e-3 * a);
        assert!((c / spectral.strain_slope - 1.0).abs() <= 1e-2);
        assert_eq!(
            rec.right_slip_sign.to_bits(),
            spectral.state.traction.right_sign.to_bits()
        );
        assert_eq!(
            ZoneCount::resolved(&run.state),
            ZoneCount::of_spectral(&spectral.state)
        );
        let (p, _, g) = run.state.resultants();
        assert!((p / 2000.0 - 1.0).abs() < 1e-12 && (g / 2e-7 - 1.0).abs() < 1e-12);
    }

    /// PZT-4 at Γ = 2e−7 C/m and η = 0.1: the spectral solver has no state with one central
    /// stick zone, the general solver loads the contact by steps, and a history from there
    /// completes with every step its own. The state is symmetric (q odd, p even), carries P
    /// and Γ, and has the structure described in the module docs: near each end the slip runs
    /// the other way beyond a second stick zone.
    #[test]
    fn at_small_friction_below_gamma1_the_general_solver_loads_the_contact_and_takes_the_history() {
        let sc = default_scenario_with(0.1, 2e-7);
        let disc = Discretisation::new(64);
        assert!(solve_normal(&sc.model, &disc, 2000.0, NormalOptions::default()).is_err());
        let normal =
            NormalEnd::solve(&sc.model, &disc, 2000.0, SolverChoice::Auto, INNER_SIZE).unwrap();
        let NormalEnd::General(run, loading) = &normal else {
            panic!("the spectral solver has no state here")
        };
        assert!(
            loading
                .spectral_failure
                .contains("no stick/slip state of the assumed form")
        );
        assert!(
            NormalEnd::solve(&sc.model, &disc, 2000.0, SolverChoice::Spectral, INNER_SIZE).is_err()
        );
        let s = &run.state;
        let n = s.mesh.len();
        let pmax = s.pressure.iter().copied().fold(0.0, f64::max);
        for i in 0..n {
            let j = n - 1 - i;
            assert!((s.pressure[i] - s.pressure[j]).abs() <= 1e-9 * pmax);
            assert!((s.shear[i] + s.shear[j]).abs() <= 1e-9 * 0.1 * pmax);
            assert!(s.shear[i].abs() <= 0.1 * s.pressure[i] * (1.0 + 1e-12));
        }
        let (p, q, g) = s.resultants();
        assert!((p / 2000.0 - 1.0).abs() < 1e-12 && (g / 2e-7 - 1.0).abs() < 1e-12);
        assert!(q.abs() < 1e-9 * 0.1 * 2000.0);
        // From the left end: slip the other way, a second stick zone, slip with friction
        // inward, the central stick zone, and the mirror image. (The elements that enter the
        // contact in a step stick from their entry, so the end element carries no layer of
        // its own.)
        let right: Vec<_> = s.zones().into_iter().filter(|z| z.1 >= 0.0).collect();
        let kinds: Vec<_> = right.iter().map(|z| z.0).collect();
        assert_eq!(kinds, [SlipNegative, Stick, SlipPositive, Exterior]);
        let a = 0.5 * (right[2].2 - s.zones()[0].2);
        eprintln!(
            "zones right of the centre (x/a): {:?}",
            right
                .iter()
                .map(|z| (z.0, z.1 / a, z.2 / a))
                .collect::<Vec<_>>()
        );
        let history = LoadHistory {
            points: vec![(0.0, 0.0), (1.0, 100.0), (3.0, -100.0)],
            punch: None,
            steps_per_segment: 10,
            max_step: 20.0,
            control: crate::history::Control::Load,
            max_displacement_step: f64::INFINITY,
        };
        let records = run_history(
            &sc.model,
            &disc,
            &normal,
            &history,
            RunOptions::new(SolverChoice::Auto),
            &mut NoObserver,
        )
        .unwrap()
        .records;
        assert_eq!(records.len(), 21);
        assert!(records.iter().all(|r| r.solver == SolverKind::General));
        assert_eq!(records[0].regime, Regime::NormalLoading);
        assert_eq!(records[0].displacement.to_bits(), 0f64.to_bits());
        assert!(records[20].displacement < records[10].displacement);
    }

    /// PZT-4 at Γ = 2e−7 C/m and η = 0.05, the smallest friction of the failure map: the
    /// general solver loads the contact by steps. Its tangential programme for the reference
    /// of the entering elements does not settle from the previous pass's solution at one step
    /// and is solved again from the step's start (`contact::general`, module `entry`); the
    /// state found has three stick zones and four slip zones.
    #[test]
    fn at_the_smallest_friction_of_the_failure_map_the_general_loading_completes() {
        let sc = default_scenario_with(0.05, 2e-7);
        let disc = Discretisation::new(64);
        let normal =
            NormalEnd::solve(&sc.model, &disc, 2000.0, SolverChoice::Auto, INNER_SIZE).unwrap();
        let NormalEnd::General(run, _) = &normal else {
            panic!("the spectral solver has no state here")
        };
        let (p, _, g) = run.state.resultants();
        assert!((p / 2000.0 - 1.0).abs() < 1e-12 && (g / 2e-7 - 1.0).abs() < 1e-12);
    }
}
