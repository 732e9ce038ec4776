//! Scenario files: the raw serde shape (strict: unknown fields are errors), and validation into
//! a [`Scenario`] that collects *every* problem with its JSON path.
//!
//! All quantities are SI: N/m for line loads (plane strain), m, Pa, C/m (line charge), V.

mod raw;
mod rules;
mod snapshots;
#[cfg(test)]
mod tests;

use std::path::Path;

use serde::Serialize;

use crate::contact::{ContactModel, Electrode, Profile};
use crate::error::{Error, Issue};
use crate::material::Material;

pub use raw::*;
use rules::*;
use snapshots::*;

/// A validated scenario.
#[derive(Debug, Clone, Serialize)]
pub struct Scenario {
    /// Name.
    pub name: String,
    /// The contact model.
    pub model: ContactModel,
    /// Normal load P of the normal loading (N/m); 0 where the history starts from the
    /// unloaded punch.
    pub normal_load: f64,
    /// The normal load that scales the run (N/m): `normal_load`, or the largest P of a history
    /// that starts from the unloaded punch (its `max_step`, Q as a fraction of ηP, the derived
    /// constants, the plots' scales and the grids of the fields).
    pub reference_load: f64,
    /// M.
    pub collocation_points: usize,
    /// Which solver takes the tangential steps (`numerics.solver`).
    pub solver: crate::history::SolverChoice,
    /// The tangential load history in N/m, if any, with a point added at every snapshot time
    /// that is not already a step time (Q(t) unchanged).
    pub history: Option<crate::history::LoadHistory>,
    /// Snapshot times (s), as given in `output.snapshots`.
    pub snapshots: Vec<f64>,
    /// Two times closer than this (s) are the same instant (matching snapshots to steps).
    pub time_tolerance: f64,
    /// The input as read, echoed in the outputs.
    pub raw: RawScenario,
}

impl Scenario {
    /// The frictionless half-width at [`Scenario::reference_load`] (m), with the pressure
    /// compliance of the punch's electrode: the size of the contact that places a history's
    /// grids and scales its plots where no normal loading gives one (`normal_load` 0).
    pub fn frictionless_half_width(&self) -> f64 {
        let (model, load) = (&self.model, self.reference_load);
        model
            .profile
            .frictionless_half_width(load, model.pressure_compliance(model.charge_split(load)))
    }
}

/// The built-in default: the seed paper's baseline (PZT-4, conducting punch, R = 60 mm,
/// P = 2000 N/m, Γ = 6e−7 C/m, η = 0.3), normal loading then three cycles of ±0.5 ηP.
pub const DEFAULT_SCENARIO: &str = r#"{
  "name": "baseline",
  "material": { "kind": "preset", "name": "pzt4" },
  "punch": { "radius": 0.06, "electrode": { "kind": "conducting", "charge": 6e-7 } },
  "friction": 0.3,
  "normal_load": 2000.0,
  "tangential_history": {
    "unit": "fraction_of_limit",
    "points": [[0.0, 0.0], [1.0, 0.5]],
    "cycle": [[2.0, -0.5], [4.0, 0.5]],
    "repeats": 3
  }
}"#;

/// Parse a scenario from JSON text; `path` names the source in messages. Anything but
/// whitespace after the JSON object is an error.
pub fn parse(text: &str, path: &Path) -> Result<RawScenario, Error> {
    let de = &mut serde_json::Deserializer::from_str(text);
    let raw = serde_path_to_error::deserialize(&mut *de).map_err(|e| {
        let at = e.path().to_string();
        let inner = e.into_inner();
        Error::ParseScenario {
            path: path.to_path_buf(),
            at,
            line: inner.line(),
            column: inner.column(),
            message: plain_message(&inner),
        }
    })?;
    de.end().map_err(|e| Error::ParseScenario {
        path: path.to_path_buf(),
        at: ".".to_string(),
        line: e.line(),
        column: e.column(),
        message: format!(
            "{} (text after the scenario's JSON object)",
            plain_message(&e)
        ),
    })?;
    Ok(raw)
}

/// The parser's message in the words of the scenario format: without its position (the error
/// gives line and column) and without Rust's type names (`f64` is a number, `struct RawPunch`
/// an object).
fn plain_message(e: &serde_json::Error) -> String {
    let text = e.to_string();
    let text = match text.rsplit_once(" at line ") {
        Some((message, _)) if e.line() > 0 => message.to_string(),
        _ => text,
    };
    let mut words: Vec<String> = Vec::new();
    let mut tokens = text.split(' ').peekable();
    while let Some(token) = tokens.next() {
        let (core, tail) = match token.find(|c: char| !c.is_alphanumeric() && c != '_') {
            Some(i) => token.split_at(i),
            None => (token, ""),
        };
        let plain = match core {
            "f64" | "f32" => Some("a number"),
            "u8" | "u16" | "u32" | "u64" | "usize" => Some("a whole number ≥ 0"),
            "i8" | "i16" | "i32" | "i64" | "isize" => Some("a whole number"),
            "struct" | "enum" if tokens.peek().is_some() => {
                // `struct RawPunch`, `internally tagged enum RawMaterial`
                let next = tokens.next().unwrap_or_default();
                let (_, tail) = next.split_at(next.find([',', ')']).unwrap_or(next.len()));
                words.push(format!(
                    "{}{tail}",
                    if core == "struct" {
                        "an object"
                    } else {
                        "an object with a `kind`"
                    }
                ));
                continue;
            }
            _ => None,
        };
        match plain {
            Some(p) => words.push(format!("{p}{tail}")),
            None => words.push(token.to_string()),
        }
    }
    words
        .join(" ")
        .replace("internally tagged an object", "an object")
}

/// Read, parse and validate a scenario file.
pub fn load(path: &Path) -> Result<Scenario, Error> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::ReadScenario {
        path: path.to_path_buf(),
        source,
    })?;
    let raw = parse(&text, path)?;
    validate(raw).map_err(|issues| Error::InvalidScenario {
        path: path.to_path_buf(),
        issues,
    })
}

/// The built-in default scenario, validated.
pub fn default_scenario() -> Scenario {
    let raw = parse(DEFAULT_SCENARIO, Path::new("<built-in>")).expect("built-in scenario parses");
    validate(raw).expect("built-in scenario is valid")
}

/// Most load steps in a run (the ramp to the first point, the lead-in, every repeat of the
/// cycle), counted from the segments before anything is expanded.
pub const MAX_LOAD_STEPS: usize = 500_000;

/// Most collocation points M (`numerics.collocation_points`).
pub const MAX_COLLOCATION_POINTS: usize = 1024;

/// Most sample points per field file (`output.field_points`).
pub const MAX_FIELD_POINTS: usize = 100_000;

/// Most snapshot times (`output.snapshots`).
pub const MAX_SNAPSHOTS: usize = 10_000;

/// Most columns, and most rows, of the subsurface grid (`output.subsurface.nx`, `.nz`).
pub const MAX_SUBSURFACE_AXIS: usize = 1001;

/// Most points of the subsurface grid (`nx·nz`): about 20 s per instant for PZT-4 on two
/// cores.
pub const MAX_SUBSURFACE_POINTS: usize = 250_000;

/// Largest |x|/a and depth z/a of the subsurface grid.
pub const MAX_SUBSURFACE_EXTENT: f64 = 100.0;

/// Check every rule; return all problems at once. Nothing whose size comes from the input
/// (the repeated cycle, the load steps) is expanded before its size is checked.
///
/// Each issue names the field by its JSON path and states the rule:
///
/// ```
/// use std::path::Path;
///
/// let text = fretsim::scenario::DEFAULT_SCENARIO.replace(r#""radius": 0.06"#, r#""radius": -1"#);
/// let raw = fretsim::parse(&text, Path::new("example.json")).expect("well-formed JSON");
/// let issues = fretsim::validate(raw).expect_err("a negative radius is invalid");
/// assert_eq!(issues[0].path, "punch.radius");
/// println!("{}", issues[0]); // `punch.radius` = … (the rule it breaks)
/// ```
pub fn validate(raw: RawScenario) -> Result<Scenario, Vec<Issue>> {
    let mut issues = Vec::new();
    validate_name(&mut issues, &raw.name);
    let material = resolve_material(&mut issues, &raw.material);
    validate_loads(&mut issues, &raw);
    validate_numerics(&mut issues, &raw.numerics);
    let piezo = material.map(|m| m.is_piezoelectric());
    let electrode = resolve_electrode(&mut issues, &raw.punch.electrode, piezo);
    let history = raw.tangential_history.as_ref().map(|h| {
        let electric = electrode.and_then(|e| match e {
            Electrode::ConductingCharge { charge } => Some(charge),
            Electrode::ConductingPotential { potential } => Some(potential),
            Electrode::None | Electrode::Insulating => None,
        });
        resolve_history(&mut issues, h, (raw.friction, raw.normal_load), electric)
    });
    let punch = history
        .as_ref()
        .and_then(|h| h.history.as_ref())
        .and_then(|h| h.punch.as_ref());
    let varies = punch.is_some_and(|p| {
        p.points
            .iter()
            .any(|&loads| crate::history::PunchLoads::of(loads.normal, loads.electric) != p.start)
    });
    let stressed = punch.is_some_and(|p| p.points.iter().any(|loads| loads.bulk_stress != 0.0));
    if varies && raw.numerics.solver == crate::history::SolverChoice::Spectral {
        issues.push(Issue::new(
            "numerics.solver",
            "\"spectral\" is invalid with a history that changes P or the electric load; it must be \
             \"auto\" or \"general\" (the spectral solver holds them fixed)",
        ));
    }
    if stressed && raw.numerics.solver == crate::history::SolverChoice::Spectral {
        issues.push(Issue::new(
            "numerics.solver",
            "\"spectral\" is invalid with a history that has a bulk stress \
             (`tangential_history.bulk_stress`); it must be \"auto\" or \"general\" (the spectral \
             solver holds σB = 0)",
        ));
    }
    // A punch off the half-plane (P = 0) carries no charge to it.
    if let (Some(Electrode::ConductingCharge { .. }), Some(h)) =
        (electrode, history.as_ref().and_then(|h| h.history.as_ref()))
        && let Some(punch) = &h.punch
        && let Some((k, loads)) = punch
            .points
            .iter()
            .enumerate()
            .find(|(_, l)| l.normal == 0.0 && l.electric != 0.0)
    {
        issues.push(Issue::new(
            "tangential_history",
            format!(
                "Γ = {} C/m at P = 0 (t = {} s) is invalid; it must be 0 where P is (a punch \
                 off the half-plane carries no charge to it)",
                loads.electric, h.points[k].0
            ),
        ));
    }
    let displaced = history
        .as_ref()
        .and_then(|h| h.history.as_ref())
        .is_some_and(|h| h.control == crate::history::Control::Displacement);
    if displaced && raw.numerics.solver == crate::history::SolverChoice::Spectral {
        issues.push(Issue::new(
            "numerics.solver",
            "\"spectral\" is invalid with a displacement history (`tangential_history.unit` = \
             \"metre\"); it must be \"auto\" or \"general\" (the spectral solver prescribes Q)",
        ));
    }
    let span = history.as_ref().and_then(|h| h.span);
    let time_tolerance = validate_output(&mut issues, &raw.output, span, history.is_some());
    match (material, electrode, issues.is_empty()) {
        (Some(material), Some(electrode), true) => {
            let history = history.and_then(|h| h.history);
            build(raw, material, electrode, history, time_tolerance)
        }
        _ => Err(issues),
    }
}

/// The validated scenario: the model, and the history with a point at every snapshot time.
fn build(
    raw: RawScenario,
    material: Material,
    electrode: Electrode,
    history: Option<crate::history::LoadHistory>,
    time_tolerance: f64,
) -> Result<Scenario, Vec<Issue>> {
    let profile = match (&raw.punch.profile, raw.punch.radius) {
        (
            Some(RawProfile::FlatRounded {
                flat_half_width,
                radius,
            }),
            _,
        ) if *flat_half_width > 0.0 => Profile::flat_rounded(*flat_half_width, *radius),
        (Some(RawProfile::Cylinder { radius } | RawProfile::FlatRounded { radius, .. }), _) => {
            Profile::cylinder(*radius)
        }
        (
            Some(RawProfile::PowerLaw {
                coefficient,
                exponent,
            }),
            _,
        ) => Profile::power_law(*coefficient, *exponent),
        (Some(RawProfile::Tabulated { points }), _) => Profile::Tabulated {
            points: crate::contact::GapTable::new(points.clone()).expect("validated table"),
        },
        (None, radius) => Profile::cylinder(radius.expect("validated: a radius or a profile")),
    };
    let model = ContactModel::try_new(material, profile, raw.friction, electrode)
        .map_err(|failure| vec![material_issue(&raw.material, &failure)])?
        .with_reference_distance(raw.reference_distance)
        .with_coupling(raw.coupling)
        .with_stick_end_kinks(raw.numerics.stick_end_kinks);
    if let Profile::Tabulated { points } = &model.profile {
        let most = history
            .as_ref()
            .and_then(|h| h.punch.as_ref())
            .map_or(0.0, |p| {
                p.points.iter().map(|l| l.normal).fold(0.0, f64::max)
            })
            .max(raw.normal_load);
        if let Some(issue) = rules::table_reach(points, most, model.compliance.y22) {
            return Err(vec![issue]);
        }
    }
    let history = history.map(|mut h| {
        insert_snapshot_points(&mut h, &raw.output.snapshots, time_tolerance);
        h
    });
    // Each added point can add up to `steps_per_segment` steps.
    if let Some(n) = history.as_ref().map(load_step_count)
        && n > MAX_LOAD_STEPS as f64
    {
        return Err(vec![Issue::new(
            "output.snapshots",
            format!(
                "{} times off the step grid (each splits a segment) giving {} load steps is invalid; \
                 it must give at most {MAX_LOAD_STEPS} load steps",
                raw.output.snapshots.len(),
                count_text(n)
            ),
        )]);
    }
    Ok(Scenario {
        name: raw.name.clone(),
        model,
        normal_load: raw.normal_load,
        reference_load: reference_load(raw.normal_load, raw.tangential_history.as_ref()),
        collocation_points: raw.numerics.collocation_points,
        solver: raw.numerics.solver,
        history,
        snapshots: raw.output.snapshots.clone(),
        time_tolerance,
        raw,
    })
}

/// The file stem of the field snapshot at time `t` (s): `t_<t with 6 decimals>`.
pub fn snapshot_stem(t: f64) -> String {
    // `+ 0.0` turns −0 into +0, so that t = −0 and t = 0 share a name.
    format!("t_{:.6}", t + 0.0)
}
