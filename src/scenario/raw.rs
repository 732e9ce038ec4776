//! The scenario file's serde shape, strict: unknown fields are errors. All quantities SI.

use serde::{Deserialize, Serialize};

use crate::contact::Coupling;
use crate::material::PiezoConstants;

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
    /// Normal load P of the normal loading (N/m), > 0; or 0: the history (whose points must
    /// give P) starts from the unloaded punch.
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
    /// Which turning points of Q (and the last step) get a `fields/step_NNNNN.csv`:
    /// `first_and_last` (the default: those of the first loading and the first cycle, the
    /// last two, and the last step, so that a long run writes a few files), `all` (also
    /// `true`) or `none` (also `false`).
    #[serde(default)]
    pub turning_point_fields: TurningFields,
    /// Sample points per field file (a multiple of 4 in [16, 100000], default 400).
    #[serde(default = "default_field_points")]
    pub field_points: usize,
    /// Axes of the field plots: `normalised` (x/a, p/p0, q/(ηp0), g/g0, by the end of normal
    /// loading; the default) or `si`.
    #[serde(default)]
    pub plot_units: PlotUnits,
    /// Also write each plot as a PNG beside its SVG (`plots/<name>.png`, 300 dpi at the plot's
    /// nominal size; default false: rendering costs about 0.1 s and tens of MB per plot).
    #[serde(default)]
    pub png: bool,
    /// Follow the fretting-fatigue indicators over each cycle of a history
    /// ([`crate::fatigue`]; `fatigue.csv`, the summary's `fatigue` section, `max_local_slip_m`
    /// in `cycles.csv`, `plots/fatigue`); default true.
    #[serde(default = "default_true")]
    pub fatigue: bool,
    /// Fields below the surface (stresses, von Mises, and the electric fields of a
    /// piezoelectric solid) on a grid of points (x, z), written to `subsurface/<stem>.csv`
    /// and mapped at every instant that gets a field file; absent (the default): none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub subsurface: Option<RawSubsurface>,
}

/// The grid of `output.subsurface`, in units of the contact half-width a at the end of normal
/// loading: `nx` columns evenly spaced over `x_range` (x from the punch axis) and `nz` rows
/// evenly spaced over depths `[0, depth]`, the first at the surface limit (evaluated at
/// z = 1e−9 a, just below the surface).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawSubsurface {
    /// Deepest row, z/a (> 0 and ≤ 100; default 2).
    #[serde(default = "default_subsurface_depth")]
    pub depth: f64,
    /// First and last column, x/a (finite, increasing, within ±100; default [−2, 2]).
    #[serde(default = "default_subsurface_x_range")]
    pub x_range: [f64; 2],
    /// Columns (2 … 1001; default 81).
    #[serde(default = "default_subsurface_nx")]
    pub nx: usize,
    /// Rows (2 … 1001; default 41); nx·nz ≤ 250,000.
    #[serde(default = "default_subsurface_nz")]
    pub nz: usize,
}

impl Default for RawSubsurface {
    fn default() -> Self {
        Self {
            depth: default_subsurface_depth(),
            x_range: default_subsurface_x_range(),
            nx: default_subsurface_nx(),
            nz: default_subsurface_nz(),
        }
    }
}

fn default_subsurface_depth() -> f64 {
    2.0
}

fn default_subsurface_x_range() -> [f64; 2] {
    [-2.0, 2.0]
}

fn default_subsurface_nx() -> usize {
    81
}

fn default_subsurface_nz() -> usize {
    41
}

/// Which turning points get field files (`output.turning_point_fields`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TurningFields {
    /// The turning points of phases 1–3 (the first loading and the first cycle), the last two
    /// turning points, and the last step.
    #[default]
    FirstAndLast,
    /// Every turning point and the last step.
    All,
    /// None.
    None,
}

impl<'de> Deserialize<'de> for TurningFields {
    fn deserialize<D: serde::Deserializer<'de>>(de: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Given {
            Flag(bool),
            Word(String),
        }
        match Given::deserialize(de)? {
            Given::Flag(true) => Ok(Self::All),
            Given::Flag(false) => Ok(Self::None),
            Given::Word(w) => match w.as_str() {
                "first_and_last" => Ok(Self::FirstAndLast),
                "all" => Ok(Self::All),
                "none" => Ok(Self::None),
                _ => Err(serde::de::Error::custom(format!(
                    "`{w}` is not one of `first_and_last`, `all`, `none`, true, false"
                ))),
            },
        }
    }
}

/// Axes of the field plots.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PlotUnits {
    /// x/a, p/p0, q/(ηp0), g/g0 and the like, scaled by the end of normal loading.
    #[default]
    Normalised,
    /// SI units.
    Si,
}

impl Default for RawOutput {
    fn default() -> Self {
        Self {
            snapshots: Vec::new(),
            turning_point_fields: TurningFields::default(),
            field_points: default_field_points(),
            plot_units: PlotUnits::default(),
            png: false,
            fatigue: true,
            subsurface: None,
        }
    }
}

pub(super) fn default_true() -> bool {
    true
}

pub(super) fn default_field_points() -> usize {
    400
}

/// Unit of the tangential loads in a history, and with it what they prescribe: Q, or the
/// punch's displacement δ (`metre`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum LoadUnit {
    /// Q as a fraction of ηP (default), with P the point's normal load where the history gives
    /// one, else `normal_load`; `max_step` as a fraction of η·`normal_load` (of η times the
    /// history's largest P where `normal_load` is 0).
    #[default]
    FractionOfLimit,
    /// Q in N/m.
    NewtonPerMetre,
    /// The punch's tangential displacement δ in m, counted from the end of normal loading
    /// (displacement control: Q is a result and reaches ±ηP in gross slip); `max_step` in m.
    Metre,
}

/// A piecewise-linear Q(t): `points` (lead-in, from Q = 0 at the end of normal loading),
/// then `cycle` repeated `repeats` times (cycle times relative to the start of each repeat).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawHistory {
    /// Unit of Q and of `max_step`.
    #[serde(default)]
    pub unit: LoadUnit,
    /// `[t (s), Q]` points; `[t, Q, P (N/m)]` where the normal load varies too, and
    /// `[t, Q, P, Γ (C/m) or φ0 (V)]` where the electric load of a conducting punch varies too
    /// (every point and cycle point with the same columns).
    pub points: Vec<Vec<f64>>,
    /// `[Δt (s), Q, …]` points of a repeated block, with the columns of `points`.
    #[serde(default)]
    pub cycle: Vec<Vec<f64>>,
    /// Number of repeats of `cycle` (≥ 0, default 1).
    #[serde(default = "default_repeats")]
    pub repeats: usize,
    /// Minimum number of load steps per segment (≥ 1, default 10).
    #[serde(default = "default_steps")]
    pub steps_per_segment: usize,
    /// Largest load step, in the unit of Q (> 0, default 0.05 ηP).
    #[serde(default)]
    pub max_step: Option<f64>,
    /// The bulk stress σB (Pa) of the half-plane at each point of `points` and `cycle`
    /// (none: σB = 0 throughout).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bulk_stress: Option<RawBulkStress>,
}

/// The bulk stress σB (Pa, tension positive) at the points of a history: one value per point
/// of `points` and one per point of `cycle`, linear in t between them like the other loads,
/// from σB = 0 at the end of normal loading.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawBulkStress {
    /// σB at each point of `tangential_history.points` (Pa).
    pub points: Vec<f64>,
    /// σB at each point of `tangential_history.cycle` (Pa).
    #[serde(default)]
    pub cycle: Vec<f64>,
}

pub(super) fn default_repeats() -> usize {
    1
}

pub(super) fn default_steps() -> usize {
    10
}

pub(super) fn default_name() -> String {
    "scenario".to_string()
}

pub(super) fn default_reference_distance() -> f64 {
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
    /// Radius R (m), > 0, of a cylinder: the shorthand for `profile` `{"kind": "cylinder"}`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// The punch's profile (instead of `radius`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<RawProfile>,
    /// Electric boundary condition (default: none, for an elastic half-plane).
    #[serde(default)]
    pub electrode: RawElectrode,
}

/// A punch profile, `h(x)` the height of its surface above its lowest point
/// ([`crate::contact::Profile`]).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum RawProfile {
    /// A cylinder of radius R (m): `h = x²/(2R)`.
    Cylinder {
        /// R (m), > 0.
        radius: f64,
    },
    /// A flat face of half-width b (m) with corners of radius R (m), the fretting-fatigue pad:
    /// `h = (|x| − b)²/(2R)` beyond the flat.
    FlatRounded {
        /// b (m), ≥ 0 (0 is the cylinder).
        flat_half_width: f64,
        /// R (m), > 0.
        radius: f64,
    },
    /// A power law `h = A|x|ⁿ`.
    PowerLaw {
        /// A (m^(1−n)), > 0.
        coefficient: f64,
        /// n, ≥ 1 (a convex profile).
        exponent: f64,
    },
    /// A table of heights of one side of a symmetric punch, `[x, h]` (m) from the axis
    /// (x = 0 first, increasing), convex and slope-continuous, joined by a convex spline
    /// ([`crate::contact::GapTable`]).
    Tabulated {
        /// `[x, h]` points (m), at least 3.
        points: Vec<[f64; 2]>,
    },
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
    /// Which solver takes the tangential steps: `auto` (default: the spectral solver, and the
    /// general element solver for the steps it cannot take), `spectral` or `general`.
    #[serde(default)]
    pub solver: crate::history::SolverChoice,
    /// The general solver's largest element, relative to the contact half-width (in
    /// [1e−4, 0.05], default 6e−3); its elements are 5e−4 a at the contact ends and 1e−3 a at
    /// the stick ends of the state it starts from.
    #[serde(default = "default_general_element_size")]
    pub general_element_size: f64,
    /// End the run at the first turning point of the load where the cycles have settled
    /// (shakedown, or steady cyclic slip over a whole period: `cycle_tolerance`), instead of
    /// taking the rest of the history (default false).
    #[serde(default)]
    pub stop_when_settled: bool,
}

pub(super) fn default_general_element_size() -> f64 {
    crate::history::general::INNER_SIZE
}

pub(super) fn default_stick_end_kinks() -> bool {
    true
}

pub(super) fn default_cycle_tolerance() -> f64 {
    1e-6
}

pub(super) fn default_m() -> usize {
    64
}

impl Default for RawNumerics {
    fn default() -> Self {
        Self {
            collocation_points: default_m(),
            cycle_tolerance: default_cycle_tolerance(),
            stick_end_kinks: default_stick_end_kinks(),
            solver: crate::history::SolverChoice::default(),
            general_element_size: default_general_element_size(),
            stop_when_settled: false,
        }
    }
}
