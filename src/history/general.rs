//! Steps taken by the general element solver ([`crate::contact::general`]): the run that
//! carries its state ([`GeneralRun`]), started from a committed spectral state by
//! [`GeneralRun::handover`], and the record of each of its steps.
//!
//! # Records
//! The contact ends are the outer edges of the outermost contact elements, the stick zone the
//! longest run of stuck elements, and the slip signs those of the slip zones beside it (0 where
//! the stick zone reaches the contact end). The zone structure — the runs of stuck elements
//! and of elements slipping either way, and how often the slip sign changes across the
//! contact — is in [`ZoneCount`]. The step's increments follow from its two states:
//!
//! ```text
//! Δδ = Δδx (a stuck point moves with the punch),   D = −Σ w_i ½(q_i + q_i') s_i,
//! W_P = P̄ Δδz,                                    W_e = −φ̄0 ΔΓ
//! ```
//!
//! with `s_i` the element's mean slip in the step (the half-plane relative to the punch), so
//! that D ≥ 0 where q opposes the slip; bars are the means of the step's two states (P, φ0 do
//! not change under the paper's loads) and ΔΓ is the change of the punch's charge (zero under
//! a constant charge).
//!
//! # Mesh
//! The band `c ± 1.25a` of the state handed over, graded towards its contact ends
//! (elements of [`END_SIZE`]·a there) and its stick ends ([`STICK_SIZE`]·a), growing by
//! [`GROWTH`] per element up to `numerics.general_element_size`·a ([`INNER_SIZE`] by
//! default). The mesh stays while the normal and electric loads do: the state is the slip
//! reference of the next step, and it belongs to its mesh. A step that changes either is
//! solved on a mesh made for the contact before and after it ([`mesh_for_loads`]), with the
//! state carried onto it ([`Solver::transfer`]). A step to P = 0 lifts the punch off
//! ([`Solver::separated`]: no contact, an undeformed surface); the step that presses it again
//! is solved on a mesh made for the frictionless contact of its loads about x = 0.
//!
//! # Displacement control
//! Under [`Control::Displacement`] a load point's tangential value is δ: the step prescribes
//! δx = δ − (δ of the state − its δx) ([`crate::contact::general::Drive::Displacement`]),
//! its regime is that of Δδ, Q is the result, and a state in which no element sticks (gross
//! slip, Q = ±ηP) is accepted; under a prescribed Q it is an error (no quasi-static state).

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::contact::general::{
    Drive, ElementState, Focus, GeneralState, Loads, Mesh, Options, Recall, Solver, StepReport,
};
use crate::contact::tangential::{SlipOptions, StepAdmissibility};
use crate::contact::{ContactModel, ContactState, Electrode};
use crate::error::SolveFailure;

use super::driver::DriverState;
use super::load::{Control, LoadPoint, PunchLoads};
use super::record::{StepFailure, StepRecord};
use super::regime::{PhaseEvent, Regime, next_regime, phase_event};

/// Element size at the contact ends of the handed-over state, relative to a.
pub const END_SIZE: f64 = 5e-4;
/// Element size at the stick ends of the handed-over state, relative to a.
pub const STICK_SIZE: f64 = 1e-3;
/// Growth of the element size per element away from the contact ends.
pub const GROWTH: f64 = 1.08;
/// Largest element, relative to a, by default (`numerics.general_element_size`).
pub const INNER_SIZE: f64 = 6e-3;

/// Which solver takes the tangential steps (`numerics.solver`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum SolverChoice {
    /// The spectral solver, and the general solver for the steps it cannot take
    /// ([`super::continue_run`]) and for a normal loading it has no state of
    /// ([`super::NormalEnd`]).
    #[default]
    Auto,
    /// The spectral solver only: a step or a normal loading it cannot take stops the run.
    Spectral,
    /// The general solver for every tangential step (the normal loading stays Spence's
    /// self-similar solution of the spectral solver where it has one, as under `Auto`).
    General,
}

/// Options of a run.
#[derive(Debug, Clone, Copy)]
pub struct RunOptions {
    /// The spectral solver's options.
    pub slip: SlipOptions,
    /// Which solver takes the steps.
    pub solver: SolverChoice,
    /// Under [`SolverChoice::Auto`]: the general solver also takes the first step of every
    /// phase and every turning point, and the spectral solver's step is handed over when the
    /// two disagree ([`super::continue_run`]).
    pub check_phases: bool,
    /// The general solver's largest element, relative to the contact half-width.
    pub general_element_size: f64,
    /// Keep every record in the run's records ([`super::HistoryRun::records`]), or only the
    /// last one (the observer sees each: a run that streams its records holds a bounded
    /// number of them, however long the history).
    pub keep_records: bool,
}

impl RunOptions {
    /// The default options for a choice of solver. Under [`SolverChoice::Auto`] the spectral
    /// solver has no last resorts: it accepts no step at a stalled residual
    /// (`stall_tolerance` 0), does not repeat its failed attempts with Newton's method
    /// (`newton_fallback` off), and gives a step up after
    /// [`SlipOptions::STEP_EVALUATIONS_BEHIND_ANOTHER_SOLVER`] residual evaluations over all
    /// its attempts (`step_evaluations`); the general solver takes such a step instead.
    pub fn new(solver: SolverChoice) -> Self {
        let slip = match solver {
            SolverChoice::Auto => SlipOptions {
                stall_tolerance: 0.0,
                newton_fallback: false,
                step_evaluations: Some(SlipOptions::STEP_EVALUATIONS_BEHIND_ANOTHER_SOLVER),
                ..SlipOptions::default()
            },
            _ => SlipOptions::default(),
        };
        Self {
            slip,
            solver,
            check_phases: solver == SolverChoice::Auto,
            keep_records: true,
            general_element_size: INNER_SIZE,
        }
    }
}

impl RunOptions {
    /// The spectral solver only, with its options.
    pub fn spectral(slip: SlipOptions) -> Self {
        Self {
            slip,
            solver: SolverChoice::Spectral,
            check_phases: false,
            general_element_size: INNER_SIZE,
            keep_records: true,
        }
    }
}

impl Default for RunOptions {
    fn default() -> Self {
        Self::new(SolverChoice::Auto)
    }
}

/// Which solver took a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum SolverKind {
    /// The paper's spectral solver (one central stick zone between two slip zones).
    #[default]
    Spectral,
    /// The general element solver (any zone structure).
    General,
}

impl SolverKind {
    /// The word in `steps.csv`.
    pub fn word(self) -> &'static str {
        match self {
            SolverKind::Spectral => "spectral",
            SolverKind::General => "general",
        }
    }
}

/// The zone structure of a state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct ZoneCount {
    /// Stick zones.
    pub stick: usize,
    /// Slip zones (either direction).
    pub slip: usize,
    /// Changes of the slip direction from one slip zone to the next, left to right.
    pub sign_changes: usize,
}

impl ZoneCount {
    /// The zones of an element state.
    pub fn of_elements(state: &GeneralState) -> Self {
        Self::of_zones(state.zones().into_iter().map(|z| z.0))
    }

    /// The zones of an element state at its resolution: a zone of one element (a layer that
    /// may be thinner than an element) is not counted, and its neighbours of one kind join.
    pub fn resolved(state: &GeneralState) -> Self {
        let mut codes: Vec<ElementState> = Vec::new();
        let mut run = (ElementState::Exterior, 0usize);
        let flush = |run: (ElementState, usize), codes: &mut Vec<ElementState>| {
            if run.1 > 1 && codes.last() != Some(&run.0) {
                codes.push(run.0);
            }
        };
        for &code in &state.codes {
            if code == run.0 {
                run.1 += 1;
            } else {
                flush(run, &mut codes);
                run = (code, 1);
            }
        }
        flush(run, &mut codes);
        Self::of_zones(codes.into_iter())
    }

    fn of_zones(zones: impl Iterator<Item = ElementState>) -> Self {
        let mut count = Self::default();
        let mut last_slip: Option<ElementState> = None;
        for code in zones {
            match code {
                ElementState::Exterior => {}
                ElementState::Stick => count.stick += 1,
                slip => {
                    count.slip += 1;
                    if last_slip.is_some_and(|s| s != slip) {
                        count.sign_changes += 1;
                    }
                    last_slip = Some(slip);
                }
            }
        }
        count
    }

    /// The zones of a spectral state: one stick zone between up to two slip zones.
    pub fn of_spectral(state: &ContactState) -> Self {
        let t = &state.traction;
        let Some(zone) = &t.stick else {
            return Self::default();
        };
        let slipping = t.left_sign != 0.0 || t.right_sign != 0.0;
        let (lo, hi) = (
            state.centre - state.half_width,
            state.centre + state.half_width,
        );
        let left = slipping && zone.lo > lo;
        let right = slipping && zone.hi < hi;
        Self {
            stick: 1,
            slip: usize::from(left) + usize::from(right),
            sign_changes: usize::from(left && right && t.left_sign * t.right_sign < 0.0),
        }
    }
}

/// A run of steps taken by the general solver. Plain data but for its solver, which is rebuilt
/// from the model and the state's mesh when the run is read back ([`GeneralRun::restore`]).
#[derive(Debug, Clone, Serialize)]
pub struct GeneralRun {
    #[serde(skip)]
    solver: Arc<Solver>,
    /// The committed element state.
    pub state: GeneralState,
    /// δ of the state minus its rigid shift δx (m).
    offset: f64,
    /// Slip sign of the current phase.
    phase_sign: Option<f64>,
    /// Phase number.
    pub phase: usize,
    /// Phases begun since the handover.
    pub phases_begun: usize,
    /// Steps taken.
    pub steps: usize,
    /// Whether the first phase begun began at the first step (from the handed-over state).
    pub first_began_at_handover: bool,
    /// The works of P and of the electric load summed over the steps taken (J/m), and those of
    /// the last step.
    works: [[f64; 2]; 2],
    /// Steps after which the spectral solver next tries to take the state back (within the
    /// phase of the handover): 2, then doubled after each try that fails, so that a phase the
    /// spectral solver cannot represent costs a few of its attempts, not one a step. Not 1:
    /// after the handover's own step the try would be the step the spectral solver just failed
    /// (or that the general solver's check contradicted), from the same state. A run handed
    /// over at the first step after a take-back ([`GeneralRun::take_back_lost`]) starts at
    /// [`GeneralRun::LOST_TAKE_BACK_WAIT`] or more.
    resume_at: usize,
    /// Largest element of a mesh made for a new normal or electric load, relative to a
    /// (`numerics.general_element_size`).
    #[serde(default = "default_element_size")]
    element_size: f64,
    /// What a load point's tangential value prescribes: Q, or the punch displacement δ.
    #[serde(default, skip_serializing_if = "Control::is_load")]
    pub control: Control,
}

fn default_element_size() -> f64 {
    INNER_SIZE
}

/// A [`GeneralRun`] as written (without its solver).
#[derive(Debug, Clone, Deserialize)]
pub struct GeneralRunData {
    state: GeneralState,
    offset: f64,
    phase_sign: Option<f64>,
    phase: usize,
    phases_begun: usize,
    steps: usize,
    first_began_at_handover: bool,
    works: [[f64; 2]; 2],
    resume_at: usize,
    #[serde(default = "default_element_size")]
    element_size: f64,
    #[serde(default)]
    control: Control,
}

/// The loads of a state at tangential load `q`.
pub fn loads_of(model: &ContactModel, normal_load: f64, q: f64) -> Loads {
    let electric = match model.electrode {
        Electrode::ConductingCharge { charge } => charge,
        Electrode::ConductingPotential { potential } => potential,
        Electrode::None | Electrode::Insulating => 0.0,
    };
    Loads {
        normal: normal_load,
        tangential: q,
        electric,
        bulk_stress: 0.0,
    }
}

/// The mesh for a run handed over at a state, with largest elements `inner`·a (module docs).
pub fn mesh_for(state: &ContactState, inner: f64) -> Mesh {
    let (c, a) = (state.centre, state.half_width);
    let mut focus = vec![
        Focus {
            at: c - a,
            size: END_SIZE * a,
        },
        Focus {
            at: c + a,
            size: END_SIZE * a,
        },
    ];
    if let Some(zone) = &state.traction.stick {
        focus.extend([zone.lo, zone.hi].map(|at| Focus {
            at,
            size: STICK_SIZE * a,
        }));
    }
    Mesh::graded(c - 1.25 * a, c + 1.25 * a, &focus, GROWTH, inner * a)
}

/// The mesh for a step from `state` (on `solver`'s mesh) to new normal or electric `loads`:
/// the band `c ± 1.25 max(a, a')` with elements of [`END_SIZE`]·max(a, a') at the state's
/// contact ends and at those expected under the new loads (`a' = a` times the ratio of the
/// frictionless half-widths, [`Solver::first_half_width`]), of [`STICK_SIZE`]·max(a, a') at
/// the ends of the state's zones, growing by [`GROWTH`] up to `inner`·max(a, a'). A mesh made
/// afresh at each change keeps the cost of a step bounded over a long history; the price is
/// the ripple of carrying a state onto other edges ([`Solver::transfer`]).
pub fn mesh_for_loads(solver: &Solver, state: &GeneralState, loads: Loads, inner: f64) -> Mesh {
    // A punch that left the half-plane comes back at x = 0 with its frictionless contact.
    let (lo, hi, grown) = match state.contact_extent() {
        Some((lo, hi)) => {
            let a = 0.5 * (hi - lo);
            let grown = a * solver.first_half_width(loads) / solver.first_half_width(state.loads);
            (lo, hi, grown)
        }
        None => {
            let a = solver.first_half_width(loads);
            (-a, a, a)
        }
    };
    let (c, a) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    let big = a.max(grown);
    let mut focus: Vec<Focus> = [c - a, c + a, c - grown, c + grown]
        .iter()
        .map(|&at| Focus {
            at,
            size: END_SIZE * big,
        })
        .collect();
    let zones = state.zones();
    for pair in zones.windows(2) {
        let at = pair[0].2;
        if at > lo && at < hi {
            focus.push(Focus {
                at,
                size: STICK_SIZE * big,
            });
        }
    }
    Mesh::graded(c - 1.25 * big, c + 1.25 * big, &focus, GROWTH, inner * big)
}

impl GeneralRun {
    /// Take over from the driver's committed state, on elements of at most `inner`·a (the
    /// solver from `recall`).
    pub fn handover(
        model: &ContactModel,
        driver: &DriverState,
        inner: f64,
        recall: &mut Recall,
    ) -> Self {
        Self::handover_onto(model, driver, &driver.state, inner, recall)
    }

    /// [`GeneralRun::handover`] on the mesh made for the spectral state `mesh_of` (the state
    /// a step from the driver's leads to: the turning point's, whose mesh the check of the
    /// next phase's first step uses again).
    pub fn handover_onto(
        model: &ContactModel,
        driver: &DriverState,
        mesh_of: &ContactState,
        inner: f64,
        recall: &mut Recall,
    ) -> Self {
        let s = &driver.state;
        let solver = recall.solver(model, mesh_for(mesh_of, inner), Options::default());
        let loads = loads_of(model, s.normal_load, s.tangential_load);
        let state = if recall.enabled() {
            solver.adopt_rounded(s, loads, 0.0)
        } else {
            solver.adopt(s, loads, 0.0)
        };
        Self {
            solver,
            state,
            offset: driver.displacement,
            phase_sign: driver.phase_sign,
            phase: driver.phase,
            phases_begun: 0,
            steps: 0,
            first_began_at_handover: false,
            works: [[0.0; 2]; 2],
            resume_at: 2,
            element_size: inner,
            control: Control::Load,
        }
    }

    /// Start from the end of a normal loading the general solver took (`state`, on
    /// `solver`'s mesh), before any slip phase, with δ counted from there; the meshes made for
    /// later normal or electric loads have elements of at most `inner`·a.
    pub fn loaded(solver: Arc<Solver>, state: GeneralState, inner: f64) -> Self {
        Self {
            solver,
            offset: -state.shift,
            state,
            phase_sign: None,
            phase: 0,
            phases_begun: 0,
            steps: 0,
            first_began_at_handover: false,
            works: [[0.0; 2]; 2],
            resume_at: 2,
            element_size: inner,
            control: Control::Load,
        }
    }

    /// The run written as `data`, its solver rebuilt for `model` on the state's mesh.
    pub fn restore(model: &ContactModel, data: GeneralRunData) -> Self {
        let solver = Solver::new(model, data.state.mesh.clone(), Options::default());
        Self {
            solver: Arc::new(solver),
            state: data.state,
            offset: data.offset,
            phase_sign: data.phase_sign,
            phase: data.phase,
            phases_begun: data.phases_begun,
            steps: data.steps,
            first_began_at_handover: data.first_began_at_handover,
            works: data.works,
            resume_at: data.resume_at,
            element_size: data.element_size,
            control: data.control,
        }
    }

    /// Whether the spectral solver is due to try to take the state back after this run's
    /// last step (see `resume_at`); `last_of_phase`: that step ends the phase, after which the
    /// spectral solver's memory no longer holds (tried then unless it is the handover's step).
    pub fn resume_due(&self, last_of_phase: bool) -> bool {
        self.steps >= self.resume_at || (last_of_phase && self.steps >= 2)
    }

    /// A try to take the state back failed: the next one after twice as many steps.
    pub fn resume_failed(&mut self) {
        self.resume_at = 2 * self.steps.max(1);
    }

    /// General steps before the first try to take the state back in a run handed over at the
    /// first step after a take-back ([`GeneralRun::take_back_lost`]), in place of 2: after
    /// the first take-back lost in a phase.
    pub const LOST_TAKE_BACK_WAIT: usize = 4;

    /// The most general steps before such a try (after the fifth take-back lost in a phase).
    pub const LONGEST_LOST_TAKE_BACK_WAIT: usize = 64;

    /// The run was handed over at the first step after the spectral solver took the state
    /// back: that take-back did not hold, and one at the next try would most likely not hold
    /// either (the general solver's state passes for a spectral one at some steps of the phase
    /// and not at the next, e.g. an end layer of reversed slip about one element thick that
    /// comes and goes), each time at the cost of a failed spectral step. The next try is due
    /// after [`GeneralRun::LOST_TAKE_BACK_WAIT`] steps instead of 2, doubled for each earlier
    /// take-back lost in the same phase (`lost_before`, counted by the driver:
    /// [`DriverState::take_back_lost`]) up to [`GeneralRun::LONGEST_LOST_TAKE_BACK_WAIT`], then
    /// doubled after any failed try, and at the end of the phase as always. (A phase whose end
    /// layer comes and goes every few steps otherwise costs a failed spectral step every four
    /// steps: 67 handovers in the 788 steps of the failure map's PZT-4 run at the potential of
    /// Γ = 6e−7 C/m, η = 0.05, variable amplitude.)
    pub fn take_back_lost(&mut self, lost_before: usize) {
        let wait = (Self::LOST_TAKE_BACK_WAIT << lost_before.min(4))
            .min(Self::LONGEST_LOST_TAKE_BACK_WAIT);
        self.resume_at = self.resume_at.max(wait);
    }

    /// The solver.
    pub fn solver(&self) -> &Arc<Solver> {
        &self.solver
    }

    /// The works of P and of the electric load summed over the steps taken before the last
    /// one (J/m).
    pub fn works_before_this_step(&self) -> [f64; 2] {
        let [sum, last] = self.works;
        [sum[0] - last[0], sum[1] - last[1]]
    }

    /// Punch displacement δ of the committed state (m).
    pub fn displacement(&self) -> f64 {
        self.offset + self.state.shift
    }

    /// Take one load step and commit it (through `recall`); its record. A step whose normal or
    /// electric load differs from the state's is solved on a mesh made for its contact
    /// ([`mesh_for_loads`]), the state carried onto it ([`Solver::transfer`]). Under
    /// [`Control::Displacement`] the point's value is δ, the regime that of Δδ, and Q a result
    /// (gross slip, where no element sticks, is a state like any other).
    pub fn step(
        &mut self,
        model: &ContactModel,
        point: LoadPoint,
        recall: &mut Recall,
    ) -> Result<StepRecord, StepFailure> {
        let LoadPoint { step, t, q, punch } = point;
        let old = &self.state;
        let loads = Loads {
            tangential: q,
            normal: punch.map_or(old.loads.normal, |p| p.normal),
            electric: punch.map_or(old.loads.electric, |p| p.electric),
            bulk_stress: punch.map_or(old.loads.bulk_stress, |p| p.bulk_stress),
        };
        let moves = PunchLoads::of(loads.normal, loads.electric)
            != PunchLoads::of(old.loads.normal, old.loads.electric);
        let limit = model.friction * old.loads.normal.min(loads.normal);
        let (drive, regime) = match self.control {
            Control::Load => (
                Drive::Load,
                next_regime(q - old.loads.tangential, 1e-12 * limit),
            ),
            Control::Displacement => {
                let from = self.displacement();
                let scale = q.abs().max(from.abs());
                (
                    Drive::Displacement(q - self.offset),
                    next_regime(q - from, 1e-12 * scale),
                )
            }
        };
        if regime.slip_sign().is_none() && !moves {
            let mut rec = self.record(step, t, regime, None);
            if self.control == Control::Load {
                rec.q = q;
            }
            return Ok(rec);
        }
        // A failed step leaves the run as it was.
        let separates = loads.normal == 0.0;
        let (solver, carried) = if moves && !separates {
            let mesh = mesh_for_loads(&self.solver, old, loads, self.element_size);
            let solver = recall.solver(model, mesh, Options::default());
            let carried = solver.transfer(old);
            (solver, Some(carried))
        } else {
            (Arc::clone(&self.solver), None)
        };
        let old = carried.as_ref().unwrap_or(&self.state);
        let (new, report) = if separates {
            let shift = match drive {
                Drive::Load => old.shift,
                Drive::Displacement(at) => at,
            };
            (solver.separated(loads, shift), StepReport::default())
        } else {
            recall
                .step_with(&solver, old, loads, drive)
                .map_err(|failure| StepFailure {
                    step,
                    t,
                    q,
                    regime,
                    failure,
                })?
        };
        if self.control == Control::Load
            && new.contact_extent().is_some()
            && new.length_of(ElementState::Stick) == 0.0
        {
            return Err(StepFailure {
                step,
                t,
                q,
                regime,
                failure: SolveFailure::NoAdmissibleState {
                    reason: "no element sticks: the contact slides as a whole".into(),
                },
            });
        }
        if let PhaseEvent::Begin(sign) = phase_event(self.phase_sign, regime) {
            self.phase_sign = Some(sign);
            self.phase += 1;
            if self.phases_begun == 0 && self.steps == 0 {
                self.first_began_at_handover = true;
            }
            self.phases_begun += 1;
        }
        let increments = Increments::between(model, old, &new);
        let last = [increments.normal_work, increments.electric_work];
        self.works = [
            [self.works[0][0] + last[0], self.works[0][1] + last[1]],
            last,
        ];
        self.solver = solver;
        self.state = new;
        self.steps += 1;
        let mut rec = self.record(step, t, regime, Some(&report));
        rec.dissipation = increments.dissipation;
        rec.normal_work = increments.normal_work;
        rec.electric_work = increments.electric_work;
        Ok(rec)
    }

    /// The record of the committed state, with zero increments.
    pub fn record(
        &self,
        step: usize,
        t: f64,
        regime: Regime,
        report: Option<&StepReport>,
    ) -> StepRecord {
        let s = &self.state;
        let (lo, hi) = s.contact_extent().unwrap_or((0.0, 0.0));
        let zones = s.zones();
        let main = zones
            .iter()
            .enumerate()
            .filter(|(_, z)| z.0 == ElementState::Stick)
            .max_by(|x, y| (x.1.2 - x.1.1).total_cmp(&(y.1.2 - y.1.1)))
            .map(|(k, _)| k);
        let sign_of = |k: Option<usize>| match k.map(|k| zones[k].0) {
            Some(ElementState::SlipNegative) => 1.0,
            Some(ElementState::SlipPositive) => -1.0,
            _ => 0.0,
        };
        let (stick_lo, stick_hi, left, right) = match main {
            Some(k) => (
                zones[k].1,
                zones[k].2,
                sign_of(k.checked_sub(1)),
                sign_of(Some(k + 1).filter(|&j| j < zones.len())),
            ),
            None => (0.5 * (lo + hi), 0.5 * (lo + hi), 0.0, 0.0),
        };
        StepRecord {
            step,
            t,
            q: s.loads.tangential,
            normal_load: s.loads.normal,
            bulk_stress: s.loads.bulk_stress,
            charge: s.resultants().2,
            potential: s.potential,
            regime,
            phase: self.phase,
            half_width: 0.5 * (hi - lo),
            eccentricity: -0.5 * (lo + hi),
            stick_lo,
            stick_hi,
            left_slip_sign: left,
            right_slip_sign: right,
            iterations: report.map_or(0, |r| r.outer_iterations),
            newton_iterations: report.map_or(0, |r| r.tangential_iterations),
            residual: report.map_or(0.0, |r| {
                if r.outer_iterations > 1 {
                    r.residual
                } else {
                    0.0
                }
            }),
            admissibility: admissibility(s, self.solver.friction()),
            displacement: self.displacement(),
            dissipation: 0.0,
            normal_work: 0.0,
            electric_work: 0.0,
            solver: SolverKind::General,
            zones: ZoneCount::of_elements(s),
        }
    }
}

/// The checks of an element state, in the measures of the spectral solver's checks: stick
/// excess `max (|q| − ηp)/(η p_max)` over stuck elements, slip reversal `max q s / max |q s|`
/// over slipping elements (q opposes the slip: ≤ 0), and `min p/p_max` over the contact.
fn admissibility(s: &GeneralState, eta: f64) -> StepAdmissibility {
    let pmax = s.pressure.iter().cloned().fold(0.0, f64::max);
    let mut out = StepAdmissibility {
        stick_excess: f64::NEG_INFINITY,
        slip_reversal: f64::NEG_INFINITY,
        min_pressure: f64::INFINITY,
        worst_at: [0.0; 3],
    };
    let work_scale = s
        .shear
        .iter()
        .zip(&s.slip)
        .map(|(q, d)| (q * d).abs())
        .fold(0.0, f64::max);
    for (i, &code) in s.codes.iter().enumerate() {
        let x = s.mesh.centre(i);
        let (p, q, d) = (s.pressure[i], s.shear[i], s.slip[i]);
        match code {
            ElementState::Exterior => continue,
            ElementState::Stick => {
                let excess = (q.abs() - eta * p) / (eta * pmax);
                if excess > out.stick_excess {
                    out.stick_excess = excess;
                    out.worst_at[0] = x;
                }
            }
            _ => {
                let reversal = if work_scale > 0.0 {
                    q * d / work_scale
                } else {
                    0.0
                };
                if reversal > out.slip_reversal {
                    out.slip_reversal = reversal;
                    out.worst_at[1] = x;
                }
            }
        }
        if p / pmax < out.min_pressure {
            out.min_pressure = p / pmax;
            out.worst_at[2] = x;
        }
    }
    let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
    out.stick_excess = finite(out.stick_excess);
    out.slip_reversal = finite(out.slip_reversal);
    out.min_pressure = finite(out.min_pressure);
    out
}

/// The increments of a step (module docs).
struct Increments {
    dissipation: f64,
    normal_work: f64,
    electric_work: f64,
}

impl Increments {
    fn between(model: &ContactModel, old: &GeneralState, new: &GeneralState) -> Self {
        let widths = new.mesh.widths();
        let dissipation = -(0..widths.len())
            .map(|i| widths[i] * 0.5 * (old.shear[i] + new.shear[i]) * new.slip[i])
            .sum::<f64>();
        // Trapezoidal in the loads that vary (exact for those that do not).
        let mean = |a: f64, b: f64| 0.5 * (a + b);
        let electric_work = match model.electrode {
            Electrode::ConductingPotential { .. } => {
                -mean(old.loads.electric, new.loads.electric)
                    * (new.resultants().2 - old.resultants().2)
            }
            Electrode::ConductingCharge { .. }
                if PunchLoads::of(0.0, new.loads.electric)
                    != PunchLoads::of(0.0, old.loads.electric) =>
            {
                -mean(old.potential, new.potential) * (new.loads.electric - old.loads.electric)
            }
            _ => 0.0,
        };
        Self {
            dissipation,
            normal_work: mean(old.loads.normal, new.loads.normal) * (new.approach - old.approach),
            electric_work,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::pressure::Discretisation;

    /// Take-backs lost again and again in one phase postpone the next try by 4, 8, 16, 32,
    /// 64 and then 64 general steps; in the next phase the first one lost waits 4 again.
    #[test]
    fn take_backs_lost_in_one_phase_wait_twice_as_long_each_time() {
        let sc = crate::scenario::default_scenario();
        let disc = Discretisation::new(sc.collocation_points);
        let mut driver = crate::history::driver_after_normal_loading(&sc, &disc);
        let mut recall = Recall::new(false);
        let mut lose = |driver: &mut DriverState| {
            let mut run = GeneralRun::handover(&sc.model, driver, INNER_SIZE, &mut recall);
            run.take_back_lost(driver.take_back_lost());
            run.resume_at
        };
        let waits: Vec<usize> = (0..6).map(|_| lose(&mut driver)).collect();
        assert_eq!(waits, [4, 8, 16, 32, 64, 64]);
        driver.phase += 1;
        assert_eq!(lose(&mut driver), 4);
    }
}
