//! Error types of the library. Every variant carries the physical context needed to act on it.

use std::fmt;
use std::path::PathBuf;

use serde::Serialize;

/// One problem found while validating input: the JSON path of the field and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Issue {
    /// JSON path of the offending field, e.g. `punch.radius`.
    pub path: String,
    /// What is wrong and the rule it must satisfy.
    pub message: String,
}

impl Issue {
    /// A new issue at `path`.
    pub fn new(path: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            path: path.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for Issue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "`{}` = {}", self.path, self.message)
    }
}

fn list(issues: &[Issue]) -> String {
    issues
        .iter()
        .map(|i| format!("  - {i}"))
        .collect::<Vec<_>>()
        .join("\n")
}

fn failure_list(files: &[PathBuf]) -> String {
    if files.is_empty() {
        return String::new();
    }
    let names: Vec<String> = files.iter().map(|f| format!("  {}", f.display())).collect();
    format!(" and in:\n{}", names.join("\n"))
}

/// Why a solve failed. Carried inside [`Error::Solve`] with the step context.
#[derive(Debug, Clone, PartialEq, thiserror::Error, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SolveFailure {
    /// An iteration did not reach its tolerance.
    #[error("{what} did not converge in {iterations} iterations (residual {residual:.3e})")]
    NoConvergence {
        /// Which iteration.
        what: &'static str,
        /// Iterations spent.
        iterations: usize,
        /// Final residual (relative).
        residual: f64,
    },
    /// A computed quantity is not finite.
    #[error("{field} is not finite")]
    NonFinite {
        /// Which quantity.
        field: &'static str,
    },
    /// A physical admissibility check failed after the solve.
    #[error("inadmissible solution: {check} (worst violation {value:.3e} at x = {x:.6e} m)")]
    Inadmissible {
        /// Which check (e.g. `|q| ≤ η p in the stick zone`).
        check: String,
        /// Size of the worst violation (relative to the local scale).
        value: f64,
        /// Where (m).
        x: f64,
    },
    /// No state of the assumed stick/slip form exists.
    #[error("no stick/slip state of the assumed form: {reason}")]
    NoAdmissibleState {
        /// Why.
        reason: String,
    },
    /// Neither solver gave the state of a normal loading: the spectral solver's failure, then
    /// the general solver's ([`crate::history::NormalEnd`]).
    #[error("{spectral}; the general solver, loading by steps: {general}")]
    NeitherSolver {
        /// The spectral solver's failure.
        spectral: Box<SolveFailure>,
        /// The general solver's failure.
        general: Box<SolveFailure>,
    },
}

/// Why the surface response of a half-plane could not be computed from its constants
/// ([`crate::halfplane::SurfaceCompliance::try_of`]): constants that pass the range checks but
/// are degenerate for the extended Stroh eigenproblem.
#[derive(Debug, Clone, PartialEq, thiserror::Error, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum MaterialFailure {
    /// A matrix the construction inverts is singular.
    #[error("the {matrix} is singular")]
    Singular {
        /// Which matrix.
        matrix: &'static str,
    },
    /// The matrix sign iteration did not reach a sign matrix (an eigenvalue of the Stroh
    /// matrix on or near the real axis: no split into decaying and growing modes).
    #[error(
        "the Stroh matrix has no clean split into decaying and growing modes (matrix sign residual {residual:.3e})"
    )]
    NoModeSplit {
        /// `‖S² − I‖/‖S‖²` of the last iterate (NaN if it is not finite).
        residual: f64,
    },
    /// A surface compliance coefficient came out non-finite or of the wrong sign.
    #[error("the surface compliance {coefficient} = {value:e} is not {rule}")]
    Compliance {
        /// Which coefficient (`y11`, `y22`, `y33`, …).
        coefficient: &'static str,
        /// Its value (SI).
        value: f64,
        /// What it must be.
        rule: &'static str,
    },
}

/// Errors of the library and the command line.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The scenario file could not be read.
    #[error("cannot read scenario {path}: {source}")]
    ReadScenario {
        /// File.
        path: PathBuf,
        /// Cause.
        #[source]
        source: std::io::Error,
    },
    /// The scenario is not valid JSON or does not fit the schema.
    #[error("{path}: invalid scenario at `{at}` (line {line}, column {column}): {message}")]
    ParseScenario {
        /// File.
        path: PathBuf,
        /// JSON path of the problem.
        at: String,
        /// Line (1-based).
        line: usize,
        /// Column (1-based).
        column: usize,
        /// Parser message.
        message: String,
    },
    /// The scenario parsed but breaks one or more rules.
    #[error("{path}: {} problem(s)\n{}", issues.len(), list(issues))]
    InvalidScenario {
        /// File (or `<built-in>`).
        path: PathBuf,
        /// Every problem found.
        issues: Vec<Issue>,
    },
    /// The solver failed on a valid scenario.
    #[error("{context}: {failure}")]
    Solve {
        /// Where in the run (phase, step, t, Q).
        context: String,
        /// What failed.
        failure: SolveFailure,
    },
    /// Some variants of a sweep failed (the others were written).
    #[error(
        "{failed} of {variants} variant(s) failed; their errors are in the `error` column of {}{}",
        csv.display(),
        failure_list(failure_files)
    )]
    SweepFailed {
        /// Variants that failed.
        failed: usize,
        /// Variants run.
        variants: usize,
        /// The sweep's CSV file.
        csv: PathBuf,
        /// Their `failure.json` files (sweeps with runs).
        failure_files: Vec<PathBuf>,
    },
    /// The output folder may not be written (it holds files fretsim did not write, it is a
    /// protected folder, or another run is writing it). Nothing was touched.
    #[error("will not write into {path}: {reason}")]
    OutputRefused {
        /// The folder as given.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// `--resume`: the folder's checkpoint cannot resume this run. Nothing was touched.
    #[error("cannot resume the run in {path}: {reason}")]
    Resume {
        /// The output folder as given.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// An output file could not be written.
    #[error("cannot write {path}: {source}")]
    WriteOutput {
        /// File or directory.
        path: PathBuf,
        /// Cause.
        #[source]
        source: std::io::Error,
    },
}

impl Error {
    /// Process exit code: 1 when the solver failed on valid input, 2 for bad input or usage.
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Solve { .. } | Error::SweepFailed { .. } => 1,
            Error::ReadScenario { .. }
            | Error::ParseScenario { .. }
            | Error::InvalidScenario { .. }
            | Error::OutputRefused { .. }
            | Error::Resume { .. }
            | Error::WriteOutput { .. } => 2,
        }
    }
}
