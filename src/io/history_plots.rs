//! The plots of a load history: the fretting loop (Q against δ, and Q against the slip
//! displacement δ − C·Q) and the zones of the contact against time.
//!
//! **The stuck compliance C.** At a load reversal every point of the contact sticks, so the
//! slope dδ/dQ at the start of a phase is the compliance of the stuck contact. C is the least
//! such slope over the reversals of the history (each extrapolated to the reversal by a
//! quadratic through the reversal and the phase's first two steps); a history without a
//! reversal takes the slope at the start of the first loading, found the same way. The
//! first loading's slope is not used when a reversal exists: a coupled contact leaves normal
//! loading with slip zones (b/a < 1) that slip again as soon as Q rises, so that slope holds
//! some slip, and δ − C·Q with it bends back on the unloading branches (measured: 70 % of the
//! slip range for `figure3_history_insulating.json`, 230 % for `figure4_fretting.json`).
//!
//! **The zones.** The records' stick ends are those of the state reached. When a load
//! returns to a stored turning point (Masing memory) the state *is* the stored one, and its
//! stick zone is the zone where |q| < ηp in that state; the points between it and the
//! previous step's stick zone sit at the friction limit without having slipped in the
//! current phase. Such a recalled step (a state equal to an earlier phase's turning state,
//! reached from a different previous step) is drawn as its own shaded wedge, so the reporting rule shows as
//! a band and not as a spike of the stick-end line.

use crate::history::{SolverKind, StepRecord};
use crate::io::svg::{Area, Figure, Series};

/// The slope dδ/dQ at record `i` of the quadratic through records `i`, `j`, `k` (Newton's
/// divided differences); `None` when two of the loads coincide.
fn slope_at(records: &[StepRecord], [i, j, k]: [usize; 3]) -> Option<f64> {
    let (q, d) = (|n: usize| records[n].q, |n: usize| records[n].displacement);
    let dq = |m: usize, n: usize| q(n) - q(m);
    if [dq(i, j), dq(j, k), dq(i, k)]
        .iter()
        .any(|x| x.abs() < f64::MIN_POSITIVE)
    {
        return None;
    }
    let f_ij = (d(j) - d(i)) / dq(i, j);
    let f_jk = (d(k) - d(j)) / dq(j, k);
    let f_ijk = (f_jk - f_ij) / dq(i, k);
    Some(f_ij - f_ijk * dq(i, j))
}

/// Where the stuck compliance C of a history comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ComplianceSource {
    /// The least slope dδ/dQ at a load reversal.
    Reversals,
    /// The slope at the start of the first loading (no reversal in the history).
    FirstLoading,
}

/// The stuck compliance C (m per N/m) of a history and where it comes from (module docs);
/// `None` without two steps of one phase after its start.
pub fn stuck_compliance(records: &[StepRecord]) -> Option<(f64, ComplianceSource)> {
    let n = records.len();
    // Each phase start with the phase's first two steps of the spectral solver (a general
    // step's δ carries its element discretisation error, which the slope would amplify).
    let starts: Vec<[usize; 3]> = (1..n)
        .filter(|&k| records[k].phase != records[k - 1].phase)
        .filter_map(|k| {
            let mut own = (k..n)
                .take_while(|&j| records[j].phase == records[k].phase)
                .filter(|&j| records[j].solver == SolverKind::Spectral);
            Some([k - 1, own.next()?, own.next()?])
        })
        .collect();
    let reversal = starts
        .iter()
        .filter(|&&[k, ..]| records[k].phase > 0)
        .filter_map(|&points| slope_at(records, points))
        .filter(|c| c.is_finite() && *c > 0.0)
        .min_by(f64::total_cmp);
    if let Some(c) = reversal {
        return Some((c, ComplianceSource::Reversals));
    }
    let first = *starts.first()?;
    slope_at(records, first)
        .filter(|c| c.is_finite())
        .map(|c| (c, ComplianceSource::FirstLoading))
}

/// Whether two records hold the same state: load, contact, stick ends and displacement
/// within round-off of their scales.
fn same_state(a: &StepRecord, b: &StepRecord) -> bool {
    let length = 1e-9 * a.half_width.abs().max(b.half_width.abs());
    let close = |x: f64, y: f64, tol: f64| (x - y).abs() <= tol;
    close(
        a.q,
        b.q,
        1e-9 * a.q.abs().max(b.q.abs()).max(f64::MIN_POSITIVE),
    ) && close(a.half_width, b.half_width, length)
        && close(a.eccentricity, b.eccentricity, length)
        && close(a.stick_lo, b.stick_lo, length)
        && close(a.stick_hi, b.stick_hi, length)
        && close(a.displacement, b.displacement, 1e-6 * length)
}

/// For each record, whether it is a recalled state (module docs): equal to a turning state
/// (the last step of an earlier phase) whose previous step differs from this one's previous
/// step. The turning states are kept by load, without repeats, so a long constant-amplitude
/// history costs a few comparisons per step.
pub fn recalled_steps(records: &[StepRecord]) -> Vec<bool> {
    use std::collections::HashMap;
    let n = records.len();
    let q_scale = records
        .iter()
        .map(|r| r.q.abs())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    // Loads in bins of 1e−6 of the largest |Q|; a neighbour bin catches a load at an edge.
    let bin = |q: f64| (q / q_scale * 1e6).round() as i64;
    let mut turning: HashMap<i64, Vec<usize>> = HashMap::new();
    let mut recalled = vec![false; n];
    for k in 1..n {
        let b = bin(records[k].q);
        let matches = |j: usize| {
            same_state(&records[j], &records[k]) && same_state(&records[j - 1], &records[k - 1])
        };
        recalled[k] = (b - 1..=b + 1).any(|b| {
            turning.get(&b).is_some_and(|js| {
                js.iter().any(|&j| {
                    records[j].phase < records[k].phase
                        && same_state(&records[j], &records[k])
                        && !same_state(&records[j - 1], &records[k - 1])
                })
            })
        });
        let last_of_phase = k + 1 == n || records[k + 1].phase != records[k].phase;
        if last_of_phase && records[k].phase > 0 {
            let js = turning.entry(b).or_default();
            if !js.iter().any(|&j| matches(j)) {
                js.push(k);
            }
        }
    }
    recalled
}

/// The loop plots: Q/(ηP) against δ, and against the slip displacement δ − C·Q when C is
/// known. δ in nm.
fn loop_plots(records: &[StepRecord], limit: f64, note: &str) -> Vec<(String, String)> {
    const NM: f64 = 1e9;
    let curve = |c: f64| -> Vec<(f64, f64)> {
        records
            .iter()
            .map(|r| ((r.displacement - c * r.q) * NM, r.q / limit))
            .collect()
    };
    let loop_figure = |title: String, x_label: &str, points, caption: String| Figure {
        title,
        x_label: x_label.into(),
        y_label: "Q/(ηP) (–)".into(),
        series: vec![Series {
            label: "",
            points,
            colour: "black",
        }],
        caption,
        ..Figure::default()
    };
    let mut plots = vec![(
        "hysteresis".to_string(),
        loop_figure(
            format!("Fretting loop{note}"),
            "tangential displacement δ (nm)",
            curve(0.0),
            String::new(),
        )
        .svg(),
    )];
    if let Some((c, source)) = stuck_compliance(records) {
        let from = match source {
            ComplianceSource::Reversals => "the least slope dδ/dQ at a load reversal",
            ComplianceSource::FirstLoading => "the slope dδ/dQ at the start of loading",
        };
        plots.push((
            "hysteresis_slip".to_string(),
            loop_figure(
                format!("Fretting loop, slip displacement{note}"),
                "slip displacement δ − C·Q (nm)",
                curve(c),
                format!("C = {c:.4e} m/(N/m), the stuck compliance: {from}"),
            )
            .svg(),
        ));
    }
    plots
}

/// The zone plot: the contact (grey band), the stick zone of each phase (blue band; a phase
/// after the first starts from the whole contact at its reversal), and the wedges of
/// recalled states (orange; module docs), in units of the step's half-width a, against t.
fn zone_plot(records: &[StepRecord], note: &str) -> String {
    let a = |r: &StepRecord| r.half_width;
    let contact = |r: &StepRecord| (-r.eccentricity - a(r), -r.eccentricity + a(r));
    let stick = |r: &StepRecord| (r.stick_lo / a(r), r.stick_hi / a(r));
    let band = |lower: Vec<(f64, f64)>, upper: Vec<(f64, f64)>| -> Vec<(f64, f64)> {
        lower.into_iter().chain(upper.into_iter().rev()).collect()
    };
    let mut figure = Figure {
        title: format!("Contact and stick zone against time{note}"),
        x_label: "time t (s)".into(),
        y_label: "x/a (–)".into(),
        caption: "a phase's stick zone starts from the whole contact at its reversal; orange: \
            a recalled state's points at the friction limit"
            .into(),
        ..Figure::default()
    };
    let (lo, hi): (Vec<_>, Vec<_>) = records
        .iter()
        .map(|r| {
            let (l, h) = contact(r);
            ((r.t, l / a(r)), (r.t, h / a(r)))
        })
        .unzip();
    figure.areas.push(Area {
        points: band(lo, hi),
        fill: "#999".into(),
        opacity: 0.25,
        label: "contact",
    });
    let recalled = recalled_steps(records);
    let mut k = 1;
    while k < records.len() {
        let phase = records[k].phase;
        let end = (k..records.len())
            .find(|&n| records[n].phase != phase)
            .unwrap_or(records.len());
        // The phase starts at the previous step: the whole contact sticks at a reversal.
        let start = &records[k - 1];
        let (c0, c1) = contact(start);
        let first = if phase > 1 {
            (c0 / a(start), c1 / a(start))
        } else {
            stick(start)
        };
        let mut lower = vec![(start.t, first.0)];
        let mut upper = vec![(start.t, first.1)];
        for n in k..end {
            let (l, h) = stick(&records[n]);
            if recalled[n] {
                let (pl, ph) = stick(&records[n - 1]);
                let t0 = records[n - 1].t;
                let t1 = records[n].t;
                for (from, to) in [(pl, l), (ph, h)] {
                    figure.areas.push(Area {
                        points: vec![(t0, from), (t1, from), (t1, to)],
                        fill: "darkorange".into(),
                        opacity: 0.6,
                        label: "at |q| = ηp, no slip (recalled state)",
                    });
                }
            }
            lower.push((records[n].t, l));
            upper.push((records[n].t, h));
        }
        figure.areas.push(Area {
            points: band(lower, upper),
            fill: "#1f5fb4".into(),
            opacity: 0.45,
            label: "stick zone (|q| < ηp)",
        });
        k = end;
    }
    figure.svg()
}

/// With a history (and at least one step after normal loading): the fretting loops and the
/// zone plot.
pub(crate) fn history_plots(
    records: &[StepRecord],
    limit: f64,
    failed: bool,
) -> Vec<(String, String)> {
    if records.len() <= 1 {
        return Vec::new();
    }
    let note = if failed { " (stopped early)" } else { "" };
    let mut plots = loop_plots(records, limit, note);
    plots.push(("stick_zone".into(), zone_plot(records, note)));
    plots
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::history::{NoObserver, SolverKind};

    fn records_of(scenario: &crate::scenario::Scenario) -> Vec<StepRecord> {
        let solution = crate::io::solve(scenario, &mut NoObserver).unwrap();
        assert!(solution.failure.is_none());
        solution.records
    }

    fn scenario_file(name: &str) -> crate::scenario::Scenario {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios")
            .join(name);
        crate::scenario::load(&path).unwrap()
    }

    /// Within each phase the slip displacement δ − C·Q moves with Q, never against it: the
    /// loop does not bend back. Checked on the coupled contacts where the first loading's
    /// slope made it bend back (by 70 % and 230 % of the slip range), over the steps of the
    /// spectral solver (a general-solver step's δ carries its element discretisation error).
    #[test]
    fn the_slip_displacement_loop_never_bends_back() {
        for name in ["figure3_history_insulating.json", "figure4_fretting.json"] {
            let records = records_of(&scenario_file(name));
            let (c, source) = stuck_compliance(&records).unwrap();
            assert_eq!(source, ComplianceSource::Reversals, "{name}");
            let slip = |r: &StepRecord| r.displacement - c * r.q;
            let range = records.iter().map(slip).fold(f64::NEG_INFINITY, f64::max)
                - records.iter().map(slip).fold(f64::INFINITY, f64::min);
            for w in records.windows(2) {
                let general = w.iter().any(|r| r.solver == SolverKind::General);
                if w[0].phase != w[1].phase || w[1].phase == 0 || general {
                    continue;
                }
                let back = -(slip(&w[1]) - slip(&w[0])) * (w[1].q - w[0].q).signum();
                // Round-off of δ and of the extrapolated slope: 1e-6 of the slip range.
                assert!(
                    back <= 1e-6 * range,
                    "{name}: step {} goes back by {back:e}",
                    w[1].step
                );
            }
        }
    }

    /// A history without a reversal takes C from the start of its loading, exactly for a
    /// quadratic δ(Q).
    #[test]
    fn without_a_reversal_c_is_the_first_loadings_slope() {
        let mut records = records_of(&crate::scenario::default_scenario());
        records.retain(|r| r.phase <= 1);
        for r in &mut records {
            r.displacement = 3e-11 * r.q + 1e-15 * r.q * r.q;
        }
        let (c, source) = stuck_compliance(&records).unwrap();
        assert_eq!(source, ComplianceSource::FirstLoading);
        assert!((c - 3e-11).abs() < 1e-9 * 3e-11, "{c:e}");
    }

    /// The default history returns to −Qmax at steps 70 and 110 in a state recalled from
    /// step 30; the zone plot draws them as orange wedges and no polyline at all.
    #[test]
    fn recalled_turning_states_are_drawn_as_bands() {
        let records = records_of(&crate::scenario::default_scenario());
        let recalled: Vec<usize> = recalled_steps(&records)
            .iter()
            .enumerate()
            .filter_map(|(k, r)| r.then_some(records[k].step))
            .collect();
        assert_eq!(recalled, [70, 110]);
        let svg = zone_plot(&records, "");
        assert_eq!(svg.matches("<polyline").count(), 0);
        let phases = records.last().unwrap().phase;
        // The contact, one stick band per phase, two wedges per recalled step.
        assert_eq!(
            svg.matches(r#"class="area""#).count(),
            1 + phases + 2 * recalled.len()
        );
        assert!(svg.contains(r#"fill="darkorange""#));
        assert!(svg.contains("stick zone (|q| &lt; ηp)"));
        // A long history (the default's records 1000 times over, 130,000 steps, each copy in
        // later phases) costs a few comparisons per step, not one per earlier step.
        let block = &records[1..];
        let phases_per_block = block.last().unwrap().phase;
        let long: Vec<StepRecord> = std::iter::once(records[0].clone())
            .chain((0..1000).flat_map(|copy| {
                block.iter().map(move |r| StepRecord {
                    phase: r.phase + copy * phases_per_block,
                    ..r.clone()
                })
            }))
            .collect();
        let flagged = recalled_steps(&long);
        assert!(flagged[70] && flagged[110] && flagged.len() == 130_001);
        let plots = history_plots(&records, 1.0, false);
        let names: Vec<&str> = plots.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["hysteresis", "hysteresis_slip", "stick_zone"]);
        assert!(
            plots[1]
                .1
                .contains("the least slope dδ/dQ at a load reversal")
        );
    }
}
