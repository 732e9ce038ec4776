//! The closed set of solver states ([`Regime`]: normal loading, stick (hold), forward slip,
//! reverse slip) and the rule for the next one, a pure function of the sign of ΔQ
//! ([`next_regime`]; module docs of [`crate::history`], "States and transitions"), and the
//! phase rule ([`phase_event`]).

use serde::{Deserialize, Serialize};

/// Solver state of a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Regime {
    /// Monotonic normal loading (Spence's self-similar state).
    NormalLoading,
    /// Hold: ΔQ = 0; the state is unchanged unless the step changes P or the electric load.
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

/// What a step does to the current phase (the monotonic stretch of Q since the last
/// reversal).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PhaseEvent {
    /// The step continues the current phase, or changes nothing (a hold).
    Continue,
    /// The step begins a phase that slips with this sign (`q/(ηp)` in its slip zones): the
    /// first slip after normal loading, or a reversal. The state it starts from is the turning
    /// state whose ∂ux/∂x the new phase's stick zones keep (the paper's stored memory at
    /// Q = Q_max, Section 4).
    Begin(f64),
}

/// The phase rule (pure): a slip step begins a phase when its sign differs from the current
/// phase's (`None` before the first slip); a hold and normal loading begin none.
pub fn phase_event(current: Option<f64>, regime: Regime) -> PhaseEvent {
    match regime.slip_sign() {
        Some(sign) if current != Some(sign) => PhaseEvent::Begin(sign),
        _ => PhaseEvent::Continue,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every (current phase, regime) pair.
    #[test]
    fn phase_rule_table() {
        use PhaseEvent::{Begin, Continue};
        use Regime::{ForwardSlip, NormalLoading, ReverseSlip, Stick};
        let table = [
            (None, ForwardSlip, Begin(1.0)),
            (None, ReverseSlip, Begin(-1.0)),
            (None, Stick, Continue),
            (None, NormalLoading, Continue),
            (Some(1.0), ForwardSlip, Continue),
            (Some(1.0), ReverseSlip, Begin(-1.0)),
            (Some(1.0), Stick, Continue),
            (Some(-1.0), ForwardSlip, Begin(1.0)),
            (Some(-1.0), ReverseSlip, Continue),
            (Some(-1.0), Stick, Continue),
        ];
        for (current, regime, expected) in table {
            assert_eq!(
                phase_event(current, regime),
                expected,
                "{current:?}, {regime}"
            );
        }
    }

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
