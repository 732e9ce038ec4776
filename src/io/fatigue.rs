//! The fretting-fatigue outputs ([`crate::fatigue`]): `fatigue.csv` (the indicators of the
//! last complete cycle on the field grid), the `fatigue` section of `summary.json` and
//! `plots/fatigue.svg`.

use serde::Serialize;

use crate::fatigue::{FatigueMaxima, FatigueProfile};
use crate::io::csv::{Column, Table};
use crate::io::plots::PlotScales;
use crate::io::svg::{Figure, PALETTE, Series};

/// The `fatigue` section of `summary.json`: the cycle the indicators are of, and the largest
/// value of each with its place.
#[derive(Debug, Clone, Serialize)]
pub struct FatigueSummary {
    /// The cycle (the last complete one).
    pub cycle: usize,
    /// Its first and last step.
    pub first_step: usize,
    /// See `first_step`.
    pub last_step: usize,
    /// Grid points (`output.field_points`).
    pub grid_points: usize,
    /// The unit a of `x_over_a` (m): the contact half-width at the end of normal loading.
    pub half_width: f64,
    /// The largest value of each indicator and where it is.
    pub maxima: FatigueMaxima,
}

impl FatigueSummary {
    /// The summary of `profile`, with the electric indicators when `electric`.
    pub fn of(profile: &FatigueProfile, electric: bool) -> Self {
        Self {
            cycle: profile.cycle,
            first_step: profile.steps.0,
            last_step: profile.steps.1,
            grid_points: profile.points.len(),
            half_width: profile.half_width,
            maxima: profile.maxima(electric),
        }
    }
}

/// `fatigue.csv`: one row per grid point (the electric columns for a piezoelectric
/// half-plane only).
pub fn fatigue_table(profile: &FatigueProfile, electric: bool) -> Table {
    let p = &profile.points;
    let real = |f: fn(&crate::fatigue::PointIndicators) -> f64| Column::Real(p.iter().map(f).collect());
    let a = profile.half_width;
    let mut columns = vec![
        ("x_m", real(|p| p.x)),
        ("x_over_a", Column::Real(p.iter().map(|p| p.x / a).collect())),
        ("slip_amplitude_m", real(|p| p.slip_amplitude)),
        ("sigma_xx_max_Pa", real(|p| p.sigma_max)),
        ("sigma_xx_min_Pa", real(|p| p.sigma_min)),
        ("sigma_xx_range_Pa", real(|p| p.sigma_max - p.sigma_min)),
        ("shear_traction_max_Pa", real(|p| p.traction_max)),
        ("ruiz_f1_J_per_m2", real(|p| p.ruiz_f1)),
        ("ruiz_f2_Pa_J_per_m2", real(|p| p.ruiz_f2)),
        ("strain_amplitude", real(|p| p.strain_amplitude)),
        ("swt_Pa", real(|p| p.swt)),
    ];
    if electric {
        columns.push(("d_x_range_C_per_m2", real(|p| p.d_x_range)));
        columns.push(("e_x_range_V_per_m", real(|p| p.e_x_range)));
    }
    Table { columns }
}

/// `plots/fatigue`: δslip, the tensile part of σmax, Ruiz's F2 and SWT along x, each over
/// its largest value (written in the legend).
pub fn fatigue_plot(profile: &FatigueProfile, scales: &PlotScales) -> (String, String) {
    let (length, x_label) = if scales.length > 0.0 {
        (
            scales.length,
            format!("x/a (a = {:.4e} m)", scales.length),
        )
    } else {
        (1.0, "x (m)".to_string())
    };
    type Curve = (&'static str, &'static str, fn(&crate::fatigue::PointIndicators) -> f64);
    let curves: [Curve; 4] = [
        ("δslip", "m", |p| p.slip_amplitude),
        ("σmax⁺", "Pa", |p| p.sigma_max.max(0.0)),
        ("Ruiz F2", "Pa·J/m²", |p| p.ruiz_f2),
        ("SWT", "Pa", |p| p.swt),
    ];
    let labels: Vec<String> = curves
        .iter()
        .map(|(name, unit, f)| format!("{name} ({:.3e} {unit})", profile.extreme(f).value))
        .collect();
    let series = curves
        .iter()
        .zip(&labels)
        .zip(PALETTE)
        .map(|(((_, _, f), label), colour)| {
            let top = profile.extreme(f).value.abs();
            let top = if top > 0.0 { top } else { 1.0 };
            Series {
                label,
                points: profile
                    .points
                    .iter()
                    .map(|p| (p.x / length, f(p) / top))
                    .collect(),
                colour,
            }
        })
        .collect();
    let figure = Figure {
        title: format!(
            "Fretting-fatigue indicators over cycle {} (steps {}–{})",
            profile.cycle, profile.steps.0, profile.steps.1
        ),
        x_label,
        y_label: "indicator / its largest value".into(),
        series,
        caption: "each over its largest value (legend); σmax⁺ = max(σmax, 0), which F2 and SWT use"
            .into(),
        ..Figure::default()
    };
    ("fatigue".into(), figure.svg())
}
