//! The analysis of a tangential history's cycles: each cycle from a positive extreme of Q to
//! the next, its loop area and friction work (the energy dissipated, computed two ways), and the
//! verdict on whether the cycles settle. Pure computation on the step records; no I/O.

use serde::Serialize;

/// One fretting cycle: from a positive extreme of Q to the next.
#[derive(Debug, Clone, Serialize)]
pub struct CycleRow {
    /// Cycle number (1-based).
    pub cycle: usize,
    /// First and last step.
    pub steps: (usize, usize),
    /// Q at the start, the minimum and the end of the cycle (N/m).
    pub loads: (f64, f64, f64),
    /// Loop area ∮Q dδ (J/m), trapezoidal over the steps.
    pub loop_area: f64,
    /// Frictional work Σ −∫ q Δs (J/m).
    pub friction_work: f64,
    /// Work of the normal load over the cycle (J/m); zero over a closed cycle.
    pub normal_work: f64,
    /// Work of the electric load over the cycle (J/m).
    pub electric_work: f64,
    /// δ at the positive and at the negative extreme (m).
    pub displacement_extremes: (f64, f64),
    /// Stick-zone ends at the positive extreme (m).
    pub stick_at_max: (f64, f64),
    /// Stick-zone ends at the negative extreme (m).
    pub stick_at_min: (f64, f64),
    /// Largest change against the latest earlier cycle under the same loads (start, minimum
    /// and end of Q), relative (stick ends to a, δ to the δ amplitude, energy to the loop
    /// area); `None` when no earlier cycle had the same loads.
    pub change: Option<f64>,
    /// The cycle compared with.
    pub compared_with: Option<usize>,
}

/// Whether the cycles have settled.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Verdict {
    /// The response repeats within the tolerance from this cycle on.
    SteadyCyclicSlip {
        /// Every cycle after this one repeats the latest earlier cycle under the same loads
        /// (start, minimum and end of Q) within the tolerance.
        from_cycle: usize,
    },
    /// Slip has stopped: the dissipation per cycle vanishes.
    Shakedown {
        /// First cycle without dissipation.
        from_cycle: usize,
    },
    /// Still changing.
    NotSettled {
        /// Change of the last cycle against the one before.
        last_change: Option<f64>,
    },
    /// Fewer than one full cycle.
    NoCycles,
}

/// Split the records into cycles (positive extreme to positive extreme) and judge them.
pub fn analyse_cycles(
    records: &[crate::history::StepRecord],
    tolerance: f64,
) -> (Vec<CycleRow>, Verdict) {
    // Positive extremes: last step of a forward phase followed by a reverse phase.
    let maxima: Vec<usize> = (1..records.len().saturating_sub(1))
        .filter(|&i| {
            records[i].regime == crate::history::Regime::ForwardSlip
                && records[i + 1].regime == crate::history::Regime::ReverseSlip
        })
        .chain(
            (records.len() > 1
                && records
                    .last()
                    .is_some_and(|r| r.regime == crate::history::Regime::ForwardSlip))
            // Lazily: with no records `len() − 1` overflows (a panic in a debug build).
            .then(|| records.len() - 1),
        )
        .collect();
    let mut rows: Vec<CycleRow> = Vec::new();
    let load_scale = records.iter().map(|r| r.q.abs()).fold(0.0, f64::max);
    for (k, w) in maxima.windows(2).enumerate() {
        let seg = &records[w[0]..=w[1]];
        let area = seg
            .windows(2)
            .map(|p| 0.5 * (p[0].q + p[1].q) * (p[1].displacement - p[0].displacement))
            .sum();
        let work = seg[1..].iter().map(|r| r.dissipation).sum();
        let normal_work = seg[1..].iter().map(|r| r.normal_work).sum();
        let electric_work = seg[1..].iter().map(|r| r.electric_work).sum();
        let min = seg
            .iter()
            .min_by(|a, b| a.q.total_cmp(&b.q))
            .expect("non-empty");
        let (hi_rec, lo_rec) = (&seg[seg.len() - 1], min);
        let mut row = CycleRow {
            cycle: k + 1,
            steps: (seg[0].step, hi_rec.step),
            loads: (seg[0].q, lo_rec.q, hi_rec.q),
            loop_area: area,
            friction_work: work,
            normal_work,
            electric_work,
            displacement_extremes: (hi_rec.displacement, lo_rec.displacement),
            stick_at_max: (hi_rec.stick_lo, hi_rec.stick_hi),
            stick_at_min: (lo_rec.stick_lo, lo_rec.stick_hi),
            change: None,
            compared_with: None,
        };
        // Compare with the latest earlier cycle under the same loads (start, minimum, end):
        // the previous cycle under constant amplitude, the same cycle one block earlier under
        // a repeated variable-amplitude block.
        let same = |a: (f64, f64, f64), b: (f64, f64, f64)| {
            let tol = 1e-9 * load_scale;
            (a.0 - b.0).abs() <= tol && (a.1 - b.1).abs() <= tol && (a.2 - b.2).abs() <= tol
        };
        if let Some(prev) = rows.iter().rev().find(|r| same(r.loads, row.loads)) {
            let a = hi_rec.half_width;
            let amp = (prev.displacement_extremes.0 - prev.displacement_extremes.1)
                .abs()
                .max(1e-300);
            let energy = prev.loop_area.abs().max(1e-300);
            let d = [
                (row.stick_at_max.0 - prev.stick_at_max.0).abs() / a,
                (row.stick_at_max.1 - prev.stick_at_max.1).abs() / a,
                (row.stick_at_min.0 - prev.stick_at_min.0).abs() / a,
                (row.stick_at_min.1 - prev.stick_at_min.1).abs() / a,
                (row.displacement_extremes.0 - prev.displacement_extremes.0).abs() / amp,
                (row.displacement_extremes.1 - prev.displacement_extremes.1).abs() / amp,
                (row.loop_area - prev.loop_area).abs() / energy,
            ];
            row.change = Some(d.into_iter().fold(0.0, f64::max));
            row.compared_with = Some(prev.cycle);
        }
        rows.push(row);
    }
    let verdict = if rows.is_empty() {
        Verdict::NoCycles
    } else if let Some(r) = rows.iter().find(|r| {
        let amp = (r.displacement_extremes.0 - r.displacement_extremes.1).abs();
        r.loop_area.abs() <= tolerance * amp * load_scale
    }) {
        Verdict::Shakedown {
            from_cycle: r.cycle,
        }
    } else {
        // Steady from cycle k when every later cycle repeats the latest earlier cycle under
        // the same loads (and at least one does).
        let repeats = |r: &CycleRow| r.change.is_some_and(|c| c <= tolerance);
        let first_steady = (1..rows.len())
            .find(|&i| rows[i..].iter().all(repeats))
            .map(|i| rows[i - 1].cycle);
        match first_steady {
            Some(from_cycle) => Verdict::SteadyCyclicSlip { from_cycle },
            None => Verdict::NotSettled {
                last_change: rows.last().and_then(|r| r.change),
            },
        }
    };
    (rows, verdict)
}
