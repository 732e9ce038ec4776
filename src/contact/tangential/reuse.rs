//! What one step keeps for the next: each thread's inner-iteration matrices, lent from step to
//! step (`LentMaps`). They change no result: every output stays byte-identical without them
//! ([`Accelerations::lent_maps`]).
//!
//! [`Accelerations::lent_maps`]: super::Accelerations::lent_maps

use std::cell::RefCell;

use super::inner::InnerMaps;

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
