//! The CSV files of a run: `steps.csv`, `cycles.csv` and the field files. Headers carry the
//! units; numbers are written as `%.10e`, counters as integers.

use crate::analysis::CycleRow;
use crate::contact::SurfacePoint;
use crate::io::folder::csv_bytes;

/// A fields CSV: `x_m, p_Pa, q_Pa, g_C_per_m2, sigma_xx_Pa, d_x_C_per_m2`.
pub(crate) fn fields_csv(points: &[SurfacePoint]) -> Vec<u8> {
    let rows: Vec<Vec<f64>> = points
        .iter()
        .map(|p| vec![p.x, p.pressure, p.traction, p.charge, p.sigma_xx, p.d_x])
        .collect();
    csv_bytes(
        &[
            "x_m",
            "p_Pa",
            "q_Pa",
            "g_C_per_m2",
            "sigma_xx_Pa",
            "d_x_C_per_m2",
        ],
        &rows,
    )
}

/// `cycles.csv`: one row per fretting cycle.
pub(crate) fn cycles_csv(cycles: &[CycleRow]) -> Vec<u8> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "cycle",
        "first_step",
        "last_step",
        "Q_start_N_per_m",
        "Q_min_N_per_m",
        "Q_end_N_per_m",
        "loop_area_J_per_m",
        "friction_work_J_per_m",
        "normal_work_J_per_m",
        "electric_work_J_per_m",
        "delta_at_max_m",
        "delta_at_min_m",
        "stick_lo_at_max_m",
        "stick_hi_at_max_m",
        "stick_lo_at_min_m",
        "stick_hi_at_min_m",
        "change_vs_previous",
        "compared_with_cycle",
    ])
    .expect("in-memory write");
    let f = |x: f64| format!("{x:.10e}");
    for c in cycles {
        w.write_record([
            c.cycle.to_string(),
            c.steps.0.to_string(),
            c.steps.1.to_string(),
            f(c.loads.0),
            f(c.loads.1),
            f(c.loads.2),
            f(c.loop_area),
            f(c.friction_work),
            f(c.normal_work),
            f(c.electric_work),
            f(c.displacement_extremes.0),
            f(c.displacement_extremes.1),
            f(c.stick_at_max.0),
            f(c.stick_at_max.1),
            f(c.stick_at_min.0),
            f(c.stick_at_min.1),
            c.change.map(f).unwrap_or_default(),
            c.compared_with.map(|k| k.to_string()).unwrap_or_default(),
        ])
        .expect("in-memory write");
    }
    w.into_inner().expect("in-memory write")
}

/// `steps.csv`: one row per accepted step.
pub(crate) fn steps_csv(records: &[crate::history::StepRecord], limit: f64) -> Vec<u8> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "step",
        "t_s",
        "Q_N_per_m",
        "Q_over_etaP",
        "regime",
        "phase",
        "a_m",
        "e_m",
        "stick_lo_m",
        "stick_hi_m",
        "left_slip_sign",
        "right_slip_sign",
        "newton_iterations",
        "evaluations",
        "residual",
        "stick_excess",
        "slip_reversal",
        "delta_m",
        "dissipation_J_per_m",
    ])
    .expect("in-memory write");
    for r in records {
        let regime = serde_json::to_value(r.regime)
            .ok()
            .and_then(|v| v.as_str().map(String::from))
            .unwrap_or_default();
        let f = |x: f64| format!("{x:.10e}");
        w.write_record([
            r.step.to_string(),
            f(r.t),
            f(r.q),
            f(r.q / limit),
            regime,
            r.phase.to_string(),
            f(r.half_width),
            f(r.eccentricity),
            f(r.stick_lo),
            f(r.stick_hi),
            f(r.left_slip_sign),
            f(r.right_slip_sign),
            r.iterations.to_string(),
            r.newton_iterations.to_string(),
            f(r.residual),
            f(r.admissibility.stick_excess),
            f(r.admissibility.slip_reversal),
            f(r.displacement),
            f(r.dissipation),
        ])
        .expect("in-memory write");
    }
    w.into_inner().expect("in-memory write")
}
