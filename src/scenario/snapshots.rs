//! Snapshot times made step times: a time that falls between steps adds the point (t, Q(t))
//! of the piecewise-linear history (with P and the electric load where it gives them),
//! splitting its segment.

/// Make every snapshot time (strictly increasing) a step time of `history`: where no step
/// (nor the end of normal loading, nor the first point) falls within `tol` of a time, add the
/// point `(t, Q(t))` of the piecewise-linear history. Q(t) is unchanged; the segment that held
/// `t` is split in two, each cut into steps by the usual rule. Splitting a segment moves its
/// steps, so the times already passed are checked again from the split segment's start (each
/// time is added at most once): the result is that of rescanning all times after every
/// addition until none is added, in about one pass.
pub(super) fn insert_snapshot_points(
    history: &mut crate::history::LoadHistory,
    snapshots: &[f64],
    tol: f64,
) {
    let mut i = 0;
    while let Some(&t) = snapshots.get(i) {
        match insert_snapshot_point(history, t, tol) {
            // Times below the split segment's start minus tol keep their nearest steps.
            Some(start) => i = snapshots.partition_point(|&s| s < start - tol),
            None => i += 1,
        }
    }
}

/// Add `(t, Q(t))` to `history` unless `t` is within `tol` of a step time, the first point or
/// lies in no segment; returns the start time of the segment that was split.
pub(super) fn insert_snapshot_point(
    history: &mut crate::history::LoadHistory,
    t: f64,
    tol: f64,
) -> Option<f64> {
    let &(t0, _) = history.points.first()?;
    if (t - t0).abs() <= tol || near_a_step(history, t, tol) {
        return None;
    }
    // Points are strictly increasing in t: the segment with w0.t < t < w1.t.
    let above = history.points.partition_point(|p| p.0 < t);
    if above == 0 || above == history.points.len() || history.points[above].0 <= t {
        return None;
    }
    let k = above - 1;
    let ta = history.points[k].0;
    history.split_segment(k, t);
    Some(ta)
}

/// Whether a step time of `history` lies within `tol` of `t`. Step `i` of `n` on the segment
/// `[ta, tb]` is at `ta + (i/n)(tb − ta)` ([`crate::history::LoadHistory::steps`]), increasing
/// in `i`, so only the segments around `t` and the steps next to its position are looked at.
pub(super) fn near_a_step(history: &crate::history::LoadHistory, t: f64, tol: f64) -> bool {
    let points = &history.points;
    // Steps of segment k lie in [t_k, t_{k+1}] up to round-off; 2 tol covers it.
    let first = points
        .partition_point(|p| p.0 < t - 2.0 * tol)
        .saturating_sub(1);
    (first..points.len().saturating_sub(1))
        .take_while(|&k| points[k].0 <= t + 2.0 * tol)
        .any(|k| {
            let (ta, tb) = (points[k].0, points[k + 1].0);
            let n = history.segment_steps(k);
            let at = ((t - ta) / (tb - ta) * n as f64).round();
            let at = if at.is_finite() {
                at.clamp(0.0, n as f64) as usize
            } else {
                0
            };
            (at.saturating_sub(2).max(1)..=(at + 2).min(n)).any(|i| {
                let f = i as f64 / n as f64;
                (ta + f * (tb - ta) - t).abs() <= tol
            })
        })
}
