//! What only makes a step faster (module docs of [`crate::history`], "Warm start" and "Recall
//! of a repeated phase"): the traces of the current phase and of the last phase of each
//! direction, from which a repeated phase recalls its steps (`Traces`); the guess at a phase
//! start, with new slip zones of the Mindlin–Deresiewicz width `a(1 − √(1 − |ΔQ|/(2ηP)))`
//! (`phase_start_guess`); and the quadratic predictor in Q of the geometry within a phase
//! (`predict`).

use std::sync::{Arc, OnceLock};

use serde::{Deserialize, Serialize};

use crate::contact::tangential::Recalled;
use crate::contact::{ContactModel, ContactState};

use super::increments::StepIncrements;

/// The accepted steps of one phase ([`Recalled`]).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct PhaseTrace {
    /// `[Q, lo, hi, a, c]` of the state the phase began from.
    pub(super) start: [f64; 5],
    /// Slip sign of the phase.
    sign: f64,
    /// The accepted steps.
    steps: Vec<TraceStep>,
}

/// An accepted step of a phase, kept for recall.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct TraceStep {
    /// The step's load (N/m).
    pub(super) q: f64,
    /// Its state, slip signs and Jacobian.
    pub(super) recalled: Recalled,
    /// Its increments, for a later step that reproduces it.
    pub(super) increments: TracedIncrements,
}

/// A traced step's increments, for a later step that repeats it: they are a function of the
/// two states and the anchor.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct TracedIncrements {
    /// [`Footprint`] of the state the step began from.
    pub(super) from: Footprint,
    /// The increments and the anchor they were taken at, set when the step is finished
    /// ([`finish_step`]).
    ///
    /// [`finish_step`]: super::finish_step
    #[serde(with = "set_once")]
    pub(super) value: Arc<OnceLock<(f64, StepIncrements)>>,
}

/// A cell set once, written as its value (`null` while unset).
mod set_once {
    use std::sync::{Arc, OnceLock};

    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub(super) fn serialize<S: Serializer, T: Serialize>(
        cell: &Arc<OnceLock<T>>,
        serializer: S,
    ) -> Result<S::Ok, S::Error> {
        cell.get().serialize(serializer)
    }

    pub(super) fn deserialize<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
        deserializer: D,
    ) -> Result<Arc<OnceLock<T>>, D::Error> {
        let cell = OnceLock::new();
        if let Some(value) = Option::<T>::deserialize(deserializer)? {
            let _ = cell.set(value);
        }
        Ok(Arc::new(cell))
    }
}

impl TracedIncrements {
    /// Whether the traced step began from a state of footprint `from`.
    pub(super) fn began_from(&self, from: Footprint) -> bool {
        self.from == from
    }

    /// The increments, for a step that repeated the traced one (`SlipStep::repeated`, which
    /// the solver grants only to a step that began where the traced one began) with δ
    /// followed at `anchor`, once they are known.
    pub(super) fn for_repeat(&self, anchor: f64) -> Option<StepIncrements> {
        let (taken_at, increments) = self.value.get()?;
        (taken_at.to_bits() == anchor.to_bits()).then_some(*increments)
    }
}

/// The bits of a state's stick ends, contact half-width and centre, and slip signs: a state
/// that began a traced step and the state a later step begins from are the same state when
/// their footprints are equal (the later one a repeat of the earlier, accepted at its geometry
/// without iterating).
pub(super) type Footprint = [u64; 6];

pub(super) fn footprint(state: &ContactState) -> Footprint {
    let [_, lo, hi, a, c] = load_and_geometry(state);
    let signs = [state.traction.left_sign, state.traction.right_sign];
    let mut out = [0; 6];
    for (o, v) in out.iter_mut().zip([lo, hi, a, c].into_iter().chain(signs)) {
        *o = v.to_bits();
    }
    out
}

/// The current phase's trace and the last finished one of each direction.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub(super) struct Traces {
    pub(super) current: Option<PhaseTrace>,
    /// Reverse (index 0) and forward (index 1).
    finished: [Option<PhaseTrace>; 2],
}

impl Traces {
    /// The step at load `q` of the last finished phase with slip sign `sign` that began from
    /// the turning state `start` (`[Q, lo, hi, a, c]`), when there is one. Loads and
    /// geometries match to 1e−9 of ηP and 1e−8 of a: a steady cycle repeats its steps to
    /// about the solver's tolerance, and the recalled state must solve the step anyway.
    pub(super) fn recall(
        &self,
        start: &[f64; 5],
        sign: f64,
        q: f64,
        limit: f64,
    ) -> Option<&TraceStep> {
        let trace = self.finished[usize::from(sign > 0.0)].as_ref()?;
        let a = start[3];
        let same_start = (trace.start[0] - start[0]).abs() <= 1e-9 * limit
            && (1..5).all(|k| (trace.start[k] - start[k]).abs() <= 1e-8 * a);
        if !same_start {
            return None;
        }
        trace.steps.iter().find(|s| (s.q - q).abs() <= 1e-9 * limit)
    }

    /// Record an accepted step (`None`: one that is not to be recalled); `start` begins a new
    /// phase (`[Q, lo, hi, a, c]` of its turning state), and the current trace is then
    /// finished.
    pub(super) fn push(&mut self, start: Option<[f64; 5]>, sign: f64, step: Option<TraceStep>) {
        if let Some(start) = start {
            if let Some(done) = self.current.take() {
                let slot = usize::from(done.sign > 0.0);
                self.finished[slot] = Some(done);
            }
            self.current = Some(PhaseTrace {
                start,
                sign,
                steps: Vec::new(),
            });
        }
        if let (Some(trace), Some(step)) = (self.current.as_mut(), step) {
            trace.steps.push(step);
        }
    }
}

/// `[Q, lo, hi, a, c]` of a state (its stick zone, or the whole contact when none).
pub(super) fn load_and_geometry(state: &ContactState) -> [f64; 5] {
    let (c, a) = (state.centre, state.half_width);
    let (lo, hi) = state
        .traction
        .stick
        .as_ref()
        .map_or((c - a, c + a), |z| (z.lo, z.hi));
    [state.tangential_load, lo, hi, a, c]
}

/// Initial guess of the stick zone at the first step of a phase with sign `sign` and
/// increment `dq` from `prev`.
pub(super) fn phase_start_guess(
    model: &ContactModel,
    prev: &ContactState,
    sign: f64,
    dq: f64,
) -> (f64, f64) {
    let (c, a) = (prev.centre, prev.half_width);
    let width =
        a * (1.0 - (1.0 - (dq.abs() / (2.0 * model.friction * prev.normal_load)).min(0.9)).sqrt());
    let width = width.max(1e-6 * a);
    let t = &prev.traction;
    let (plo, phi) = t.stick.as_ref().map_or((c - a, c + a), |s| (s.lo, s.hi));
    // A slip zone already slipping in the new direction keeps slipping and its stick end moves
    // inward at once (start just inside it: outside, the residuals do not depend on that end);
    // elsewhere new slip zones open at the contact ends.
    let lo = if (t.left_sign - sign).abs() < 1e-12 {
        plo + width
    } else {
        c - a + width
    };
    let hi = if (t.right_sign - sign).abs() < 1e-12 {
        phi - width
    } else {
        c + a - width
    };
    (lo, hi)
}

/// Steps of the current phase kept for the predictor of the next step ([`predict`]).
pub(super) const HISTORY_POINTS: usize = 3;

/// The geometry `(lo, hi, a, c)` of a step at load q, extrapolated from the steps of the
/// phase so far (`[Q, lo, hi, a, c]`, oldest first): by the polynomial in Q through the last
/// three (quadratic), two (linear) or one (constant). `None` before the phase's first step.
///
/// The geometry is smooth in Q within a phase, so the quadratic predictor starts the step
/// closer to its solution than the linear one of the stick ends alone with the previous
/// (a, c), which saves residual evaluations.
pub(super) fn predict(history: &[[f64; 5]], q: f64) -> Option<[f64; 4]> {
    let last = history.last()?;
    // Points with distinct loads only (a repeated load would make the polynomial singular).
    let mut points: Vec<&[f64; 5]> = vec![last];
    for p in history.iter().rev().skip(1) {
        if points
            .iter()
            .all(|o| (o[0] - p[0]).abs() > 1e-12 * o[0].abs().max(p[0].abs()))
        {
            points.push(p);
        }
    }
    let mut out = [0.0; 4];
    for (j, v) in out.iter_mut().enumerate() {
        // Lagrange's form through the points.
        *v = points
            .iter()
            .enumerate()
            .map(|(i, pi)| {
                let weight: f64 = points
                    .iter()
                    .enumerate()
                    .filter(|&(k, _)| k != i)
                    .map(|(_, pk)| (q - pk[0]) / (pi[0] - pk[0]))
                    .product();
                weight * pi[j + 1]
            })
            .sum();
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A traced step's increments go to a later step only when it begins from the state the
    /// traced step began from (footprints equal to the bit; that it then repeated the traced
    /// step, at its geometry to the bit, is the solver's `repeated`, tested in the tangential
    /// module) and follows δ at the same anchor, and only once they are known.
    #[test]
    fn traced_increments_need_the_start_and_the_anchor() {
        let increments = StepIncrements {
            displacement: 1e-9,
            dissipation: 2e-9,
            normal_work: 3e-9,
            electric_work: 0.0,
            new_ux: 4e-9,
            new_approach: 5e-9,
        };
        let (from, anchor) = ([1, 2, 3, 4, 5, 6], 1e-6);
        let traced = TracedIncrements {
            from,
            value: Arc::new(OnceLock::new()),
        };
        assert!(traced.for_repeat(anchor).is_none(), "not yet finished");
        traced.value.set((anchor, increments)).unwrap();
        let got = traced.for_repeat(anchor).expect("the traced step's");
        assert_eq!(got.dissipation.to_bits(), increments.dissipation.to_bits());
        assert!(traced.began_from(from));
        for k in 0..6 {
            let mut other = from;
            other[k] += 1;
            assert!(!traced.began_from(other), "from, bit {k}");
        }
        let next = f64::from_bits(anchor.to_bits() + 1);
        assert!(traced.for_repeat(next).is_none(), "anchor");
    }

    /// The predictor is the polynomial through the phase's last steps: exact for a quadratic
    /// path from three steps, for a linear one from two, constant from one, and a repeated
    /// load does not make it singular.
    #[test]
    fn predictor_is_exact_for_polynomial_paths() {
        let path = |q: f64| {
            [
                q,
                -1.0 + 0.1 * q - 0.02 * q * q,
                0.5 - 0.3 * q,
                2.0 + q * q,
                -q,
            ]
        };
        let close = |p: [f64; 4], q: f64| {
            p.iter()
                .zip(&path(q)[1..])
                .all(|(a, b)| (a - b).abs() <= 1e-12 * b.abs().max(1.0))
        };
        assert!(predict(&[], 1.0).is_none());
        let three = [path(1.0), path(2.0), path(3.0)];
        assert!(close(predict(&three, 3.5).unwrap(), 3.5));
        let line = |q: f64| [q, 1.0 + q, 2.0 - q, 3.0, 0.5 * q];
        let two = [line(1.0), line(2.0)];
        let p = predict(&two, 4.0).unwrap();
        assert!(
            p.iter()
                .zip(&line(4.0)[1..])
                .all(|(a, b)| (a - b).abs() < 1e-12)
        );
        assert!((predict(&[line(1.0)], 4.0).unwrap()[0] - 2.0).abs() < 1e-15);
        // A repeated load: the duplicate is dropped and the rest is used.
        let repeated = [line(1.0), line(2.0), line(2.0)];
        let p = predict(&repeated, 4.0).unwrap();
        assert!(p.iter().all(|v| v.is_finite()));
        assert!(
            p.iter()
                .zip(&line(4.0)[1..])
                .all(|(a, b)| (a - b).abs() < 1e-12)
        );
    }
}
