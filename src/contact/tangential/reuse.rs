//! What one evaluation or step keeps for the next: the parts of recent evaluations that
//! depend on only two of the four unknowns (`Reused`, shared by the attempts of one step), and
//! each thread's inner-iteration matrices, lent from step to step (`LentMaps`). Neither changes
//! a result: every output stays byte-identical without them
//! ([`Accelerations::reused_parts`], [`Accelerations::lent_maps`]).
//!
//! [`Accelerations::reused_parts`]: super::Accelerations::reused_parts
//! [`Accelerations::lent_maps`]: super::Accelerations::lent_maps

use std::cell::RefCell;
use std::sync::Arc;

use crate::contact::{Inherited, StickZone};

use super::inner::InnerMaps;

/// The fixed parts of recent evaluations that depend on only two of the four unknowns: `H'q̃`
/// of the chain and the remembered strain at the stick points (lo, hi), and S with the
/// inherited traction at the sample points (a, c). A finite-difference Jacobian moves one
/// unknown at a time, so two of its four evaluations find each part of its base point here
/// and skip the chain's sums (every output stays byte-identical, as it must). An
/// entry is taken only for the same grid, bit-identical points, the same inherited link (the
/// same `Arc`) and extras and the same slip signs (and stick ends, for a mixed state's S), so
/// what it holds is what the evaluation would compute, bit for bit. It lives for one
/// `solve_slip` call, whose attempts share one memory.
#[derive(Default)]
pub(super) struct Reused {
    pub(super) stick: Vec<(PartsKey, Arc<StickParts>)>,
    pub(super) samples: Vec<(PartsKey, Arc<SampleParts>)>,
}

/// `(H'q̃ of the chain, remembered strain)` at the stick points.
pub(super) type StickParts = (Vec<f64>, Vec<f64>);

/// `(S, inherited traction)` at the pressure points and at the charge points.
pub(super) type SampleParts = (Vec<(f64, f64)>, Vec<(f64, f64)>);

/// What an entry of [`Reused`] depends on: the grid's size, the interval the points are
/// mapped onto, the fixed part of q̃ (its inherited link, compared by identity, and its
/// extras), the slip signs, and for a mixed state's S the stick ends (else zero). The key
/// holds the link itself, so that no later link can take its address while the entry lives.
#[derive(Clone)]
pub(super) struct PartsKey {
    nodes: usize,
    interval: [u64; 2],
    link: Option<Arc<Inherited>>,
    extras: Vec<[u64; 3]>,
    signs: [u64; 2],
    ends: [u64; 2],
}

impl PartialEq for PartsKey {
    fn eq(&self, other: &Self) -> bool {
        let same_link = match (&self.link, &other.link) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            (None, None) => true,
            _ => false,
        };
        same_link
            && self.nodes == other.nodes
            && self.interval == other.interval
            && self.extras == other.extras
            && self.signs == other.signs
            && self.ends == other.ends
    }
}

impl PartsKey {
    pub(super) fn new(
        nodes: usize,
        (centre, half): (f64, f64),
        closed: &StickZone,
        ends: [f64; 2],
    ) -> Self {
        Self {
            nodes,
            interval: [centre.to_bits(), half.to_bits()],
            link: closed.inherited.clone(),
            extras: closed
                .extras
                .iter()
                .map(|&(u, v, a)| [u.to_bits(), v.to_bits(), a.to_bits()])
                .collect(),
            signs: closed.end_signs.map(f64::to_bits),
            ends: ends.map(f64::to_bits),
        }
    }
}

/// Entries kept of each kind: a finite-difference Jacobian's base point and its last moves.
const REUSED_ENTRIES: usize = 4;

impl Reused {
    /// The entry of `key` in `list`, or `make()` kept as the newest (the oldest dropped).
    pub(super) fn get_or_make<T>(
        list: &mut Vec<(PartsKey, Arc<T>)>,
        key: PartsKey,
        make: impl FnOnce() -> T,
    ) -> Arc<T> {
        if let Some((_, parts)) = list.iter().find(|(k, _)| *k == key) {
            return parts.clone();
        }
        let parts = Arc::new(make());
        if list.len() == REUSED_ENTRIES {
            list.remove(0);
        }
        list.push((key, parts.clone()));
        parts
    }
}

/// This thread's [`InnerMaps`] of one grid (kept in [`crate::cache`] between steps), lent to
/// one step and given back when the step ends; or, without
/// [`Accelerations::lent_maps`](super::Accelerations::lent_maps), fresh ones for the step.
/// Allocated afresh at every step the matrices are mapped and zeroed page by page: about half
/// of a recalled step at M = 512, whose matrices hold 10 MB. Every evaluation writes all of
/// them, so what they held before changes nothing.
pub(super) struct LentMaps(pub(super) RefCell<InnerMaps>, Option<bool>);

impl LentMaps {
    /// The maps of the fine grid (`coarse` false) or of the coarse one: this thread's when
    /// `lend`, else fresh ones.
    pub(super) fn lend(coarse: bool, lend: bool) -> Self {
        if lend {
            Self(
                RefCell::new(crate::cache::take_inner_maps(coarse)),
                Some(coarse),
            )
        } else {
            Self(RefCell::default(), None)
        }
    }
}

impl Drop for LentMaps {
    fn drop(&mut self) {
        if let Some(coarse) = self.1 {
            crate::cache::give_back_inner_maps(coarse, self.0.take());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::residual::{Geometry, INNER_TOLERANCE, StepProblem};
    use super::super::tests::{advance_driver, forward_problem};
    use super::*;
    use crate::contact::pressure::Discretisation;

    /// A finite-difference Jacobian's evaluations take the parts their base point shares with
    /// them from [`Reused`] (the sample parts when a stick end moves, the stick parts when the
    /// contact moves), and each such evaluation is bit for bit the one made without them.
    #[test]
    fn reused_parts_leave_the_evaluations_unchanged() {
        use crate::contact::normal::{NormalOptions, solve_normal};
        use crate::history::{DriverState, LoadPoint};
        let sc = crate::scenario::default_scenario();
        let disc = Discretisation::new(64);
        let normal =
            solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default()).unwrap();
        let mut driver = DriverState::after_normal_loading(&normal);
        for (step, f) in [0.1, 0.2].into_iter().enumerate() {
            let q = f * sc.model.friction * sc.normal_load;
            let point = LoadPoint {
                step: step + 1,
                t: (step + 1) as f64,
                q,
            };
            advance_driver(&sc, &disc, &mut driver, point);
        }
        let base = normal.state.traction.stick.clone().map(Arc::new);
        let state = &driver.state;
        let g = Geometry::of(state).expect("slip state");
        let link = state
            .traction
            .stick
            .as_ref()
            .and_then(|z| z.inherited.clone());
        let maps = LentMaps::lend(false, true);
        let (last_link, shared) = (RefCell::new(None), RefCell::new(Reused::default()));
        let with_shared = forward_problem(
            &sc,
            &disc,
            &driver,
            base.as_ref(),
            &maps.0,
            (&last_link, &shared),
        );
        let evaluate = |p: &StepProblem<'_>, g: &Geometry| {
            let (r, s, _) = p
                .evaluate_with(g, state, link.clone(), INNER_TOLERANCE)
                .unwrap();
            (
                r.map(f64::to_bits),
                s.pressure
                    .beta
                    .iter()
                    .map(|b| b.to_bits())
                    .collect::<Vec<_>>(),
            )
        };
        evaluate(&with_shared, &g);
        let d = 1e-6 * g.a;
        let moves = [Geometry { lo: g.lo + d, ..g }, Geometry { a: g.a + d, ..g }];
        for moved in moves {
            let fresh = RefCell::new(Reused::default());
            let with_fresh = StepProblem {
                reused: &fresh,
                ..with_shared
            };
            assert!(evaluate(&with_shared, &moved) == evaluate(&with_fresh, &moved));
        }
        // The base point's sample parts served the moved stick end, its stick parts the moved
        // contact: two entries of each kind, not three.
        let kept = shared.borrow();
        assert_eq!((kept.stick.len(), kept.samples.len()), (2, 2));
    }
}
