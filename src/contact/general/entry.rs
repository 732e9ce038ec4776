//! The slip reference of the elements that enter the contact within a step.
//!
//! A point that enters the contact at the instant `t_e` of a step `[t0, t1]` is free before
//! and sticks (or slips) from then on: its slip in the step is measured from its relative
//! displacement `w = ux − δx` **at entry**, `w(x, t_e)`, not from `w(x, t0)` (module docs of
//! [`super`]: the slip of a step is `s = Δux − Δδx` against the previous state). Taking the
//! step-start value instead makes an entering element stick to where its free surface was at
//! `t0`, so it carries the free surface's motion until entry as a tangential mismatch: on an
//! uncoupled contact under `Q = λP` that is λ times the gap it closed, and elements at the
//! advancing ends slip where the exact contact sticks everywhere (Mindlin's incremental
//! argument).
//!
//! Before entry the point moves with the free surface; that motion is what the step-start
//! reference leaves out. Near a contact end the free surface's motion in a step goes with the
//! closing of its gap, so an entering element i is given the part `φ_i` of the motion of B,
//! the first element outside the new contact beyond it (a free point next to the new end):
//!
//! ```text
//! w_ref,i = w_i(t0) + φ_i (w_B(t1) − w_B(t0)),   φ_i = gap_i(t0) / (gap_B(t0) − gap_B(t1))
//! ```
//!
//! clamped to [0, 1], with the element mean gaps of the previous state and of the new one
//! (φ_i = 1 where B's gap does not close). This is exact in the two cases where the answer
//! is known: on an uncoupled contact under `Q = λP` the free surface moves by
//! `−λ(y11/y22)` times the closing of its gap (q = λp gives `ux = λ(y11/y22)uz` up to a
//! constant), so an element that closes `gap_i(t0)` by entry has moved by `φ_i` of what B
//! moved in closing (nearly all of) `gap_B(t0)`; and where the free surface does not move
//! (a normal load raised at constant Q on an uncoupled contact) the reference is the
//! step-start one. Elsewhere `φ_i` ranges from 0 at the old end to 1 at the new, and the
//! reference errs by the motion's departure from that proportion, a fraction of one step's
//! motion of the end.
//!
//! An element whose gap at `t0` is not positive touches the punch at the step's start
//! already and enters then (φ_i = 0). That happens above Γ1 = kP, where the conducting-punch
//! model has no state with both p ≥ 0 and a non-negative gap: Spence's state and the normal
//! subproblem's (the last set with p ≥ 0, module docs of [`super`]) overlap the punch just
//! outside the contact ends (the paper's baseline: −1e−11 to −3e−11 m over about three
//! elements of 5e−4 a, against a²/2R = 1.5e−8 m), and the contact of a later step takes such
//! elements in. Given B's motion over the whole step (φ_i = 1: B's gap opens there), they
//! would slip the old way at the advancing end in every step.
//!
//! Where nothing was in contact before the step (the surface undeformed), the ring is split
//! at the profile's lowest point x = 0, where the punch touched first, and each side takes
//! its own B. A ring between two elements of the previous contact (a gap closing inside)
//! keeps the step-start reference.
//!
//! `w_B(t1)` depends on the new tractions, so the reference is found by a fixed-point
//! iteration (secant steps) on the solution of the tangential programme. A pass starts from
//! the previous pass's solution; where its programme does not settle from there it is solved
//! from the step's start, and where that fails too the step keeps the previous pass's
//! solution (at worst that of the step-start reference).

use super::mesh::Mesh;
use super::{ElementState, GeneralState};

/// The entering elements of a step, grouped into rings.
#[derive(Debug, Clone, Default)]
pub(super) struct Entry {
    rings: Vec<Ring>,
}

/// A run of entering elements and the free element B beyond it.
#[derive(Debug, Clone)]
struct Ring {
    /// `(element, φ)`.
    members: Vec<(usize, f64)>,
    /// B.
    outer: usize,
}

impl Entry {
    /// The rings of the elements in `contact` that were out of contact in `previous`, with
    /// the element mean gaps of the previous state (`gaps`) and of the new one (`now`).
    pub fn new(
        mesh: &Mesh,
        previous: &GeneralState,
        (gaps, now): (&[f64], &[f64]),
        contact: &[bool],
    ) -> Self {
        let n = contact.len();
        let entering = |i: usize| contact[i] && previous.codes[i] == ElementState::Exterior;
        let free = |j: Option<usize>| j.filter(|&j| j < n && !contact[j]);
        let ring = |members: std::ops::RangeInclusive<usize>, b: usize| Ring {
            members: members
                .map(|k| {
                    let closed = gaps[b] - now[b];
                    let phi = if gaps[k] <= 0.0 {
                        0.0
                    } else if closed > 0.0 {
                        gaps[k] / closed
                    } else {
                        1.0
                    };
                    (k, phi.clamp(0.0, 1.0))
                })
                .collect(),
            outer: b,
        };
        let mut rings = Vec::new();
        let mut i = 0;
        while i < n {
            if !entering(i) {
                i += 1;
                continue;
            }
            let first = i;
            while i < n && entering(i) {
                i += 1;
            }
            let last = i - 1;
            match (free(first.checked_sub(1)), free(Some(last + 1))) {
                (Some(left), Some(right)) => {
                    // The first touch, on the undeformed surface at the profile's lowest
                    // point x = 0: each side takes its own B; an element across x = 0 keeps
                    // the step-start reference.
                    let left_end = (first..=last).take_while(|&k| mesh.edges[k + 1] <= 0.0).last();
                    let right_start = (first..=last).find(|&k| mesh.edges[k] >= 0.0);
                    if let Some(end) = left_end {
                        rings.push(ring(first..=end, left));
                    }
                    if let Some(start) = right_start {
                        rings.push(ring(start..=last, right));
                    }
                }
                (Some(b), None) | (None, Some(b)) => rings.push(ring(first..=last, b)),
                // Between two elements of the previous contact, or at the band's end: the
                // step-start reference.
                (None, None) => {}
            }
        }
        Self { rings }
    }

    /// The free elements B, one per ring, whose `ux(t1) − Δδx` the reference needs.
    pub fn outer(&self) -> Vec<usize> {
        self.rings.iter().map(|r| r.outer).collect()
    }

    /// Writes the entry references into `reference` (per element, in the form `ux(t0)` of the
    /// slip reference: `w + δx(t0)`), with `moved[k] = ux_B(t1) − Δδx` for ring k's B.
    pub fn apply(&self, previous: &GeneralState, moved: &[f64], reference: &mut [f64]) {
        for (ring, &b) in self.rings.iter().zip(moved) {
            let motion = b - previous.displacement[ring.outer];
            for &(k, phi) in &ring.members {
                reference[k] = previous.displacement[k] + phi * motion;
            }
        }
    }

    /// Whether no element enters.
    pub fn is_empty(&self) -> bool {
        self.rings.is_empty()
    }
}
