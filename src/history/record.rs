//! What a step reports: its record ([`StepRecord`]), the observer that receives the records and
//! each phase's memory ([`Observer`], [`NoObserver`]), and a failed step with its context
//! ([`StepFailure`]).

use std::sync::Arc;

use serde::Serialize;

use crate::contact::SurfacePoint;
use crate::contact::general::{GeneralState, Solver};
use crate::contact::memory::Memory;
use crate::contact::tangential::StepAdmissibility;
use crate::contact::{ContactModel, ContactState};
use crate::error::SolveFailure;

use super::general::{SolverKind, ZoneCount};
use super::regime::Regime;

/// One recorded step.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct StepRecord {
    /// Step number (0 = end of normal loading).
    pub step: usize,
    /// Time (s).
    pub t: f64,
    /// Tangential load Q (N/m).
    pub q: f64,
    /// Normal load P (N/m).
    pub normal_load: f64,
    /// Bulk stress σB of the half-plane (Pa; absent where zero).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub bulk_stress: f64,
    /// Resultant charge Γ on a conducting punch (C/m; 0 without one).
    pub charge: f64,
    /// Potential φ0 of a conducting punch (V; 0 without one).
    pub potential: f64,
    /// Regime.
    pub regime: Regime,
    /// Phase number (0 = normal loading; increments at each reversal).
    pub phase: usize,
    /// Contact half-width a (m).
    pub half_width: f64,
    /// Eccentricity e = −c (m).
    pub eccentricity: f64,
    /// Stick-zone left end (m).
    pub stick_lo: f64,
    /// Stick-zone right end (m).
    pub stick_hi: f64,
    /// `q/(ηp)` in the left slip zone (±1; 0 before any slip).
    pub left_slip_sign: f64,
    /// `q/(ηp)` in the right slip zone.
    pub right_slip_sign: f64,
    /// (Quasi-)Newton iterations on the step's geometry (stick ends, a, c) in the accepted
    /// attempt (`newton_iterations` in `steps.csv`).
    pub iterations: usize,
    /// Residual evaluations of the accepted attempt, each a coupled linear solve at fixed
    /// geometry, including those of finite-difference Jacobians (`evaluations` in `steps.csv`).
    pub newton_iterations: usize,
    /// Final relative change of the block iteration.
    pub residual: f64,
    /// Checks.
    pub admissibility: StepAdmissibility,
    /// Tangential displacement δ of the punch relative to the half-plane's datum (m), zero at
    /// the end of normal loading.
    pub displacement: f64,
    /// Energy dissipated by friction in this step (J/m), `−∫ q Δs dx` with the mid-step q.
    pub dissipation: f64,
    /// Work of the normal load in this step, `P Δδn` (J/m).
    pub normal_work: f64,
    /// Work of the electric load in this step, `−φ̄0 ΔΓ` (J/m; zero under a constant charge).
    /// The electrode's free charge on the surface is `ω = −g`: Gauss's law across the surface
    /// (the solid at z > 0, outward normal −z, no displacement in the conductor) gives
    /// `ω = 0 − D·(−ẑ) = Dz(x, 0⁺) = −g`, so `∫ω = −Γ`, and the source that holds φ0 does
    /// `φ0 d∫ω`. Over a closed cycle the works of Q, P and the electric load add up to the
    /// dissipation.
    pub electric_work: f64,
    /// The solver that took the step.
    pub solver: SolverKind,
    /// The zone structure of the state.
    pub zones: ZoneCount,
}

/// The committed state of a step, as the solver that took it holds it.
#[derive(Debug, Clone, Copy)]
pub enum StateView<'a> {
    /// A state of the spectral solver.
    Spectral(&'a ContactState),
    /// An element state of the general solver, with the solver (its mesh and coefficients).
    General(&'a Arc<Solver>, &'a GeneralState),
}

/// An owned [`StateView`], kept for field output. Written as the state alone (the general
/// solver is rebuilt when it is read back, [`SolvedState::restore`]).
#[derive(Debug, Clone)]
pub enum SolvedState {
    /// See [`StateView::Spectral`].
    Spectral(Box<ContactState>),
    /// See [`StateView::General`].
    General(Arc<Solver>, Box<GeneralState>),
}

impl<'a> StateView<'a> {
    /// An owned copy.
    pub fn to_owned(self) -> SolvedState {
        match self {
            StateView::Spectral(s) => SolvedState::Spectral(Box::new(s.clone())),
            StateView::General(solver, s) => {
                SolvedState::General(Arc::clone(solver), Box::new(s.clone()))
            }
        }
    }

    /// The spectral state, if the spectral solver holds it.
    pub fn spectral(self) -> Option<&'a ContactState> {
        match self {
            StateView::Spectral(s) => Some(s),
            StateView::General(..) => None,
        }
    }
}

/// A [`SolvedState`] as written and read back.
#[derive(Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolvedStateData<S = ContactState, G = GeneralState> {
    /// A spectral state.
    Spectral(S),
    /// An element state.
    General(G),
}

impl Serialize for SolvedState {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let data: SolvedStateData<&ContactState, &GeneralState> = match self {
            SolvedState::Spectral(s) => SolvedStateData::Spectral(s),
            SolvedState::General(_, s) => SolvedStateData::General(s),
        };
        data.serialize(serializer)
    }
}

impl SolvedState {
    /// The state written as `data`, for `model` (an element state gets a solver on its mesh).
    pub fn restore(model: &ContactModel, data: SolvedStateData) -> Self {
        match data {
            SolvedStateData::Spectral(s) => SolvedState::Spectral(Box::new(s)),
            SolvedStateData::General(s) => {
                let solver = Solver::new(
                    model,
                    s.mesh.clone(),
                    crate::contact::general::Options::default(),
                );
                SolvedState::General(Arc::new(solver), Box::new(s))
            }
        }
    }

    /// The borrowed view.
    pub fn view(&self) -> StateView<'_> {
        match self {
            SolvedState::Spectral(s) => StateView::Spectral(s),
            SolvedState::General(solver, s) => StateView::General(solver, s),
        }
    }

    /// Contact centre and half-width (m).
    pub fn contact(&self) -> (f64, f64) {
        match self {
            SolvedState::Spectral(s) => (s.centre, s.half_width),
            SolvedState::General(_, s) => {
                let (lo, hi) = s.contact_extent().unwrap_or((0.0, 0.0));
                (0.5 * (lo + hi), 0.5 * (hi - lo))
            }
        }
    }

    /// p, q, g, σxx0 and Dx0 at x.
    pub fn surface_point(&self, model: &ContactModel, x: f64) -> SurfacePoint {
        match self {
            SolvedState::Spectral(s) => model.surface_point(s, x),
            SolvedState::General(solver, s) => solver.surface_point(model, s, x),
        }
    }
}

/// Receives the accepted steps (progress bars, writers, test recorders).
pub trait Observer {
    /// Called once per accepted step with the committed state.
    fn on_step(&mut self, _record: &StepRecord, _state: StateView<'_>) {}
    /// Called when the general solver takes over from the spectral solver, with the step the
    /// spectral solver could not take.
    fn on_handover(&mut self, _failure: &StepFailure) {}
    /// Called when a new phase begins, with the memory that the phase will keep.
    fn on_phase(&mut self, _phase: usize, _memory: &Memory) {}
    /// Called after the step at each turning point of the load and the last step
    /// ([`super::turning_points`]), with the state after it: everything the steps that
    /// follow need ([`super::HistoryState`]), to be written as a checkpoint.
    fn on_checkpoint(&mut self, _last: &StepRecord, _state: super::HistoryStateView<'_>) {}
    /// Asked after [`Observer::on_checkpoint`] at each turning point: whether the run should
    /// end there (the history's later steps are not taken; the run is complete, not failed).
    fn stop(&self) -> bool {
        false
    }
}

/// An observer that does nothing.
pub struct NoObserver;
impl Observer for NoObserver {}

/// A failed step, with its context.
#[derive(Debug, Clone)]
pub struct StepFailure {
    /// Step number.
    pub step: usize,
    /// Time.
    pub t: f64,
    /// Q.
    pub q: f64,
    /// Regime attempted.
    pub regime: Regime,
    /// The failure.
    pub failure: SolveFailure,
}

impl std::fmt::Display for StepFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "step {} (t = {} s, Q = {} N/m, {})",
            self.step, self.t, self.q, self.regime
        )
    }
}

fn is_zero(value: &f64) -> bool {
    *value == 0.0
}
