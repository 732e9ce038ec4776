//! The admissibility checks of a step (tangential module docs, "Checks"): `p ≥ 0`,
//! `|q| ≤ ηp` on the stick zone, and in each slip zone a slip increment that opposes the
//! friction, measured by the frictional work density `s η p Δs` at six points of each zone.

use crate::contact::{ContactModel, ContactState};
use crate::error::SolveFailure;

use super::StepAdmissibility;

pub(super) fn check(adm: &StepAdmissibility, tol: f64) -> Result<(), SolveFailure> {
    let [stick_at, slip_at, pressure_at] = adm.worst_at;
    crate::contact::first_violation(&[
        (
            "p ≥ 0",
            -adm.min_pressure,
            tol,
            adm.min_pressure,
            pressure_at,
        ),
        (
            "|q| ≤ η p in the stick zone",
            adm.stick_excess,
            tol,
            adm.stick_excess,
            stick_at,
        ),
        (
            "slip in the slip zones must oppose the friction",
            adm.slip_reversal,
            tol.max(1e-2),
            adm.slip_reversal,
            slip_at,
        ),
    ])
}

/// The admissibility measures of a step from `old` to `new` (tangential module docs).
pub fn assess_step(
    model: &ContactModel,
    old: &ContactState,
    new: &ContactState,
) -> StepAdmissibility {
    let stick = new.traction.stick.as_ref().expect("slip state");
    let eta = model.friction;
    let (c, a) = (new.centre, new.half_width);
    let p0 = new.pressure_at(c);
    let mut out = StepAdmissibility {
        stick_excess: f64::NEG_INFINITY,
        slip_reversal: f64::NEG_INFINITY,
        min_pressure: 1.0,
        worst_at: [f64::NAN; 3],
    };
    let (mut p, mut q) = (Vec::new(), Vec::new());
    let xs: Vec<f64> = (1..400)
        .map(|i| c + a * (-1.0 + 2.0 * i as f64 / 400.0))
        .collect();
    new.pressures_into(&xs, &mut p);
    for (&x, p) in xs.iter().zip(&p) {
        let ratio = p / p0;
        if ratio < out.min_pressure {
            out.min_pressure = ratio;
            out.worst_at[2] = x;
        }
    }
    // The end itself exactly: a point rounded just inside an end would see q̃'s square root of
    // the rounding error (about 2e−9 η p0 at 1e−21 m).
    let xs: Vec<f64> = (0..=200)
        .map(|i| {
            if i == 200 {
                stick.hi
            } else {
                stick.lo + (stick.hi - stick.lo) * i as f64 / 200.0
            }
        })
        .collect();
    new.pressures_into(&xs, &mut p);
    new.tractions_with(&xs, &p, &mut q);
    for ((&x, p), q) in xs.iter().zip(&p).zip(&q) {
        let excess = (q.abs() - eta * p) / (eta * p0);
        if excess > out.stick_excess {
            out.stick_excess = excess;
            out.worst_at[0] = x;
        }
    }
    // Slip increments at points of each slip zone, by the check's rule
    // ([`crate::contact::slip_check_rule_nodes`]: the sign is checked to 1e−2 of the largest slip,
    // the rule gives it to 1.2e−4 or better).
    let nodes = crate::contact::slip_check_rule_nodes(new.pressure.beta.len());
    let slips = slip_work_densities(model, old, new, nodes);
    let largest = slips
        .iter()
        .fold(0.0f64, |m, (_, _, s)| m.max(s.abs()))
        .max(1e-300);
    for (x, zs, s) in slips {
        let reversal = zs * s / largest;
        if reversal > out.slip_reversal {
            out.slip_reversal = reversal;
            out.worst_at[1] = x;
        }
    }
    out
}

/// The frictional work density per unit η, `p(x) Δs(x)`, with the slip sign of the zone, at
/// six points of each slip zone of `new` (¼, ½, ¾, 0.9, 0.97 and all of the way from the
/// stick end to the inner of the two contact ends: points that enter or leave the contact
/// have no slip increment). `Δs(x)` is the running integral of the strain change from the
/// stick end, by graded quadrature with `nodes` per piece, split at every point where either
/// state is not smooth ([`crate::contact::step_breakpoints`]) and at the six points.
fn slip_work_densities(
    model: &ContactModel,
    old: &ContactState,
    new: &ContactState,
    nodes: usize,
) -> Vec<(f64, f64, f64)> {
    let stick = new.traction.stick.as_ref().expect("slip state");
    let (c, a) = (new.centre, new.half_width);
    let mut d_strain =
        |xs: &[f64], out: &mut Vec<f64>| new.strain_changes_into(model, old, xs, out);
    let breaks = crate::contact::step_breakpoints(old, new);
    let mut slips = Vec::new();
    let zones = [
        (
            stick.hi,
            (c + a).min(old.centre + old.half_width),
            new.traction.right_sign,
        ),
        (
            stick.lo,
            (c - a).max(old.centre - old.half_width),
            new.traction.left_sign,
        ),
    ];
    for (from, to, zone_sign) in zones {
        let samples: Vec<f64> = [0.25, 0.5, 0.75, 0.9, 0.97, 1.0]
            .iter()
            .map(|f| from + f * (to - from))
            .collect();
        let (left, right) = (from.min(to), from.max(to));
        let mut pts: Vec<f64> = breaks
            .iter()
            .copied()
            .filter(|x| *x > left && *x < right)
            .collect();
        pts.extend(&samples);
        pts.extend([left, right]);
        let table = crate::contact::graded_cumulative(pts, nodes, None, &mut d_strain);
        for x in samples {
            // ∫ from `left` to x: the nodes of the pieces before x (x is a piece end).
            let before: f64 = table
                .nodes
                .iter()
                .filter(|n| n.0 < x)
                .map(|n| n.1 * n.2)
                .sum();
            let slip = if to > from {
                before
            } else {
                before - table.total
            };
            slips.push((x, zone_sign, slip * new.pressure_at(x)));
        }
    }
    slips
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::pressure::Discretisation;

    /// The slip check reads the sign of the slip increments (to 1e−2 of the largest slip of
    /// the step, `check`); its rule, `slip_check_rule_nodes`, against eight times the nodes
    /// over the first two phases of the default history (each step's six points in each slip
    /// zone, relative to the step's largest), with the states the driver reaches.
    #[test]
    fn the_slip_check_rule_reads_the_sign_to_a_small_error() {
        let sc = crate::scenario::default_scenario();
        let disc = Discretisation::new(sc.collocation_points);
        let nodes = crate::contact::slip_check_rule_nodes(disc.nodes());
        let mut worst: f64 = 0.0;
        crate::history::walk_default_history(&disc, 30, |old, new| {
            if new.traction.stick.is_none() || old.traction.stick.is_none() {
                return;
            }
            let coarse = slip_work_densities(&sc.model, old, new, nodes);
            let fine = slip_work_densities(&sc.model, old, new, 8 * nodes);
            let largest = fine.iter().fold(0.0f64, |m, s| m.max(s.2.abs()));
            for (c, f) in coarse.iter().zip(&fine) {
                worst = worst.max((c.2 - f.2).abs() / largest);
            }
        });
        println!("worst slip check error {worst:.2e}");
        // Measured 2.3e−5 (and 1.2e−4 at worst over the regression batch).
        assert!(worst > 0.0 && worst < 1e-4, "{worst:e}");
    }
}
