//! The hybrid driver (`numerics.solver`): the general element solver takes the steps the
//! spectral solver cannot, and agrees with it where both can.

use std::path::Path;

use fretsim::history::{GeneralRun, NoObserver, SolverKind, StepRecord};

/// A scenario from JSON text.
fn scenario(text: &str) -> fretsim::Scenario {
    let raw = fretsim::parse(text, Path::new("test.json")).unwrap();
    fretsim::validate(raw).unwrap()
}

/// The paper's Figure-3 history (PZT-4, conducting punch, Γ = 6e−7 C/m) at η = 0.1:
/// A = 0.3 ηP, B = 0.5 ηP, back to 0.3 ηP.
fn figure3_at_eta_0_1(solver: &str) -> String {
    format!(
        r#"{{
  "name": "figure3_eta_0_1",
  "material": {{ "kind": "preset", "name": "pzt4" }},
  "punch": {{ "radius": 0.06, "electrode": {{ "kind": "conducting", "charge": 6e-7 }} }},
  "friction": 0.1,
  "normal_load": 2000.0,
  "tangential_history": {{ "points": [[0.0, 0.0], [1.0, 0.3], [2.0, 0.5], [3.0, 0.3]] }},
  "numerics": {{ "solver": "{solver}" }}
}}"#
    )
}

/// The first reversal of the Figure-3 history at η = 0.1 (step 21, the first step after B)
/// stops the spectral solver: the receding contact end leaves a layer that slips the old
/// way, with a second stick zone beside it. Under `auto` the general solver takes that step
/// and the next ones (and checks the first step of every phase: the first loading step from
/// Spence's state, whose end zones slip inwards, is its too), finds the layers (a step with
/// two stick zones or with slip of both signs), and hands back to the spectral solver within
/// the phase once the layers are gone; the run completes. Where the spectral solver took a
/// step, its state is the one it reaches alone (it resumes from its own memory).
#[test]
fn figure3_history_at_eta_0_1_completes_and_the_spectral_solver_resumes() {
    let spectral =
        fretsim::solve(&scenario(&figure3_at_eta_0_1("spectral")), &mut NoObserver).unwrap();
    assert!(spectral.failure.is_some());
    assert_eq!(
        spectral.records.len(),
        21,
        "the spectral solver stops at step 21"
    );
    let auto = fretsim::solve(&scenario(&figure3_at_eta_0_1("auto")), &mut NoObserver).unwrap();
    assert!(auto.failure.is_none(), "{:?}", auto.failure);
    let r = &auto.records;
    assert_eq!(r.len(), 31);
    let a = r[0].half_width;
    for (s, x) in spectral.records.iter().zip(r) {
        if x.solver == SolverKind::Spectral {
            for (u, v) in [
                (s.stick_lo, x.stick_lo),
                (s.stick_hi, x.stick_hi),
                (s.half_width, x.half_width),
                (s.eccentricity, x.eccentricity),
            ] {
                assert!((u - v).abs() < 1e-9 * a, "step {}: {u:e} {v:e}", s.step);
            }
        }
    }
    assert_eq!(r[21].solver, SolverKind::General);
    let general: Vec<&StepRecord> = r
        .iter()
        .filter(|s| s.solver == SolverKind::General)
        .collect();
    assert!(
        general
            .iter()
            .any(|s| s.zones.stick >= 2 || s.zones.sign_changes >= 1),
        "the end layers"
    );
    assert!(general.len() < 15, "{} general steps", general.len());
    assert_eq!(r[20].solver, SolverKind::Spectral);
    assert_eq!(
        r[30].solver,
        SolverKind::Spectral,
        "the spectral solver resumed"
    );
    assert_eq!(auto.summary.solver.general_steps, general.len());
    let handovers = &auto.summary.solver.handovers;
    assert!(handovers.iter().any(|h| h.step == 21), "{handovers:?}");
    // δ and the dissipation go on across the handovers: the punch moves back in every step of
    // the reversal, and every step dissipates.
    for w in r[20..].windows(2) {
        assert!(w[1].displacement < w[0].displacement, "step {}", w[1].step);
        assert!(w[1].dissipation > 0.0, "step {}", w[1].step);
    }
}

/// The paper's baseline (PZT-4, conducting punch, Γ = 6e−7 C/m, η = 0.3) over one cycle
/// 0 → 0.5 → −0.5 → 0.5 ηP in steps of 0.1 ηP.
fn baseline_cycle(solver: &str, element: f64) -> fretsim::Solution {
    let text = format!(
        r#"{{
  "name": "baseline_cycle",
  "material": {{ "kind": "preset", "name": "pzt4" }},
  "punch": {{ "radius": 0.06, "electrode": {{ "kind": "conducting", "charge": 6e-7 }} }},
  "friction": 0.3,
  "normal_load": 2000.0,
  "tangential_history": {{
    "points": [[0.0, 0.0], [1.0, 0.5], [2.0, -0.5], [3.0, 0.5]],
    "steps_per_segment": 5,
    "max_step": 0.2
  }},
  "numerics": {{ "solver": "{solver}", "general_element_size": {element} }}
}}"#
    );
    fretsim::solve(&scenario(&text), &mut NoObserver).unwrap()
}

/// `numerics.solver = general` against the spectral solver over the baseline cycle: every
/// step's stick ends, half-width and eccentricity within one element of the default 6e−3 a
/// (measured 3.2e−3 a; a stick end lies within an element), within 2e−3 a with elements of
/// at most 3e−3 a (measured 1.5e−3 a), and the friction work of the cycle within 0.5 %
/// (measured 0.09–0.13 %, the trapezoidal dissipation of 0.2 ηP steps; 0.011 % with 0.05 ηP
/// steps).
#[test]
fn general_solver_agrees_with_the_spectral_solver_over_a_cycle() {
    let spectral = baseline_cycle("spectral", 6e-3);
    assert!(spectral.failure.is_none());
    assert_eq!(spectral.records.len(), 16);
    let a = spectral.records[0].half_width;
    let work = |s: &fretsim::Solution| s.cycles.last().unwrap().friction_work;
    for (element, bound) in [(6e-3, 6e-3), (3e-3, 2e-3)] {
        let general = baseline_cycle("general", element);
        assert!(general.failure.is_none());
        assert_eq!(general.records.len(), 16);
        for (s, g) in spectral.records.iter().zip(&general.records).skip(1) {
            assert_eq!(g.solver, SolverKind::General);
            for (x, y) in [
                (s.stick_lo, g.stick_lo),
                (s.stick_hi, g.stick_hi),
                (s.half_width, g.half_width),
                (s.eccentricity, g.eccentricity),
            ] {
                assert!(
                    (x - y).abs() < bound * a,
                    "{element}, step {}: {x:e} {y:e}",
                    s.step
                );
            }
        }
        let change = work(&general) / work(&spectral) - 1.0;
        assert!(change.abs() < 5e-3, "{element}: {change:e}");
    }
}

/// PZT-4 at Γ = 2e−7 C/m (below Γ1 = kP = 5.0e−7 C/m), η = 0.5, loaded to Q = 0.3167 ηP in 32
/// steps: the shear traction translates the contact (one end advances, the other recedes).
/// Below Γ1 p ≥ 0 and a non-negative gap allow a range of contact ends; the model's is the one
/// with the pressure smooth at both ends (module docs of `contact::general`, "smooth contact
/// ends"). Both solvers must then give the same contact: the spectral solver by its bounded
/// form (a = 41.970 µm, e = 0.740 µm at M = 32, 64, 128), the general solver by the largest
/// admissible set (measured: within 3e−3 µm of those at its default elements; before that
/// rule its advancing end stayed at the normal-loading end, a = 41.62 µm and e = 0.40 µm).
/// Under `auto` the first reversal step is no longer kept by the general solver for the rest
/// of the history (measured: 94 of the 96 steps spectral; before, 64 general).
#[test]
fn contact_translates_alike_in_both_solvers_below_gamma1() {
    let text = |solver: &str| {
        format!(
            r#"{{"name": "below_gamma1", "material": {{"kind": "preset", "name": "pzt4"}},
 "punch": {{"radius": 0.06, "electrode": {{"kind": "conducting", "charge": 2e-07}}}},
 "friction": 0.5, "normal_load": 2000.0,
 "numerics": {{"collocation_points": 32, "solver": "{solver}"}},
 "tangential_history": {{"unit": "fraction_of_limit",
   "points": [[0, 0], [1, 0.316667], [2, -0.316667]],
   "steps_per_segment": 5, "max_step": 0.01}}}}"#
        )
    };
    let run = |solver: &str| fretsim::solve(&scenario(&text(solver)), &mut NoObserver).unwrap();
    let (spectral, general) = (run("spectral"), run("general"));
    let (s, g) = (&spectral.records[32], &general.records[32]);
    assert_eq!(g.solver, SolverKind::General);
    let a = s.half_width;
    eprintln!(
        "a = {:.6e} / {:.6e} m, e = {:.6e} / {:.6e} m (spectral / general)",
        s.half_width, g.half_width, s.eccentricity, g.eccentricity
    );
    assert!((s.half_width / 4.1970e-5 - 1.0).abs() < 1e-4);
    assert!((s.eccentricity / 7.40e-7 - 1.0).abs() < 2e-3);
    for (u, v) in [
        (s.half_width, g.half_width),
        (s.eccentricity, g.eccentricity),
    ] {
        assert!((u - v).abs() < 1e-3 * a, "{u:e} vs {v:e}");
    }
    let auto = run("auto");
    assert!(auto.failure.is_none());
    let taken = auto
        .records
        .iter()
        .filter(|r| r.solver == SolverKind::General)
        .count();
    assert!(taken <= 8, "{taken} general steps under auto");
}

/// A take-back that does not hold: in the Figure-3 history at η = 0.1 the spectral solver
/// takes the state back at step 24 and fails step 25 (the receding end's layer of reversed
/// slip comes back). A run handed over at the first step after a take-back tries the next one
/// after [`GeneralRun::LOST_TAKE_BACK_WAIT`] general steps, not after 2 (before: taken back at
/// step 26, the spectral solver from step 27; now at step 28, from step 29), so that where the
/// general solver's state passes for a spectral one only at every other step the spectral
/// solver fails a step at most every `LOST_TAKE_BACK_WAIT` steps, not every second one.
#[test]
fn a_lost_take_back_postpones_the_next_try() {
    let auto = fretsim::solve(&scenario(&figure3_at_eta_0_1("auto")), &mut NoObserver).unwrap();
    assert!(auto.failure.is_none(), "{:?}", auto.failure);
    let r = &auto.records;
    let lost: Vec<usize> = auto
        .summary
        .solver
        .handovers
        .iter()
        .map(|h| h.step)
        .filter(|&h| h >= 2 && r[h - 1].solver == SolverKind::General)
        .collect();
    assert_eq!(lost, [25], "the take-back at step 24 is lost at step 25");
    for &h in &lost {
        let held = &r[h..(h + GeneralRun::LOST_TAKE_BACK_WAIT).min(r.len())];
        assert!(
            held.iter().all(|s| s.solver == SolverKind::General),
            "step {h}: the next take-back before {} general steps",
            GeneralRun::LOST_TAKE_BACK_WAIT
        );
    }
    let wait = GeneralRun::LOST_TAKE_BACK_WAIT;
    assert_eq!(
        r[25 + wait].solver,
        SolverKind::Spectral,
        "taken back again"
    );
}

/// At the paper's baseline Γ = 6e−7 C/m exceeds Γ1 = kP (5.0e−7 C/m), and the conducting-punch
/// model's states overlap the punch just outside the contact (Spence's state, handed over:
/// gaps of −1.3e−11 to −2.6e−11 m over the three elements beyond each end, a²/2R = 1.5e−8 m).
/// The general solver takes those elements into its contact in its first step. They touch
/// the punch at the step's start already, so they enter with the step-start slip reference
/// (`contact::general::entry`, φ = 0); given the motion of the free element beyond them over
/// the whole step instead (φ = 1), they slipped the old way: a third slip zone at the
/// advancing end at every step, which made each phase start a handover and kept the random
/// variable-amplitude history of the benches under the general solver at every step. The
/// first two loading steps of the baseline, 0.05 ηP each: the general solver finds one stick
/// zone between two slip zones of one sign, as the spectral solver does, and under `auto` no
/// step is handed over.
#[test]
fn above_gamma1_the_elements_that_overlap_the_punch_enter_from_the_step_start() {
    let text = |solver: &str| {
        format!(
            r#"{{"name": "baseline_first_loading", "material": {{"kind": "preset", "name": "pzt4"}},
 "punch": {{"radius": 0.06, "electrode": {{"kind": "conducting", "charge": 6e-07}}}},
 "friction": 0.3, "normal_load": 2000.0,
 "numerics": {{"solver": "{solver}"}},
 "tangential_history": {{"points": [[0, 0], [1, 0.1]], "steps_per_segment": 2}}}}"#
        )
    };
    let run = |solver: &str| fretsim::solve(&scenario(&text(solver)), &mut NoObserver).unwrap();
    let general = run("general");
    assert!(general.failure.is_none());
    for r in &general.records[1..] {
        assert_eq!(r.solver, SolverKind::General);
        assert_eq!(
            (r.zones.stick, r.zones.slip, r.zones.sign_changes),
            (1, 2, 0),
            "step {}",
            r.step
        );
    }
    let auto = run("auto");
    assert!(auto.failure.is_none());
    assert_eq!(auto.summary.solver.handover_count, 0);
    assert!(
        auto.records
            .iter()
            .all(|r| r.solver == SolverKind::Spectral)
    );
}

/// Every call a run makes of its observer, written out to the bit (`{:?}` of the records and
/// of the states, the checkpoints' states as they are written), and an end asked for at the
/// `stop_at`-th checkpoint.
struct Calls {
    seen: Vec<String>,
    checkpoints: usize,
    stop_at: usize,
}

impl Calls {
    fn new(stop_at: usize) -> Self {
        Self {
            seen: Vec::new(),
            checkpoints: 0,
            stop_at,
        }
    }
}

impl fretsim::history::Observer for Calls {
    fn on_step(&mut self, record: &StepRecord, state: fretsim::history::StateView<'_>) {
        let state = match state {
            fretsim::history::StateView::Spectral(s) => format!("{s:?}"),
            fretsim::history::StateView::General(_, s) => format!("{s:?}"),
        };
        self.seen.push(format!("step {record:?} {state}"));
    }
    fn on_handover(&mut self, failure: &fretsim::history::StepFailure) {
        self.seen
            .push(format!("handover {failure}: {:?}", failure.failure));
    }
    fn on_phase(&mut self, phase: usize, memory: &fretsim::contact::memory::Memory) {
        self.seen.push(format!("phase {phase} {memory:?}"));
    }
    fn on_checkpoint(&mut self, last: &StepRecord, state: fretsim::history::HistoryStateView<'_>) {
        self.checkpoints += 1;
        let written = serde_json::to_string(&state).expect("a state is written");
        self.seen
            .push(format!("checkpoint {} {written}", last.step));
    }
    fn stop(&self) -> bool {
        self.checkpoints >= self.stop_at
    }
}

/// The default scenario's history under `auto`, with the general solver's checks run beside
/// the steps or in turn (`Accelerations::concurrent_checks`), ended at the `stop_at`-th
/// checkpoint: what the observer saw, the records and the state written at the end.
fn default_history_checked(concurrent: bool, stop_at: usize) -> (Vec<String>, usize, String) {
    use fretsim::contact::normal::{NormalOptions, solve_normal};
    use fretsim::contact::pressure::Discretisation;
    let sc = fretsim::scenario::default_scenario();
    let disc = Discretisation::new(sc.collocation_points);
    let normal = fretsim::history::NormalEnd::Spectral(Box::new(
        solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default()).unwrap(),
    ));
    let mut options = fretsim::history::RunOptions::new(sc.solver);
    options.slip.accelerations.concurrent_checks = concurrent;
    let history = sc.history.as_ref().expect("a history");
    let mut calls = Calls::new(stop_at);
    let run =
        fretsim::history::run_history(&sc.model, &disc, &normal, history, options, &mut calls)
            .expect("the default history completes");
    let state = serde_json::to_string(&run.state).expect("a state is written");
    (calls.seen, run.records.len(), state)
}

/// The general solver's checks run beside the spectral solver's steps give the run of the
/// checks taken in turn, to the bit: every call of the observer (records, states, phases,
/// handovers, the checkpoints' states) and the final state. The default history exercises
/// every path: its turning points' checks agree (their checkpoints wait for them), the first
/// loading's first step is confirmed, and the first step of every later phase is contradicted
/// (end layers) after the spectral solver has gone on past it, so the run is taken back to
/// the turning state. Ended by the observer at the second turning point (whose checkpoint
/// waits for its check while later steps are tried), the state is that turning point's.
#[test]
fn checks_beside_the_steps_give_the_run_of_checks_in_turn() {
    for stop_at in [usize::MAX, 2] {
        let (beside, beside_records, beside_state) = default_history_checked(true, stop_at);
        let (in_turn, records, state) = default_history_checked(false, stop_at);
        let handovers = in_turn.iter().filter(|c| c.starts_with("handover")).count();
        let checkpoints = in_turn
            .iter()
            .filter(|c| c.starts_with("checkpoint"))
            .count();
        println!(
            "stop at {stop_at}: {} calls, {handovers} handovers, {checkpoints} checkpoints, {records} records",
            in_turn.len()
        );
        assert!(handovers > 0, "no check contradicted");
        assert_eq!(beside.len(), in_turn.len());
        for (k, (x, y)) in beside.iter().zip(&in_turn).enumerate() {
            assert!(x == y, "call {k} differs");
        }
        assert_eq!(beside_records, records);
        assert!(beside_state == state, "the final states differ");
        if stop_at == 2 {
            assert_eq!(checkpoints, 2);
        }
    }
}
