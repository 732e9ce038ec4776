//! The switches of everything that carries information from one evaluation or step to the
//! next only to go faster ([`Accelerations`]): the spectral tangential solver's, and the
//! general solver's recall of repeated steps. With all of them off ([`Accelerations::none`],
//! the reference path) each step is solved from the previous state, the memory and the load
//! alone, with every table of the chain evaluated directly. The fast path reaches the same
//! states to the solver's tolerance, or bit for bit where a switch says so; the integration
//! test `the_fast_path_reaches_the_reference_states` compares the two over a coupled history.
//!
//! The process-wide tables keyed by size (quadrature rules, Chebyshev points) are no such
//! mechanism: they are pure functions of their key and live in `crate::cache`.

use serde::Serialize;

/// Which speed-ups are on (each `true` in [`Default`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Accelerations {
    /// Start a step from the same step of the last phase in the same direction that began
    /// from the same turning state, when there is one ([`super::Recalled`]; the history
    /// driver keeps them and consults this switch). In a steady cycle that state solves the
    /// step again, in one evaluation.
    pub recall: bool,
    /// Within a phase, start each attempt from the finite-difference Jacobian of the coarse
    /// companion grid ([`Discretisation::coarse`]) at its first iterate instead of the one
    /// carried from the previous step, or, for slip signs other than the previous step's,
    /// instead of a fine finite-difference one (where the grid has a coarse companion). The
    /// states are the same to the tolerance; the steps take fewer residual evaluations (the
    /// second step of a phase that began mixed, M = 128: 8 instead of 11).
    ///
    /// [`Discretisation::coarse`]: crate::contact::pressure::Discretisation::coarse
    pub coarse_jacobian: bool,
    /// At a phase start, try the mixed slip pattern that began the last phase that began mixed
    /// (after the standard pattern's attempts, before the other mixed ones), from its stick end
    /// next to the edge that slipped against the phase ([`super::PhaseStart`]; the history
    /// driver keeps it). The states are the same to the tolerance; the later reversals of a
    /// coupled contact start their mixed attempt near their own state.
    pub mixed_start_guesses: bool,
    /// Within a phase, update the Jacobian by the projected secant update
    /// (`SecantDirections`) instead of Broyden's: each update keeps the Jacobian's action on
    /// the attempt's earlier step directions. The states are the same to the tolerance; the
    /// steps take fewer residual evaluations.
    pub projected_updates: bool,
    /// Let the stick zones the solver accepts tabulate `H'q̃` and q̃ piecewise when they
    /// begin a phase ([`StickZone::tabulate`], which the history driver calls on the turning
    /// state), instead of summing their chains at every evaluation. The zone of normal
    /// loading has its own switch ([`NormalOptions::zone_tables`]).
    ///
    /// [`StickZone::tabulate`]: crate::contact::StickZone::tabulate
    /// [`NormalOptions::zone_tables`]: crate::contact::normal::NormalOptions::zone_tables
    pub chain_tables: bool,
    /// Start a step within a phase from the stick ends, half-width and centre extrapolated
    /// in Q through the phase's last three steps, and a phase's first step from the centre
    /// moved by dc/dQ of the previous phase's first step (the history driver's `predict`);
    /// off, from the Mindlin–Deresiewicz guess and the previous state's contact. The states
    /// are the same to the tolerance.
    pub continuation: bool,
    /// Let the general solver's steps reuse the solver of a mesh built again and the result
    /// of a step that begins from a state equal to the bit to a remembered one's under the
    /// same loads ([`crate::contact::general::Recall`]: the end-layer steps that begin every
    /// phase of a steady cycle). Bit-identical: a step is a pure function of its solver, its
    /// state and its loads.
    pub general_recall: bool,
    /// Under `numerics.solver = auto`, run the general solver's checks of the spectral
    /// solver's steps (the first step of each phase, each turning point) on a thread of their
    /// own while the spectral solver takes the steps after them; what the observer sees of a
    /// step waits until every check before it has agreed, and a check that contradicts takes
    /// the run back to the state before its step (`history::checks`). The records and what the
    /// observer sees are the same as with the checks run in turn, to the bit.
    ///
    /// Off by default: the checks' thread is one per stretch of spectral steps, and a steady
    /// history begins a stretch at every take-back, so over 10,000 cycles of the default
    /// contact the allocator's pages left by those threads reach a peak of 112 MB (125 MB
    /// without returning each thread's free pages at its end), against the run's 100 MB
    /// bound; a thread for the whole run is what it needs first. On, the default run takes
    /// about 10 % less time and the 100 random reversals of the benches about 30 % less.
    pub concurrent_checks: bool,
}

impl Default for Accelerations {
    /// Every speed-up on but [`Accelerations::concurrent_checks`]: the fast path.
    fn default() -> Self {
        Self {
            recall: true,
            coarse_jacobian: true,
            mixed_start_guesses: true,
            projected_updates: true,
            chain_tables: true,
            continuation: true,
            general_recall: true,
            concurrent_checks: false,
        }
    }
}

impl Accelerations {
    /// Every speed-up off: the reference path.
    pub fn none() -> Self {
        Self {
            recall: false,
            coarse_jacobian: false,
            mixed_start_guesses: false,
            projected_updates: false,
            chain_tables: false,
            continuation: false,
            general_recall: false,
            concurrent_checks: false,
        }
    }

    /// Which tables the zones the solver accepts may build.
    pub(crate) fn zone_tables(self) -> crate::contact::ZoneTables {
        crate::contact::ZoneTables {
            chain: self.chain_tables,
        }
    }
}
