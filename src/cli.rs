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
        #[arg(long)]
        out: Option<PathBuf>,
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
