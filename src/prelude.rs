//! The names most programs need, in one `use fretsim::prelude::*;`.
//!
//! ```
//! use fretsim::prelude::*;
//!
//! let scenario: Scenario = default_scenario();
//! let solution: Solution = solve(&scenario, &mut NoObserver).expect("the default scenario solves");
//! assert!(matches!(
//!     solution.summary.history.as_ref().map(|h| &h.verdict),
//!     Some(Verdict::SteadyCyclicSlip { .. })
//! ));
//! ```

pub use crate::analysis::{CycleRow, Verdict};
pub use crate::contact::{ContactModel, ContactState, Coupling, Electrode, Profile};
pub use crate::error::{Error, Issue, SolveFailure};
pub use crate::history::{LoadHistory, NoObserver, Observer, StateView, StepRecord};
pub use crate::io::{RunResult, Solution, run, solve};
pub use crate::material::{Material, PiezoConstants};
pub use crate::scenario::{Scenario, default_scenario, load, parse, validate};
