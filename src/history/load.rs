//! The prescribed load: the piecewise-linear tangential load Q(t) ([`LoadHistory`]), its
//! validation, its cut into `max(steps_per_segment, ⌈|ΔQ|/max_step⌉)` equal steps per segment,
//! and the load at one step ([`LoadPoint`]).

use serde::Serialize;

use crate::error::Issue;

/// A piecewise-linear tangential load history in N/m.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LoadHistory {
    /// `(t, Q)` points, t strictly increasing (s, N/m).
    pub points: Vec<(f64, f64)>,
    /// Minimum number of steps per segment.
    pub steps_per_segment: usize,
    /// Largest |ΔQ| of a step (N/m).
    pub max_step: f64,
}

impl LoadHistory {
    /// A history from a lead-in and a cycle block repeated `repeats` times. Cycle times are
    /// relative to the start of each repetition (which is the end of the previous one).
    pub fn with_cycles(
        lead_in: &[(f64, f64)],
        cycle: &[(f64, f64)],
        repeats: usize,
    ) -> Vec<(f64, f64)> {
        let mut points = lead_in.to_vec();
        for _ in 0..repeats {
            let t0 = points.last().map_or(0.0, |p| p.0);
            points.extend(cycle.iter().map(|(t, q)| (t0 + t, *q)));
        }
        points
    }

    /// The load points of a run, numbered from 1: a ramp from Q = 0 to the first point in one
    /// segment's worth of steps (when it is not zero), then [`Self::steps`].
    pub fn load_points(&self) -> Vec<LoadPoint> {
        let (t0, q0) = self.points.first().copied().unwrap_or((0.0, 0.0));
        let mut steps = Vec::new();
        if q0.abs() > 0.0 {
            let n = self
                .steps_per_segment
                .max((q0.abs() / self.max_step).ceil() as usize);
            for i in 1..=n {
                steps.push((t0, q0 * i as f64 / n as f64));
            }
        }
        steps.extend(self.steps().into_iter().map(|(_, t, q)| (t, q)));
        steps
            .into_iter()
            .enumerate()
            .map(|(i, (t, q))| LoadPoint { step: i + 1, t, q })
            .collect()
    }

    /// Check the history before any solving: finite values, strictly increasing times, and
    /// `|Q| < ηP` at every point (a point at or beyond ηP is gross sliding).
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
            if !q.is_finite() {
                issues.push(Issue::new(
                    format!("{path}.points[{i}].q"),
                    format!("{q} N/m is invalid; it must be finite"),
                ));
            } else if q.abs() >= limit {
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

    /// The number of steps of segment `k` (from point `k` to point `k + 1`):
    /// `max(steps_per_segment, ⌈|ΔQ|/max_step⌉)`, one for a hold.
    pub fn segment_steps(&self, k: usize) -> usize {
        let (q0, q1) = (self.points[k].1, self.points[k + 1].1);
        let n = self
            .steps_per_segment
            .max(((q1 - q0).abs() / self.max_step).ceil() as usize)
            .max(1);
        if (q1 - q0).abs() > 0.0 { n } else { 1 }
    }

    /// The load steps `(t, Q)` after the first point, each with its segment index.
    pub fn steps(&self) -> Vec<(usize, f64, f64)> {
        let mut out = Vec::new();
        for (k, w) in self.points.windows(2).enumerate() {
            let ((t0, q0), (t1, q1)) = (w[0], w[1]);
            let n = self.segment_steps(k);
            for i in 1..=n {
                let f = i as f64 / n as f64;
                out.push((k, t0 + f * (t1 - t0), q0 + f * (q1 - q0)));
            }
        }
        out
    }
}

/// A load point of the history: step number, time (s) and Q (N/m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadPoint {
    /// Step number.
    pub step: usize,
    /// Time (s).
    pub t: f64,
    /// Tangential load (N/m).
    pub q: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn history_validation_names_each_point() {
        let h = LoadHistory {
            points: vec![(0.0, 0.0), (1.0, 500.0), (0.5, 700.0)],
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

    #[test]
    fn steps_cover_each_segment_and_holds_take_one_step() {
        let h = LoadHistory {
            points: vec![(0.0, 0.0), (1.0, 10.0), (2.0, 10.0), (3.0, -10.0)],
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
