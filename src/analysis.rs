//! The analysis of a tangential history's cycles: each cycle from a positive extreme of Q to
//! the next, its loop area and friction work (the energy dissipated, computed two ways), its
//! regime (partial, gross or no slip) and energy ratio `W/(4Q*δ*)`, and the verdict on
//! whether the cycles settle. Pure computation on the step records; no I/O.

use serde::Serialize;

use crate::history::StepRecord;

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
    /// Partial slip, gross slip or no slip ([`CycleRegime`]).
    pub regime: CycleRegime,
    /// The slip amplitude δ_s (m): half the range over the cycle of the slip displacement
    /// `δ − C·Q`, with C the stuck compliance taken as `Δδ/ΔQ` from the cycle's positive
    /// extreme to its first step that changes Q (right after the extreme every point sticks:
    /// C to first order in the step); `None` when no step of the cycle changes Q.
    pub slip_amplitude: Option<f64>,
    /// The energy ratio of fretting maps, `W/(4Q*δ*)`: the friction work over the rectangle
    /// of the loop's amplitudes `Q* = (Q_max − Q_min)/2` and `δ* = (δ_max − δ_min)/2` (below
    /// about 0.2 partial slip, towards 1 gross slip); `None` for a loop without amplitude.
    pub energy_ratio: Option<f64>,
    /// The largest local slip amplitude δslip(x) over the field grid (m;
    /// [`crate::fatigue`]), which needs the states and not only the records: `None` here, set
    /// by the run from its [`crate::fatigue::FatigueAnalysis`].
    pub max_local_slip: Option<f64>,
}

/// What a cycle's contact did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CycleRegime {
    /// Slip stopped: the friction work is below the verdict's tolerance (as the loop area is
    /// for [`Verdict::Shakedown`]).
    NoSlip,
    /// Some point sticks at every step.
    PartialSlip,
    /// At some step no point sticks: the contact slides as a whole (only a prescribed
    /// displacement reaches it).
    GrossSlip,
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
pub fn analyse_cycles(records: &[StepRecord], tolerance: f64) -> (Vec<CycleRow>, Verdict) {
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
            .reduce(|m, r| if lower(r, m) { r } else { m })
            .expect("non-empty");
        let (hi_rec, lo_rec) = (&seg[seg.len() - 1], min);
        let gross = seg[1..].iter().any(slides);
        let mut slip = SlipRange::default();
        seg.iter().for_each(|r| slip.add(r));
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
            regime: partial_or_gross(gross),
            slip_amplitude: slip.amplitude(),
            energy_ratio: energy_ratio(work, (hi_rec, lo_rec)),
            max_local_slip: None,
        };
        compare_with_earlier(&rows, &mut row, hi_rec.half_width, load_scale);
        rows.push(row);
    }
    mark_no_slip(&mut rows, load_scale, tolerance);
    let verdict = judge(&rows, load_scale, tolerance);
    (rows, verdict)
}

/// The range of the slip displacement `δ − C·Q` over a cycle's records, taken in order
/// (`CycleRow::slip_amplitude`): the first two give C.
#[derive(Debug, Clone, Default)]
struct SlipRange {
    first: Option<(f64, f64)>,
    compliance: Option<f64>,
    range: Option<(f64, f64)>,
}

impl SlipRange {
    fn add(&mut self, r: &StepRecord) {
        let Some((q0, d0)) = self.first else {
            self.first = Some((r.q, r.displacement));
            return;
        };
        if self.compliance.is_none() {
            if r.q - q0 == 0.0 {
                return;
            }
            let c = (r.displacement - d0) / (r.q - q0);
            self.compliance = Some(c);
            let s0 = d0 - c * q0;
            self.range = Some((s0, s0));
        }
        let c = self.compliance.expect("set above");
        let s = r.displacement - c * r.q;
        if let Some((lo, hi)) = self.range.as_mut() {
            *lo = lo.min(s);
            *hi = hi.max(s);
        }
    }

    fn amplitude(&self) -> Option<f64> {
        self.range.map(|(lo, hi)| 0.5 * (hi - lo))
    }
}

/// Whether no point of the record's state sticks while some slips.
fn slides(record: &StepRecord) -> bool {
    record.zones.stick == 0 && record.zones.slip > 0
}

fn partial_or_gross(gross: bool) -> CycleRegime {
    if gross {
        CycleRegime::GrossSlip
    } else {
        CycleRegime::PartialSlip
    }
}

/// `W/(4Q*δ*)` of a cycle with friction work `work` between its extremes (`CycleRow`).
fn energy_ratio(work: f64, (hi, lo): (&StepRecord, &StepRecord)) -> Option<f64> {
    let rectangle = (hi.q - lo.q) * (hi.displacement - lo.displacement);
    (rectangle.abs() > 0.0).then(|| work / rectangle)
}

/// The cycles whose friction work is below the verdict's measure of no slip (the test of
/// [`Verdict::Shakedown`] on the loop area: the two are the same energy over a closed cycle,
/// and the friction work is also that of the last, open, cycle of a history).
fn mark_no_slip(rows: &mut [CycleRow], load_scale: f64, tolerance: f64) {
    for r in rows.iter_mut() {
        let amp = (r.displacement_extremes.0 - r.displacement_extremes.1).abs();
        if r.friction_work.abs() <= tolerance * amp * load_scale {
            r.regime = CycleRegime::NoSlip;
        }
    }
}

/// Whether the cycle dissipates nothing within the tolerance: loop area at most `tolerance`
/// times the δ range times the largest |Q| of the history.
fn settled(r: &CycleRow, load_scale: f64, tolerance: f64) -> bool {
    let amp = (r.displacement_extremes.0 - r.displacement_extremes.1).abs();
    r.loop_area.abs() <= tolerance * amp * load_scale
}

/// Whether `record` is the cycle's negative extreme rather than `min`: its Q is lower, or
/// equal to 1e−12 (a plateau at −ηP in gross slip, which carries the rounding of `∫q`) at a
/// smaller δ (the displacement's turning point).
fn lower(record: &StepRecord, min: &StepRecord) -> bool {
    let tie = 1e-12 * record.q.abs().max(min.q.abs());
    if (record.q - min.q).abs() <= tie {
        record.displacement < min.displacement
    } else {
        record.q < min.q
    }
}

/// [`analyse_cycles`] as the records arrive, holding the cycle under way and not the records:
/// [`CycleAnalysis::push`] each record in order, then [`CycleAnalysis::finish`]. Its rows and
/// verdict are those of [`analyse_cycles`] on the same records, to the bit (the sums are taken
/// in the same order). The cycles are compared at the end, when the largest |Q| of the history
/// (the scale of the comparison) is known; a row is kept per cycle (`cycles.csv`).
#[derive(Debug, Clone, Default)]
pub struct CycleAnalysis {
    /// The cycles closed so far, with a at each one's positive extreme.
    rows: Vec<(CycleRow, f64)>,
    /// The previous record.
    previous: Option<StepRecord>,
    /// Whether any record came after the first.
    several: bool,
    /// The cycle under way, from the last positive extreme.
    open: Option<OpenCycle>,
    /// The largest |Q| so far.
    load_scale: f64,
}

/// A cycle under way: its first record, the sums so far and its least Q.
#[derive(Debug, Clone)]
struct OpenCycle {
    first: StepRecord,
    area: f64,
    work: f64,
    normal_work: f64,
    electric_work: f64,
    min: StepRecord,
    /// Whether the contact slid as a whole at some step.
    gross: bool,
    /// The range of the slip displacement.
    slip: SlipRange,
}

impl OpenCycle {
    fn new(first: StepRecord) -> Self {
        // The sums start where `Iterator::sum` does.
        let zero = std::iter::empty::<f64>().sum();
        Self {
            min: first.clone(),
            first,
            area: zero,
            work: zero,
            normal_work: zero,
            electric_work: zero,
            gross: false,
            slip: SlipRange::default(),
        }
        .starting_at()
    }

    /// The slip range begins at the first record.
    fn starting_at(mut self) -> Self {
        self.slip.add(&self.first);
        self
    }

    /// Add the step from `previous` to `record`.
    fn add(&mut self, previous: &StepRecord, record: &StepRecord) {
        self.area += 0.5 * (previous.q + record.q) * (record.displacement - previous.displacement);
        self.work += record.dissipation;
        self.normal_work += record.normal_work;
        self.electric_work += record.electric_work;
        if lower(record, &self.min) {
            self.min = record.clone();
        }
        self.gross |= slides(record);
        self.slip.add(record);
    }

    /// The row of the cycle ending at `last`, numbered `cycle`.
    fn close(self, cycle: usize, last: &StepRecord) -> CycleRow {
        let (hi_rec, lo_rec) = (last, &self.min);
        CycleRow {
            cycle,
            steps: (self.first.step, hi_rec.step),
            loads: (self.first.q, lo_rec.q, hi_rec.q),
            loop_area: self.area,
            friction_work: self.work,
            normal_work: self.normal_work,
            electric_work: self.electric_work,
            displacement_extremes: (hi_rec.displacement, lo_rec.displacement),
            stick_at_max: (hi_rec.stick_lo, hi_rec.stick_hi),
            stick_at_min: (lo_rec.stick_lo, lo_rec.stick_hi),
            change: None,
            compared_with: None,
            regime: partial_or_gross(self.gross),
            slip_amplitude: self.slip.amplitude(),
            energy_ratio: energy_ratio(self.work, (hi_rec, lo_rec)),
            max_local_slip: None,
        }
    }
}

impl CycleAnalysis {
    /// An analysis with no records yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Take the next record.
    pub fn push(&mut self, record: &StepRecord) {
        use crate::history::Regime;
        self.load_scale = f64::max(self.load_scale, record.q.abs());
        if let Some(previous) = self.previous.take() {
            // The previous record is a positive extreme when a reverse phase follows its
            // forward phase (record 0, the end of normal loading, never is).
            if self.several
                && previous.regime == Regime::ForwardSlip
                && record.regime == Regime::ReverseSlip
            {
                self.close_at(&previous);
            }
            if let Some(open) = &mut self.open {
                open.add(&previous, record);
            }
            self.several = true;
        }
        self.previous = Some(record.clone());
    }

    /// Close the cycle under way (if any) at the positive extreme `extreme`, and open the next.
    fn close_at(&mut self, extreme: &StepRecord) {
        if let Some(open) = self.open.take() {
            let row = open.close(self.rows.len() + 1, extreme);
            self.rows.push((row, extreme.half_width));
        }
        self.open = Some(OpenCycle::new(extreme.clone()));
    }

    /// The cycles so far.
    pub fn cycle_count(&self) -> usize {
        self.rows.len()
    }

    /// Whether the cycles closed so far have settled, by the rules of the verdict with the
    /// largest |Q| so far as its scale: the last two cycles slip no more than the tolerance
    /// (no slip: shakedown), or the cycles at the end each repeat the latest earlier cycle
    /// under the same loads within the tolerance, over at least one period (the cycles from
    /// the one the last cycle repeats to the last: one under constant amplitude, a block
    /// under a repeated variable-amplitude block). A run may stop there
    /// (`numerics.stop_when_settled`).
    pub fn settled(&self, tolerance: f64) -> bool {
        let (rows, scale) = (&self.rows, self.load_scale);
        let n = rows.len();
        let no_slip = |r: &CycleRow| {
            let amp = (r.displacement_extremes.0 - r.displacement_extremes.1).abs();
            r.friction_work.abs() <= tolerance * amp * scale
        };
        if n >= 2 && rows[n - 2..].iter().all(|(r, _)| no_slip(r)) {
            return true;
        }
        let mut repeating = 0;
        let mut period = 0;
        for k in (0..n).rev() {
            let (row, half_width) = &rows[k];
            let Some(j) = (0..k)
                .rev()
                .find(|&j| same_loads(rows[j].0.loads, row.loads, scale))
            else {
                break;
            };
            if change_against(&rows[j].0, row, *half_width) > tolerance {
                break;
            }
            if k + 1 == n {
                period = k - j;
            }
            repeating += 1;
        }
        repeating > 0 && repeating >= period
    }

    /// The rows and the verdict, the last record closing a cycle when it ends a forward phase.
    pub fn finish(mut self, tolerance: f64) -> (Vec<CycleRow>, Verdict) {
        if let Some(last) = self.previous.take()
            && self.several
            && last.regime == crate::history::Regime::ForwardSlip
        {
            self.close_at(&last);
        }
        let mut rows: Vec<CycleRow> = Vec::with_capacity(self.rows.len());
        for (mut row, half_width) in self.rows {
            compare_with_earlier(&rows, &mut row, half_width, self.load_scale);
            rows.push(row);
        }
        mark_no_slip(&mut rows, self.load_scale, tolerance);
        let verdict = judge(&rows, self.load_scale, tolerance);
        (rows, verdict)
    }
}

/// Compare `row` with the latest earlier cycle of `rows` under the same loads (start, minimum,
/// end of Q, within 1e−9 of `load_scale`): the previous cycle under constant amplitude, the same
/// cycle one block earlier under a repeated variable-amplitude block. `half_width` is a at the
/// cycle's positive extreme (the scale of the stick ends).
fn compare_with_earlier(rows: &[CycleRow], row: &mut CycleRow, half_width: f64, load_scale: f64) {
    if let Some(prev) = rows
        .iter()
        .rev()
        .find(|r| same_loads(r.loads, row.loads, load_scale))
    {
        row.change = Some(change_against(prev, row, half_width));
        row.compared_with = Some(prev.cycle);
    }
}

/// Whether two cycles have the same loads (start, minimum, end of Q) within 1e−9 of
/// `load_scale`.
fn same_loads(a: (f64, f64, f64), b: (f64, f64, f64), load_scale: f64) -> bool {
    let tol = 1e-9 * load_scale;
    (a.0 - b.0).abs() <= tol && (a.1 - b.1).abs() <= tol && (a.2 - b.2).abs() <= tol
}

/// The largest change of `row` against `prev`: stick ends relative to `half_width`, δ at the
/// extremes relative to the δ range of `prev`, the loop area relative to that of `prev`.
fn change_against(prev: &CycleRow, row: &CycleRow, half_width: f64) -> f64 {
    let a = half_width;
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
    d.into_iter().fold(0.0, f64::max)
}

/// The verdict on the cycles `rows` (compared, [`compare_with_earlier`]), with `load_scale`
/// the largest |Q| of the history.
fn judge(rows: &[CycleRow], load_scale: f64, tolerance: f64) -> Verdict {
    if rows.is_empty() {
        Verdict::NoCycles
    } else if let Some(r) = rows.iter().find(|r| settled(r, load_scale, tolerance)) {
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
            // The last cycle compared (the history's last cycle may be open, and is not).
            None => Verdict::NotSettled {
                last_change: rows.iter().rev().find_map(|r| r.change),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::history::NoObserver;

    /// The records of every scenario in `scenarios/` with a history, and of the default one.
    fn scenario_records() -> Vec<(String, Vec<StepRecord>, f64)> {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
        let mut paths: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        paths.sort();
        let scenarios = paths
            .into_iter()
            .map(|p| crate::scenario::load(&p).unwrap())
            .chain([crate::scenario::default_scenario()]);
        scenarios
            .filter(|s| s.history.is_some())
            .map(|s| {
                let solution = crate::io::solve(&s, &mut NoObserver).unwrap();
                (
                    s.name.clone(),
                    solution.records,
                    s.raw.numerics.cycle_tolerance,
                )
            })
            .collect()
    }

    fn incremental(records: &[StepRecord], tolerance: f64) -> (Vec<CycleRow>, Verdict) {
        let mut analysis = CycleAnalysis::new();
        records.iter().for_each(|r| analysis.push(r));
        analysis.finish(tolerance)
    }

    /// The cycle analysis taken as the records arrive gives the rows and the verdict of
    /// [`analyse_cycles`] to the bit (compared as JSON, which writes floats exactly), on every
    /// scenario's records (constant and variable amplitude, a partial unloading) and on every
    /// prefix of the default run's (a history stopped at any step).
    #[test]
    fn the_incremental_analysis_gives_the_batch_rows_and_verdict() {
        let json = |x: &(Vec<CycleRow>, Verdict)| serde_json::to_string(x).unwrap();
        let all = scenario_records();
        let mut cycles = 0;
        for (name, records, tolerance) in &all {
            let batch = analyse_cycles(records, *tolerance);
            cycles += batch.0.len();
            assert_eq!(
                json(&incremental(records, *tolerance)),
                json(&batch),
                "{name}"
            );
        }
        assert!(cycles >= 20, "{cycles} cycles compared");
        let (_, default, tolerance) = all.last().unwrap();
        for n in 0..=default.len() {
            let prefix = &default[..n];
            assert_eq!(
                json(&incremental(prefix, *tolerance)),
                json(&analyse_cycles(prefix, *tolerance)),
                "first {n} records"
            );
        }
    }
}
