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
//! [`scenario::parse`] and [`scenario::validate`] (or [`scenario::load`] for a file) give a
//! [`scenario::Scenario`]; [`io::solve`] solves it and writes nothing; [`io::run()`] also
//! writes the output folder that `fretsim run` writes.
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
//! - [`material`]: constants, presets, validation.
//! - [`halfplane`]: surface compliance (extended Stroh formalism), the paper's f_ij, Δ1…Δ4.
//! - [`quadrature`]: Gauss–Chebyshev grids, factored collocation matrices, Chebyshev series;
//!   [`transforms`]: the grids' cosine and sine sums by real FFTs.
//! - [`contact`]: the contact model and state; [`contact::frictionless`] (Hertz, Zhou & Lee),
//!   [`contact::normal`] (Spence's self-similar partial slip), [`contact::pressure`] (shared
//!   pressure and charge sub-problems).
//! - `cache`: the crate's only statics (tables keyed by size, each thread's scratch
//!   buffers); the speed-ups that carry information from step to step are switched by
//!   [`contact::tangential::Accelerations`].
//! - [`analytical`]: closed-form oracles.
//! - [`analysis`]: the cycles of a history, the energy per cycle and the verdict.
//! - [`scenario`], [`io`], [`cli`], [`error`]: input, solving and writing a run or a sweep, arguments,
//!   errors. The numerical modules do no I/O.
#![warn(missing_docs)]
#![deny(clippy::float_cmp)]

pub mod analysis;
pub mod analytical;
mod cache;
pub mod cli;
pub mod contact;
pub mod error;
pub mod halfplane;
pub mod history;
pub mod io;
pub mod material;
pub mod quadrature;
pub mod scenario;
mod shared;
pub mod subsurface;
pub mod transforms;

// The entry points most programs need, at the crate root.
pub use analysis::Verdict;
pub use contact::{ContactModel, Coupling, Electrode, Profile};
pub use error::{Error, Issue, SolveFailure};
pub use io::{RunResult, Solution, run, solve};
pub use material::{Material, PiezoConstants};
pub use scenario::{Scenario, default_scenario, load, parse, validate};
