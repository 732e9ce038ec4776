//! A step's increments, functions of its two states ([`StepIncrements`]): Δδ at the anchor, the
//! frictional dissipation ([`step_dissipation`]) and the works of P and of the electric load;
//! the inputs they need ([`IncrementInputs`]) are taken apart from the solve, so that a run
//! computes them while it solves the next step.

use std::sync::Arc;

use crate::contact::{ContactModel, ContactState};

use super::driver::{DriverState, SolvedStep};

/// What the increments of a step need.
#[derive(Clone)]
pub struct IncrementInputs {
    /// The committed state before the step.
    pub old: Arc<ContactState>,
    /// The state of the step.
    pub new: Arc<ContactState>,
    /// The material point at which δ is followed (m).
    pub anchor: f64,
    /// `ux` of the old state at the anchor, when the previous step computed it (m).
    pub old_ux: Option<f64>,
    /// The normal approach of the old state, when already computed (m).
    pub old_approach: Option<f64>,
}

/// The increments of a step and the values at its state that the next step reuses.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StepIncrements {
    /// Δδ (m).
    pub displacement: f64,
    /// Frictional dissipation (J/m).
    pub dissipation: f64,
    /// Work of P, `P Δδn` (J/m).
    pub normal_work: f64,
    /// Work of the electric load, `−φ̄0 ΔΓ` (J/m; [`super::StepRecord::electric_work`]).
    pub electric_work: f64,
    /// `ux` of the new state at the anchor (m).
    pub new_ux: f64,
    /// Normal approach δn of the new state (m).
    pub new_approach: f64,
}

impl StepIncrements {
    /// The increments between `inputs.old` and `inputs.new`.
    ///
    /// The punch moves rigidly, so on the new stick zone `Δux` is uniform and equals `Δδ`; it
    /// is taken at the material point `anchor` of the stick zone. The driver keeps one anchor
    /// for as long as it sticks, so that the increments telescope: δ is then `ux(anchor)` of
    /// the current state plus a constant, and a cycle that repeats its states repeats δ
    /// exactly (averaging over points that change from step to step leaves the
    /// discretisation error of `ux` to accumulate as a drift, measured at 2e−6 of the loop's δ
    /// range per cycle for the Figure-4 history). `ux(anchor)` and δn come from one pass over
    /// each state ([`ContactState::displacement_and_approach`]); the old state's are taken
    /// from `inputs` when the previous step computed them. The dissipation is
    /// [`step_dissipation`]'s.
    pub fn compute(model: &ContactModel, inputs: &IncrementInputs) -> Self {
        let (old, new) = (&inputs.old, &inputs.new);
        let (new_ux, new_approach) = new.displacement_and_approach(model, inputs.anchor);
        let (old_ux, old_approach) = match (inputs.old_ux, inputs.old_approach) {
            (Some(ux), Some(approach)) => (ux, approach),
            (ux, approach) => {
                let (u, n) = old.displacement_and_approach(model, inputs.anchor);
                (ux.unwrap_or(u), approach.unwrap_or(n))
            }
        };
        let (displacement, dissipation) = match new.traction.stick {
            Some(_) => (new_ux - old_ux, step_dissipation(model, old, new)),
            None => (0.0, 0.0),
        };
        let electric_work = match (old.potential, new.potential) {
            (Some(a), Some(b)) => -0.5 * (a + b) * (new.charge - old.charge),
            _ => 0.0,
        };
        Self {
            displacement,
            dissipation,
            normal_work: new.normal_load * (new_approach - old_approach),
            electric_work,
            new_ux,
            new_approach,
        }
    }
}

impl SolvedStep {
    /// The increments, when they are known without computing them: the step reproduced a
    /// recalled step (the same geometry and slip signs to the bit) that began from the state
    /// this one began from, and δ is followed at the same anchor. They are then the recalled
    /// step's, which were computed from the same two states.
    pub fn known_increments(&self) -> Option<StepIncrements> {
        self.known
    }

    /// The inputs of this step's increments, with what the driver already knows of the old
    /// state (call after the previous step is finished).
    pub fn increment_inputs(&self, driver: &DriverState) -> IncrementInputs {
        let anchor = self.inputs.anchor;
        IncrementInputs {
            old_ux: driver
                .anchor_ux
                .filter(|(x, _)| x.to_bits() == anchor.to_bits())
                .map(|(_, u)| u),
            old_approach: driver.approach,
            ..self.inputs.clone()
        }
    }
}

/// The frictional dissipation between two states (zero when the new state has no stick zone).
///
/// In a slip zone the slip increment is `Δs(x) = ∫ from the stick end to x of Δε` (Δε the
/// change of the surface strain), and the dissipated energy `−∫ q̄ Δs dx` (q̄ the mean of the
/// two tractions, second order in the step) is evaluated after an integration by parts as
/// `∓∫ Δε(t) T(t) dt`, with T the integral of q̄ from t to the contact end, so that Δε is
/// needed only at the quadrature nodes.
pub fn step_dissipation(model: &ContactModel, old: &ContactState, new: &ContactState) -> f64 {
    let m = new.pressure.beta.len();
    let rule = (
        crate::contact::slip_zone_rule_nodes(m),
        Some(crate::contact::slip_zone_smooth_nodes(m)),
    );
    step_dissipation_with(model, old, new, rule)
}

/// q and the surface strain `∂ux/∂x` of `state` at each of `xs`, its pressure computed once
/// for both.
fn traction_and_strain(
    model: &ContactModel,
    state: &ContactState,
    xs: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let (mut p, mut h, mut q, mut strain) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    state.pressures_and_cauchys_into(xs, &mut p, &mut h);
    state.tractions_with(xs, &p, &mut q);
    state.strains_with(model, xs, (&p, &h), &mut strain);
    (q, strain)
}

/// The slip increments `Δs(x) = Δux(x) − Δδ` of the step from `old` to `new` at the points
/// `xs` (m; the half-plane's displacement relative to the punch, as the general solver's
/// element slip): zero on the new stick zone and outside the new contact, and in a slip zone
/// `Δs(x) = ∫ Δε` from the stick end to x ([`step_dissipation`]'s slip increment, with the
/// same strain change and breakpoints). Each slip zone is cut at the points of `xs` inside
/// it as well, so that one pass of the graded rule gives the running integral at every one:
/// `slip_zone_rule_nodes(M)` nodes on the pieces that end at a breakpoint of the step or at
/// a zone end, `grid_nodes` on those between two of `xs` (smooth inside).
pub fn slip_increments(
    model: &ContactModel,
    old: &ContactState,
    new: &ContactState,
    xs: &[f64],
    grid_nodes: usize,
) -> Vec<f64> {
    let mut out = vec![0.0; xs.len()];
    let Some(stick) = new.traction.stick.as_ref() else {
        return out;
    };
    let (left_end, right_end) = (new.centre - new.half_width, new.centre + new.half_width);
    let breaks = crate::contact::step_breakpoints(old, new);
    let full = crate::contact::slip_zone_rule_nodes(new.pressure.beta.len());
    for (from, to) in [(stick.hi, right_end), (left_end, stick.lo)] {
        let inside: Vec<usize> = (0..xs.len())
            .filter(|&i| xs[i] > from && xs[i] < to)
            .collect();
        if inside.is_empty() {
            continue;
        }
        let mut pts = zone_ends_and_breaks(&breaks, from, to);
        let singular = pts.clone();
        pts.extend(inside.iter().map(|&i| xs[i]));
        let is_singular = |x: f64| singular.iter().any(|s| s.to_bits() == x.to_bits());
        let (at, weights) = crate::contact::graded_nodes(pts, |x0, x1| {
            if is_singular(x0) || is_singular(x1) {
                full
            } else {
                grid_nodes
            }
        });
        let ((_, strain_new), (_, strain_old)) = (
            traction_and_strain(model, new, &at),
            traction_and_strain(model, old, &at),
        );
        let terms: Vec<f64> = weights
            .iter()
            .zip(strain_new.iter().zip(&strain_old))
            .map(|(w, (n, o))| w * (n - o))
            .collect();
        // Right zone: Δs(x) = ∫_{hi}^{x} Δε; left zone: Δs(x) = −∫_{x}^{lo} Δε. Every point
        // of `xs` ends pieces, so the nodes below it are those of the pieces before it.
        let running: Vec<f64> = terms
            .iter()
            .scan(0.0, |sum, t| {
                *sum += t;
                Some(*sum)
            })
            .collect();
        let total = running.last().copied().unwrap_or(0.0);
        let right = from.to_bits() == stick.hi.to_bits();
        for &i in &inside {
            let below = at.partition_point(|&t| t < xs[i]);
            let before = below.checked_sub(1).map_or(0.0, |k| running[k]);
            out[i] = if right { before } else { before - total };
        }
    }
    out
}

/// [`step_dissipation`] by the graded rule with `nodes` per piece, and `smooth` nodes of the
/// plain rule on the pieces both of whose ends the balancing made (none: the graded rule on
/// every piece; [`crate::contact::graded_cumulative`]).
fn step_dissipation_with(
    model: &ContactModel,
    old: &ContactState,
    new: &ContactState,
    (nodes, smooth): (usize, Option<usize>),
) -> f64 {
    let Some(stick) = new.traction.stick.as_ref() else {
        return 0.0;
    };
    // q̄ onto `out` and Δε onto `changes` at each of xs, each state's pressure computed once
    // for its traction and strain.
    let mean_and_change = |xs: &[f64], out: &mut Vec<f64>, changes: &mut Vec<f64>| {
        let fields = |state: &ContactState| traction_and_strain(model, state, xs);
        let ((q_new, strain_new), (q_old, strain_old)) = (fields(new), fields(old));
        out.extend(q_new.iter().zip(&q_old).map(|(n, o)| 0.5 * (o + n)));
        changes.extend(strain_new.iter().zip(&strain_old).map(|(n, o)| n - o));
    };
    let left_end = (old.centre - old.half_width).min(new.centre - new.half_width);
    let right_end = (old.centre + old.half_width).max(new.centre + new.half_width);
    // Measured on the default history: without the contact ends among the breakpoints the
    // step dissipation differs from the one with them by up to 1e−4 of itself (3e−2 at the
    // first steps after a reversal, where it is small); with them, and with the pieces
    // balanced (`graded_cumulative` halves a piece that is more than three times as long as
    // a neighbour, so that no singular point sits just outside a long piece), the rule of
    // `slip_zone_rule_nodes` agrees with four times its nodes to 5e−9 at every step,
    // M = 64 … 512. The pieces that the balancing made at both ends take the plain rule of
    // `slip_zone_smooth_nodes` (half the nodes: test
    // `the_dissipation_rule_gives_the_step_dissipations_to_a_small_error`).
    // (Unbalanced, one step, 0.048a of slip zone next to a 0.003a piece, was off by 4e−4 of
    // itself even with 96 nodes.)
    let breaks = crate::contact::step_breakpoints(old, new);
    // q̄ and Δε on the graded nodes of each slip zone, split at the traction's breakpoints,
    // with the running integral of q̄ for the inner integral.
    let table = |from: f64, to: f64| {
        let pts = zone_ends_and_breaks(&breaks, from, to);
        let mut changes = Vec::new();
        let table = crate::contact::graded_cumulative(pts, nodes, smooth, &mut |xs, out| {
            mean_and_change(xs, out, &mut changes)
        });
        (table, changes)
    };
    // Right zone: −∫_{hi}^{R} Δε(t) ∫_t^R q̄; left zone: +∫_{L}^{lo} Δε(t) ∫_L^t q̄.
    let (right_table, right_changes) = table(stick.hi, right_end);
    let right: f64 = right_table
        .nodes
        .iter()
        .zip(right_changes)
        .map(|(&(_, w, _, before), d)| w * d * (right_table.total - before))
        .sum();
    let (left_table, left_changes) = table(left_end, stick.lo);
    let left: f64 = left_table
        .nodes
        .iter()
        .zip(left_changes)
        .map(|(&(_, w, _, before), d)| w * d * before)
        .sum();
    -right + left
}

/// The ends of a slip zone `[from, to]` and the traction's breakpoints strictly inside it: the
/// pieces of its graded rule (the breakpoints first, then `from` and `to`).
fn zone_ends_and_breaks(breaks: &[f64], from: f64, to: f64) -> Vec<f64> {
    let mut pts: Vec<f64> = breaks
        .iter()
        .copied()
        .filter(|x| *x > from && *x < to)
        .collect();
    pts.extend([from, to]);
    pts
}

#[cfg(test)]
mod tests {
    use crate::contact::pressure::Discretisation;

    use crate::history::walk_default_history;

    use super::*;

    /// The slip increments at many points, with the mean traction, integrate to the step's
    /// dissipation `−∫ q̄ Δs dx` ([`step_dissipation`], which integrates by parts and never
    /// forms Δs): the midpoint rule on 2,000 and 4,000 points over the contact, over the first loading
    /// and the first reversal of the default (coupled PZT-4) history at M = 64, to the
    /// dissipation in the part of the contact that the step leaves.
    #[test]
    fn the_slip_increments_integrate_to_the_step_dissipation() {
        let sc = crate::scenario::default_scenario();
        let disc = Discretisation::new(64);
        let (mut worst, mut largest) = ([0.0f64; 2], 0.0f64);
        walk_default_history(&disc, 20, |old, new| {
            let (lo, hi) = (new.centre - new.half_width, new.centre + new.half_width);
            let exact = step_dissipation(&sc.model, old, new);
            largest = largest.max(exact.abs());
            for (k, n) in [2000, 4000].into_iter().enumerate() {
                let h = (hi - lo) / n as f64;
                let xs: Vec<f64> = (0..n).map(|j| lo + (j as f64 + 0.5) * h).collect();
                let slips = slip_increments(&sc.model, old, new, &xs, 16);
                let (mut q_new, mut q_old) = (Vec::new(), Vec::new());
                new.tractions_into(&xs, &mut q_new);
                old.tractions_into(&xs, &mut q_old);
                let by_points: f64 = (0..n)
                    .map(|j| -0.5 * (q_new[j] + q_old[j]) * slips[j] * h)
                    .sum();
                worst[k] = worst[k].max((by_points - exact).abs());
            }
        });
        let relative = [worst[0] / largest, worst[1] / largest];
        println!(
            "−∫ q̄ Δs by 2,000 and 4,000 points within {:.2e} and {:.2e} of the largest step \
             dissipation",
            relative[0], relative[1]
        );
        assert!(largest > 0.0);
        // Measured 4.5e−5 and 4.4e−5: not the points' error, which is smaller, but the
        // sliver of contact that the step's state leaves (the contact moves by about 2e−3 a a
        // step here), whose slip the dissipation counts over both states' contacts and the
        // slip increments, by their definition, do not (about 1e−12 J/m a step).
        assert!(relative[0] < 1e-4 && relative[1] < 1e-4, "{relative:?}");
    }

    /// The graded rule of `fatigue::GRID_PIECE_NODES` nodes on the pieces between grid points
    /// gives the slip increments at the fatigue indicators' default grid (400 points over
    /// ±2a) as the graded 64-node rule does, to a small fraction of the step's largest, over
    /// the first loading and the first reversal of the default history at M = 64.
    #[test]
    fn the_grid_rule_gives_the_slip_increments_to_a_small_error() {
        let sc = crate::scenario::default_scenario();
        let disc = Discretisation::new(64);
        let (mut worst, mut steps) = (0.0f64, 0);
        walk_default_history(&disc, 30, |old, new| {
            let n = 400;
            let (c, a) = (new.centre, new.half_width);
            let xs: Vec<f64> = (0..n)
                .map(|i| c + 2.0 * a * ((2 * i + 1) as f64 - n as f64) / n as f64)
                .collect();
            let fine = slip_increments(&sc.model, old, new, &xs, 64);
            let largest = fine.iter().fold(0.0f64, |m, s| m.max(s.abs()));
            if largest == 0.0 {
                return;
            }
            steps += 1;
            let slips = slip_increments(&sc.model, old, new, &xs, crate::fatigue::GRID_PIECE_NODES);
            let error = slips
                .iter()
                .zip(&fine)
                .fold(0.0f64, |m, (s, f)| m.max((s - f).abs()));
            worst = worst.max(error / largest);
        });
        println!("slip increments over {steps} steps within {worst:.2e} of the step's largest");
        assert!(steps >= 25, "{steps}");
        // Measured 4.8e−14.
        assert!(worst < 1e-12, "{worst:.2e}");
    }

    /// The dissipation's rule (the graded rule, and the plain rule on the pieces that the
    /// balancing made at both ends, `slip_zone_smooth_nodes`) gives the step dissipations as
    /// four times the graded rule on every piece does, to a small fraction of the largest, over
    /// the first two phases of the default history at M = 128.
    #[test]
    fn the_dissipation_rule_gives_the_step_dissipations_to_a_small_error() {
        let sc = crate::scenario::default_scenario();
        let disc = Discretisation::new(128);
        let fine = (4 * crate::contact::slip_zone_rule_nodes(128), None);
        let graded = crate::contact::slip_zone_rule_nodes(128);
        let (mut rule, mut reference, mut few) = (Vec::new(), Vec::new(), Vec::new());
        walk_default_history(&disc, 30, |old, new| {
            rule.push(step_dissipation(&sc.model, old, new));
            reference.push(step_dissipation_with(&sc.model, old, new, fine));
            few.push(step_dissipation_with(
                &sc.model,
                old,
                new,
                (graded, Some(4)),
            ));
        });
        let largest = reference.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        let worst_of = |rule: &[f64]| {
            rule.iter()
                .zip(&reference)
                .fold(0.0f64, |m, (r, e)| m.max((r - e).abs()))
                / largest
        };
        let (worst, with_four) = (worst_of(&rule), worst_of(&few));
        println!("step dissipations within {worst:.2e} of the largest ({with_four:.2e} with 4)");
        // The smooth pieces are there and carry weight: 4 plain nodes on them are too few.
        assert!(with_four > 1e-6, "{with_four:e}");
        // Measured 1.5e−14, as with the graded rule's 32 nodes on every piece (8 plain nodes
        // on the smooth pieces: 1.6e−7; 4: 4.7e−6). The dissipation's discretisation error at
        // M = 128 is 4.1e−5 of a cycle's friction work (`docs/performance.md`).
        assert!(worst > 0.0 && worst < 1e-12, "{worst:e}");
    }
}
