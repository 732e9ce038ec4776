//! The prescribed loads: the piecewise-linear tangential load Q(t) ([`LoadHistory`]), and with
//! it, where the history gives them, the normal load P(t) and the electric load (Γ(t) or
//! φ0(t)) on the same time axis ([`PunchHistory`]); their validation, their cut into steps
//! ([`LoadHistory::segment_steps`]), and the loads at one step ([`LoadPoint`]).
//!
//! # Steps
//! A segment from point k to point k + 1 is cut into
//! `n = max(steps_per_segment, ⌈max(|ΔQ|, η|ΔP|)/max_step⌉)` equal steps (`steps_per_segment`
//! where only the electric load or the bulk stress σB changes); a segment along which no load
//! changes is one step (a hold). The run begins with a ramp from the end of normal
//! loading (Q = 0, P and the electric load of the normal loading) to the first point, cut by
//! the same rule, when the first point differs from it.

use serde::{Deserialize, Serialize};

use crate::error::Issue;

/// A piecewise-linear load history: Q(t) in N/m (or the punch displacement δ(t) in m, under
/// [`Control::Displacement`]), and optionally P(t) and the electric load.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LoadHistory {
    /// `(t, Q)` points (`(t, δ)` under [`Control::Displacement`]), t strictly increasing
    /// (s, N/m or m).
    pub points: Vec<(f64, f64)>,
    /// What the second value of a point prescribes.
    #[serde(skip_serializing_if = "Control::is_load")]
    pub control: Control,
    /// The normal and electric loads at the same points, when the history prescribes them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub punch: Option<PunchHistory>,
    /// Minimum number of steps per segment.
    pub steps_per_segment: usize,
    /// Largest |ΔQ| (and η|ΔP|) of a step (N/m); under [`Control::Displacement`] the largest
    /// η|ΔP| (the bound on |Δδ| is [`LoadHistory::max_displacement_step`]).
    pub max_step: f64,
    /// Largest |Δδ| of a step (m) under [`Control::Displacement`] (infinite: none).
    #[serde(skip_serializing_if = "is_infinite")]
    pub max_displacement_step: f64,
}

/// How the tangential loading of a history is prescribed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Control {
    /// The tangential load Q(t); δ is a result.
    #[default]
    Load,
    /// The punch's rigid tangential displacement δ(t), counted from the end of normal loading
    /// (as the δ of the records); Q is a result, and reaches ±ηP in gross slip.
    Displacement,
}

fn is_infinite(value: &f64) -> bool {
    value.is_infinite()
}

impl Control {
    /// Whether Q is prescribed.
    pub fn is_load(&self) -> bool {
        *self == Control::Load
    }
}

/// P and the electric load along a [`LoadHistory`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PunchHistory {
    /// Those of the normal loading, where the history starts from.
    pub start: PunchLoads,
    /// At each point of the history.
    pub points: Vec<PunchLoads>,
    /// The friction coefficient η, which turns a change of P into the tangential load scale of
    /// `max_step`.
    pub friction: f64,
}

impl LoadHistory {
    /// A history from a lead-in and a cycle block repeated `repeats` times. Cycle times are
    /// relative to the start of each repetition (which is the end of the previous one).
    pub fn with_cycles<T: Copy>(
        lead_in: &[(f64, T)],
        cycle: &[(f64, T)],
        repeats: usize,
    ) -> Vec<(f64, T)> {
        let mut points = lead_in.to_vec();
        for _ in 0..repeats {
            let t0 = points.last().map_or(0.0, |p| p.0);
            points.extend(cycle.iter().map(|(t, v)| (t0 + t, *v)));
        }
        points
    }

    /// The loads at point `k`.
    fn loads_at(&self, k: usize) -> (f64, Option<PunchLoads>) {
        (self.points[k].1, self.punch.as_ref().map(|h| h.points[k]))
    }

    /// Steps from loads `a` to loads `b` (module docs).
    fn steps_between(&self, a: (f64, Option<PunchLoads>), b: (f64, Option<PunchLoads>)) -> usize {
        let (dp, de) = match (a.1, b.1) {
            (Some(x), Some(y)) => (
                y.normal - x.normal,
                (y.electric - x.electric).abs() + (y.bulk_stress - x.bulk_stress).abs(),
            ),
            _ => (0.0, 0.0),
        };
        let eta = self.punch.as_ref().map_or(0.0, |h| h.friction);
        // Steps the change of Q (or δ) and of P need.
        let needed = match self.control {
            Control::Load => ((b.0 - a.0).abs().max(eta * dp.abs()) / self.max_step).ceil(),
            Control::Displacement => ((b.0 - a.0).abs() / self.max_displacement_step)
                .ceil()
                .max((eta * dp.abs() / self.max_step).ceil()),
        };
        if b.0 - a.0 != 0.0 || dp != 0.0 {
            self.steps_per_segment.max(needed as usize).max(1)
        } else if de != 0.0 {
            self.steps_per_segment.max(1)
        } else {
            1
        }
    }

    /// Whether the bulk stress σB is not zero at some point.
    pub fn has_bulk_stress(&self) -> bool {
        self.punch
            .as_ref()
            .is_some_and(|h| h.points.iter().any(|p| p.bulk_stress != 0.0))
    }

    /// Steps of the ramp from the end of normal loading to the first point (0 when it is there).
    pub fn ramp_steps(&self) -> usize {
        let start = (0.0, self.punch.as_ref().map(|h| h.start));
        match self.points.first() {
            Some(_) if self.loads_at(0) != start => self.steps_between(start, self.loads_at(0)),
            _ => 0,
        }
    }

    /// The load points of a run, numbered from 1: a ramp from the end of normal loading to the
    /// first point (when it differs from it), then [`Self::steps`].
    pub fn load_points(&self) -> Vec<LoadPoint> {
        let mut steps = Vec::new();
        if let Some(&(t0, _)) = self.points.first() {
            let start = (0.0, self.punch.as_ref().map(|h| h.start));
            let first = self.loads_at(0);
            if first != start {
                let n = self.steps_between(start, first);
                for i in 1..=n {
                    let (_, punch) = between(start, first, i as f64 / n as f64);
                    steps.push((t0, (first.0 * i as f64 / n as f64, punch)));
                }
            }
        }
        steps.extend(
            self.steps_with_punch()
                .into_iter()
                .map(|(_, t, loads)| (t, loads)),
        );
        steps
            .into_iter()
            .enumerate()
            .map(|(i, (t, (q, punch)))| LoadPoint {
                step: i + 1,
                t,
                q,
                punch,
            })
            .collect()
    }

    /// Check the history before any solving: finite values, strictly increasing times, P ≥ 0
    /// where given (P = 0: the punch has left the half-plane, and Q must be 0), and, where Q is
    /// prescribed, `|Q| < ηP` at every point (a point at or
    /// beyond ηP is gross sliding, which only a prescribed displacement reaches; both are
    /// linear along a segment, so the points suffice). `limit` is ηP of the normal loading.
    pub fn validate(&self, path: &str, limit: f64) -> Vec<Issue> {
        let mut issues = Vec::new();
        if self.points.is_empty() {
            issues.push(Issue::new(
                format!("{path}.points"),
                "[] is invalid; it must hold at least one point",
            ));
        }
        for (i, &(t, q)) in self.points.iter().enumerate() {
            if !t.is_finite() {
                issues.push(Issue::new(
                    format!("{path}.points[{i}].t"),
                    format!("{t} s is invalid; it must be finite"),
                ));
            }
            let punch = self.punch.as_ref().map(|h| (h.points[i], h.friction));
            if let Some((loads, _)) = punch {
                if !(loads.normal.is_finite() && loads.normal >= 0.0) {
                    issues.push(Issue::new(
                        format!("{path}.points[{i}].p"),
                        format!("{} N/m is invalid; it must be finite and ≥ 0", loads.normal),
                    ));
                }
                if !loads.electric.is_finite() {
                    issues.push(Issue::new(
                        format!("{path}.points[{i}].electric"),
                        format!("{} is invalid; it must be finite", loads.electric),
                    ));
                }
            }
            let limit = punch.map_or(limit, |(loads, eta)| eta * loads.normal);
            if self.control == Control::Displacement {
                if !q.is_finite() {
                    issues.push(Issue::new(
                        format!("{path}.points[{i}].delta"),
                        format!("{q} m is invalid; it must be finite"),
                    ));
                }
            } else if !q.is_finite() {
                issues.push(Issue::new(
                    format!("{path}.points[{i}].q"),
                    format!("{q} N/m is invalid; it must be finite"),
                ));
            } else if limit == 0.0 && punch.is_some() {
                // Separation: no contact, so no tangential load.
                if q != 0.0 {
                    issues.push(Issue::new(
                        format!("{path}.points[{i}].q"),
                        format!(
                            "{q} N/m is invalid at P = 0; it must be 0 (the punch has left the \
                             half-plane)"
                        ),
                    ));
                }
            } else if limit.is_finite() && q.abs() >= limit {
                issues.push(Issue::new(
                    format!("{path}.points[{i}].q"),
                    format!(
                        "{q} N/m (= {:.4} ηP) is invalid; it must satisfy |Q| < ηP = {limit} N/m (at or beyond ηP the contact slides as a whole)",
                        q / limit
                    ),
                ));
            }
            if i > 0 {
                let prev = self.points[i - 1].0;
                if t.is_finite() && prev.is_finite() && t <= prev {
                    issues.push(Issue::new(
                        format!("{path}.points[{i}].t"),
                        format!("{t} s is invalid; it must be > previous t = {prev} s"),
                    ));
                }
            }
        }
        if self.steps_per_segment == 0 {
            issues.push(Issue::new(
                format!("{path}.steps_per_segment"),
                "0 is invalid; it must be ≥ 1",
            ));
        }
        if self.control == Control::Displacement
            && (self.max_displacement_step.is_nan() || self.max_displacement_step <= 0.0)
        {
            issues.push(Issue::new(
                format!("{path}.max_step"),
                format!(
                    "{} m is invalid; it must be > 0",
                    self.max_displacement_step
                ),
            ));
        }
        if !(self.max_step.is_finite() && self.max_step > 0.0) {
            issues.push(Issue::new(
                format!("{path}.max_step"),
                format!(
                    "{} N/m is invalid; it must be finite and > 0",
                    self.max_step
                ),
            ));
        }
        issues
    }

    /// The number of steps of segment `k` (from point `k` to point `k + 1`): module docs.
    pub fn segment_steps(&self, k: usize) -> usize {
        self.steps_between(self.loads_at(k), self.loads_at(k + 1))
    }

    /// The load steps `(t, Q)` after the first point, each with its segment index.
    pub fn steps(&self) -> Vec<(usize, f64, f64)> {
        self.steps_with_punch()
            .into_iter()
            .map(|(k, t, (q, _))| (k, t, q))
            .collect()
    }

    /// [`Self::steps`] with P and the electric load of each step.
    fn steps_with_punch(&self) -> Vec<(usize, f64, (f64, Option<PunchLoads>))> {
        let mut out = Vec::new();
        for k in 0..self.points.len().saturating_sub(1) {
            let (t0, t1) = (self.points[k].0, self.points[k + 1].0);
            let (a, b) = (self.loads_at(k), self.loads_at(k + 1));
            let n = self.segment_steps(k);
            for i in 1..=n {
                let f = i as f64 / n as f64;
                out.push((k, t0 + f * (t1 - t0), between(a, b, f)));
            }
        }
        out
    }

    /// Add the point at time `t` within segment `k` (`t_k < t < t_{k+1}`), its loads
    /// interpolated: the loads along the history are unchanged.
    pub fn split_segment(&mut self, k: usize, t: f64) {
        let ((ta, _), (tb, _)) = (self.points[k], self.points[k + 1]);
        let f = (t - ta) / (tb - ta);
        let (q, punch) = between(self.loads_at(k), self.loads_at(k + 1), f);
        self.points.insert(k + 1, (t, q));
        if let (Some(h), Some(loads)) = (self.punch.as_mut(), punch) {
            h.points.insert(k + 1, loads);
        }
    }
}

/// The loads a fraction `f` of the way from `a` to `b`.
fn between(
    a: (f64, Option<PunchLoads>),
    b: (f64, Option<PunchLoads>),
    f: f64,
) -> (f64, Option<PunchLoads>) {
    let mix = |x: f64, y: f64| x + f * (y - x);
    let punch = match (a.1, b.1) {
        (Some(x), Some(y)) => Some(PunchLoads {
            normal: mix(x.normal, y.normal),
            electric: mix(x.electric, y.electric),
            bulk_stress: mix(x.bulk_stress, y.bulk_stress),
        }),
        _ => None,
    };
    (mix(a.0, b.0), punch)
}

/// A load point of the history: step number, time (s), Q (N/m), and P and the electric load
/// where the history prescribes them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadPoint {
    /// Step number.
    pub step: usize,
    /// Time (s).
    pub t: f64,
    /// Tangential load (N/m).
    pub q: f64,
    /// P and the electric load of the step; `None`: those of the normal loading.
    pub punch: Option<PunchLoads>,
}

/// The normal and electric loads on the punch at a point of a history.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PunchLoads {
    /// P (N/m), > 0.
    pub normal: f64,
    /// Γ (C/m) under a charge-controlled conducting punch, φ0 (V) under a potential-controlled
    /// one; 0 otherwise.
    pub electric: f64,
    /// The bulk stress σB of the half-plane (Pa, tension positive; 0 at the end of normal
    /// loading), [`crate::contact::general::Loads::bulk_stress`].
    #[serde(skip_serializing_if = "is_zero")]
    pub bulk_stress: f64,
}

fn is_zero(value: &f64) -> bool {
    *value == 0.0
}

impl PunchLoads {
    /// The loads P and `electric` with no bulk stress; two are equal when every value is (a
    /// load held constant along a history is the same number at every step).
    pub fn of(normal: f64, electric: f64) -> Self {
        Self {
            normal,
            electric,
            bulk_stress: 0.0,
        }
    }

    /// The same loads with the bulk stress σB (Pa).
    pub fn with_bulk_stress(self, bulk_stress: f64) -> Self {
        Self {
            bulk_stress,
            ..self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn history_validation_names_each_point() {
        let h = LoadHistory {
            points: vec![(0.0, 0.0), (1.0, 500.0), (0.5, 700.0)],
            punch: None,
            control: Control::Load,
            max_displacement_step: f64::INFINITY,
            steps_per_segment: 4,
            max_step: 10.0,
        };
        let issues = h.validate("tangential_history", 600.0);
        let paths: Vec<_> = issues.iter().map(|i| i.path.as_str()).collect();
        assert_eq!(
            paths,
            [
                "tangential_history.points[2].q",
                "tangential_history.points[2].t"
            ]
        );
        assert!(issues[0].message.contains("|Q| < ηP"));
        assert!(issues[1].message.contains("must be > previous t = 1 s"));
    }

    /// Under a prescribed displacement a point's value is δ (m): any finite value (no ηP
    /// rule: gross slip is a state), counted in steps by `max_displacement_step`.
    #[test]
    fn displacement_histories_name_delta_and_count_their_steps_in_metres() {
        let mut h = LoadHistory {
            points: vec![(0.0, 0.0), (1.0, 1e-6), (2.0, f64::NAN)],
            punch: None,
            control: Control::Displacement,
            max_displacement_step: 1e-7,
            steps_per_segment: 4,
            max_step: 10.0,
        };
        let issues = h.validate("tangential_history", 600.0);
        assert_eq!(issues.len(), 1);
        assert_eq!(issues[0].path, "tangential_history.points[2].delta");
        assert!(
            issues[0]
                .message
                .contains("m is invalid; it must be finite")
        );
        h.points[2].1 = -4.95e-6;
        assert!(h.validate("tangential_history", 600.0).is_empty());
        // 1 µm in steps of at most 0.1 µm, then 5.95 µm: 10 and 60 steps.
        assert_eq!((h.segment_steps(0), h.segment_steps(1)), (10, 60));
        h.max_displacement_step = f64::INFINITY;
        assert_eq!((h.segment_steps(0), h.segment_steps(1)), (4, 4));
    }

    #[test]
    fn steps_cover_each_segment_and_holds_take_one_step() {
        let h = LoadHistory {
            points: vec![(0.0, 0.0), (1.0, 10.0), (2.0, 10.0), (3.0, -10.0)],
            punch: None,
            control: Control::Load,
            max_displacement_step: f64::INFINITY,
            steps_per_segment: 2,
            max_step: 4.0,
        };
        let steps = h.steps();
        assert_eq!(steps.len(), 3 + 1 + 5);
        assert!((steps[2].2 - 10.0).abs() < 1e-12 && (steps[3].2 - 10.0).abs() < 1e-12);
        assert!((steps.last().unwrap().2 + 10.0).abs() < 1e-12);
        let cyc =
            LoadHistory::with_cycles(&[(0.0, 0.0), (1.0, 5.0)], &[(1.0, -5.0), (2.0, 5.0)], 2);
        assert_eq!(cyc.len(), 6);
        assert!((cyc[5].0 - 5.0).abs() < 1e-12);
    }
}
