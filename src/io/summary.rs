//! `summary.json`: the derived constants, the normal-loading state, the history's results and
//! the solver's work counters, as serialisable data.

use std::collections::{BTreeMap, VecDeque};

use serde::Serialize;

use crate::analysis::{CycleRow, Verdict};
use crate::contact::ContactModel;
use crate::contact::normal::NormalLoading;
use crate::halfplane::{PaperCoefficients, SurfaceCompliance, SurfaceFieldCoefficients};
use crate::history::{Loading, NormalEnd, ZoneCount};
use crate::history::{SolverKind, StepRecord};
use crate::scenario::{RawScenario, Scenario};

/// Constants derived from the material, reported in `summary.json`.
#[derive(Debug, Serialize)]
pub struct Derived {
    /// Surface compliance coefficients (fretsim's convention).
    pub compliance: SurfaceCompliance,
    /// The same in the paper's convention (Appendix A.2).
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
    /// The true gap just outside the contact ends.
    pub outside_gap: crate::contact::GapReport,
    /// Charge carried by the pressure, Γ1 = kP (C/m).
    pub pressure_charge: f64,
    /// q/(ηp) in the right slip zone: +1 when the friction points outward, −1 inward (which
    /// happens below Γ1 for a conducting punch); 0 without slip zones. Of a general solver's
    /// state: in the slip zone right of its longest stick zone.
    pub right_slip_sign: f64,
    /// The solver that gave the state: `spectral` (Spence's self-similar state) or `general`
    /// (loaded by steps where the spectral form holds no state; `history::NormalEnd`).
    pub solver: SolverKind,
    /// The zone structure of the state.
    pub zones: ZoneCount,
    /// Load steps of the general solver's loading (0 for the spectral solver's state).
    pub load_steps: usize,
    /// Why the spectral solver gave no state, when the general solver did.
    pub spectral_failure: Option<String>,
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
    /// The inputs as the solver used them.
    pub resolved: Resolved,
    /// Normal-loading results.
    pub normal_loading: NormalSummary,
    /// Tangential history results (absent without a history).
    pub history: Option<HistorySummary>,
    /// The field snapshots written at the requested times.
    pub snapshots: Vec<SnapshotSummary>,
    /// Work counters and checks.
    pub solver: SolverStatistics,
    /// The fretting-fatigue indicators of the last complete cycle (absent without a history
    /// or without a complete cycle).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fatigue: Option<crate::io::fatigue::FatigueSummary>,
    /// Warnings.
    pub warnings: Vec<String>,
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

pub(crate) fn normal_summary(model: &ContactModel, normal: &NormalEnd) -> NormalSummary {
    match normal {
        NormalEnd::Spectral(n) => spectral_normal_summary(model, n),
        NormalEnd::General(run, loading) => general_normal_summary(model, run, loading),
    }
}

pub(crate) fn spectral_normal_summary(model: &ContactModel, n: &NormalLoading) -> NormalSummary {
    let s = &n.state;
    let w_total = s.potential_charge_force();
    NormalSummary {
        half_width: s.half_width,
        eccentricity: -s.centre,
        stick_half_width: n.stick_half_width,
        stick_ratio: n.stick_half_width / s.half_width,
        strain_slope: n.strain_slope,
        peak_pressure: s.pressure_at(s.centre),
        charge: s.charge,
        potential: s.potential,
        pressure_resultant: s.pressure_force(),
        // The inverse-square-root part integrates exactly from its series; the rest by quadrature.
        charge_resultant: s.split.ratio * s.pressure_force() + w_total,
        iterations: n.iterations,
        admissibility: n.admissibility,
        outside_gap: model.outside_gap(s),
        pressure_charge: model.pressure_charge(s.normal_load),
        right_slip_sign: s.traction.right_sign,
        solver: SolverKind::Spectral,
        zones: ZoneCount::of_spectral(s),
        load_steps: 0,
        spectral_failure: None,
    }
}

/// The summary of a general solver's normal loading: the contact ends are the outer edges of
/// its contact elements, the stick zone its longest run of stuck elements, the checks those of
/// its steps (`history::general`), and the gap the element mean gap outside the contact.
fn general_normal_summary(
    model: &ContactModel,
    run: &crate::history::GeneralRun,
    loading: &Loading,
) -> NormalSummary {
    let s = &run.state;
    let rec = run.record(0, 0.0, crate::history::Regime::NormalLoading, None);
    let (pressure_resultant, _, charge_resultant) = s.resultants();
    let a = rec.half_width;
    let stick_half_width = 0.5 * (rec.stick_hi - rec.stick_lo);
    let check = rec.admissibility;
    let conducting = matches!(
        model.electrode,
        crate::contact::Electrode::ConductingCharge { .. }
            | crate::contact::Electrode::ConductingPotential { .. }
    );
    NormalSummary {
        half_width: a,
        eccentricity: rec.eccentricity,
        stick_half_width,
        stick_ratio: stick_half_width / a,
        strain_slope: crate::history::locked_in_strain_slope(s),
        peak_pressure: s.pressure.iter().copied().fold(0.0, f64::max),
        charge: charge_resultant,
        potential: conducting.then_some(s.potential),
        pressure_resultant,
        charge_resultant,
        iterations: loading.iterations,
        admissibility: crate::contact::normal::Admissibility {
            stick_excess: check.stick_excess,
            stick_excess_at: check.worst_at[0],
            slip_reversal: check.slip_reversal,
            slip_reversal_at: check.worst_at[1],
            min_pressure: check.min_pressure,
        },
        outside_gap: outside_gap(model, run, (-rec.eccentricity, a)),
        pressure_charge: model.pressure_charge(s.loads.normal),
        right_slip_sign: rec.right_slip_sign,
        solver: SolverKind::General,
        zones: ZoneCount::of_elements(s),
        load_steps: loading.steps,
        spectral_failure: Some(loading.spectral_failure.clone()),
    }
}

/// The smallest element mean gap within one half-width outside either end of an element
/// state's contact `(c, a)`.
fn outside_gap(
    model: &ContactModel,
    run: &crate::history::GeneralRun,
    (c, a): (f64, f64),
) -> crate::contact::GapReport {
    let s = &run.state;
    let gaps = run.solver().gaps(s);
    let mut report = crate::contact::GapReport {
        min_gap: f64::INFINITY,
        at: c + a,
        scale: model.profile.gap(a),
    };
    for (i, &gap) in gaps.iter().enumerate() {
        let x = s.mesh.centre(i);
        let outside = ((x - c).abs() - a) / a;
        if outside > 0.0 && outside <= 1.0 && gap < report.min_gap {
            report.min_gap = gap;
            report.at = x;
        }
    }
    report
}

/// Summary of the tangential history, in `summary.json`.
#[derive(Debug, Serialize)]
pub struct HistorySummary {
    /// Number of accepted steps after normal loading.
    pub steps: usize,
    /// Number of phases (monotonic segments between reversals).
    pub phases: usize,
    /// The states at the end of each phase (step, Q, stick ends, eccentricity): the first
    /// and the last [`LISTED`] of them (all of them in a run of at most 2·`LISTED`).
    pub turning_points: Vec<crate::history::StepRecord>,
    /// How many turning points the history has.
    pub turning_point_count: usize,
    /// The failure, if the run stopped early.
    pub failure: Option<String>,
    /// The cycles: the first and the last [`LISTED`] (`cycles.csv` has every one).
    pub cycles: Vec<CycleRow>,
    /// How many cycles the history has.
    pub cycle_count: usize,
    /// Shakedown verdict.
    pub verdict: Verdict,
    /// Tolerance of the verdict (relative).
    pub verdict_tolerance: f64,
    /// Whether the run ended early, at the first turning point where the cycles had settled
    /// (`numerics.stop_when_settled`).
    pub stopped_when_settled: bool,
}

/// Inputs as the solver used them: a preset resolved to its constants, and the load history
/// in N/m with the cycle block expanded and the snapshot points added.
#[derive(Debug, Serialize)]
pub struct Resolved {
    /// Material constants.
    pub material: crate::material::Material,
    /// The load history (absent without one).
    pub load_history: Option<crate::history::LoadHistory>,
}

/// Work counters and checks of the whole run, in `summary.json`.
#[derive(Debug, Serialize)]
pub struct SolverStatistics {
    /// Collocation nodes M per interval.
    pub collocation_points: usize,
    /// Block iterations of the normal-loading solve.
    pub normal_loading_iterations: usize,
    /// Accepted load steps after normal loading.
    pub history_steps: usize,
    /// Newton iterations summed over the history (`newton_iterations` in `steps.csv`).
    pub newton_iterations: usize,
    /// Most Newton iterations in one step.
    pub max_newton_iterations: usize,
    /// Residual evaluations summed over the history (`evaluations` in `steps.csv`).
    pub residual_evaluations: usize,
    /// Largest final residual of a step of the spectral solver.
    pub max_residual: Option<f64>,
    /// History steps taken by the general element solver (`solver` in `steps.csv`; the end of
    /// normal loading, step 0, is not counted: see `normal_loading.solver`).
    pub general_steps: usize,
    /// The steps at which the general solver took over, with the reason the spectral solver
    /// could not take each: the first and the last [`LISTED`].
    pub handovers: Vec<Handover>,
    /// How many times the general solver took over.
    pub handover_count: usize,
    /// How many handovers each kind of reason caused (the reason with its numbers written
    /// `#`; at most [`REASON_KINDS`] kinds, the rest counted under `other`).
    pub handover_reasons: BTreeMap<String, usize>,
    /// Worst `stick_excess` of a step (≤ 0 when admissible).
    pub worst_stick_excess: Option<f64>,
    /// Worst `slip_reversal` of a step (≤ 0 when admissible).
    pub worst_slip_reversal: Option<f64>,
}

/// How many items of a list that grows with the history (turning points, cycles, handovers)
/// `summary.json` lists at its start and at its end: a long history's summary stays a
/// summary (`steps.csv` and `cycles.csv` have every step and cycle).
pub const LISTED: usize = 25;

/// Kinds of handover reason counted apart in [`SolverStatistics::handover_reasons`].
pub const REASON_KINDS: usize = 32;

/// The first and the last [`LISTED`] items of `items`, in order.
fn first_and_last<T: Clone>(items: &[T]) -> Vec<T> {
    if items.len() <= 2 * LISTED {
        return items.to_vec();
    }
    items[..LISTED]
        .iter()
        .chain(&items[items.len() - LISTED..])
        .cloned()
        .collect()
}

/// The handovers of a run as it goes: how many, how many of each kind of reason, and the first
/// and the last [`LISTED`] in full. Its size does not grow with the history (it is written into
/// every checkpoint).
#[derive(Debug, Clone, Default, Serialize, serde::Deserialize)]
pub struct HandoverLog {
    #[serde(flatten)]
    listed: Listed<Handover>,
    reasons: BTreeMap<String, usize>,
}

impl HandoverLog {
    /// Log a handover.
    pub fn push(&mut self, handover: Handover) {
        let kind = reason_kind(&handover.reason);
        let key = if self.reasons.contains_key(&kind) || self.reasons.len() < REASON_KINDS {
            kind
        } else {
            "other".to_string()
        };
        *self.reasons.entry(key).or_insert(0) += 1;
        self.listed.push(handover);
    }
}

/// A reason with each number (a run of digits, signs, points and exponent letters holding a
/// digit) written `#`: "finds 2 stick and 3 slip zones" → "finds # stick and # slip zones".
fn reason_kind(reason: &str) -> String {
    let numeric = |c: char| c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '+' | '-');
    let mut out = String::with_capacity(reason.len());
    let mut run = String::new();
    let flush = |run: &mut String, out: &mut String| {
        if run.chars().any(|c| c.is_ascii_digit()) {
            out.push('#');
        } else {
            out.push_str(run);
        }
        run.clear();
    };
    for c in reason.chars() {
        if numeric(c) {
            run.push(c);
        } else {
            flush(&mut run, &mut out);
            out.push(c);
        }
    }
    flush(&mut run, &mut out);
    out
}

/// A step that the spectral solver could not take, taken by the general solver.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct Handover {
    /// Step number.
    pub step: usize,
    /// Time (s).
    pub t: f64,
    /// Tangential load Q (N/m).
    pub q: f64,
    /// Why the spectral solver could not take it.
    pub reason: String,
}

/// A field snapshot at a requested time, in `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct SnapshotSummary {
    /// Requested time (s), from `output.snapshots`.
    pub t: f64,
    /// The field file, relative to the output folder.
    pub file: String,
    /// The step solved at that time.
    pub step: usize,
    /// Time of that step (s); equals `t` within the scenario's time tolerance.
    pub step_t: f64,
    /// Tangential load Q (N/m).
    pub q: f64,
    /// Q/(ηP).
    pub q_over_limit: f64,
    /// Regime of the step.
    pub regime: crate::history::Regime,
    /// Phase of the step.
    pub phase: usize,
    /// Contact half-width a (m).
    pub half_width: f64,
    /// Eccentricity e = −c (m).
    pub eccentricity: f64,
    /// Stick-zone left end (m).
    pub stick_lo: f64,
    /// Stick-zone right end (m).
    pub stick_hi: f64,
}

/// The first and the last [`LISTED`] items of a list as it grows, and how many it has: the
/// items [`first_and_last`] keeps of the whole list.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub(crate) struct Listed<T> {
    count: usize,
    first: Vec<T>,
    last: VecDeque<T>,
}

impl<T> Default for Listed<T> {
    fn default() -> Self {
        Self {
            count: 0,
            first: Vec::new(),
            last: VecDeque::new(),
        }
    }
}

impl<T> Listed<T> {
    /// Add an item at the end.
    pub(crate) fn push(&mut self, item: T) {
        self.count += 1;
        if self.first.len() < LISTED {
            self.first.push(item);
        } else {
            if self.last.len() == LISTED {
                self.last.pop_front();
            }
            self.last.push_back(item);
        }
    }

    /// The items kept, in order.
    fn into_items(self) -> Vec<T> {
        self.first.into_iter().chain(self.last).collect()
    }
}

/// What `summary.json` and the warnings take from the step records, counted as they arrive
/// ([`RecordTally::push`] each record in order, step 0 first): the number of steps, the last
/// record, the turning points (the last step of each phase after the first loading began),
/// the work counters and the worst checks, and the steps the spectral solver accepted at a
/// stalled residual. Its size does not grow with the history.
#[derive(Debug, Clone, Default)]
pub(crate) struct RecordTally {
    records: usize,
    last: Option<StepRecord>,
    turning_points: Listed<StepRecord>,
    newton_iterations: usize,
    max_newton_iterations: usize,
    residual_evaluations: usize,
    max_residual: Option<f64>,
    general_steps: usize,
    worst_stick_excess: Option<f64>,
    worst_slip_reversal: Option<f64>,
    /// Steps of the spectral solver with a residual at or above `stall`, and the worst one.
    stalled: usize,
    worst_stalled: Option<StepRecord>,
    stall: f64,
}

impl RecordTally {
    /// A tally that counts as stalled the spectral steps with a residual of at least `stall`.
    pub(crate) fn new(stall: f64) -> Self {
        Self {
            stall,
            ..Self::default()
        }
    }

    /// Take the next record.
    pub(crate) fn push(&mut self, r: &StepRecord) {
        // The largest finite value of a step after normal loading.
        fn worst(acc: &mut Option<f64>, x: f64) {
            if x.is_finite() {
                *acc = Some(acc.map_or(x, |a| f64::max(a, x)));
            }
        }
        if let Some(prev) = &self.last
            && prev.phase != r.phase
            && prev.phase > 0
        {
            self.turning_points.push(prev.clone());
        }
        if self.records > 0 {
            self.newton_iterations += r.iterations;
            self.max_newton_iterations = self.max_newton_iterations.max(r.iterations);
            self.residual_evaluations += r.newton_iterations;
            if r.solver == SolverKind::Spectral {
                worst(&mut self.max_residual, r.residual);
            }
            worst(&mut self.worst_stick_excess, r.admissibility.stick_excess);
            worst(&mut self.worst_slip_reversal, r.admissibility.slip_reversal);
        }
        if r.solver == SolverKind::General && r.step > 0 {
            self.general_steps += 1;
        }
        if r.solver == SolverKind::Spectral && r.residual >= self.stall {
            self.stalled += 1;
            // The last of equal worst residuals, as `Iterator::max_by`.
            if self
                .worst_stalled
                .as_ref()
                .is_none_or(|w| r.residual.total_cmp(&w.residual).is_ge())
            {
                self.worst_stalled = Some(r.clone());
            }
        }
        self.records += 1;
        self.last = Some(r.clone());
    }

    /// The last record taken.
    pub(crate) fn last(&self) -> Option<&StepRecord> {
        self.last.as_ref()
    }

    /// How many spectral steps stalled, and the worst of them.
    pub(crate) fn stalled(&self) -> (usize, Option<&StepRecord>) {
        (self.stalled, self.worst_stalled.as_ref())
    }
}

pub(crate) fn solver_statistics(
    scenario: &Scenario,
    normal: &NormalEnd,
    tally: &RecordTally,
    handovers: HandoverLog,
) -> SolverStatistics {
    SolverStatistics {
        collocation_points: scenario.collocation_points,
        normal_loading_iterations: match normal {
            NormalEnd::Spectral(n) => n.iterations,
            NormalEnd::General(_, loading) => loading.iterations,
        },
        history_steps: tally.records.saturating_sub(1),
        newton_iterations: tally.newton_iterations,
        max_newton_iterations: tally.max_newton_iterations,
        residual_evaluations: tally.residual_evaluations,
        max_residual: tally.max_residual,
        general_steps: tally.general_steps,
        handover_count: handovers.listed.count,
        handovers: handovers.listed.into_items(),
        handover_reasons: handovers.reasons,
        worst_stick_excess: tally.worst_stick_excess,
        worst_slip_reversal: tally.worst_slip_reversal,
    }
}

/// The history's part of the summary: its steps and phases, the turning points (the last step
/// of each phase, and the last step), the failure if the history stopped, the cycles and the
/// verdict.
pub(crate) fn history_summary(
    tally: &RecordTally,
    failure: Option<&crate::error::Error>,
    cycles: &[CycleRow],
    verdict: Verdict,
    tolerance: f64,
) -> HistorySummary {
    let mut turning_points = tally.turning_points.clone();
    if let Some(last) = tally.last.as_ref().filter(|r| r.phase > 0) {
        turning_points.push(last.clone());
    }
    HistorySummary {
        steps: tally.records.saturating_sub(1),
        phases: tally.last.as_ref().map_or(0, |r| r.phase),
        turning_point_count: turning_points.count,
        turning_points: turning_points.into_items(),
        failure: failure.map(|e| e.to_string()),
        cycles: first_and_last(cycles),
        cycle_count: cycles.len(),
        verdict,
        verdict_tolerance: tolerance,
        stopped_when_settled: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn handover(step: usize, reason: &str) -> Handover {
        Handover {
            step,
            t: step as f64,
            q: 0.0,
            reason: reason.to_string(),
        }
    }

    /// A reason's kind writes its numbers `#` and keeps its words.
    #[test]
    fn a_reason_kind_writes_the_numbers_as_hashes() {
        assert_eq!(
            reason_kind(
                "the general solver finds 2 stick and 3 slip zones (1 slip sign changes) where \
                 the spectral solver's state has 1 and 2"
            ),
            "the general solver finds # stick and # slip zones (# slip sign changes) where \
             the spectral solver's state has # and #"
        );
        assert_eq!(
            reason_kind("worst violation 1.041e1 at x = -4.536959e-5 m; the end"),
            "worst violation # at x = # m; the end"
        );
    }

    /// The log of 2·LISTED + 5 handovers keeps the count, the first and the last LISTED,
    /// and the reasons' counts; beyond `REASON_KINDS` kinds the rest go under `other`.
    #[test]
    fn the_handover_log_keeps_the_first_and_the_last_and_counts_the_rest() {
        let mut log = HandoverLog::default();
        let n = 2 * LISTED + 5;
        for step in 0..n {
            log.push(handover(step, &format!("residual {step}e-3 stalled")));
        }
        assert_eq!(log.listed.count, n);
        let listed: Vec<usize> = log
            .listed
            .clone()
            .into_items()
            .iter()
            .map(|h| h.step)
            .collect();
        assert_eq!(listed, (0..LISTED).chain(n - LISTED..n).collect::<Vec<_>>());
        assert_eq!(log.reasons.len(), 1);
        assert_eq!(log.reasons["residual # stalled"], n);
        for k in 0..2 * REASON_KINDS {
            log.push(handover(1000, &"x".repeat(k + 1)));
        }
        assert_eq!(log.reasons.len(), REASON_KINDS + 1);
        assert_eq!(log.reasons["other"], REASON_KINDS + 1);
        assert_eq!(log.listed.count, n + 2 * REASON_KINDS);
    }

    /// Lists of at most 2·LISTED items are kept whole; longer ones lose their middle.
    #[test]
    fn first_and_last_keep_short_lists_whole() {
        let short: Vec<usize> = (0..2 * LISTED).collect();
        assert_eq!(first_and_last(&short), short);
        let long: Vec<usize> = (0..3 * LISTED).collect();
        let kept = first_and_last(&long);
        assert_eq!(kept.len(), 2 * LISTED);
        assert_eq!(kept[LISTED - 1], LISTED - 1);
        assert_eq!(kept[LISTED], 2 * LISTED);
    }
}
