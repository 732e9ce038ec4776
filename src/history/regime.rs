//! The closed set of solver states ([`Regime`]: normal loading, stick (hold), forward slip,
//! reverse slip) and the rule for the next one, a pure function of the sign of ΔQ
//! ([`next_regime`]; module docs of [`crate::history`], "States and transitions").

use serde::{Deserialize, Serialize};

/// Solver state of a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Regime {
    /// Monotonic normal loading (Spence's self-similar state).
    NormalLoading,
    /// Hold: ΔQ = 0, whole state unchanged.
    Stick,
    /// ΔQ > 0: both slip zones carry `q = +ηp`.
    ForwardSlip,
    /// ΔQ < 0: both slip zones carry `q = −ηp`.
    ReverseSlip,
}

impl Regime {
    /// `q/(ηp)` in the slip zones, `None` when nothing slips.
    pub fn slip_sign(self) -> Option<f64> {
        match self {
            Regime::ForwardSlip => Some(1.0),
            Regime::ReverseSlip => Some(-1.0),
            Regime::Stick | Regime::NormalLoading => None,
        }
    }
}

impl std::fmt::Display for Regime {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Regime::NormalLoading => "normal loading",
            Regime::Stick => "stick",
            Regime::ForwardSlip => "forward slip",
            Regime::ReverseSlip => "reverse slip",
        })
    }
}

/// The regime of a step with load increment `dq` (pure; `tol` absorbs round-off in ΔQ).
pub fn next_regime(dq: f64, tol: f64) -> Regime {
    if dq > tol {
        Regime::ForwardSlip
    } else if dq < -tol {
        Regime::ReverseSlip
    } else {
        Regime::Stick
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transition_table() {
        let tol = 1e-9;
        for (dq, expected) in [
            (1.0, Regime::ForwardSlip),
            (-1.0, Regime::ReverseSlip),
            (0.0, Regime::Stick),
            (1e-12, Regime::Stick),
        ] {
            assert_eq!(next_regime(dq, tol), expected, "dq = {dq}");
        }
        assert_eq!(Regime::ForwardSlip.slip_sign(), Some(1.0));
        assert_eq!(Regime::ReverseSlip.slip_sign(), Some(-1.0));
        assert_eq!(Regime::Stick.slip_sign(), None);
        assert_eq!(Regime::NormalLoading.slip_sign(), None);
    }
}
