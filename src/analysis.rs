//! The analysis of a tangential history's cycles: each cycle from a positive extreme of Q to
//! the next, its loop area and friction work (the energy dissipated, computed two ways), its
//! regime (partial, gross or no slip) and energy ratio `W/(4Q*δ*)`, and the verdict on
//! whether the cycles settle. Pure computation on the step records; no I/O.

use serde::Serialize;

use crate::history::{Control, StepRecord};

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
    /// Slip stopped: the friction work is below the verdict's tolerance, or below
    /// [`NO_SLIP_FRACTION`] of the first cycle's under the same loads (the discretisation's
    /// floor); [`Verdict::Shakedown`] starts at the first such cycle.
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

/// Split the records of a history under `control` into cycles (positive extreme to positive
/// extreme) and judge them. The history's last record is a positive extreme when it ends a
/// forward phase that returns to where the cycle began ([`Scales::returns_to`]); a stretch
/// after the last cycle is not a row.
pub fn analyse_cycles(
    records: &[StepRecord],
    control: Control,
    tolerance: f64,
) -> (Vec<CycleRow>, Verdict) {
    // Positive extremes: last step of a forward phase followed by a reverse phase.
    let mut scales = Scales::new(control);
    records.iter().for_each(|r| scales.add(r));
    let load_scale = scales.load;
    let mut maxima: Vec<usize> = (1..records.len().saturating_sub(1))
        .filter(|&i| {
            records[i].regime == crate::history::Regime::ForwardSlip
                && records[i + 1].regime == crate::history::Regime::ReverseSlip
        })
        .collect();
    if let [_, .., last] = records
        && last.regime == crate::history::Regime::ForwardSlip
        && maxima
            .last()
            .is_none_or(|&m| scales.returns_to(last, &records[m]))
    {
        maxima.push(records.len() - 1);
    }
    let mut rows: Vec<CycleRow> = Vec::new();
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
    let verdict = judge(&rows, tolerance);
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

/// The friction work of a cycle, as a fraction of that of the first cycle under the same
/// loads, below which the cycle counts as slip-free ([`no_slip`]): above the discretisation's
/// floor. Where the exact contact shakes down (P and Q in phase below the friction ratio,
/// Klarbring, Ciavarella and Barber 2007), the element solver still dissipates a little each
/// cycle: measured 1.1e−3 of the first cycle's work at 10 steps a segment and 2.1e−3 at 40
/// (the third cycle's; the second's 1.5e−3 and 3.0e−3), against 0.43 and more where the
/// contact keeps slipping (test
/// `in_phase_normal_and_tangential_loads_shake_down_below_the_friction_ratio_only` and the
/// coupled one beside it).
pub const NO_SLIP_FRACTION: f64 = 1e-2;

/// Whether a cycle `r` is slip-free: its friction work at most `tolerance` times its δ range
/// times the largest |Q| of the history (`load_scale`), or at most [`NO_SLIP_FRACTION`] of
/// that of `first`, the first earlier cycle under the same loads.
fn no_slip(r: &CycleRow, first: Option<&CycleRow>, load_scale: f64, tolerance: f64) -> bool {
    let amp = (r.displacement_extremes.0 - r.displacement_extremes.1).abs();
    r.friction_work.abs() <= tolerance * amp * load_scale
        || first.is_some_and(|f| {
            f.friction_work.abs() > 0.0
                && r.friction_work.abs() <= NO_SLIP_FRACTION * f.friction_work.abs()
        })
}

/// The first cycle of `earlier` under the loads of `row` ([`same_loads`]).
fn first_alike<'a>(
    earlier: &'a [CycleRow],
    row: &CycleRow,
    load_scale: f64,
) -> Option<&'a CycleRow> {
    earlier
        .iter()
        .find(|r| same_loads(r.loads, row.loads, load_scale))
}

/// The cycles that do not slip ([`no_slip`]): their regime is [`CycleRegime::NoSlip`].
fn mark_no_slip(rows: &mut [CycleRow], load_scale: f64, tolerance: f64) {
    for k in 0..rows.len() {
        let (earlier, rest) = rows.split_at_mut(k);
        let r = &mut rest[0];
        if no_slip(
            r,
            first_alike(earlier, r, load_scale),
            load_scale,
            tolerance,
        ) {
            r.regime = CycleRegime::NoSlip;
        }
    }
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
    /// The largest |Q| and |δ| so far, and what drives the history.
    scales: Scales,
}

/// The largest |Q| and |δ| of the records so far, and the history's control: the scales of
/// the analysis's comparisons.
#[derive(Debug, Clone, Copy, Default)]
struct Scales {
    control: Control,
    load: f64,
    displacement: f64,
}

impl Scales {
    fn new(control: Control) -> Self {
        Self {
            control,
            ..Self::default()
        }
    }

    fn add(&mut self, record: &StepRecord) {
        self.load = f64::max(self.load, record.q.abs());
        self.displacement = f64::max(self.displacement, record.displacement.abs());
    }

    /// Whether the history's last record `last`, at the end of a forward phase, closes the
    /// cycle that began at the positive extreme `start`: the prescribed quantity (Q under load
    /// control, δ under displacement control) reaches the start's, within 1e−9 of its largest
    /// magnitude. A history that ends part of the way up (at Q = 0 after its last reversal,
    /// say) leaves that stretch open, as one that ends in a reverse phase does: not a cycle.
    /// (Under displacement control Q says nothing: on the gross-slip plateau it is back at
    /// ηP long before δ returns.)
    fn returns_to(&self, last: &StepRecord, start: &StepRecord) -> bool {
        match self.control {
            Control::Load => last.q >= start.q - 1e-9 * self.load,
            Control::Displacement => {
                last.displacement >= start.displacement - 1e-9 * self.displacement
            }
        }
    }
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
    /// An analysis of a history under `control`, with no records yet.
    pub fn new(control: Control) -> Self {
        Self {
            scales: Scales::new(control),
            ..Self::default()
        }
    }

    /// Take the next record.
    pub fn push(&mut self, record: &StepRecord) {
        use crate::history::Regime;
        self.scales.add(record);
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
        let (rows, scale) = (&self.rows, self.scales.load);
        let n = rows.len();
        let slip_free = |k: usize| {
            let r = &rows[k].0;
            let first = rows[..k]
                .iter()
                .map(|(f, _)| f)
                .find(|f| same_loads(f.loads, r.loads, scale));
            no_slip(r, first, scale, tolerance)
        };
        if n >= 2 && slip_free(n - 2) && slip_free(n - 1) {
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

    /// The rows and the verdict, the last record closing a cycle when it ends a forward phase
    /// that returns to where the cycle began ([`Scales::returns_to`]).
    pub fn finish(mut self, tolerance: f64) -> (Vec<CycleRow>, Verdict) {
        if let Some(last) = self.previous.take()
            && self.several
            && last.regime == crate::history::Regime::ForwardSlip
            && self
                .open
                .as_ref()
                .is_none_or(|open| self.scales.returns_to(&last, &open.first))
        {
            self.close_at(&last);
        }
        let mut rows: Vec<CycleRow> = Vec::with_capacity(self.rows.len());
        for (mut row, half_width) in self.rows {
            compare_with_earlier(&rows, &mut row, half_width, self.scales.load);
            rows.push(row);
        }
        mark_no_slip(&mut rows, self.scales.load, tolerance);
        let verdict = judge(&rows, tolerance);
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

/// The verdict on the cycles `rows` (compared, [`compare_with_earlier`], and marked,
/// [`mark_no_slip`]): shakedown from the first slip-free cycle.
fn judge(rows: &[CycleRow], tolerance: f64) -> Verdict {
    if rows.is_empty() {
        Verdict::NoCycles
    } else if let Some(r) = rows.iter().find(|r| r.regime == CycleRegime::NoSlip) {
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
    fn scenario_records() -> Vec<(String, Vec<StepRecord>, Control, f64)> {
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
                    s.history.as_ref().map_or(Control::Load, |h| h.control),
                    s.raw.numerics.cycle_tolerance,
                )
            })
            .collect()
    }

    fn incremental(
        records: &[StepRecord],
        control: Control,
        tolerance: f64,
    ) -> (Vec<CycleRow>, Verdict) {
        let mut analysis = CycleAnalysis::new(control);
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
        for (name, records, control, tolerance) in &all {
            let batch = analyse_cycles(records, *control, *tolerance);
            cycles += batch.0.len();
            assert_eq!(
                json(&incremental(records, *control, *tolerance)),
                json(&batch),
                "{name}"
            );
        }
        assert!(cycles >= 20, "{cycles} cycles compared");
        let (_, default, control, tolerance) = all.last().unwrap();
        for n in 0..=default.len() {
            let prefix = &default[..n];
            assert_eq!(
                json(&incremental(prefix, *control, *tolerance)),
                json(&analyse_cycles(prefix, *control, *tolerance)),
                "first {n} records"
            );
        }
    }

    /// A steady Cattaneo–Mindlin cycle (uncoupled ν = 0.5, ±0.5 ηP) run three times and then
    /// loaded part of the way up, to Q = 0: the stretch after the last positive extreme is not
    /// a cycle, so the rows are the two full cycles and the verdict is steady cyclic slip (an
    /// open third row, compared with nothing, left it not settled). Loaded on to +0.5 ηP, the
    /// third cycle closes.
    #[test]
    fn a_history_ending_part_of_the_way_up_leaves_its_last_stretch_out_of_the_cycles() {
        let records = |end: &str| {
            let text = format!(
                r#"{{
                  "name": "open_end",
                  "material": {{ "kind": "elastic", "shear_modulus": 27.3e9, "poisson_ratio": 0.5 }},
                  "punch": {{ "radius": 0.01 }},
                  "friction": 0.3,
                  "normal_load": 2240.0,
                  "tangential_history": {{
                    "unit": "fraction_of_limit",
                    "points": [[0.0, 0.0], [1.0, 0.5], [2.0, -0.5], [3.0, 0.5], [4.0, -0.5],
                               [5.0, 0.5], [6.0, -0.5], {end}],
                    "steps_per_segment": 8
                  }}
                }}"#
            );
            let raw = crate::scenario::parse(&text, std::path::Path::new("open_end")).unwrap();
            let scenario = crate::scenario::validate(raw).unwrap();
            crate::io::solve(&scenario, &mut NoObserver)
                .unwrap()
                .records
        };
        let open = records("[7.0, 0.0]");
        let (rows, verdict) = analyse_cycles(&open, Control::Load, 1e-6);
        assert_eq!(rows.len(), 2);
        let at_5 = open.iter().find(|r| (r.t - 5.0).abs() < 1e-12).unwrap();
        assert_eq!(rows[1].steps.1, at_5.step, "the last row ends at t = 5");
        assert_eq!(verdict, Verdict::SteadyCyclicSlip { from_cycle: 1 });
        assert_eq!(incremental(&open, Control::Load, 1e-6).0.len(), 2);
        let closed = records("[7.0, 0.0], [7.5, 0.5]");
        let (rows, verdict) = analyse_cycles(&closed, Control::Load, 1e-6);
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[2].steps.1, closed.last().unwrap().step);
        assert_eq!(verdict, Verdict::SteadyCyclicSlip { from_cycle: 1 });
    }

    /// Under displacement control a cycle closes when δ returns, not Q: the gross-slip history
    /// of `scenarios/displacement_gross_slip.json` at η = 0.1 (δ_g a third of the amplitude)
    /// ends at δ = 0 on its way up, where Q is already back on the +ηP plateau. Its rows are
    /// the two full cycles, each spanning the whole δ range ±60 nm with an energy ratio below 1
    /// (the trailing stretch, taken as a cycle, spanned half the range with a ratio of 1.35).
    #[test]
    fn under_displacement_control_a_cycle_closes_when_the_displacement_returns() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/displacement_gross_slip.json");
        let text = std::fs::read_to_string(&path)
            .unwrap()
            .replace("\"friction\": 0.3", "\"friction\": 0.1");
        let scenario =
            crate::scenario::validate(crate::scenario::parse(&text, &path).unwrap()).unwrap();
        let records = crate::io::solve(&scenario, &mut NoObserver)
            .unwrap()
            .records;
        let last = records.last().unwrap();
        assert!(last.displacement.abs() < 1e-15 && last.q > 0.999 * 0.1 * 2240.0);
        let (rows, verdict) = analyse_cycles(&records, Control::Displacement, 1e-6);
        assert_eq!(rows.len(), 2);
        for r in &rows {
            let range = r.displacement_extremes.0 - r.displacement_extremes.1;
            assert!((range - 1.2e-7).abs() < 1e-15, "δ range {range}");
            assert_eq!(r.regime, CycleRegime::GrossSlip);
            let ratio = r.energy_ratio.unwrap();
            assert!(ratio > 0.5 && ratio < 1.0, "energy ratio {ratio}");
        }
        assert_eq!(verdict, Verdict::SteadyCyclicSlip { from_cycle: 1 });
        let by_load = analyse_cycles(&records, Control::Load, 1e-6).0;
        assert_eq!(
            by_load.len(),
            3,
            "Q alone takes the trailing stretch for a cycle"
        );
    }
}
