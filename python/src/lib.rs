//! `fretsim._core`: the library's scenario validation, solve and tables for Python. Results
//! cross as plain Python values (dicts of lists, JSON text); the package `fretsim` turns the
//! lists into numpy arrays. The solve runs without the interpreter lock.

use std::path::Path;

use fretsim::error::Error;
use fretsim::io::{
    Column, Table, cycles_table, fatigue_table, fields_table, steps_table, subsurface_table,
};
use fretsim::scenario::{self, Scenario};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

create_exception!(
    _core,
    ScenarioError,
    PyValueError,
    "A scenario that breaks a rule."
);
create_exception!(
    _core,
    SolveError,
    pyo3::exceptions::PyRuntimeError,
    "The solver failed on a valid scenario before any step was solved."
);
create_exception!(
    _core,
    OutputError,
    pyo3::exceptions::PyOSError,
    "An output folder that may not be written, or a write that failed."
);

/// The error as a Python exception: input problems carry `(message, [(json_path, rule)])`.
fn to_py(error: Error) -> PyErr {
    let message = error.to_string();
    match error {
        Error::InvalidScenario { issues, .. } => {
            let list: Vec<(String, String)> =
                issues.into_iter().map(|i| (i.path, i.message)).collect();
            ScenarioError::new_err((message, list))
        }
        Error::ParseScenario { at, .. } => {
            ScenarioError::new_err((message.clone(), vec![(at, message)]))
        }
        Error::Solve { .. } | Error::SweepFailed { .. } => SolveError::new_err(message),
        Error::ReadScenario { .. }
        | Error::OutputRefused { .. }
        | Error::Resume { .. }
        | Error::WriteOutput { .. } => OutputError::new_err(message),
    }
}

fn checked(text: &str, label: &str) -> Result<Scenario, Error> {
    let path = Path::new(label);
    let raw = scenario::parse(text, path)?;
    scenario::validate(raw).map_err(|issues| Error::InvalidScenario {
        path: path.to_path_buf(),
        issues,
    })
}

/// Validate a scenario given as JSON text; return it with every default filled in (JSON).
#[pyfunction]
fn validate(text: &str, label: &str) -> PyResult<String> {
    let scenario = checked(text, label).map_err(to_py)?;
    Ok(serde_json::to_string(&scenario.raw).expect("a scenario serialises"))
}

/// The built-in default scenario (JSON).
#[pyfunction]
fn default_scenario() -> String {
    scenario::DEFAULT_SCENARIO.to_string()
}

/// The material presets with their constants and sources (JSON).
#[pyfunction]
fn materials() -> String {
    let rows: Vec<_> = fretsim::material::presets()
        .into_iter()
        .map(|p| serde_json::json!({"name": p.name, "source": p.source, "material": p.material}))
        .collect();
    serde_json::to_string(&rows).expect("presets serialise")
}

fn table_dict<'py>(py: Python<'py>, table: &Table) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    for (name, column) in &table.columns {
        let values = match column {
            Column::Real(v) => PyList::new(py, v)?,
            Column::MaybeReal(v) => PyList::new(py, v)?,
            Column::Count(v) => PyList::new(py, v)?,
            Column::MaybeCount(v) => PyList::new(py, v)?,
            Column::Text(v) => PyList::new(py, v)?,
        };
        dict.set_item(*name, values)?;
    }
    Ok(dict)
}

/// What a solved scenario gives Python: the summary (JSON), the step, cycle and field tables,
/// the tables of the fields below the surface (`output.subsurface`) by the stem of their
/// field file, the fretting-fatigue indicators of the last complete cycle (`fatigue.csv`),
/// and the failure that stopped the history, if any.
struct Outcome {
    summary: String,
    steps: Table,
    cycles: Table,
    fields: Vec<(String, String, Table)>,
    subsurface: Vec<(String, Table)>,
    fatigue: Option<Table>,
    failure: Option<String>,
}

fn outcome(scenario: &Scenario, solution: &fretsim::io::Solution) -> Outcome {
    let all = || solution.fields.iter().chain(&solution.turning_fields);
    Outcome {
        summary: serde_json::to_string(&solution.summary).expect("a summary serialises"),
        steps: steps_table(&solution.records, scenario.model.friction),
        cycles: cycles_table(&solution.cycles),
        fields: all()
            .map(|f| (f.stem.clone(), f.label.clone(), fields_table(&f.points)))
            .collect(),
        subsurface: all()
            .filter_map(|f| Some((f.stem.clone(), subsurface_table(f.subsurface.as_ref()?))))
            .collect(),
        fatigue: solution
            .fatigue
            .as_ref()
            .map(|f| fatigue_table(f, scenario.model.compliance.electric.is_some())),
        failure: solution.failure.as_ref().map(|e| e.to_string()),
    }
}

fn outcome_dict<'py>(py: Python<'py>, o: &Outcome) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    dict.set_item("summary", &o.summary)?;
    dict.set_item("steps", table_dict(py, &o.steps)?)?;
    dict.set_item("cycles", table_dict(py, &o.cycles)?)?;
    let fields = PyDict::new(py);
    for (stem, label, table) in &o.fields {
        let entry = table_dict(py, table)?;
        entry.set_item("label", label)?;
        fields.set_item(stem, entry)?;
    }
    dict.set_item("fields", fields)?;
    let subsurface = PyDict::new(py);
    for (stem, table) in &o.subsurface {
        subsurface.set_item(stem, table_dict(py, table)?)?;
    }
    dict.set_item("subsurface", subsurface)?;
    match &o.fatigue {
        Some(table) => dict.set_item("fatigue", table_dict(py, table)?)?,
        None => dict.set_item("fatigue", py.None())?,
    }
    dict.set_item("failure", &o.failure)?;
    Ok(dict)
}

/// Every step record of a run, as the run takes them.
#[derive(Default)]
struct Recorder {
    records: Vec<fretsim::history::StepRecord>,
}

impl fretsim::history::Observer for Recorder {
    fn on_step(
        &mut self,
        record: &fretsim::history::StepRecord,
        _state: fretsim::history::StateView<'_>,
    ) {
        self.records.push(record.clone());
    }
}

/// Solve one scenario (JSON text); with `out`, also write the output folder that
/// `fretsim run` writes (the same rules: a new folder or a previous fretsim output).
fn solve_one(text: &str, label: &str, out: Option<&str>) -> Result<Outcome, Error> {
    let scenario = checked(text, label)?;
    let Some(out) = out else {
        let solution = fretsim::io::solve(&scenario, &mut fretsim::history::NoObserver)?;
        return Ok(outcome(&scenario, &solution));
    };
    // As `fretsim run`: a failed normal loading leaves failure.json; a history that stops
    // part-way is written and returned with its failure. The written run streams its records
    // into `steps.csv`; Python gets them all, collected as they are taken.
    let mut recorder = Recorder::default();
    let mut result = fretsim::io::run_partial(&scenario, Path::new(out), &mut recorder)?;
    result.solution.records = recorder.records;
    Ok(outcome(&scenario, &result.solution))
}

/// Solve a scenario (JSON text) and return its results as a dict.
#[pyfunction]
#[pyo3(signature = (text, label, out=None))]
fn run<'py>(
    py: Python<'py>,
    text: &str,
    label: &str,
    out: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let result = py.detach(|| solve_one(text, label, out));
    outcome_dict(py, &result.map_err(to_py)?)
}

/// Solve many scenarios (JSON texts) in parallel; each entry is a result dict or the exception
/// its scenario raised.
#[pyfunction]
fn run_many<'py>(py: Python<'py>, texts: Vec<String>) -> PyResult<Vec<Bound<'py, PyAny>>> {
    use rayon::prelude::*;
    let results: Vec<Result<Outcome, Error>> = py.detach(|| {
        texts
            .par_iter()
            .enumerate()
            .map(|(i, t)| solve_one(t, &format!("<scenario {i}>"), None))
            .collect()
    });
    results
        .into_iter()
        .map(|r| match r {
            Ok(o) => outcome_dict(py, &o).map(Bound::into_any),
            Err(e) => Ok(to_py(e).into_value(py).into_bound(py).into_any()),
        })
        .collect()
}

/// The extension module.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(validate, m)?)?;
    m.add_function(wrap_pyfunction!(default_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(materials, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(run_many, m)?)?;
    m.add("ScenarioError", m.py().get_type::<ScenarioError>())?;
    m.add("SolveError", m.py().get_type::<SolveError>())?;
    m.add("OutputError", m.py().get_type::<OutputError>())?;
    Ok(())
}
