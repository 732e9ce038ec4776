//! Command-line arguments (clap derive only; no physics).

use std::path::PathBuf;

use clap::{Parser, Subcommand};

/// Fretting contact of a rigid cylindrical punch on a piezoelectric or elastic half-plane.
#[derive(Debug, Parser)]
#[command(name = "fretsim", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scenario (the built-in paper baseline when none is given).
    Run {
        /// Scenario file (JSON).
        scenario: Option<PathBuf>,
        /// Output folder (default: `output/<scenario name>`).
        #[arg(long, conflicts_with = "resume")]
        out: Option<PathBuf>,
        /// Resume the interrupted run of the same scenario into this output folder from its
        /// last checkpoint (written at every turning point of the load); with no checkpoint
        /// there, run from the start. The output equals the uninterrupted run's.
        #[arg(long, value_name = "DIR")]
        resume: Option<PathBuf>,
        /// No progress output.
        #[arg(long)]
        quiet: bool,
    },
    /// Sweep over scenario fields: one CSV row per variant, variants solved in parallel. By
    /// default each variant is the normal-loading solve alone (e.g. b/a and C against η, the
    /// paper's Figures 8–9); with `--runs` each variant's whole scenario is run into
    /// `variant_NNNN/` and the fields of all variants are plotted together (Figures 6–7, 10–19).
    Sweep {
        /// Scenario file (JSON).
        scenario: PathBuf,
        /// `FIELD=START:END:COUNT` (repeatable; the Cartesian product is run).
        #[arg(long, required = true)]
        vary: Vec<crate::io::Vary>,
        /// Output folder (default: `output/<scenario name>-sweep`).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Run only every N-th variant starting at I (`I/N`), for array jobs.
        #[arg(long)]
        shard: Option<crate::io::Shard>,
        /// Run each variant's whole scenario (history, snapshots, plots) into
        /// `OUT/variant_NNNN/`, and write comparison plots `OUT/plots/compare_*.svg` (not with
        /// `--shard`).
        #[arg(long)]
        runs: bool,
        /// No progress output.
        #[arg(long)]
        quiet: bool,
    },
    /// Validate a scenario file without solving.
    Check {
        /// Scenario file (JSON).
        scenario: PathBuf,
    },
    /// List the built-in materials with their constants and derived coefficients.
    Materials {
        /// Only this preset.
        name: Option<String>,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
}
