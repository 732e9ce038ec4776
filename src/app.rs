//! Orchestration: scenario → model → normal loading → outputs. No physics here.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::contact::normal::{NormalLoading, NormalOptions, solve_normal};
use crate::contact::pressure::Discretisation;
use crate::contact::{ContactModel, SurfacePoint};
use crate::error::Error;
use crate::halfplane::{PaperCoefficients, SurfaceCompliance, SurfaceFieldCoefficients};
use crate::output::{Staging, csv_bytes};
use crate::scenario::{RawScenario, Scenario};

/// Constants derived from the material, reported in `summary.json`.
#[derive(Debug, Serialize)]
pub struct Derived {
    /// Surface compliance coefficients (fretsim's convention).
    pub compliance: SurfaceCompliance,
    /// The same in the seed paper's convention (Appendix A.2).
    pub paper_coefficients: PaperCoefficients,
    /// Δ1…Δ4 (Section 5).
    pub field_coefficients: SurfaceFieldCoefficients,
    /// Effective plane-strain compliance of the pressure problem Y* (1/Pa).
    pub pressure_compliance: f64,
    /// Shear-to-pressure coupling κ/Y* (Dundurs' β for an elastic solid).
    pub coupling_ratio: f64,
    /// Charge carried by the pressure under a conducting punch, Γ1 = kP (C/m).
    pub pressure_charge: f64,
}

/// Normal-loading results, reported in `summary.json`.
#[derive(Debug, Serialize)]
pub struct NormalSummary {
    /// Contact half-width a (m).
    pub half_width: f64,
    /// Eccentricity e = −c (m).
    pub eccentricity: f64,
    /// Stick-zone half-width b (m).
    pub stick_half_width: f64,
    /// b/a.
    pub stick_ratio: f64,
    /// Slope C of the locked-in strain (1/m).
    pub strain_slope: f64,
    /// Peak pressure (Pa).
    pub peak_pressure: f64,
    /// Resultant charge Γ (C/m).
    pub charge: f64,
    /// Contact potential φ0 relative to the datum (V), conducting punch only.
    pub potential: Option<f64>,
    /// ∫p dx (N/m), equals P.
    pub pressure_resultant: f64,
    /// ∫g dx (C/m), equals Γ.
    pub charge_resultant: f64,
    /// Block iterations.
    pub iterations: usize,
    /// Worst admissibility violations.
    pub admissibility: crate::contact::normal::Admissibility,
}

/// `summary.json`.
#[derive(Debug, Serialize)]
pub struct Summary {
    /// fretsim version.
    pub fretsim_version: &'static str,
    /// The scenario as read.
    pub scenario: RawScenario,
    /// Derived constants.
    pub derived: Derived,
    /// Normal-loading results.
    pub normal_loading: NormalSummary,
    /// Warnings.
    pub warnings: Vec<String>,
}

/// What a run produced.
#[derive(Debug)]
pub struct RunResult {
    /// Output folder.
    pub out_dir: PathBuf,
    /// Summary (as written).
    pub summary: Summary,
}

/// Derived constants of a model at normal load P.
pub fn derived(model: &ContactModel, normal_load: f64) -> Derived {
    let split = model.charge_split(normal_load);
    let ystar = model.pressure_compliance(split);
    Derived {
        compliance: model.compliance,
        paper_coefficients: model.compliance.paper_coefficients(),
        field_coefficients: model.field_coefficients,
        pressure_compliance: ystar,
        coupling_ratio: model.pressure_shear_coupling(split) / ystar,
        pressure_charge: model.pressure_charge(normal_load),
    }
}

/// Sample points for field output: the contact and a margin of one half-width each side,
/// never exactly at the contact ends (where g and Dx0 are singular for a conducting punch).
pub fn field_points(centre: f64, half_width: f64, count: usize) -> Vec<f64> {
    (0..count)
        .map(|i| centre + 2.0 * half_width * ((2 * i + 1) as f64 - count as f64) / count as f64)
        .collect()
}

fn normal_summary(n: &NormalLoading) -> NormalSummary {
    let s = &n.state;
    let w_total = s.potential_charge.integral() * s.half_width;
    NormalSummary {
        half_width: s.half_width,
        eccentricity: -s.centre,
        stick_half_width: n.stick_half_width,
        stick_ratio: n.stick_half_width / s.half_width,
        strain_slope: n.strain_slope,
        peak_pressure: s.pressure_at(s.centre),
        charge: s.charge,
        potential: s.potential,
        pressure_resultant: s.pressure.integral() * s.half_width,
        // The inverse-square-root part integrates exactly from its series; the rest by quadrature.
        charge_resultant: s.split.ratio * s.pressure.integral() * s.half_width + w_total,
        iterations: n.iterations,
        admissibility: n.admissibility,
    }
}

/// Solve a validated scenario and write its outputs into `out_dir` (replacing it).
pub fn run(scenario: &Scenario, out_dir: &Path) -> Result<RunResult, Error> {
    let model = &scenario.model;
    let disc = Discretisation::new(scenario.collocation_points);
    let normal = solve_normal(model, &disc, scenario.normal_load, NormalOptions::default())
        .map_err(|failure| Error::Solve {
            context: "normal loading".into(),
            failure,
        })?;
    let mut warnings = Vec::new();
    let gamma1 = model.pressure_charge(scenario.normal_load);
    if normal.state.split.conducting && normal.state.charge > gamma1 {
        warnings.push(format!(
            "Γ = {:.4e} C/m exceeds the charge carried by the pressure Γ1 = kP = {gamma1:.4e} C/m: the conducting-punch model \
             (smooth pressure at the contact ends) implies a slightly negative gap just outside the contact",
            normal.state.charge
        ));
    }
    let summary = Summary {
        fretsim_version: env!("CARGO_PKG_VERSION"),
        scenario: scenario.raw.clone(),
        derived: derived(model, scenario.normal_load),
        normal_loading: normal_summary(&normal),
        warnings,
    };
    let points: Vec<SurfacePoint> = field_points(normal.state.centre, normal.state.half_width, 400)
        .into_iter()
        .map(|x| model.surface_point(&normal.state, x))
        .collect();
    let rows: Vec<Vec<f64>> = points
        .iter()
        .map(|p| vec![p.x, p.pressure, p.traction, p.charge, p.sigma_xx, p.d_x])
        .collect();
    let staging = Staging::new(out_dir)?;
    let result = (|| {
        staging.write(
            "summary.json",
            &serde_json::to_vec_pretty(&summary).expect("summary serialises"),
        )?;
        staging.write(
            "fields/normal_loading.csv",
            &csv_bytes(
                &[
                    "x_m",
                    "p_Pa",
                    "q_Pa",
                    "g_C_per_m2",
                    "sigma_xx_Pa",
                    "d_x_C_per_m2",
                ],
                &rows,
            ),
        )?;
        Ok::<(), Error>(())
    })();
    match result {
        Ok(()) => Ok(RunResult {
            out_dir: staging.commit()?,
            summary,
        }),
        Err(e) => {
            staging.abandon();
            Err(e)
        }
    }
}
