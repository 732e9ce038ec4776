//! The surface-strain memory `∂ux/∂x` that points carry while they stick (seed Section 4:
//! "calculated and stored" at the end of normal loading and at every reversal).
//!
//! A point in the stick zone of a monotonic phase keeps the strain it had when the phase began.
//! At the end of a phase with final stick zone `[lo, hi]`, points outside it take the strain of
//! the end state, computed exactly from eq. (A) of [`crate::halfplane`] with that state's
//! representations (`−(w12 + χ w13) p − w13 w + y11 H'q`), while points inside keep their
//! previous memory. The memory is therefore piecewise: each piece remembers the state (or the
//! normal-loading law `C|x|`) it came from and evaluates it exactly at any x, so nothing is lost
//! at the old stick/slip kinks and no resampling error accumulates over cycles. Pieces that are
//! overwritten drop their source, so a steady cyclic history keeps a bounded number of pieces.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::{ContactModel, ContactState};

/// Where the strain of a memory piece comes from.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum StrainSource {
    /// Spence's self-similar normal-loading law `∂ux/∂x = C|x|` (seed eq. 20).
    Linear {
        /// C (1/m).
        slope: f64,
    },
    /// The strain of a stored end-of-phase state (eq. A evaluated exactly).
    State {
        /// The state.
        #[serde(with = "crate::shared")]
        state: Arc<ContactState>,
    },
}

/// One piece `[lo, hi]` of the memory.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Piece {
    /// Left end (m; −∞ for the first piece).
    #[serde(with = "crate::shared::extended")]
    pub lo: f64,
    /// Right end (m; +∞ for the last piece).
    #[serde(with = "crate::shared::extended")]
    pub hi: f64,
    /// Source of the strain.
    #[serde(with = "crate::shared")]
    pub source: Arc<StrainSource>,
}

/// The stored strain field, covering the whole real line.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Memory {
    /// Pieces in increasing x, contiguous.
    pub pieces: Vec<Piece>,
}

impl Memory {
    /// Memory at the end of normal loading: `C|x|` on the stick zone `[lo, hi]`, the end state
    /// elsewhere.
    pub fn after_normal_loading(state: Arc<ContactState>, slope: f64, lo: f64, hi: f64) -> Self {
        let state = Arc::new(state.as_ref().clone().frozen());
        let outside = Arc::new(StrainSource::State { state });
        Self {
            pieces: vec![
                Piece {
                    lo: f64::NEG_INFINITY,
                    hi: lo,
                    source: outside.clone(),
                },
                Piece {
                    lo,
                    hi,
                    source: Arc::new(StrainSource::Linear { slope }),
                },
                Piece {
                    lo: hi,
                    hi: f64::INFINITY,
                    source: outside,
                },
            ],
        }
    }

    /// Memory at the start of the next phase: `state`'s strain outside its stick zone
    /// `[lo, hi]`, the current memory inside.
    pub fn committed(&self, state: Arc<ContactState>, lo: f64, hi: f64) -> Self {
        let state = Arc::new(state.as_ref().clone().frozen());
        let outside = Arc::new(StrainSource::State { state });
        let mut pieces = vec![Piece {
            lo: f64::NEG_INFINITY,
            hi: lo,
            source: outside.clone(),
        }];
        for p in &self.pieces {
            let (a, b) = (p.lo.max(lo), p.hi.min(hi));
            if b > a {
                pieces.push(Piece {
                    lo: a,
                    hi: b,
                    source: p.source.clone(),
                });
            }
        }
        pieces.push(Piece {
            lo: hi,
            hi: f64::INFINITY,
            source: outside,
        });
        Self { pieces }
    }

    /// The remembered strain at x.
    pub fn strain(&self, model: &ContactModel, x: f64) -> f64 {
        match self.piece_at(x).source.as_ref() {
            StrainSource::Linear { slope } => slope * x.abs(),
            StrainSource::State { state } => state.strain_at(model, x),
        }
    }

    /// The piece that holds x (the first whose right end is not below x).
    fn piece_at(&self, x: f64) -> &Piece {
        self.pieces
            .iter()
            .find(|p| x <= p.hi)
            .unwrap_or_else(|| self.pieces.last().expect("pieces"))
    }

    /// [`Self::strain`] at each of `xs` into `out`, bit for bit: each run of consecutive points
    /// in one piece in a batch ([`ContactState::strains_into`]).
    pub fn strains_into(&self, model: &ContactModel, xs: &[f64], out: &mut Vec<f64>) {
        out.clear();
        let mut values = Vec::new();
        let mut start = 0;
        while start < xs.len() {
            let piece = self.piece_at(xs[start]);
            let run = xs[start..]
                .iter()
                .take_while(|&&x| std::ptr::eq(self.piece_at(x), piece))
                .count();
            let batch = &xs[start..start + run];
            match piece.source.as_ref() {
                StrainSource::Linear { slope } => out.extend(batch.iter().map(|x| slope * x.abs())),
                StrainSource::State { state } => {
                    state.strains_into(model, batch, &mut values);
                    out.extend(&values);
                }
            }
            start += run;
        }
    }

    /// The stored end-of-phase states (turning points) whose tangential load is within `tol`
    /// of `load`, each once.
    pub fn states_at_load(&self, load: f64, tol: f64) -> Vec<Arc<ContactState>> {
        let mut found: Vec<Arc<ContactState>> = Vec::new();
        for p in &self.pieces {
            if let StrainSource::State { state } = p.source.as_ref()
                && (state.tangential_load - load).abs() <= tol
                && !found.iter().any(|f| Arc::ptr_eq(f, state))
            {
                found.push(state.clone());
            }
        }
        found
    }

    /// The interior breakpoints (old stick/slip boundaries), for output.
    pub fn breakpoints(&self) -> Vec<f64> {
        self.pieces.iter().skip(1).map(|p| p.lo).collect()
    }
}
