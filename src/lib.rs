//! # fretsim
//!
//! Fretting contact of a rigid cylindrical punch (radius R) on a transversely isotropic
//! piezoelectric half-plane (poled normal to the surface) or an isotropic elastic half-plane,
//! in plane strain, after the paper (equation numbers below are the paper's):
//!
//! J. Su, L.-L. Ke and Y.-S. Wang, "Two-dimensional fretting contact of piezoelectric materials
//! under a rigid conducting cylindrical punch", *Journal of Mechanics of Materials and
//! Structures* 11(5), 535–558 (2016), doi:10.2140/jomms.2016.11.535.
//!
//! ## The model
//! The surface response of the half-plane to a pressure p, shear traction q and surface charge g
//! on the contact `[c − a, c + a]` is, with `H'f(x) = (1/π)⨍ f(s)/(s − x) ds`,
//!
//! ```text
//! ∂ux/∂x = −w12 p − w13 g + y11 H'q      (seed eq. 11)
//! ∂uz/∂x =  w12 q + y22 H'p + y23 H'g    (seed eq. 12)
//! ∂φ/∂x  =  w13 q + y23 H'p + y33 H'g    (seed eq. 13)
//! ```
//!
//! with coefficients computed from the constants ([`halfplane`]). The rigid punch imposes
//! `∂uz/∂x = −x/R`, a conducting punch `∂φ/∂x = 0`; Coulomb friction `|q| ≤ ηp` holds with
//! equality in the slip zones and the stick zones keep the strain `∂ux/∂x` they had when they
//! stuck. The resulting Cauchy singular integral equations are solved by Gauss–Chebyshev
//! collocation ([`quadrature`]) with the contact geometry (a, c, stick-zone ends) fixed by the
//! consistency conditions of bounded solutions ([`contact`]).
//!
//! ## Use as a library
//! `use fretsim::prelude::*;` brings the names most programs need ([`prelude`]).
//! [`scenario::parse`] and [`scenario::validate`] (or [`scenario::load`] for a file) give a
//! [`scenario::Scenario`]; [`io::solve`] solves it and writes nothing; [`io::run()`] also
//! writes the output folder that `fretsim run` writes. The [`Solution`] holds the summary
//! (everything of `summary.json`), the step records (Q, δ, the stick zone, the solver that
//! took each step), the cycles and the sampled fields (p, q, g, σxx0, Dx0 at each snapshot);
//! [`io::steps_table`], [`io::cycles_table`] and [`io::fields_table`] give them as the
//! columns of the CSV files. An [`history::Observer`] passed to [`solve`] sees each step as
//! it is accepted (with the contact state) and can stop the run.
//!
//! ```
//! use fretsim::history::NoObserver;
//!
//! // The built-in scenario: PZT-4, conducting punch, P = 2000 N/m, three cycles of ±0.5 ηP.
//! let scenario = fretsim::default_scenario();
//! let solution = fretsim::solve(&scenario, &mut NoObserver).expect("the default scenario solves");
//! let normal = &solution.summary.normal_loading;
//! assert!((normal.pressure_resultant - 2000.0).abs() < 1e-6); // ∫p dx = P
//! assert!(normal.stick_ratio > 0.0 && normal.stick_ratio < 1.0); // slip zones at both ends
//! let history = solution.summary.history.as_ref().expect("it has a history");
//! println!("{} steps, {} cycles", history.steps, history.cycles.len());
//! ```
//!
//! ## Symbols
//! | symbol | meaning | unit |
//! |---|---|---|
//! | P, Q | normal and tangential line loads | N/m |
//! | Γ, φ0 | resultant charge on the punch, its potential | C/m, V |
//! | η | friction coefficient | – |
//! | a, c | contact half-width and centre (eccentricity e = −c) | m |
//! | b | stick-zone half-width in normal loading | m |
//! | C | slope of the locked-in strain `∂ux/∂x = C|x|` | 1/m |
//! | p, q, g | pressure, shear traction on the half-plane, surface charge (`Dz = −g`) | Pa, Pa, C/m² |
//! | σxx0, Dx0 | surface in-plane stress and electric displacement | Pa, C/m² |
//! | Y*, κ, k | pressure compliance, shear–pressure coupling, charge per force | 1/Pa, 1/Pa, C/N |
//! | d | datum distance of the regularised log kernel | m |
//!
//! ## Modules
//! The public ones (the library's interface):
//! - [`scenario`]: the scenario (material, punch, friction, loads, numerics, output), its
//!   parsing and validation; [`material`]: constants, presets, validation.
//! - [`contact`]: the contact model ([`ContactModel`], [`Profile`], [`Electrode`]) and state;
//!   [`contact::frictionless`] (Hertz, Zhou & Lee), [`contact::normal`] (Spence's
//!   self-similar partial slip), [`contact::memory`] (the strain memory of the stick zones).
//! - [`history`]: the load history and its driver ([`history::run_history`]), the step
//!   records and the [`history::Observer`] of a run.
//! - [`analysis`]: the cycles of a history, the energy per cycle and the verdict;
//!   [`analytical`]: closed-form oracles; [`halfplane`]: the surface compliance (extended
//!   Stroh formalism), the paper's f_ij, Δ1…Δ4; [`subsurface`]: the stresses and electric
//!   fields below the surface from p, q and g.
//! - [`fatigue`]: surface fretting-fatigue indicators per cycle (local slip amplitude, σxx0
//!   range, Ruiz's F1 and F2, Smith–Watson–Topper, the ranges of Dx0 and Ex).
//! - [`io`]: solving a scenario and writing its output folder; [`cli`]: the command;
//!   [`error`]: errors and their exit codes.
//!
//! Internal to the crate (public only under the `internals` feature, which the crate's own
//! tests and benches enable; `cargo doc --document-private-items` documents them):
//! `quadrature` (Gauss–Chebyshev grids, factored collocation matrices, Chebyshev series),
//! `transforms` (the grids' cosine and sine sums by real FFTs), `contact::pressure` (the
//! pressure and charge sub-problems), `contact::tangential` (the spectral slip solver of the
//! paper; its speed-ups are switched by [`contact::Accelerations`]), `contact::general` (the
//! element solver for any zone structure), the output writers under `io`, and `cache` (the
//! crate's only statics: tables keyed by size, each thread's scratch buffers). The numerical
//! modules do no I/O.
#![warn(missing_docs)]
#![deny(clippy::float_cmp)]
// The documentation of public items names the internal functions that implement them; those
// links resolve with `cargo doc --document-private-items`.
#![allow(rustdoc::private_intra_doc_links)]

/// Declares a module internal to the crate: `pub(crate)`, and public only under the
/// `internals` feature, which the crate's own integration tests, benches and examples enable
/// (no stable interface).
macro_rules! internal {
    ($(#[$attr:meta])* mod $name:ident;) => {
        $(#[$attr])*
        #[cfg(feature = "internals")]
        pub mod $name;
        $(#[$attr])*
        #[cfg(not(feature = "internals"))]
        pub(crate) mod $name;
    };
}

/// Re-exports names of internal modules: `pub(crate)`, and public only under the `internals`
/// feature.
macro_rules! internal_use {
    ($($tree:tt)*) => {
        #[cfg(feature = "internals")]
        pub use $($tree)*
        #[cfg(not(feature = "internals"))]
        #[allow(unused_imports)]
        pub(crate) use $($tree)*

    };
}

pub mod analysis;
pub mod analytical;
mod cache;
pub mod cli;
pub mod contact;
pub mod error;
pub mod fatigue;
pub mod halfplane;
pub mod history;
pub mod io;
pub mod material;
pub mod prelude;
internal! { mod quadrature; }
pub mod scenario;
mod shared;
pub mod subsurface;
internal! { mod transforms; }

// The entry points most programs need, at the crate root.
pub use analysis::Verdict;
pub use contact::{ContactModel, Coupling, Electrode, Profile};
pub use error::{Error, Issue, SolveFailure};
pub use io::{RunResult, Solution, run, solve};
pub use material::{Material, PiezoConstants};
pub use scenario::{Scenario, default_scenario, load, parse, validate};
