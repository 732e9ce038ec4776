//! The input/output layer on top of the numerical core: solving a scenario and writing what a
//! run and a sweep produce. The numerical modules (`halfplane`, `quadrature`, `contact`,
//! `history`, `analysis`) do no I/O; everything that touches the file system is here, in
//! `scenario` (reading) and in the command (`main.rs`).
//!
//! - [`mod@run`]: [`solve`] (a scenario's results, nothing written) and [`run()`] (solve, then write
//!   the output folder);
//! - [`summary`]: the contents of `summary.json`;
//! - [`csv`], [`plots`], [`history_plots`], [`svg`]: the files of a run; [`png`]: the PNG
//!   beside each SVG plot (resvg, embedded font);
//! - [`mod@sweep`]: `fretsim sweep`, and its result plots and maps (`sweep_plots`);
//! - [`checkpoint`]: the checkpoints a run writes as it goes, and resuming from one;
//! - [`folder`]: the output folder's rules: never touch what fretsim did not write, replace a
//!   previous output atomically.

pub mod checkpoint;
pub mod csv;
pub mod folder;
pub mod history_plots;
pub mod plots;
pub mod png;
pub mod run;
pub mod summary;
pub mod svg;
pub mod sweep;
mod sweep_plots;

pub use run::{RunResult, Solution, run, run_resumed, run_with, solve};
pub use sweep::{Shard, SweepOptions, SweepOutput, Vary, sweep};
