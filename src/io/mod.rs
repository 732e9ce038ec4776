//! The input/output layer on top of the numerical core: solving a scenario and writing what a
//! run and a sweep produce. The numerical modules (`halfplane`, `quadrature`, `contact`,
//! `history`, `analysis`) do no I/O; everything that touches the file system is here, in
//! `scenario` (reading) and in the command ([`crate::cli`]).
//!
//! What a program calls: [`solve`] (a scenario's results, nothing written), [`run()`] (solve,
//! then write the output folder that `fretsim run` writes) and [`run_partial`] (the same, with
//! a failure part-way through the history kept beside what was written); the results are a
//! [`Solution`] (with [`summary`], the contents of `summary.json`) and, as columns,
//! [`steps_table`], [`cycles_table`] and [`fields_table`] (the CSV files' contents).
//!
//! Inside (crate-internal): `run` (the above), `csv`, `plots`, `history_plots`, `svg` (the
//! files of a run), `png` (the PNG beside each SVG plot: resvg, embedded font), `sweep`
//! (`fretsim sweep`, its result plots and maps in `sweep_plots`), `checkpoint` (the
//! checkpoints a run writes as it goes, and resuming from one) and `folder` (the output
//! folder's rules: never touch what fretsim did not write, replace a previous output
//! atomically).
//!
//! A written run ([`run()`], [`run_partial`], `fretsim run`) keeps no record per step: each
//! record goes, as it is taken, into `steps.csv`, the incremental cycle analysis
//! ([`crate::analysis::CycleAnalysis`]), the summary's counts and the steps the history plots
//! draw (all of a history of up to 4,096 steps, else the first and the last 2,048 cut to whole
//! phases). Its memory does not grow with the history's length but for a row per cycle (and
//! the turning-point states that `output.turning_point_fields = all` asks for, each with its
//! subsurface grid under `output.subsurface`). [`solve`]
//! returns every record.

internal! { mod checkpoint; }
internal! { mod csv; }
internal! { mod fatigue; }
internal! { mod folder; }
internal! { mod history_plots; }
internal! { mod plots; }
internal! { mod png; }
internal! { mod run; }
internal! { mod subsurface; }
pub mod summary;
internal! { mod svg; }
internal! { mod sweep; }
mod sweep_plots;

pub use self::csv::{Column, Table, cycles_table, fields_table, steps_table};
pub use fatigue::fatigue_table;
pub(crate) use run::run_resumed;
pub use run::{FieldSet, RunResult, Solution, run, run_partial, solve};
pub use subsurface::{SubsurfaceGrid, SubsurfaceMap, subsurface_table};
pub(crate) use sweep::{Shard, SweepOptions, Vary, sweep};
