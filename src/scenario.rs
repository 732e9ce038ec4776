//! Scenario files: the raw serde shape (strict: unknown fields are errors), and validation into
//! a [`Scenario`] that collects *every* problem with its JSON path.
//!
//! All quantities are SI: N/m for line loads (plane strain), m, Pa, C/m (line charge), V.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::contact::{ContactModel, Coupling, Electrode, Profile};
use crate::error::{Error, Issue};
use crate::material::{IsotropicConstants, Material, PiezoConstants, preset};

/// Scenario as written in the file.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawScenario {
    /// Name, used for the default output folder `output/<name>/`.
    #[serde(default = "default_name")]
    pub name: String,
    /// The half-plane.
    pub material: RawMaterial,
    /// The punch.
    pub punch: RawPunch,
    /// Coulomb friction coefficient η (–), ≥ 0.
    pub friction: f64,
    /// Normal load P (N/m), > 0.
    pub normal_load: f64,
    /// Datum distance d of the regularised log kernel (m), > 0 (default 0.01 m).
    #[serde(default = "default_reference_distance")]
    pub reference_distance: f64,
    /// Shear–pressure coupling: `full` (default) or `goodman`.
    #[serde(default)]
    pub coupling: Coupling,
    /// Numerical settings.
    #[serde(default)]
    pub numerics: RawNumerics,
    /// Tangential load history after normal loading (optional).
    #[serde(default)]
    pub tangential_history: Option<RawHistory>,
    /// Output options.
    #[serde(default)]
    pub output: RawOutput,
}

/// Output options.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawOutput {
    /// Times t (s, in the history's time axis) at which the fields are written to
    /// `fields/t_<t>.csv` and plotted; strictly increasing, within the history's span.
    #[serde(default)]
    pub snapshots: Vec<f64>,
    /// Also write `fields/step_NNNNN.csv` at every turning point and at the last step
    /// (default true).
    #[serde(default = "default_true")]
    pub turning_point_fields: bool,
    /// Sample points per field file (a multiple of 4 in [16, 100000], default 400).
    #[serde(default = "default_field_points")]
    pub field_points: usize,
}

impl Default for RawOutput {
    fn default() -> Self {
        Self {
            snapshots: Vec::new(),
            turning_point_fields: true,
            field_points: default_field_points(),
        }
    }
}

fn default_true() -> bool {
    true
}

fn default_field_points() -> usize {
    400
}

/// Unit of the tangential loads in a history.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum LoadUnit {
    /// Q as a fraction of ηP (default).
    #[default]
    FractionOfLimit,
    /// Q in N/m.
    NewtonPerMetre,
}

/// A piecewise-linear Q(t): `points` (lead-in, from Q = 0 at the end of normal loading),
/// then `cycle` repeated `repeats` times (cycle times relative to the start of each repeat).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawHistory {
    /// Unit of Q and of `max_step`.
    #[serde(default)]
    pub unit: LoadUnit,
    /// `[t (s), Q]` points.
    pub points: Vec<(f64, f64)>,
    /// `[Δt (s), Q]` points of a repeated block.
    #[serde(default)]
    pub cycle: Vec<(f64, f64)>,
    /// Number of repeats of `cycle` (≥ 0, default 1).
    #[serde(default = "default_repeats")]
    pub repeats: usize,
    /// Minimum number of load steps per segment (≥ 1, default 10).
    #[serde(default = "default_steps")]
    pub steps_per_segment: usize,
    /// Largest load step, in the unit of Q (> 0, default 0.05 ηP).
    #[serde(default)]
    pub max_step: Option<f64>,
}

fn default_repeats() -> usize {
    1
}

fn default_steps() -> usize {
    10
}

fn default_name() -> String {
    "scenario".to_string()
}

fn default_reference_distance() -> f64 {
    1e-2
}

/// Material: a preset by name, or constants.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum RawMaterial {
    /// `{"kind": "preset", "name": "pzt4"}`.
    Preset {
        /// Preset name (`fretsim materials` lists them).
        name: String,
    },
    /// `{"kind": "piezoelectric", "c11": …, …}` (Pa, C/m², C/(V·m)).
    Piezoelectric(PiezoConstants),
    /// `{"kind": "elastic", "shear_modulus" or "youngs_modulus": …, "poisson_ratio": …}`.
    Elastic {
        /// μ (Pa).
        #[serde(default)]
        shear_modulus: Option<f64>,
        /// E (Pa).
        #[serde(default)]
        youngs_modulus: Option<f64>,
        /// ν (–).
        poisson_ratio: f64,
    },
}

/// The punch.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawPunch {
    /// Radius R (m), > 0.
    pub radius: f64,
    /// Electric boundary condition (default: none, for an elastic half-plane).
    #[serde(default)]
    pub electrode: RawElectrode,
}

/// Electrode model.
#[derive(Debug, Clone, Deserialize, Serialize, Default)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum RawElectrode {
    /// No electric load (elastic half-plane).
    #[default]
    None,
    /// Conducting punch with either `charge` Γ (C/m) or `potential` φ0 (V).
    Conducting {
        /// Γ (C/m).
        #[serde(default)]
        charge: Option<f64>,
        /// φ0 (V).
        #[serde(default)]
        potential: Option<f64>,
    },
    /// Insulating punch: no surface charge on the contact (`g ≡ 0`).
    Insulating {},
}

/// Numerical settings.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawNumerics {
    /// Number of collocation nodes M per interval (8 ≤ M ≤ 1024, default 64).
    #[serde(default = "default_m")]
    pub collocation_points: usize,
    /// Relative tolerance for "a cycle repeats its predecessor" in the shakedown verdict
    /// (0 < tol < 1, default 1e−6).
    #[serde(default = "default_cycle_tolerance")]
    pub cycle_tolerance: f64,
    /// Carry the square-root kinks of p and w at the stick ends in closed form (default true).
    #[serde(default = "default_stick_end_kinks")]
    pub stick_end_kinks: bool,
}

fn default_stick_end_kinks() -> bool {
    true
}

fn default_cycle_tolerance() -> f64 {
    1e-6
}

fn default_m() -> usize {
    64
}

impl Default for RawNumerics {
    fn default() -> Self {
        Self {
            collocation_points: default_m(),
            cycle_tolerance: default_cycle_tolerance(),
            stick_end_kinks: default_stick_end_kinks(),
        }
    }
}

/// A validated scenario.
#[derive(Debug, Clone, Serialize)]
pub struct Scenario {
    /// Name.
    pub name: String,
    /// The contact model.
    pub model: ContactModel,
    /// Normal load P (N/m).
    pub normal_load: f64,
    /// M.
    pub collocation_points: usize,
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

fn positive(issues: &mut Vec<Issue>, path: &str, value: f64, unit: &str) {
    if !(value.is_finite() && value > 0.0) {
        issues.push(Issue::new(
            path,
            format!("{value} {unit} is invalid; it must be finite and > 0"),
        ));
    }
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

/// Check every rule; return all problems at once. Nothing whose size comes from the input
/// (the repeated cycle, the load steps) is expanded before its size is checked.
pub fn validate(raw: RawScenario) -> Result<Scenario, Vec<Issue>> {
    let mut issues = Vec::new();
    validate_name(&mut issues, &raw.name);
    let material = resolve_material(&mut issues, &raw.material);
    validate_loads(&mut issues, &raw);
    validate_numerics(&mut issues, &raw.numerics);
    let piezo = material.map(|m| m.is_piezoelectric());
    let electrode = resolve_electrode(&mut issues, &raw.punch.electrode, piezo);
    let history = raw
        .tangential_history
        .as_ref()
        .map(|h| resolve_history(&mut issues, h, raw.friction, raw.normal_load));
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
    let model = ContactModel::try_new(
        material,
        Profile::cylinder(raw.punch.radius),
        raw.friction,
        electrode,
    )
    .map_err(|failure| vec![material_issue(&raw.material, &failure)])?
    .with_reference_distance(raw.reference_distance)
    .with_coupling(raw.coupling)
    .with_stick_end_kinks(raw.numerics.stick_end_kinks);
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
        collocation_points: raw.numerics.collocation_points,
        history,
        snapshots: raw.output.snapshots.clone(),
        time_tolerance,
        raw,
    })
}

/// The name is a plain file name: it becomes the folder `output/<name>/`.
fn validate_name(issues: &mut Vec<Issue>, name: &str) {
    let plain = name
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'));
    if !plain || name.is_empty() || name == "." || name == ".." {
        issues.push(Issue::new(
            "name",
            format!(
                "{name:?} is invalid; it must be a plain name of ASCII letters, digits, `-`, `_` and `.`, \
                 not empty, `.` or `..` (it names the folder output/<name>)"
            ),
        ));
    }
}

/// The issue for constants whose surface response cannot be computed.
fn material_issue(raw: &RawMaterial, failure: &crate::error::MaterialFailure) -> Issue {
    Issue::new(
        material_path(raw),
        format!(
            "these constants are invalid; they must give a half-plane surface response ({failure})"
        ),
    )
}

fn material_path(raw: &RawMaterial) -> &'static str {
    match raw {
        RawMaterial::Preset { .. } => "material.name",
        _ => "material",
    }
}

/// The material: a preset, or constants in range with a computable surface response.
fn resolve_material(issues: &mut Vec<Issue>, raw: &RawMaterial) -> Option<Material> {
    let material = match raw {
        RawMaterial::Preset { name } => match preset(name) {
            Some(p) => Some(p.material),
            None => {
                let names: Vec<_> = crate::material::presets().iter().map(|p| p.name).collect();
                issues.push(Issue::new(
                    "material.name",
                    format!(
                        "\"{name}\" is invalid; it must be one of {}",
                        names.join(", ")
                    ),
                ));
                None
            }
        },
        RawMaterial::Piezoelectric(c) => Some(Material::Piezoelectric(*c)),
        RawMaterial::Elastic {
            shear_modulus,
            youngs_modulus,
            poisson_ratio,
        } => match (shear_modulus, youngs_modulus) {
            (Some(mu), None) => Some(Material::Elastic(IsotropicConstants {
                shear_modulus: *mu,
                poisson_ratio: *poisson_ratio,
            })),
            (None, Some(e)) => {
                // E and ν are the inputs: check them, not the derived μ.
                let found = crate::material::validate_youngs("material", *e, *poisson_ratio);
                let ok = found.is_empty();
                issues.extend(found);
                let m = IsotropicConstants::from_youngs(*e, *poisson_ratio);
                return ok.then(|| surface_response(issues, raw, Material::Elastic(m)))?;
            }
            _ => {
                issues.push(Issue::new(
                    "material",
                    "an elastic material is invalid without exactly one of `shear_modulus` and `youngs_modulus`",
                ));
                None
            }
        },
    }?;
    let found = material.validate(material_path(raw));
    let ok = found.is_empty();
    issues.extend(found);
    ok.then(|| surface_response(issues, raw, material))?
}

/// `Some(material)` when its surface response can be computed, else an issue.
fn surface_response(issues: &mut Vec<Issue>, raw: &RawMaterial, m: Material) -> Option<Material> {
    match crate::halfplane::SurfaceCompliance::try_of(&m) {
        Ok(_) => Some(m),
        Err(failure) => {
            issues.push(material_issue(raw, &failure));
            None
        }
    }
}

/// Punch radius, loads, datum distance and friction.
fn validate_loads(issues: &mut Vec<Issue>, raw: &RawScenario) {
    positive(issues, "punch.radius", raw.punch.radius, "m");
    positive(issues, "normal_load", raw.normal_load, "N/m");
    positive(issues, "reference_distance", raw.reference_distance, "m");
    if !(raw.friction.is_finite() && raw.friction >= 0.0) {
        issues.push(Issue::new(
            "friction",
            format!("{} is invalid; it must be finite and ≥ 0", raw.friction),
        ));
    }
}

fn validate_numerics(issues: &mut Vec<Issue>, numerics: &RawNumerics) {
    let m = numerics.collocation_points;
    let tol = numerics.cycle_tolerance;
    if !(tol.is_finite() && tol > 0.0 && tol < 1.0) {
        issues.push(Issue::new(
            "numerics.cycle_tolerance",
            format!("{tol} is invalid; it must lie in (0, 1)"),
        ));
    }
    if !(8..=MAX_COLLOCATION_POINTS).contains(&m) {
        issues.push(Issue::new(
            "numerics.collocation_points",
            format!("{m} is invalid; it must lie in [8, {MAX_COLLOCATION_POINTS}]"),
        ));
    }
}

/// The electrode, consistent with the material (`piezo` is `None` when the material is
/// invalid).
fn resolve_electrode(
    issues: &mut Vec<Issue>,
    raw: &RawElectrode,
    piezo: Option<bool>,
) -> Option<Electrode> {
    match (raw, piezo) {
        (RawElectrode::None, Some(true)) => {
            issues.push(Issue::new(
                "punch.electrode",
                "none is invalid for a piezoelectric half-plane; it must be `conducting` or `insulating`",
            ));
            None
        }
        (RawElectrode::None, _) => Some(Electrode::None),
        (_, Some(false)) => {
            issues.push(Issue::new(
                "punch.electrode",
                "an electric load is invalid for an elastic half-plane; it must be {\"kind\": \"none\"} or omitted",
            ));
            None
        }
        (RawElectrode::Conducting { charge, potential }, _) => match (charge, potential) {
            (Some(g), None) if g.is_finite() => Some(Electrode::ConductingCharge { charge: *g }),
            (None, Some(v)) if v.is_finite() => {
                Some(Electrode::ConductingPotential { potential: *v })
            }
            (Some(g), None) => {
                issues.push(Issue::new(
                    "punch.electrode.charge",
                    format!("{g} C/m is invalid; it must be finite"),
                ));
                None
            }
            (None, Some(v)) => {
                issues.push(Issue::new(
                    "punch.electrode.potential",
                    format!("{v} V is invalid; it must be finite"),
                ));
                None
            }
            _ => {
                issues.push(Issue::new(
                    "punch.electrode",
                    "a conducting punch is invalid without exactly one of `charge` (C/m) and `potential` (V)",
                ));
                None
            }
        },
        (RawElectrode::Insulating {}, _) => Some(Electrode::Insulating),
    }
}

/// A history checked before it is expanded: the expanded history (`None` when it would be too
/// long), and its time span.
struct CheckedHistory {
    history: Option<crate::history::LoadHistory>,
    span: Option<(f64, f64)>,
}

/// Check a history's size from its segments, then expand and check it.
fn resolve_history(
    issues: &mut Vec<Issue>,
    h: &RawHistory,
    friction: f64,
    normal_load: f64,
) -> CheckedHistory {
    let limit = friction * normal_load;
    let scale = match h.unit {
        LoadUnit::FractionOfLimit => limit,
        LoadUnit::NewtonPerMetre => 1.0,
    };
    let max_step = h.max_step.map_or(0.05 * limit, |m| m * scale);
    if friction <= 0.0 {
        issues.push(Issue::new(
            "tangential_history",
            "a history is invalid without friction; it must have `friction` > 0",
        ));
    }
    let sized = limit.is_finite() && limit > 0.0 && h.steps_per_segment > 0;
    let steps = if sized && max_step.is_finite() && max_step > 0.0 {
        h.load_steps(scale, max_step)
    } else {
        // Each segment takes at least one step.
        h.point_count() - 1.0
    };
    if steps > MAX_LOAD_STEPS as f64 {
        issues.push(Issue::new(
            "tangential_history",
            format!(
                "{} load steps ({} points, {} cycle points × {} repeats, steps_per_segment = {}, \
                 max_step = {max_step:e} N/m) is invalid; it must be at most {MAX_LOAD_STEPS}",
                count_text(steps),
                h.points.len(),
                h.cycle.len(),
                h.repeats,
                h.steps_per_segment
            ),
        ));
        validate_cycle(issues, &h.cycle);
        return CheckedHistory {
            history: None,
            span: h.span(),
        };
    }
    let lead: Vec<(f64, f64)> = h.points.iter().map(|(t, q)| (*t, q * scale)).collect();
    let cycle: Vec<(f64, f64)> = h.cycle.iter().map(|(t, q)| (*t, q * scale)).collect();
    let repeats = if cycle.is_empty() { 0 } else { h.repeats };
    let points = crate::history::LoadHistory::with_cycles(&lead, &cycle, repeats);
    let history = crate::history::LoadHistory {
        points,
        steps_per_segment: h.steps_per_segment,
        max_step,
    };
    if friction > 0.0 && limit.is_finite() && limit > 0.0 {
        issues.extend(history.validate("tangential_history", limit));
    }
    validate_cycle(issues, &h.cycle);
    let span = history
        .points
        .first()
        .zip(history.points.last())
        .map(|(a, b)| (a.0, b.0));
    CheckedHistory {
        history: Some(history),
        span,
    }
}

/// The cycle's times: strictly increasing and > 0.
fn validate_cycle(issues: &mut Vec<Issue>, cycle: &[(f64, f64)]) {
    for (i, w) in cycle.windows(2).enumerate() {
        if w[1].0 <= w[0].0 {
            issues.push(Issue::new(
                format!("tangential_history.cycle[{}].t", i + 1),
                format!(
                    "{} s is invalid; it must be > previous Δt = {} s",
                    w[1].0, w[0].0
                ),
            ));
        }
    }
    if let Some(first) = cycle.first()
        && first.0 <= 0.0
    {
        issues.push(Issue::new(
            "tangential_history.cycle[0].t",
            format!("{} s is invalid; it must be > 0", first.0),
        ));
    }
}

/// A count held as f64: in full up to 1e12, else in exponent form.
fn count_text(n: f64) -> String {
    if n < 1e12 {
        format!("{n:.0}")
    } else {
        format!("{n:.3e}")
    }
}

/// Steps of a `(ΔQ)` segment, as [`crate::history::LoadHistory::steps`] cuts it.
fn segment_steps(dq: f64, steps_per_segment: f64, max_step: f64) -> f64 {
    if dq.abs() > 0.0 {
        steps_per_segment.max((dq.abs() / max_step).ceil()).max(1.0)
    } else {
        1.0
    }
}

/// Load steps of a run of an expanded history: the ramp to the first point and the segments.
fn load_step_count(h: &crate::history::LoadHistory) -> f64 {
    let sps = h.steps_per_segment as f64;
    let ramp = h
        .points
        .first()
        .map_or(0.0, |&(_, q)| ramp_steps(q, sps, h.max_step));
    ramp + h
        .points
        .windows(2)
        .map(|w| segment_steps(w[1].1 - w[0].1, sps, h.max_step))
        .sum::<f64>()
}

/// Steps of the ramp from Q = 0 to the first point `q` (as `history::run_history` takes them).
fn ramp_steps(q: f64, steps_per_segment: f64, max_step: f64) -> f64 {
    if q.abs() > 0.0 {
        steps_per_segment.max((q.abs() / max_step).ceil())
    } else {
        0.0
    }
}

impl RawHistory {
    /// Points after the cycle is repeated, counted without repeating it.
    fn point_count(&self) -> f64 {
        let repeats = if self.cycle.is_empty() {
            0
        } else {
            self.repeats
        };
        self.points.len() as f64 + repeats as f64 * self.cycle.len() as f64
    }

    /// Load steps of a run (the ramp to the first point, the lead-in, each repeat of the
    /// cycle), counted from the segments without repeating the cycle; `scale` turns Q into
    /// N/m, `max_step` is in N/m.
    fn load_steps(&self, scale: f64, max_step: f64) -> f64 {
        let sps = self.steps_per_segment as f64;
        let steps = |q0: f64, q1: f64| segment_steps(q1 * scale - q0 * scale, sps, max_step);
        let within =
            |pts: &[(f64, f64)]| pts.windows(2).map(|w| steps(w[0].1, w[1].1)).sum::<f64>();
        let repeats = if self.cycle.is_empty() {
            0.0
        } else {
            self.repeats as f64
        };
        let first = self
            .points
            .first()
            .or(self.cycle.first().filter(|_| repeats > 0.0));
        let mut total = first.map_or(0.0, |p| ramp_steps(p.1 * scale, sps, max_step));
        total += within(&self.points);
        if let (Some(c0), Some(c1)) = (self.cycle.first(), self.cycle.last())
            && repeats > 0.0
        {
            let cycle = within(&self.cycle);
            let join = self.points.last().map_or(0.0, |p| steps(p.1, c0.1));
            total += join + cycle + (repeats - 1.0) * (steps(c1.1, c0.1) + cycle);
        }
        total
    }

    /// The time span `[first t, last t]` of the expanded history, computed without expanding
    /// it (to round-off: for checks of a history too long to expand).
    fn span(&self) -> Option<(f64, f64)> {
        let repeats = if self.cycle.is_empty() {
            0.0
        } else {
            self.repeats as f64
        };
        let t_lead = self.points.last().map_or(0.0, |p| p.0);
        let first = self.points.first().map(|p| p.0).or_else(|| {
            self.cycle
                .first()
                .filter(|_| repeats > 0.0)
                .map(|c| t_lead + c.0)
        })?;
        let last = self
            .cycle
            .last()
            .filter(|_| repeats > 0.0)
            .map_or(t_lead, |c| t_lead + repeats * c.0);
        Some((first, last))
    }
}

/// The file stem of the field snapshot at time `t` (s): `t_<t with 6 decimals>`.
pub fn snapshot_stem(t: f64) -> String {
    // `+ 0.0` turns −0 into +0, so that t = −0 and t = 0 share a name.
    format!("t_{:.6}", t + 0.0)
}

/// Check the output options; returns the time tolerance used to match snapshot times to steps
/// (1e−9 of the history's largest time scale).
fn validate_output(
    issues: &mut Vec<Issue>,
    out: &RawOutput,
    span: Option<(f64, f64)>,
    has_history: bool,
) -> f64 {
    let n = out.field_points;
    if !(16..=MAX_FIELD_POINTS).contains(&n) || !n.is_multiple_of(4) {
        issues.push(Issue::new(
            "output.field_points",
            format!(
                "{n} is invalid; it must be a multiple of 4 in [16, {MAX_FIELD_POINTS}] (so that no sample falls on a contact end)"
            ),
        ));
    }
    if out.snapshots.len() > MAX_SNAPSHOTS {
        issues.push(Issue::new(
            "output.snapshots",
            format!(
                "{} times is invalid; it must hold at most {MAX_SNAPSHOTS}",
                out.snapshots.len()
            ),
        ));
        return 0.0;
    }
    let Some((t0, t1)) = span.filter(|(a, b)| a.is_finite() && b.is_finite()) else {
        if !has_history && !out.snapshots.is_empty() {
            issues.push(Issue::new(
                "output.snapshots",
                "a list of times is invalid without a `tangential_history`; it must be [] or omitted \
                 (the fields at the end of normal loading are always written to fields/normal_loading.csv)",
            ));
        }
        return 0.0;
    };
    let tol = 1e-9 * t0.abs().max(t1.abs()).max(t1 - t0);
    for (i, &t) in out.snapshots.iter().enumerate() {
        let path = format!("output.snapshots[{i}]");
        if !t.is_finite() {
            issues.push(Issue::new(
                path,
                format!("{t} s is invalid; it must be finite"),
            ));
            continue;
        }
        if t < t0 - tol || t > t1 + tol {
            issues.push(Issue::new(
                path.clone(),
                format!("{t} s is invalid; it must lie within the history's span [{t0}, {t1}] s"),
            ));
        }
        if i > 0 {
            let prev = out.snapshots[i - 1];
            if prev.is_finite() && t <= prev {
                issues.push(Issue::new(
                    path,
                    format!("{t} s is invalid; it must be > previous t = {prev} s"),
                ));
            } else if snapshot_stem(t) == snapshot_stem(prev) {
                issues.push(Issue::new(
                    path,
                    format!(
                        "{t} s is invalid; it must differ from the previous t = {prev} s in the first 6 decimals \
                         (both would be written to fields/{}.csv)",
                        snapshot_stem(t)
                    ),
                ));
            }
        }
    }
    tol
}

/// Make every snapshot time (strictly increasing) a step time of `history`: where no step
/// (nor the end of normal loading, nor the first point) falls within `tol` of a time, add the
/// point `(t, Q(t))` of the piecewise-linear history. Q(t) is unchanged; the segment that held
/// `t` is split in two, each cut into steps by the usual rule. Splitting a segment moves its
/// steps, so the times already passed are checked again from the split segment's start (each
/// time is added at most once): the result is that of rescanning all times after every
/// addition until none is added, in about one pass.
fn insert_snapshot_points(history: &mut crate::history::LoadHistory, snapshots: &[f64], tol: f64) {
    let mut i = 0;
    while let Some(&t) = snapshots.get(i) {
        match insert_snapshot_point(history, t, tol) {
            // Times below the split segment's start minus tol keep their nearest steps.
            Some(start) => i = snapshots.partition_point(|&s| s < start - tol),
            None => i += 1,
        }
    }
}

/// Add `(t, Q(t))` to `history` unless `t` is within `tol` of a step time, the first point or
/// lies in no segment; returns the start time of the segment that was split.
fn insert_snapshot_point(
    history: &mut crate::history::LoadHistory,
    t: f64,
    tol: f64,
) -> Option<f64> {
    let &(t0, _) = history.points.first()?;
    if (t - t0).abs() <= tol || near_a_step(history, t, tol) {
        return None;
    }
    // Points are strictly increasing in t: the segment with w0.t < t < w1.t.
    let above = history.points.partition_point(|p| p.0 < t);
    if above == 0 || above == history.points.len() || history.points[above].0 <= t {
        return None;
    }
    let k = above - 1;
    let ((ta, qa), (tb, qb)) = (history.points[k], history.points[k + 1]);
    let q = qa + (t - ta) / (tb - ta) * (qb - qa);
    history.points.insert(k + 1, (t, q));
    Some(ta)
}

/// Whether a step time of `history` lies within `tol` of `t`. Step `i` of `n` on the segment
/// `[ta, tb]` is at `ta + (i/n)(tb − ta)` ([`crate::history::LoadHistory::steps`]), increasing
/// in `i`, so only the segments around `t` and the steps next to its position are looked at.
fn near_a_step(history: &crate::history::LoadHistory, t: f64, tol: f64) -> bool {
    let points = &history.points;
    // Steps of segment k lie in [t_k, t_{k+1}] up to round-off; 2 tol covers it.
    let first = points
        .partition_point(|p| p.0 < t - 2.0 * tol)
        .saturating_sub(1);
    (first..points.len().saturating_sub(1))
        .take_while(|&k| points[k].0 <= t + 2.0 * tol)
        .any(|k| {
            let (ta, tb) = (points[k].0, points[k + 1].0);
            let n = history.segment_steps(k);
            let at = ((t - ta) / (tb - ta) * n as f64).round();
            let at = if at.is_finite() {
                at.clamp(0.0, n as f64) as usize
            } else {
                0
            };
            (at.saturating_sub(2).max(1)..=(at + 2).min(n)).any(|i| {
                let f = i as f64 / n as f64;
                (ta + f * (tb - ta) - t).abs() <= tol
            })
        })
}

#[cfg(test)]
mod tests {
    /// Type errors read in the format's words: no Rust type names, no repeated position.
    #[test]
    fn parse_messages_show_no_rust_type_names() {
        let base: serde_json::Value = serde_json::from_str(DEFAULT_SCENARIO).unwrap();
        let cases = [
            ("friction", serde_json::json!("x"), "expected a number"),
            ("punch", serde_json::json!(3), "expected an object"),
            (
                "material",
                serde_json::json!("pzt4"),
                "expected an object with a `kind`",
            ),
            (
                "numerics",
                serde_json::json!({"collocation_points": -3}),
                "expected a whole number ≥ 0",
            ),
        ];
        for (field, value, expected) in cases {
            let mut v = base.clone();
            v[field] = value;
            let text = serde_json::to_string_pretty(&v).unwrap();
            let message = match parse(&text, Path::new("s.json")) {
                Err(e) => e.to_string(),
                Ok(_) => panic!("{field}: parsed"),
            };
            assert!(message.contains(expected), "{field}: {message}");
            for rust in ["f64", "usize", "u64", "struct", "enum", "Raw", " at line "] {
                assert!(!message.contains(rust), "{field}: {message}");
            }
        }
    }

    use super::*;

    fn check(text: &str) -> Result<Scenario, Error> {
        let raw = parse(text, Path::new("t.json"))?;
        validate(raw).map_err(|issues| Error::InvalidScenario {
            path: "t.json".into(),
            issues,
        })
    }

    fn issues(text: &str) -> Vec<Issue> {
        match check(text) {
            Err(Error::InvalidScenario { issues, .. }) => issues,
            other => panic!("expected invalid scenario, got {other:?}"),
        }
    }

    #[test]
    fn default_scenario_is_the_paper_baseline() {
        let s = default_scenario();
        assert_eq!(s.name, "baseline");
        assert!(
            matches!(s.model.electrode, Electrode::ConductingCharge { charge } if (charge - 6e-7).abs() < 1e-20)
        );
    }

    #[test]
    fn unknown_field_is_named_with_line_and_column() {
        let text = "{\n \"frictoin\": 0.3 }";
        match check(text) {
            Err(Error::ParseScenario { message, line, .. }) => {
                assert!(message.contains("frictoin"), "{message}");
                assert_eq!(line, 2);
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn wrong_type_names_the_json_path() {
        let text = DEFAULT_SCENARIO.replace("\"radius\": 0.06", "\"radius\": \"big\"");
        match check(&text) {
            Err(Error::ParseScenario { at, .. }) => assert_eq!(at, "punch.radius"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn every_problem_is_collected() {
        let text = DEFAULT_SCENARIO
            .replace("\"radius\": 0.06", "\"radius\": -0.06")
            .replace("\"friction\": 0.3", "\"friction\": -1")
            .replace("\"normal_load\": 2000.0", "\"normal_load\": 0");
        let paths: Vec<_> = issues(&text).into_iter().map(|i| i.path).collect();
        assert_eq!(
            paths,
            [
                "punch.radius",
                "normal_load",
                "friction",
                "tangential_history"
            ]
        );
        let msg = issues(&text)[0].to_string();
        assert_eq!(
            msg,
            "`punch.radius` = -0.06 m is invalid; it must be finite and > 0"
        );
    }

    #[test]
    fn electric_load_on_elastic_material_is_rejected() {
        let text = r#"{"material": {"kind": "elastic", "shear_modulus": 27.3e9, "poisson_ratio": 0.3},
            "punch": {"radius": 0.01, "electrode": {"kind": "conducting", "charge": 1e-7}},
            "friction": 0.3, "normal_load": 2240}"#;
        assert_eq!(issues(text)[0].path, "punch.electrode");
    }

    #[test]
    fn unknown_preset_and_bad_constants_are_named() {
        let text = DEFAULT_SCENARIO.replace("\"pzt4\"", "\"pzt99\"");
        assert_eq!(issues(&text)[0].path, "material.name");
        let text = r#"{"material": {"kind": "piezoelectric", "c11": 139e9, "c13": 74.3e9, "c33": 115e9, "c44": -1,
            "e31": -5.2, "e33": 15.1, "e15": 12.7, "eps11": 6.461e-9, "eps33": 5.62e-9},
            "punch": {"radius": 0.06, "electrode": {"kind": "conducting", "charge": 6e-7}},
            "friction": 0.3, "normal_load": 2000}"#;
        assert_eq!(issues(text)[0].path, "material.c44");
    }

    #[test]
    fn text_after_the_object_is_rejected_with_line_and_column() {
        let text = format!("{DEFAULT_SCENARIO}\n{{}}");
        match check(&text) {
            Err(e @ Error::ParseScenario { line, column, .. }) => {
                assert_eq!((line, column), (14, 1));
                assert_eq!(
                    e.to_string(),
                    "t.json: invalid scenario at `.` (line 14, column 1): trailing characters \
                     (text after the scenario's JSON object)"
                );
            }
            other => panic!("{other:?}"),
        }
        assert!(check(&format!("{DEFAULT_SCENARIO}\n \n")).is_ok());
    }

    #[test]
    fn name_must_be_a_plain_name() {
        for bad in ["../evil", "a/b", "", ".", "..", "a b", "c:\\x"] {
            let text = DEFAULT_SCENARIO.replace("\"baseline\"", &format!("{bad:?}"));
            let found = issues(&text);
            assert_eq!(found[0].path, "name", "{bad}");
        }
        let text = DEFAULT_SCENARIO.replace("\"baseline\"", "\"../evil\"");
        assert_eq!(
            issues(&text)[0].to_string(),
            "`name` = \"../evil\" is invalid; it must be a plain name of ASCII letters, digits, `-`, `_` and `.`, \
             not empty, `.` or `..` (it names the folder output/<name>)"
        );
        let text = DEFAULT_SCENARIO.replace("\"baseline\"", "\"run-2_b.v1\"");
        assert!(check(&text).is_ok());
    }

    #[test]
    fn collocation_points_are_limited() {
        let text = DEFAULT_SCENARIO.replacen(
            "\"friction\": 0.3,",
            "\"friction\": 0.3, \"numerics\": {\"collocation_points\": 1025},",
            1,
        );
        assert_eq!(
            issues(&text)[0].to_string(),
            "`numerics.collocation_points` = 1025 is invalid; it must lie in [8, 1024]"
        );
    }

    #[test]
    fn stroh_failure_is_an_issue_at_the_material() {
        let failure =
            crate::halfplane::SurfaceCompliance::try_of(&Material::Piezoelectric(PiezoConstants {
                c44: 2.56e-90,
                ..crate::material::PZT4
            }))
            .unwrap_err();
        let raw = RawMaterial::Piezoelectric(crate::material::PZT4);
        let issue = material_issue(&raw, &failure);
        assert_eq!(issue.path, "material");
        assert!(
            issue.message.starts_with(
                "these constants are invalid; they must give a half-plane surface response ("
            ),
            "{issue}"
        );
    }

    #[test]
    fn conducting_needs_exactly_one_electric_load() {
        let text =
            DEFAULT_SCENARIO.replace("\"charge\": 6e-7", "\"charge\": 6e-7, \"potential\": 1.0");
        assert_eq!(issues(&text)[0].path, "punch.electrode");
    }
}

#[cfg(test)]
mod history_tests {
    use super::*;

    fn issues_of(text: &str) -> Vec<Issue> {
        validate(parse(text, Path::new("t.json")).unwrap())
            .err()
            .unwrap_or_default()
    }

    #[test]
    fn history_rules_name_the_point() {
        let base = DEFAULT_SCENARIO.replace(
            "[[0.0, 0.0], [1.0, 0.5]]",
            "[[0.0, 0.0], [1.0, 1.2], [0.5, 0.1]]",
        );
        let paths: Vec<_> = issues_of(&base).into_iter().map(|i| i.path).collect();
        assert_eq!(
            paths,
            [
                "tangential_history.points[1].q",
                "tangential_history.points[2].t"
            ]
        );
        let newton = DEFAULT_SCENARIO
            .replace("\"fraction_of_limit\"", "\"newton_per_metre\"")
            .replace("[[0.0, 0.0], [1.0, 0.5]]", "[[0.0, 0.0], [1.0, 600.0]]");
        let found = issues_of(&newton);
        assert_eq!(found[0].path, "tangential_history.points[1].q");
        assert!(
            found[0].message.contains("|Q| < ηP = 600"),
            "{}",
            found[0].message
        );
        let backwards =
            DEFAULT_SCENARIO.replace("[[2.0, -0.5], [4.0, 0.5]]", "[[2.0, -0.5], [1.0, 0.5]]");
        assert!(
            issues_of(&backwards)
                .iter()
                .any(|i| i.path == "tangential_history.cycle[1].t")
        );
    }

    fn with_output(output: &str) -> String {
        DEFAULT_SCENARIO.replacen(
            "\"friction\": 0.3,",
            &format!("\"friction\": 0.3, \"output\": {output},"),
            1,
        )
    }

    #[test]
    fn output_rules_name_the_field() {
        // The default history spans [0, 13] s.
        let found = issues_of(&with_output(
            r#"{"snapshots": [1.0, 0.5, 14.0, 14.0000001], "field_points": 402}"#,
        ));
        let paths: Vec<_> = found.iter().map(|i| i.path.as_str()).collect();
        assert_eq!(
            paths,
            [
                "output.field_points",
                "output.snapshots[1]",
                "output.snapshots[2]",
                "output.snapshots[3]",
                "output.snapshots[3]",
            ]
        );
        assert_eq!(
            found[0].to_string(),
            "`output.field_points` = 402 is invalid; it must be a multiple of 4 in [16, 100000] (so that no sample falls on a contact end)"
        );
        assert!(found[1].message.contains("must be > previous t = 1 s"));
        assert!(
            found[2]
                .message
                .contains("must lie within the history's span [0, 13] s")
        );
        assert!(found[4].message.contains("first 6 decimals"));
        let no_history = r#"{"material": {"kind": "preset", "name": "pzt4"},
            "punch": {"radius": 0.06, "electrode": {"kind": "conducting", "charge": 6e-7}},
            "friction": 0.3, "normal_load": 2000, "output": {"snapshots": [1.0]}}"#;
        let found = issues_of(no_history);
        assert_eq!(found[0].path, "output.snapshots");
        assert!(found[0].message.contains("without a `tangential_history`"));
    }

    #[test]
    fn snapshot_times_off_the_step_grid_become_history_points() {
        // Default history: 10 steps on [0, 1] (max step 0.05 ηP over 0.5 ηP), so 0.3 is a step
        // time and 0.35 is not. Splitting [0, 1] at 0.35 regrids [0, 0.35] into 10 steps
        // 0.035 s apart, so 0.3 is then added as well; 0 and 13 (the ends) add nothing.
        let text = with_output(r#"{"snapshots": [0.0, 0.3, 0.35, 13.0]}"#);
        let s = validate(parse(&text, Path::new("t.json")).unwrap()).unwrap();
        let h = s.history.unwrap();
        assert_eq!(h.points.len(), 10);
        let added: Vec<(f64, f64)> = h.points[1..3].to_vec();
        assert!((added[0].0 - 0.3).abs() < 1e-15 && (added[0].1 - 90.0).abs() < 1e-9);
        assert!((added[1].0 - 0.35).abs() < 1e-15 && (added[1].1 - 105.0).abs() < 1e-9);
        assert_eq!(s.snapshots, [0.0, 0.3, 0.35, 13.0]);
        assert!((s.time_tolerance - 1.3e-8).abs() < 1e-20);
        assert_eq!(snapshot_stem(-0.0), "t_0.000000");
        assert_eq!(snapshot_stem(2.5), "t_2.500000");
    }

    #[test]
    fn load_steps_are_counted_and_limited_before_expanding() {
        // The default history: ramp 0, lead-in 10, then 3 × (20 + 20) steps (max step 30 N/m
        // over 300 N/m and 10 per segment): 130 steps.
        let s = default_scenario();
        let h = s.history.as_ref().unwrap();
        assert_eq!(load_step_count(h) as usize, 130);
        let raw = s.raw.tangential_history.as_ref().unwrap();
        assert_eq!(raw.load_steps(600.0, h.max_step) as usize, 130);
        let text = DEFAULT_SCENARIO.replace("\"repeats\": 3", "\"repeats\": 1000000000000000000");
        let found = issues_of(&text);
        assert_eq!(found.len(), 1);
        assert_eq!(
            found[0].to_string(),
            "`tangential_history` = 4.000e19 load steps (2 points, 2 cycle points × 1000000000000000000 repeats, \
             steps_per_segment = 10, max_step = 3e1 N/m) is invalid; it must be at most 500000"
        );
        let just = DEFAULT_SCENARIO.replace("\"repeats\": 3", "\"repeats\": 12499");
        assert!(validate(parse(&just, Path::new("t.json")).unwrap()).is_ok());
        let over = DEFAULT_SCENARIO.replace("\"repeats\": 3", "\"repeats\": 12500");
        assert!(issues_of(&over)[0].message.starts_with("500010 load steps"));
        let tiny =
            DEFAULT_SCENARIO.replace("\"repeats\": 3", "\"repeats\": 3, \"max_step\": 1e-300");
        assert_eq!(issues_of(&tiny)[0].path, "tangential_history");
    }

    #[test]
    fn snapshots_are_limited() {
        let times: Vec<String> = (0..=MAX_SNAPSHOTS)
            .map(|i| format!("{}", i as f64 * 1e-3))
            .collect();
        let found = issues_of(&with_output(&format!(
            "{{\"snapshots\": [{}]}}",
            times.join(", ")
        )));
        assert_eq!(found.len(), 1);
        assert_eq!(
            found[0].to_string(),
            "`output.snapshots` = 10001 times is invalid; it must hold at most 10000"
        );
    }

    /// The former rule, one time at a time over the whole step list: the oracle.
    #[allow(clippy::doc_lazy_continuation)]
    /// Make `t` a step time of `history`: if no step (nor the end of normal loading, nor the first
    /// point) falls within `tol` of it, add the point `(t, Q(t))` of the piecewise-linear history.
    /// Q(t) is unchanged; the segment that held `t` is split in two, each cut into steps by the
    /// usual rule. Returns whether a point was added.
    fn insert_snapshot_point_by_rescanning(
        history: &mut crate::history::LoadHistory,
        t: f64,
        tol: f64,
    ) -> bool {
        let Some(&(t0, _)) = history.points.first() else {
            return false;
        };
        let on_grid = (t - t0).abs() <= tol
            || history
                .steps()
                .iter()
                .any(|&(_, ts, _)| (ts - t).abs() <= tol);
        if on_grid {
            return false;
        }
        let Some(k) = history
            .points
            .windows(2)
            .position(|w| w[0].0 < t && t < w[1].0)
        else {
            return false;
        };
        let ((ta, qa), (tb, qb)) = (history.points[k], history.points[k + 1]);
        let q = qa + (t - ta) / (tb - ta) * (qb - qa);
        history.points.insert(k + 1, (t, q));
        true
    }

    #[test]
    fn snapshot_points_match_rescanning_after_every_addition() {
        // Random histories and snapshot sets (fixed seed): the same points as the former
        // rule, which rescanned every time against every step after each addition.
        let mut state = 0x5eed_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..300 {
            let n = 2 + (next() * 6.0) as usize;
            let mut t = 0.0;
            let points: Vec<(f64, f64)> = (0..n)
                .map(|_| {
                    let p = (t, 2.0 * next() - 1.0);
                    t += 0.1 + next() * 3.0;
                    p
                })
                .collect();
            let base = crate::history::LoadHistory {
                points,
                steps_per_segment: 1 + (next() * 12.0) as usize,
                max_step: 0.02 + next() * 0.3,
            };
            let span = base.points.last().unwrap().0;
            let mut snaps: Vec<f64> = (0..(next() * 40.0) as usize)
                .map(|_| {
                    let s = next() * span;
                    // Half of them on a step time, to exercise the tolerance.
                    if next() < 0.5 {
                        let steps = base.steps();
                        steps[(next() * steps.len() as f64) as usize].1
                    } else {
                        s
                    }
                })
                .collect();
            snaps.sort_by(f64::total_cmp);
            snaps.dedup();
            let tol = 1e-9 * span;
            let mut fast = base.clone();
            insert_snapshot_points(&mut fast, &snaps, tol);
            let mut slow = base.clone();
            while snaps
                .iter()
                .any(|&t| insert_snapshot_point_by_rescanning(&mut slow, t, tol))
            {}
            assert_eq!(fast, slow, "case {case}");
        }
    }

    #[test]
    fn ten_thousand_snapshots_are_placed_quickly() {
        let times: Vec<String> = (1..=MAX_SNAPSHOTS)
            .map(|i| format!("{}", i as f64 * 1e-4))
            .collect();
        let text = with_output(&format!("{{\"snapshots\": [{}]}}", times.join(", ")));
        let started = std::time::Instant::now();
        let s = validate(parse(&text, Path::new("t.json")).unwrap()).unwrap();
        assert!(s.history.unwrap().points.len() > 1000);
        assert!(
            started.elapsed().as_secs_f64() < 5.0,
            "{:?}",
            started.elapsed()
        );
    }

    #[test]
    fn default_history_has_three_cycles_in_newtons() {
        let s = default_scenario();
        let h = s.history.unwrap();
        assert_eq!(h.points.len(), 8);
        assert!((h.points[1].1 - 300.0).abs() < 1e-9 && (h.points[2].1 + 300.0).abs() < 1e-9);
        assert!((h.max_step - 30.0).abs() < 1e-9);
    }
}
