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
//! **A long history.** The plots draw every step of a history of at most 2·[`DRAWN_STEPS`]
//! steps; of a longer one, the first and the last [`DRAWN_STEPS`] steps, each cut to whole
//! phases, as two curves (and two sets of bands), and the titles say which steps are drawn. C
//! and the recalled states are found over every step ([`PlotWindow`]).
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

/// The slope dδ/dQ at the first of three records of the quadratic through them (Newton's
/// divided differences); `None` when two of the loads coincide.
fn slope_at([ri, rj, rk]: [&StepRecord; 3]) -> Option<f64> {
    let (q, d) = (|r: &StepRecord| r.q, |r: &StepRecord| r.displacement);
    let dq = |m: &StepRecord, n: &StepRecord| q(n) - q(m);
    if [dq(ri, rj), dq(rj, rk), dq(ri, rk)]
        .iter()
        .any(|x| x.abs() < f64::MIN_POSITIVE)
    {
        return None;
    }
    let f_ij = (d(rj) - d(ri)) / dq(ri, rj);
    let f_jk = (d(rk) - d(rj)) / dq(rj, rk);
    let f_ijk = (f_jk - f_ij) / dq(ri, rk);
    Some(f_ij - f_ijk * dq(ri, rj))
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
#[cfg(test)]
fn stuck_compliance(records: &[StepRecord]) -> Option<(f64, ComplianceSource)> {
    let mut tally = Compliances::default();
    records.iter().for_each(|r| tally.push(r));
    tally.compliance()
}

/// The stuck compliance from the spectral solver's phase starts ([`ComplianceTally`]), or,
/// in a history with none (the general solver took every step, its normal loading included),
/// from the general solver's: its δ then carries the same discretisation error as the loop
/// it is drawn with.
#[derive(Debug, Clone)]
struct Compliances([ComplianceTally; 2]);

impl Default for Compliances {
    fn default() -> Self {
        Self([SolverKind::Spectral, SolverKind::General].map(|kind| ComplianceTally {
            kind,
            ..ComplianceTally::default()
        }))
    }
}

impl Compliances {
    fn push(&mut self, r: &StepRecord) {
        self.0.iter_mut().for_each(|t| t.push(r));
    }

    fn compliance(&self) -> Option<(f64, ComplianceSource)> {
        let [spectral, general] = &self.0;
        if spectral.first.is_some() {
            spectral.compliance()
        } else {
            general.compliance()
        }
    }
}

/// [`stuck_compliance`] as the records arrive: each phase start (the step before the phase,
/// with the phase's first two steps of one solver, `kind`: a general step's δ carries its
/// element discretisation error, which the slope would amplify in a mix), folded into the
/// least slope at a reversal and the slope at the first start.
#[derive(Debug, Clone, Default)]
struct ComplianceTally {
    kind: SolverKind,
    previous: Option<StepRecord>,
    /// The phase start under way: the step before it and its spectral steps so far.
    start: Option<(StepRecord, Vec<StepRecord>)>,
    /// The slope at the first complete start (`Some(None)`: that start has no slope).
    first: Option<Option<f64>>,
    /// The least positive finite slope at a reversal.
    reversal: Option<f64>,
}

impl ComplianceTally {
    fn push(&mut self, r: &StepRecord) {
        if let Some(prev) = self.previous.take()
            && prev.phase != r.phase
        {
            self.start = Some((prev, Vec::new()));
        }
        if r.solver == self.kind
            && let Some((before, own)) = &mut self.start
        {
            own.push(r.clone());
            if let [j, k] = own.as_slice() {
                let slope = slope_at([before, j, k]);
                self.first.get_or_insert(slope);
                if before.phase > 0
                    && let Some(c) = slope.filter(|c| c.is_finite() && *c > 0.0)
                {
                    // The first of equal least slopes, as `Iterator::min_by`.
                    if self.reversal.is_none_or(|m| c.total_cmp(&m).is_lt()) {
                        self.reversal = Some(c);
                    }
                }
                self.start = None;
            }
        }
        self.previous = Some(r.clone());
    }

    fn compliance(&self) -> Option<(f64, ComplianceSource)> {
        if let Some(c) = self.reversal {
            return Some((c, ComplianceSource::Reversals));
        }
        self.first?
            .filter(|c| c.is_finite())
            .map(|c| (c, ComplianceSource::FirstLoading))
    }
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
/// step.
#[cfg(test)]
fn recalled_steps(records: &[StepRecord]) -> Vec<bool> {
    let q_scale = records.iter().map(|r| r.q.abs()).fold(0.0, f64::max);
    let mut tally = RecallTally::new(q_scale);
    records.iter().map(|r| tally.push(r)).collect()
}

/// [`recalled_steps`] as the records arrive. The turning states are kept by load, without
/// repeats, so a long constant-amplitude history costs a few comparisons per step and a few
/// kept states. The loads are binned in 1e−6 of `q_scale` (the largest |Q| of the history, or
/// of its load points), a neighbour bin catching a load at an edge: the bins only narrow the
/// search (two states with equal loads within 1e−9 of |Q| fall in neighbour bins).
#[derive(Debug, Clone)]
struct RecallTally {
    q_scale: f64,
    /// The turning states (with the step before each) by the bin of their load.
    turning: std::collections::HashMap<i64, Vec<(StepRecord, StepRecord)>>,
    /// The last two records, the latest last.
    previous: [Option<StepRecord>; 2],
}

impl RecallTally {
    fn new(q_scale: f64) -> Self {
        Self {
            q_scale: q_scale.max(f64::MIN_POSITIVE),
            turning: Default::default(),
            previous: [None, None],
        }
    }

    fn bin(&self, q: f64) -> i64 {
        (q / self.q_scale * 1e6).round() as i64
    }

    /// Take the next record; whether it is a recalled state.
    fn push(&mut self, r: &StepRecord) -> bool {
        let [before, last] = std::mem::take(&mut self.previous);
        let mut recalled = false;
        if let Some(last) = &last {
            // The last record ends its phase: keep it as a turning state unless it repeats one.
            if let Some(before) = &before
                && last.phase != r.phase
                && last.phase > 0
            {
                let js = self.turning.entry(self.bin(last.q)).or_default();
                if !js
                    .iter()
                    .any(|(jb, j)| same_state(j, last) && same_state(jb, before))
                {
                    js.push((before.clone(), last.clone()));
                }
            }
            let b = self.bin(r.q);
            recalled = (b - 1..=b + 1).any(|b| {
                self.turning.get(&b).is_some_and(|js| {
                    js.iter().any(|(jb, j)| {
                        j.phase < r.phase && same_state(j, r) && !same_state(jb, last)
                    })
                })
            });
        }
        self.previous = [last, Some(r.clone())];
        recalled
    }
}

/// Steps a long history's plots draw at its start, and at its end: a history of at most
/// twice as many steps is drawn whole.
pub(crate) const DRAWN_STEPS: usize = 2048;

/// What the history plots draw, gathered as the records arrive ([`PlotWindow::push`]): every
/// step of a history of at most 2·[`DRAWN_STEPS`] steps; of a longer one, the first and the last
/// [`DRAWN_STEPS`] steps, each cut to whole phases (the steps between are counted, not kept).
/// The stuck compliance and the recalled states are found over every step.
#[derive(Debug, Clone)]
pub(crate) struct PlotWindow {
    head: Vec<(StepRecord, bool)>,
    tail: std::collections::VecDeque<(StepRecord, bool)>,
    /// Steps taken, and steps dropped between the head and the tail.
    taken: usize,
    dropped: usize,
    compliance: Compliances,
    recall: RecallTally,
}

/// A run of consecutive steps drawn, each with whether it is a recalled state.
struct Drawn<'a> {
    records: Vec<&'a StepRecord>,
    recalled: Vec<bool>,
}

impl PlotWindow {
    /// An empty window for a history whose largest |Q| is `q_scale` (N/m).
    pub(crate) fn new(q_scale: f64) -> Self {
        Self {
            head: Vec::new(),
            tail: Default::default(),
            taken: 0,
            dropped: 0,
            compliance: Compliances::default(),
            recall: RecallTally::new(q_scale),
        }
    }

    /// Take the next record.
    pub(crate) fn push(&mut self, r: &StepRecord) {
        self.compliance.push(r);
        let recalled = self.recall.push(r);
        self.taken += 1;
        if self.head.len() < DRAWN_STEPS {
            self.head.push((r.clone(), recalled));
            return;
        }
        if self.tail.len() == DRAWN_STEPS {
            self.tail.pop_front();
            self.dropped += 1;
        }
        self.tail.push_back((r.clone(), recalled));
    }

    /// The records kept (at most 2·[`DRAWN_STEPS`], whatever the history's length).
    pub(crate) fn kept(&self) -> usize {
        self.head.len() + self.tail.len()
    }

    /// The runs of steps drawn: one, or the first and the last cut to whole phases (the head
    /// ends with the last step of a phase, the tail starts with one, the step before its first
    /// whole phase).
    fn drawn(&self) -> Vec<Drawn<'_>> {
        fn run(items: Vec<&(StepRecord, bool)>) -> Drawn<'_> {
            Drawn {
                records: items.iter().map(|&(r, _)| r).collect(),
                recalled: items.iter().map(|&&(_, f)| f).collect(),
            }
        }
        if self.dropped == 0 {
            return vec![run(self.head.iter().chain(&self.tail).collect())];
        }
        let ends_phase = |w: &[&(StepRecord, bool)]| w[0].0.phase != w[1].0.phase;
        let head: Vec<_> = self.head.iter().collect();
        let head_end = head.windows(2).rposition(ends_phase).map_or(head.len(), |k| k + 1);
        let tail: Vec<_> = self.tail.iter().collect();
        let tail_start = tail.windows(2).position(ends_phase).unwrap_or(0);
        vec![
            run(head[..head_end].to_vec()),
            run(tail[tail_start..].to_vec()),
        ]
    }
}

/// The steps drawn, for a title: empty when every step is.
fn drawn_note(drawn: &[Drawn<'_>], taken: usize) -> String {
    if drawn.len() < 2 {
        return String::new();
    }
    let span = |d: &Drawn<'_>| {
        let (first, last) = (d.records[0].step, d.records[d.records.len() - 1].step);
        format!("{first}–{last}")
    };
    format!(
        ", steps {} and {} of {} drawn",
        span(&drawn[0]),
        span(&drawn[1]),
        taken.saturating_sub(1)
    )
}

/// The loop plots: Q/(ηP) against δ, and against the slip displacement δ − C·Q when C is
/// known. δ in nm. A curve per run of steps drawn.
fn loop_plots(
    drawn: &[Drawn<'_>],
    compliance: Option<(f64, ComplianceSource)>,
    limit: f64,
    note: &str,
) -> Vec<(String, String)> {
    const NM: f64 = 1e9;
    const COLOURS: [&str; 2] = ["black", "#d62728"];
    let labels: Vec<String> = if drawn.len() < 2 {
        vec![String::new()]
    } else {
        drawn
            .iter()
            .map(|d| {
                format!(
                    "steps {}–{}",
                    d.records[0].step,
                    d.records[d.records.len() - 1].step
                )
            })
            .collect()
    };
    let curves = |c: f64| -> Vec<Series<'_>> {
        drawn
            .iter()
            .zip(&labels)
            .zip(COLOURS)
            .map(|((d, label), colour)| Series {
                label,
                points: d
                    .records
                    .iter()
                    .map(|r| ((r.displacement - c * r.q) * NM, r.q / limit))
                    .collect(),
                colour,
            })
            .collect()
    };
    let loop_figure = |title: String, x_label: &str, series, caption: String| Figure {
        title,
        x_label: x_label.into(),
        y_label: "Q/(ηP) (–)".into(),
        series,
        caption,
        ..Figure::default()
    };
    let mut plots = vec![(
        "hysteresis".to_string(),
        loop_figure(
            format!("Fretting loop{note}"),
            "tangential displacement δ (nm)",
            curves(0.0),
            String::new(),
        )
        .svg(),
    )];
    if let Some((c, source)) = compliance {
        let from = match source {
            ComplianceSource::Reversals => "the least slope dδ/dQ at a load reversal",
            ComplianceSource::FirstLoading => "the slope dδ/dQ at the start of loading",
        };
        plots.push((
            "hysteresis_slip".to_string(),
            loop_figure(
                format!("Fretting loop, slip displacement{note}"),
                "slip displacement δ − C·Q (nm)",
                curves(c),
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
/// Bands per run of steps drawn.
fn zone_plot(drawn: &[Drawn<'_>], note: &str) -> String {
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
    for run in drawn {
        let (records, recalled) = (&run.records, &run.recalled);
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
        let mut k = 1;
        while k < records.len() {
            let phase = records[k].phase;
            let end = (k..records.len())
                .find(|&n| records[n].phase != phase)
                .unwrap_or(records.len());
            // The phase starts at the previous step: the whole contact sticks at a reversal.
            let start = records[k - 1];
            let (c0, c1) = contact(start);
            let first = if phase > 1 {
                (c0 / a(start), c1 / a(start))
            } else {
                stick(start)
            };
            let mut lower = vec![(start.t, first.0)];
            let mut upper = vec![(start.t, first.1)];
            for n in k..end {
                let (l, h) = stick(records[n]);
                if recalled[n] {
                    let (pl, ph) = stick(records[n - 1]);
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
    }
    figure.svg()
}

/// With a history (and at least one step after normal loading): the fretting loops and the
/// zone plot of the steps `window` drew; the titles say which steps when not all of them.
pub(crate) fn history_plots(
    window: &PlotWindow,
    limit: f64,
    failed: bool,
) -> Vec<(String, String)> {
    if window.taken <= 1 {
        return Vec::new();
    }
    let drawn = window.drawn();
    let note = format!(
        "{}{}",
        drawn_note(&drawn, window.taken),
        if failed { " (stopped early)" } else { "" }
    );
    let mut plots = loop_plots(&drawn, window.compliance.compliance(), limit, &note);
    plots.push(("stick_zone".into(), zone_plot(&drawn, &note)));
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

    /// The plot window of `records`.
    fn window_of(records: &[StepRecord]) -> PlotWindow {
        let q_scale = records.iter().map(|r| r.q.abs()).fold(0.0, f64::max);
        let mut window = PlotWindow::new(q_scale);
        records.iter().for_each(|r| window.push(r));
        window
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
        let window = window_of(&records);
        let svg = zone_plot(&window.drawn(), "");
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
        let plots = history_plots(&window, 1.0, false);
        let names: Vec<&str> = plots.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["hysteresis", "hysteresis_slip", "stick_zone"]);
        assert!(
            plots[1]
                .1
                .contains("the least slope dδ/dQ at a load reversal")
        );
    }
}
