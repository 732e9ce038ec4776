//! The load-history driver: a piecewise-linear tangential load Q(t) (and, where the history
//! gives them, the normal load P(t) and the electric load Γ(t) or φ0(t)) walked step by step
//! through a closed set of solver states, with the strain memory stored at the start of every
//! monotonic phase (seed Section 4; `docs/formulation.md` §4).
//!
//! # States and transitions
//! [`Regime`] is closed: normal loading, stick (hold), forward slip, reverse slip. The next
//! regime is a pure function of the sign of ΔQ ([`next_regime`]): `ΔQ > 0` forward slip,
//! `ΔQ < 0` reverse slip, `ΔQ = 0` stick (nothing changes, the state is carried over). A phase
//! begins whenever the slip direction differs from the previous slip phase's (or at the first
//! slip step after normal loading): then the memory is recomputed from the current state over
//! the whole contact ([`Memory::committed`]). A hold between two segments of the same
//! direction does not start a new phase.
//!
//! # Steps
//! Each segment `(t0, Q0) → (t1, Q1)` is cut into `max(steps_per_segment, ⌈|ΔQ|/max_step⌉)`
//! equal steps (`η|ΔP|` counts as `|ΔQ|` where P varies; [`LoadHistory::load_points`]). Each step is tried by [`try_step`] from the
//! committed state and memory ([`solve_slip`] solves and checks it) and leaves the driver as it
//! was; [`DriverState::commit`] then stores it (trial, then commit). A failure stops the run
//! with the step, t, Q and regime; the steps already solved are kept by the caller (observer).
//!
//! # The state as data
//! Everything a step needs from the past is [`HistoryState`]: the spectral driver's
//! [`DriverState`] (committed state, memory, phase, displacement datum, and what only makes
//! steps faster: the recall traces, the warm start) and the general solver's run while it
//! holds the steps. It is written by serde and read back to the bit; a run passes it to its
//! observer at every turning point of the load ([`turning_points`],
//! [`Observer::on_checkpoint`]), and a run continued from a state read back takes the same
//! steps as the run that wrote it (test
//! `a_run_continued_from_a_checkpoint_read_back_takes_the_same_steps_to_the_bit`).
//!
//! A step's increments — Δδ at the anchor, the frictional dissipation and the works of P and
//! of the electric load ([`StepIncrements`], [`step_dissipation`]) — need only the step's two
//! states, and the next step needs none of them, so [`run_history`] computes them on a second
//! thread while it solves the next step ([`try_step`] and [`DriverState::commit`], then
//! [`finish_step`] in order); [`continue_run`] does the same from any driver state, and the
//! tests' `advance` does it sequentially. The records are the same either way.
//!
//! # Two solvers
//! [`continue_run`] hands a step that the spectral solver cannot take (it fails, or could only
//! accept it at a stalled residual) to the general element solver ([`GeneralRun`], from the
//! last committed state), which keeps the following steps until the spectral solver, trying
//! each load from its own memory within the phase of the handover, agrees with it (same zone
//! structure, ends within two elements); the spectral solver then commits that state with its
//! own increments. Under [`SolverChoice::Auto`] the general solver also takes the first step
//! of every phase, where thin end zones that slip the old way form in a coupled contact, and
//! the spectral solver's step is handed over when the two disagree; it checks every turning
//! point too. With `Accelerations::concurrent_checks` (off by default) the checks run on a
//! thread of their own while the spectral solver takes the steps after them, and what the
//! observer sees of a step waits until the checks before it have agreed (`checks`): a
//! contradicted step takes the run back to the state before it, and the run is the one of
//! checks taken in turn, to the bit. The spectral solver tries
//! to take the state back after 2, 4, 8, … general steps of the phase and at its last step (a
//! try gives up after 100 residual evaluations, a step under `auto` after
//! `SlipOptions::step_evaluations`; a failed one costs several general steps). A take-back
//! lost at the next step postpones the next try by 4 general steps, doubled for each one lost
//! before in the phase, up to 64 (`GeneralRun::take_back_lost`). Each record says which solver took
//! the step ([`SolverKind`]) and the zone structure ([`ZoneCount`]). Where the spectral
//! solver has no normal-loading state, the general solver loads the contact by steps and
//! holds every step of the history ([`NormalEnd`]; the state then has no spectral driver).
//! The spectral solver holds P and the electric load fixed (its memory is a past at the
//! normal loading's P and Γ): the first step that changes either is handed to the general
//! solver, which holds every later step, and the spectral driver is dropped. The regime of
//! such a step is still that of ΔQ (stick where Q holds), though its contact may slip.
//!
//! # Warm start
//! Inside a phase the geometry of the step (stick ends, contact half-width and centre) is
//! extrapolated from the last three steps by the quadratic in Q through them (`predict`), and
//! the previous step's Jacobian starts the quasi-Newton iteration (after a step with mixed
//! slip signs the Mindlin–Deresiewicz guess below is tried first). At the
//! start of a phase the zones that already slip in the new direction keep slipping and the
//! others stick, with new slip zones of the Mindlin–Deresiewicz width
//! `a(1 − √(1 − |ΔQ|/(2ηP)))` at the ends that start to slip, and the contact centre moves by
//! ΔQ times dc/dQ of the previous phase's first step.
//!
//! # Recall of a repeated phase
//! The driver keeps the accepted steps of the current phase and of the last finished phase of
//! each direction (`Traces`). When a phase begins from the same turning state as the last
//! phase of its direction (the load to 1e−9 of ηP, stick ends, a and c to 1e−8 a), each of
//! its steps is started from that phase's step at the same load ([`Recalled`]). In a steady
//! cycle that step solves the new one to the tolerance in one residual evaluation. Otherwise
//! its residual exceeds the recall limit, and the step is solved as above
//! (`SlipOptions::recall`).
//!
//! A step's checks, φ0 and increments are functions of its two states (and the anchor, for
//! δ). When a step begins from a state whose geometry and slip signs are to the bit those of
//! the state the recalled step began from, and is accepted at the recalled geometry (its first
//! evaluation solved it), its two states are the recalled step's to the solver's tolerance:
//! it takes that step's checks and φ0 ([`Recalled::admissibility`]) and, when δ is followed
//! at the same anchor, its increments ([`SolvedStep::known_increments`]) instead of
//! evaluating them (test
//! `repeated_steps_take_the_checks_and_increments_they_would_compute`). In a steady cycle
//! every step does: the step is one residual evaluation.
//!
//! [`Memory::committed`]: crate::contact::memory::Memory::committed
//! [`solve_slip`]: crate::contact::tangential::solve_slip
//! [`Recalled`]: crate::contact::tangential::Recalled
//! [`Recalled::admissibility`]: crate::contact::tangential::Recalled::admissibility

mod checks;
mod driver;
internal! { mod general; }
mod hints;
mod increments;
mod load;
mod normal;
mod record;
mod regime;
mod run;
mod state;
mod turnings;

pub use general::{RunOptions, SolverChoice, SolverKind, ZoneCount};
pub use load::{Control, LoadHistory, LoadPoint, PunchHistory, PunchLoads};
pub use normal::{Loading, NormalEnd};
pub use record::{NoObserver, Observer, SolvedState, StateView, StepFailure, StepRecord};
pub use regime::Regime;
pub use run::{HistoryFailure, HistoryRun, run_history};
pub use state::{HistoryState, HistoryStateView};
pub use turnings::Turnings;

internal_use! { driver::{DriverState, SolvedStep, Trial, Tried, finish_step, try_step}; }
#[cfg(any(test, feature = "internals"))]
pub use driver::{Solved, advance, solve_step};
internal_use! { general::{GeneralRun, GeneralRunData}; }
internal_use! { increments::{IncrementInputs, StepIncrements, slip_increments, step_dissipation}; }
internal_use! { normal::{load_by_steps, locked_in_strain_slope}; }
internal_use! { record::SolvedStateData; }
internal_use! { regime::{PhaseEvent, next_regime, phase_event}; }
internal_use! { run::{continue_run, run_from, turning_points}; }
internal_use! { state::HistoryStateData; }

#[cfg(test)]
use crate::contact::pressure::Discretisation;

/// The driver at the end of the normal loading of scenario `sc` on `disc` (tests' start).
#[cfg(test)]
pub(crate) fn driver_after_normal_loading(
    sc: &crate::scenario::Scenario,
    disc: &Discretisation,
) -> DriverState {
    use crate::contact::normal::{NormalOptions, solve_normal};
    let normal = solve_normal(&sc.model, disc, sc.normal_load, NormalOptions::default()).unwrap();
    DriverState::after_normal_loading(&normal)
}

/// The first `steps` steps of the default scenario's history from the end of its normal
/// loading on `disc`, each taken by [`advance`] with the default options; `visit` sees each
/// step's state before and after it (the tests' walk over the first phases).
#[cfg(test)]
pub(crate) fn walk_default_history(
    disc: &Discretisation,
    steps: usize,
    mut visit: impl FnMut(&crate::contact::ContactState, &crate::contact::ContactState),
) {
    let sc = crate::scenario::default_scenario();
    let mut driver = driver_after_normal_loading(&sc, disc);
    let history = sc.history.as_ref().expect("default history").steps();
    for (i, &(_, t, q)) in history.iter().take(steps).enumerate() {
        let old = driver.state.clone();
        let point = LoadPoint {
            step: i + 1,
            t,
            q,
            punch: None,
        };
        let options = crate::contact::tangential::SlipOptions::default();
        advance(
            &sc.model,
            disc,
            &mut driver,
            point,
            options,
            &mut NoObserver,
        )
        .unwrap();
        visit(&old, &driver.state);
    }
}

/// The default scenario (PZT-4, conducting punch, R = 60 mm, P = 2000 N/m, its history) with
/// friction `eta` and charge `gamma` (C/m).
#[cfg(test)]
pub(crate) fn default_scenario_with(eta: f64, gamma: f64) -> crate::scenario::Scenario {
    let mut raw: serde_json::Value =
        serde_json::from_str(crate::scenario::DEFAULT_SCENARIO).expect("JSON");
    raw["friction"] = eta.into();
    raw["punch"]["electrode"]["charge"] = gamma.into();
    let raw =
        crate::scenario::parse(&raw.to_string(), std::path::Path::new("<test>")).expect("parses");
    crate::scenario::validate(raw).expect("valid")
}
