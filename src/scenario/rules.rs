//! The validation rules, one function per section of the file (material, electrode, loads,
//! history, numerics, output); each pushes every problem it finds, with its JSON path.

use crate::contact::Electrode;
use crate::error::Issue;
use crate::history::{Control, LoadHistory, PunchHistory, PunchLoads};
use crate::material::{IsotropicConstants, Material, preset};

use super::*;

pub(super) fn positive(issues: &mut Vec<Issue>, path: &str, value: f64, unit: &str) {
    if !(value.is_finite() && value > 0.0) {
        issues.push(Issue::new(
            path,
            format!("{value} {unit} is invalid; it must be finite and > 0"),
        ));
    }
}

/// The name is a plain file name: it becomes the folder `output/<name>/`.
pub(super) fn validate_name(issues: &mut Vec<Issue>, name: &str) {
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
pub(super) fn material_issue(raw: &RawMaterial, failure: &crate::error::MaterialFailure) -> Issue {
    Issue::new(
        material_path(raw),
        format!(
            "these constants are invalid; they must give a half-plane surface response ({failure})"
        ),
    )
}

pub(super) fn material_path(raw: &RawMaterial) -> &'static str {
    match raw {
        RawMaterial::Preset { .. } => "material.name",
        _ => "material",
    }
}

/// The material: a preset, or constants in range with a computable surface response.
pub(super) fn resolve_material(issues: &mut Vec<Issue>, raw: &RawMaterial) -> Option<Material> {
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
pub(super) fn surface_response(
    issues: &mut Vec<Issue>,
    raw: &RawMaterial,
    m: Material,
) -> Option<Material> {
    match crate::halfplane::SurfaceCompliance::try_of(&m) {
        Ok(_) => Some(m),
        Err(failure) => {
            issues.push(material_issue(raw, &failure));
            None
        }
    }
}

/// The punch's shape: `radius` (a cylinder) or `profile`, one of them, with its rules; a
/// profile that is not a cylinder is for the general solver only.
fn validate_profile(issues: &mut Vec<Issue>, raw: &RawScenario) {
    let punch = &raw.punch;
    match (punch.radius, &punch.profile) {
        (Some(r), None) => positive(issues, "punch.radius", r, "m"),
        (None, None) => issues.push(Issue::new(
            "punch",
            "an object without `radius` or `profile` is invalid; it must give one of them (a cylinder's `radius`, or a `profile`)",
        )),
        (Some(_), Some(_)) => issues.push(Issue::new(
            "punch.profile",
            "a profile beside `punch.radius` is invalid; it must be one or the other",
        )),
        (None, Some(profile)) => {
            let at = |field: &str| format!("punch.profile.{field}");
            let cylinder = match profile {
                RawProfile::Cylinder { radius } => {
                    positive(issues, &at("radius"), *radius, "m");
                    true
                }
                &RawProfile::FlatRounded {
                    flat_half_width,
                    radius,
                } => {
                    positive(issues, &at("radius"), radius, "m");
                    if !(flat_half_width.is_finite() && flat_half_width >= 0.0) {
                        issues.push(Issue::new(
                            at("flat_half_width"),
                            format!("{flat_half_width} m is invalid; it must be finite and ≥ 0"),
                        ));
                    }
                    flat_half_width == 0.0
                }
                &RawProfile::PowerLaw {
                    coefficient,
                    exponent,
                } => {
                    positive(issues, &at("coefficient"), coefficient, "m^(1−n)");
                    if !(exponent.is_finite() && (1.0..=20.0).contains(&exponent)) {
                        issues.push(Issue::new(
                            at("exponent"),
                            format!(
                                "{exponent} is invalid; it must lie in [1, 20] (below 1 the profile is not convex and has a cusp at its tip)"
                            ),
                        ));
                    }
                    false
                }
                RawProfile::Tabulated { points } => {
                    if let Err(issue) = crate::contact::GapTable::new(points.clone()) {
                        issues.push(match issue.point {
                            Some(i) => Issue::new(
                                format!("punch.profile.points[{i}]"),
                                format!("{:?} {}", points[i], issue.message),
                            ),
                            None => Issue::new(at("points"), issue.message),
                        });
                    }
                    false
                }
            };
            if !cylinder && raw.numerics.solver == crate::history::SolverChoice::Spectral {
                issues.push(Issue::new(
                    "numerics.solver",
                    "\"spectral\" is invalid with a punch that is not a cylinder; it must be \"auto\" or \"general\" (the spectral solver takes a cylinder only)",
                ));
            }
        }
    }
}

/// The contact of a tabulated profile must lie well inside its table: the frictionless
/// half-width under the largest P of the scenario, `a`, at most 0.8 of the last x (the
/// friction, the coupling and Q move the ends by a few per cent of a), and the slope there
/// small, at most 0.1 at 1.25 a (the half-plane's small-slope assumption). `compliance` is
/// the larger pressure compliance `y22` (the wider contact).
pub(super) fn table_reach(
    table: &crate::contact::GapTable,
    load: f64,
    compliance: f64,
) -> Option<Issue> {
    let a = table.frictionless_half_width(load, compliance);
    let extent = table.extent();
    if a > 0.8 * extent {
        return Some(Issue::new(
            "punch.profile.points",
            format!(
                "a table to x = {extent:.4e} m is invalid for this contact: under P = {load} N/m its frictionless half-width is a = {a:.4e} m, and the table must reach at least 1.25 a = {:.4e} m",
                1.25 * a
            ),
        ));
    }
    let slope = table.slope(1.25 * a);
    (slope > 0.1).then(|| {
        Issue::new(
            "punch.profile.points",
            format!(
                "a table whose slope reaches {slope:.3} at 1.25 a = {:.4e} m is invalid; the half-plane solution needs small slopes, at most 0.1 over the contact",
                1.25 * a
            ),
        )
    })
}

/// Punch radius, loads, datum distance and friction.
pub(super) fn validate_loads(issues: &mut Vec<Issue>, raw: &RawScenario) {
    validate_profile(issues, raw);
    if raw.normal_load != 0.0 {
        positive(issues, "normal_load", raw.normal_load, "N/m");
    } else {
        validate_unloaded_start(issues, raw);
    }
    positive(issues, "reference_distance", raw.reference_distance, "m");
    if !(raw.friction.is_finite() && raw.friction >= 0.0) {
        issues.push(Issue::new(
            "friction",
            format!("{} is invalid; it must be finite and ≥ 0", raw.friction),
        ));
    }
}

pub(super) fn validate_numerics(issues: &mut Vec<Issue>, numerics: &RawNumerics) {
    let m = numerics.collocation_points;
    let tol = numerics.cycle_tolerance;
    if !(tol.is_finite() && tol > 0.0 && tol < 1.0) {
        issues.push(Issue::new(
            "numerics.cycle_tolerance",
            format!("{tol} is invalid; it must lie in (0, 1)"),
        ));
    }
    let h = numerics.general_element_size;
    if !(1e-4..=0.05).contains(&h) {
        issues.push(Issue::new(
            "numerics.general_element_size",
            format!("{h} is invalid; it must lie in [1e-4, 0.05]"),
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
pub(super) fn resolve_electrode(
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
pub(super) struct CheckedHistory {
    pub(super) history: Option<crate::history::LoadHistory>,
    pub(super) span: Option<(f64, f64)>,
}

/// The value of column `k` of a raw history point, `default` when it has fewer columns (the
/// column count is checked by [`history_columns`]).
fn column(point: &[f64], k: usize, default: f64) -> f64 {
    point.get(k).copied().unwrap_or(default)
}

/// The columns of a history's points (2, 3 or 4, the same for every point and cycle point):
/// an issue for each point that breaks the rule, and the count of the first point.
fn history_columns(issues: &mut Vec<Issue>, h: &RawHistory, electric: Option<f64>) -> usize {
    let columns = h.points.first().or(h.cycle.first()).map_or(2, Vec::len);
    let rule = match electric {
        Some(_) => "[t, Q], [t, Q, P] or [t, Q, P, electric load]",
        None => "[t, Q] or [t, Q, P] (an electric column needs a conducting punch)",
    };
    let most = if electric.is_some() { 4 } else { 3 };
    let named = h
        .points
        .iter()
        .enumerate()
        .map(|(i, p)| (format!("tangential_history.points[{i}]"), p))
        .chain(
            h.cycle
                .iter()
                .enumerate()
                .map(|(i, p)| (format!("tangential_history.cycle[{i}]"), p)),
        );
    for (path, p) in named {
        if !(2..=most).contains(&p.len()) {
            issues.push(Issue::new(
                path,
                format!("{} columns is invalid; a point must be {rule}", p.len()),
            ));
        } else if p.len() != columns && (2..=most).contains(&columns) {
            issues.push(Issue::new(
                path,
                format!(
                    "{} columns is invalid; it must have the {columns} columns of the first point",
                    p.len()
                ),
            ));
        }
    }
    columns
}

/// `normal_load` = 0: the history starts from the unloaded punch, so its points must give P
/// (a third column) and press the punch somewhere; a charge-controlled punch starts without
/// charge (its charge rises in the history's fourth column). The general solver takes its
/// steps (the rule on a history that changes P rejects `numerics.solver` = "spectral").
fn validate_unloaded_start(issues: &mut Vec<Issue>, raw: &RawScenario) {
    let Some(h) = &raw.tangential_history else {
        issues.push(Issue::new(
            "normal_load",
            "0 N/m is invalid without a `tangential_history`; it must be > 0, or 0 with a history \
             whose points give P (the punch starts unloaded and the history presses it)",
        ));
        return;
    };
    let columns = h.points.first().or(h.cycle.first()).map_or(2, Vec::len);
    if columns < 3 {
        issues.push(Issue::new(
            "normal_load",
            "0 N/m is invalid with a history of [t, Q] points; it must be > 0, or 0 with points \
             [t, Q, P] (or [t, Q, P, electric load]) that give P",
        ));
        return;
    }
    if !h
        .points
        .iter()
        .chain(&h.cycle)
        .any(|p| column(p, 2, 0.0) > 0.0)
    {
        issues.push(Issue::new(
            "normal_load",
            "0 N/m is invalid with a history whose P is 0 throughout; some point must press the \
             punch (P > 0)",
        ));
    }
    // `numerics.solver` = "spectral": the rule on a history that changes P says so.
    if let RawElectrode::Conducting {
        charge: Some(g), ..
    } = &raw.punch.electrode
        && *g != 0.0
    {
        issues.push(Issue::new(
            "punch.electrode.charge",
            format!(
                "{g} C/m is invalid with `normal_load` 0; it must be 0 (a punch that starts off \
                 the half-plane carries no charge to it; raise Γ in the history's fourth column)"
            ),
        ));
    }
}

/// The normal load that scales a run (`max_step`, Q as a fraction of ηP, the plots):
/// `normal_load`, or, for a history from the unloaded punch (`normal_load` 0), the largest P
/// of its points.
pub(super) fn reference_load(normal_load: f64, h: Option<&RawHistory>) -> f64 {
    if normal_load != 0.0 {
        return normal_load;
    }
    h.map_or(0.0, |h| {
        h.points
            .iter()
            .chain(&h.cycle)
            .map(|p| column(p, 2, 0.0))
            .fold(0.0, f64::max)
    })
}

/// Check a history's size from its segments, then expand and check it. `electric` is the
/// electric load of the normal loading (Γ or φ0 of a conducting punch; `None` without one).
pub(super) fn resolve_history(
    issues: &mut Vec<Issue>,
    h: &RawHistory,
    (friction, normal_load): (f64, f64),
    electric: Option<f64>,
) -> CheckedHistory {
    let limit = friction * reference_load(normal_load, Some(h));
    let columns = history_columns(issues, h, electric);
    // Q of a point in N/m (a fraction of η times the point's own P), or δ in m.
    let q_of = |p: &[f64]| match h.unit {
        LoadUnit::FractionOfLimit => column(p, 1, 0.0) * (friction * column(p, 2, normal_load)),
        LoadUnit::NewtonPerMetre | LoadUnit::Metre => column(p, 1, 0.0),
    };
    // `max_step` in the unit of Q; under a prescribed displacement it bounds |Δδ| (m), and
    // η|ΔP| keeps its default.
    let load_step = |scale: f64| h.max_step.map_or(0.05 * limit, |m| m * scale);
    let (control, max_step, max_displacement_step) = match h.unit {
        LoadUnit::FractionOfLimit => (Control::Load, load_step(limit), f64::INFINITY),
        LoadUnit::NewtonPerMetre => (Control::Load, load_step(1.0), f64::INFINITY),
        LoadUnit::Metre => (
            Control::Displacement,
            0.05 * limit,
            h.max_step.unwrap_or(f64::INFINITY),
        ),
    };
    // The tangential value of a point on the scale of `max_step`: Q (N/m), or δ in units of
    // `max_displacement_step` times `max_step` (as `LoadHistory` counts steps).
    let tangential_scale = match control {
        Control::Load => 1.0,
        Control::Displacement if max_displacement_step.is_finite() => {
            max_step / max_displacement_step
        }
        Control::Displacement => 0.0,
    };
    if friction <= 0.0 {
        issues.push(Issue::new(
            "tangential_history",
            "a history is invalid without friction; it must have `friction` > 0",
        ));
    }
    let sized = limit.is_finite() && limit > 0.0 && h.steps_per_segment > 0;
    let steps = if sized && max_step.is_finite() && max_step > 0.0 {
        h.load_steps(
            &|p| {
                (
                    q_of(p) * tangential_scale,
                    friction * column(p, 2, normal_load),
                )
            },
            limit,
            max_step,
        )
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
    let start = PunchLoads::of(normal_load, electric.unwrap_or(0.0));
    let bulk = validate_bulk_stress(issues, h);
    let bulk_at =
        |values: Option<&Vec<f64>>, i: usize| values.and_then(|v| v.get(i)).copied().unwrap_or(0.0);
    let punch_of = |p: &[f64], bulk_stress: f64| PunchLoads {
        normal: column(p, 2, start.normal),
        electric: column(p, 3, start.electric),
        bulk_stress,
    };
    let time = |p: &[f64]| column(p, 0, 0.0);
    let lead: Vec<(f64, f64)> = h.points.iter().map(|p| (time(p), q_of(p))).collect();
    let cycle: Vec<(f64, f64)> = h.cycle.iter().map(|p| (time(p), q_of(p))).collect();
    let repeats = if cycle.is_empty() { 0 } else { h.repeats };
    let points = LoadHistory::with_cycles(&lead, &cycle, repeats);
    let punch = (columns > 2 || bulk.is_some()).then(|| {
        let lead: Vec<(f64, PunchLoads)> = h
            .points
            .iter()
            .enumerate()
            .map(|(i, p)| (time(p), punch_of(p, bulk_at(bulk.map(|b| &b.points), i))))
            .collect();
        let cycle: Vec<(f64, PunchLoads)> = h
            .cycle
            .iter()
            .enumerate()
            .map(|(i, p)| (time(p), punch_of(p, bulk_at(bulk.map(|b| &b.cycle), i))))
            .collect();
        PunchHistory {
            start,
            points: LoadHistory::with_cycles(&lead, &cycle, repeats)
                .into_iter()
                .map(|p| p.1)
                .collect(),
            friction,
        }
    });
    let history = LoadHistory {
        points,
        punch,
        steps_per_segment: h.steps_per_segment,
        max_step,
        control,
        max_displacement_step,
    };
    if friction > 0.0 && limit.is_finite() && limit > 0.0 && (2..=4).contains(&columns) {
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

/// The bulk stress of a history, when it has one: one finite value (|σB| ≤ 1e14 Pa) per point
/// of `points` and of `cycle`. `None` where there is none (and where it breaks a rule: the
/// issues say which).
fn validate_bulk_stress<'h>(
    issues: &mut Vec<Issue>,
    h: &'h RawHistory,
) -> Option<&'h RawBulkStress> {
    let bulk = h.bulk_stress.as_ref()?;
    let before = issues.len();
    for (name, values, count) in [
        ("points", &bulk.points, h.points.len()),
        ("cycle", &bulk.cycle, h.cycle.len()),
    ] {
        if values.len() != count {
            issues.push(Issue::new(
                format!("tangential_history.bulk_stress.{name}"),
                format!(
                    "{} values is invalid; it must have one per point of \
                     `tangential_history.{name}` ({count})",
                    values.len()
                ),
            ));
        }
        for (i, v) in values.iter().enumerate() {
            if !(v.is_finite() && v.abs() <= MAX_BULK_STRESS) {
                issues.push(Issue::new(
                    format!("tangential_history.bulk_stress.{name}[{i}]"),
                    format!(
                        "{v:e} Pa is invalid; it must be finite with |σB| ≤ {MAX_BULK_STRESS:e} Pa"
                    ),
                ));
            }
        }
    }
    (issues.len() == before).then_some(bulk)
}

/// The largest bulk stress |σB| (Pa), the largest stiffness a material may have.
const MAX_BULK_STRESS: f64 = 1e14;

/// The cycle's times: strictly increasing and > 0.
pub(super) fn validate_cycle(issues: &mut Vec<Issue>, cycle: &[Vec<f64>]) {
    let cycle: Vec<(f64, f64)> = cycle.iter().map(|p| (column(p, 0, 0.0), 0.0)).collect();
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
pub(super) fn count_text(n: f64) -> String {
    if n < 1e12 {
        format!("{n:.0}")
    } else {
        format!("{n:.3e}")
    }
}

/// Steps of a `(ΔQ)` segment, as [`crate::history::LoadHistory::steps`] cuts it.
pub(super) fn segment_steps(dq: f64, steps_per_segment: f64, max_step: f64) -> f64 {
    if dq.abs() > 0.0 {
        steps_per_segment.max((dq.abs() / max_step).ceil()).max(1.0)
    } else {
        1.0
    }
}

/// Load steps of a run of an expanded history: the ramp to the first point and the segments
/// (as f64: a count that overflows is a count too large).
pub(super) fn load_step_count(h: &LoadHistory) -> f64 {
    h.ramp_steps() as f64
        + (0..h.points.len().saturating_sub(1))
            .map(|k| h.segment_steps(k) as f64)
            .sum::<f64>()
}

/// Steps of the ramp from the end of normal loading to the first point, whose loads differ
/// from it by `change` (N/m, as [`segment_steps`]).
pub(super) fn ramp_steps(change: f64, steps_per_segment: f64, max_step: f64) -> f64 {
    if change > 0.0 {
        steps_per_segment.max((change / max_step).ceil())
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
    /// cycle), counted from the segments without repeating the cycle; `loads` gives a point's
    /// Q and ηP in N/m, the first from the end of normal loading at `(0, start)`; `max_step` is
    /// in N/m.
    pub(super) fn load_steps(
        &self,
        loads: &dyn Fn(&[f64]) -> (f64, f64),
        start: f64,
        max_step: f64,
    ) -> f64 {
        let sps = self.steps_per_segment as f64;
        let change =
            |(q0, p0): (f64, f64), (q1, p1): (f64, f64)| (q1 - q0).abs().max((p1 - p0).abs());
        let steps = |a: &[f64], b: &[f64]| segment_steps(change(loads(a), loads(b)), sps, max_step);
        let within = |pts: &[Vec<f64>]| pts.windows(2).map(|w| steps(&w[0], &w[1])).sum::<f64>();
        let repeats = if self.cycle.is_empty() {
            0.0
        } else {
            self.repeats as f64
        };
        let first = self
            .points
            .first()
            .or(self.cycle.first().filter(|_| repeats > 0.0));
        let mut total = first.map_or(0.0, |p| {
            ramp_steps(change((0.0, start), loads(p)), sps, max_step)
        });
        total += within(&self.points);
        if let (Some(c0), Some(c1)) = (self.cycle.first(), self.cycle.last())
            && repeats > 0.0
        {
            let cycle = within(&self.cycle);
            let join = self.points.last().map_or(0.0, |p| steps(p, c0));
            total += join + cycle + (repeats - 1.0) * (steps(c1, c0) + cycle);
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
        let t = |p: &Vec<f64>| column(p, 0, 0.0);
        let t_lead = self.points.last().map_or(0.0, t);
        let first = self.points.first().map(t).or_else(|| {
            self.cycle
                .first()
                .filter(|_| repeats > 0.0)
                .map(|c| t_lead + t(c))
        })?;
        let last = self
            .cycle
            .last()
            .filter(|_| repeats > 0.0)
            .map_or(t_lead, |c| t_lead + repeats * t(c));
        Some((first, last))
    }
}

/// Check the output options; returns the time tolerance used to match snapshot times to steps
/// (1e−9 of the history's largest time scale).
pub(super) fn validate_output(
    issues: &mut Vec<Issue>,
    out: &RawOutput,
    span: Option<(f64, f64)>,
    has_history: bool,
) -> f64 {
    if let Some(grid) = &out.subsurface {
        validate_subsurface(issues, grid);
    }
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

/// Check the subsurface grid (`output.subsurface`): its extent in units of a and its size.
fn validate_subsurface(issues: &mut Vec<Issue>, grid: &RawSubsurface) {
    let depth = grid.depth;
    if !(depth.is_finite() && depth > 0.0 && depth <= MAX_SUBSURFACE_EXTENT) {
        issues.push(Issue::new(
            "output.subsurface.depth",
            format!(
                "{depth} is invalid; it must be in (0, {MAX_SUBSURFACE_EXTENT}] (the deepest row, z/a)"
            ),
        ));
    }
    let [x0, x1] = grid.x_range;
    for (i, x) in [x0, x1].into_iter().enumerate() {
        if !(x.is_finite() && x.abs() <= MAX_SUBSURFACE_EXTENT) {
            issues.push(Issue::new(
                format!("output.subsurface.x_range[{i}]"),
                format!(
                    "{x} is invalid; it must be finite and within [−{MAX_SUBSURFACE_EXTENT}, {MAX_SUBSURFACE_EXTENT}] (x/a)"
                ),
            ));
        }
    }
    if x0.is_finite() && x1.is_finite() && x1 <= x0 {
        issues.push(Issue::new(
            "output.subsurface.x_range[1]",
            format!("{x1} is invalid; it must be > x_range[0] = {x0} (x/a)"),
        ));
    }
    let axis_ok = |n: usize| (2..=MAX_SUBSURFACE_AXIS).contains(&n);
    for (name, n) in [("nx", grid.nx), ("nz", grid.nz)] {
        if !axis_ok(n) {
            issues.push(Issue::new(
                format!("output.subsurface.{name}"),
                format!("{n} is invalid; it must be in [2, {MAX_SUBSURFACE_AXIS}]"),
            ));
        }
    }
    if axis_ok(grid.nx) && axis_ok(grid.nz) && grid.nx * grid.nz > MAX_SUBSURFACE_POINTS {
        issues.push(Issue::new(
            "output.subsurface",
            format!(
                "nx·nz = {} points is invalid; it must be at most {MAX_SUBSURFACE_POINTS}",
                grid.nx * grid.nz
            ),
        ));
    }
}
