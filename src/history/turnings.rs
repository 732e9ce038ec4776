//! The turning points of the load that the contact still remembers, with the spectral solver's
//! state at each one it took ([`Turnings`]): where the spectral solver resumes after the
//! general solver held the end of a phase.
//!
//! # The rule
//! Within a phase, the state depends on the remembered turning states and Q only (the
//! spectral solver's memory, and Mindlin–Deresiewicz for an uncoupled contact). A load that
//! reaches the last turning point of its own direction again closes the loop between that
//! point and the turning point after it, and the contact forgets both (Masing's memory rule,
//! the rainflow count of the load):
//! ```text
//! remembered  R₀ (the start), R₁, …, Rₙ        the phase under way began at Rₙ
//! a step to Q in the direction d of the phase: while n ≥ 2 and d·Q ≥ d·Rₙ₋₁,
//!             forget Rₙ₋₁ and Rₙ (n ← n − 2); at n = 1, at the mirror 2R₀ − R₁ of the
//!             first turning point, forget R₁ (the first loading's state in the other
//!             direction)
//! ```
//! After the loop closed, the phase under way is the phase that ended at `Rₙ₋₁` continued
//! (the first loading, when that was R₁): the state at Q is the one that phase reaches at Q.
//! When the spectral solver took the step that ended it, its driver state there (kept at every
//! turning point; the start's, the end of the normal loading, too) can take the state back by
//! stepping on to Q, although the general solver held the steps of the loop (whose turning
//! states the spectral memory cannot hold); the general solver's state of the step checks it,
//! in its zones and their ends and in its shear tractions. The rule is exact for an uncoupled
//! contact (Mindlin–Deresiewicz); on a coupled one the contact moves with Q, a closed loop can
//! leave memory behind, and the check decides.
//!
//! # Replay
//! After the general solver has held the steps through turning points of its own, no kept
//! state continues the phase under way. At a turning point the general solver took, with one
//! stick zone (a state of the spectral form), the spectral solver rebuilds its state from the
//! most recent kept one by stepping through the reduced history: the turning points
//! remembered after it, then the load of the step. By the rule above that is the history the
//! contact remembers; the general solver's state of the step checks it, as above (on a
//! coupled contact the loops left out can have left memory in the stick zone, a thin stick
//! zone or another shear there, which the spectral state does not have, and the check then
//! refuses it).
//!
//! The loads alone decide what is remembered: as many turning points as the load's open
//! nested loops (a handful in a random history, two in a repeated cycle), with the spectral
//! driver's state at no more than [`KEPT_STATES`] of them.

use serde::{Deserialize, Serialize};

use super::driver::DriverState;

/// Most driver states kept ([`Turnings::end_phase`]): a history whose amplitudes keep
/// shrinking remembers every turning point, and each state holds a contact state and its
/// memory.
const KEPT_STATES: usize = 16;

/// Whether a load going in direction `d` has reached `at` (a turning point reached again
/// closes its loop; to round-off, so that a cycle repeated from load points computed again
/// closes too).
fn reaches(d: f64, load: f64, at: f64) -> bool {
    d * (load - at) >= -1e-12 * load.abs().max(at.abs())
}

/// One remembered turning point.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Turning {
    /// Q or δ at the turning point.
    load: f64,
    /// The spectral driver's state after the step that ended the phase there, when the
    /// spectral solver took it.
    driver: Option<Box<DriverState>>,
}

/// The remembered turning points of a run, oldest first (module docs).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Turnings {
    remembered: Vec<Turning>,
    /// The direction of the last change of the load (0 before the first).
    direction: f64,
    /// Replays ([`Turnings::replay`]) that failed since the last that did not.
    #[serde(default)]
    replays_failed: u32,
    /// Turning points to pass before the next replay.
    #[serde(default)]
    replay_wait: u32,
}

impl Turnings {
    /// The start of a history at `load`, with the spectral driver's state there (the end of
    /// the normal loading), from which the first loading in either direction goes on.
    pub fn new(load: f64, driver: Option<&DriverState>) -> Self {
        Self {
            remembered: vec![Turning {
                load,
                driver: driver.map(|d| Box::new(d.continuation())),
            }],
            direction: 0.0,
            replays_failed: 0,
            replay_wait: 0,
        }
    }

    /// The step from `from` to `to`: the loops it closes are forgotten. Returns the spectral
    /// driver's state at the end of the phase that the step now continues, when a loop closed
    /// and the spectral solver took the step that ended that phase.
    pub fn step(&mut self, from: f64, to: f64) -> Option<Box<DriverState>> {
        if (to - from).abs() <= 0.0 {
            return None;
        }
        let d = (to - from).signum();
        if self.remembered.is_empty() {
            // A state read back from before the turning points were kept.
            self.remembered.push(Turning {
                load: from,
                driver: None,
            });
        }
        if d * self.direction < 0.0 {
            // `from` was a turning point the caller has not ended (a run resumed there).
            self.end_phase(from, None);
        }
        self.direction = d;
        let mut continued = None;
        loop {
            let n = self.remembered.len() - 1;
            if n >= 2 && reaches(d, to, self.remembered[n - 1].load) {
                self.remembered.pop();
                continued = self.remembered.pop().map(|t| t.driver);
            } else if n == 1
                && reaches(
                    d,
                    to,
                    2.0 * self.remembered[0].load - self.remembered[1].load,
                )
            {
                // Past the mirror of the first turning point: the first loading's in the
                // other direction, which goes on from the start.
                self.remembered.pop();
                continued = Some(self.remembered[0].driver.clone());
            } else {
                break;
            }
        }
        continued.flatten()
    }

    /// The step that ended a phase at `load`, with the spectral driver's state after it when
    /// the spectral solver took it. At most [`KEPT_STATES`] driver states are kept: the first
    /// turning point's and the most recent ones.
    pub fn end_phase(&mut self, load: f64, driver: Option<&DriverState>) {
        self.push(load, driver);
        let mut kept = self
            .remembered
            .iter()
            .filter(|t| t.driver.is_some())
            .count();
        for t in self.remembered.iter_mut().skip(2) {
            if kept <= KEPT_STATES {
                break;
            }
            if t.driver.take().is_some() {
                kept -= 1;
            }
        }
    }

    fn push(&mut self, load: f64, driver: Option<&DriverState>) {
        let last = self.remembered.last().map(|t| t.load);
        if last.is_some_and(|l| l.to_bits() == load.to_bits()) {
            // Already ended there (the step after a resumed run's turning point).
            if let (Some(t), Some(d)) = (self.remembered.last_mut(), driver) {
                t.driver.get_or_insert_with(|| Box::new(d.continuation()));
            }
            return;
        }
        self.remembered.push(Turning {
            load,
            driver: driver.map(|d| Box::new(d.continuation())),
        });
    }

    /// The most recent turning point with a kept driver state, that state, and the loads of
    /// the turning points remembered after it, oldest first: the reduced history from which
    /// the spectral solver can rebuild its state (module docs, *Replay*). `None` when no state
    /// is kept, or when the last replay failed fewer turning points ago than its wait (1, 3,
    /// 7, … up to 31 after 1, 2, 3, … failures in a row, so that a history the spectral
    /// solver cannot rebuild costs at most one replay in 32 turning points).
    pub fn replay(&mut self) -> Option<(&DriverState, Vec<f64>)> {
        if self.replay_wait > 0 {
            self.replay_wait -= 1;
            return None;
        }
        let j = self.remembered.iter().rposition(|t| t.driver.is_some())?;
        let loads = self.remembered[j + 1..].iter().map(|t| t.load).collect();
        let driver = self.remembered[j].driver.as_deref()?;
        Some((driver, loads))
    }

    /// The outcome of the replay [`Turnings::replay`] gave.
    pub fn replayed(&mut self, taken: bool) {
        if taken {
            self.replays_failed = 0;
        } else {
            self.replays_failed += 1;
            self.replay_wait = (1u32 << self.replays_failed.min(5)) - 1;
        }
    }

    /// The loads remembered, oldest first.
    pub fn loads(&self) -> Vec<f64> {
        self.remembered.iter().map(|t| t.load).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Walk loads, ending a phase at each reversal, and return what is remembered.
    fn walk(loads: &[f64]) -> Vec<f64> {
        let mut t = Turnings::new(loads[0], None);
        for w in loads.windows(3) {
            t.step(w[0], w[1]);
            if (w[1] - w[0]) * (w[2] - w[1]) < 0.0 {
                t.end_phase(w[1], None);
            }
        }
        let n = loads.len();
        t.step(loads[n - 2], loads[n - 1]);
        t.loads()
    }

    /// Masing's rule on a hand-made history: a loop that closes is forgotten, a nested one
    /// inside it first; at the mirror of the first turning point the first loading in the
    /// other direction is reached; a repeated cycle remembers no more than its own turning
    /// point.
    #[test]
    fn a_closed_loop_is_forgotten_and_an_open_one_remembered() {
        // 0 → 5 → −5 (the first loading's mirror) → 3 → −2 → 4: (3, −2) closes at 4 > 3.
        assert_eq!(walk(&[0.0, 5.0, -5.0, 3.0, -2.0, 4.0]), vec![0.0, -5.0]);
        // … → 2: still inside, (3, −2) remembered.
        assert_eq!(
            walk(&[0.0, 5.0, -5.0, 3.0, -2.0, 2.0]),
            vec![0.0, -5.0, 3.0, -2.0]
        );
        // 0 → 5 → −5 → 3 → −2 → 1 → −1 → 4: (1, −1) then (3, −2) close.
        assert_eq!(
            walk(&[0.0, 5.0, -5.0, 3.0, -2.0, 1.0, -1.0, 4.0]),
            vec![0.0, -5.0]
        );
        // Past the mirror: 0 → 5 → −6, and 0 → 5 → −4 → 6.
        assert_eq!(walk(&[0.0, 5.0, -6.0]), vec![0.0]);
        assert_eq!(walk(&[0.0, 5.0, -4.0]), vec![0.0, 5.0]);
        assert_eq!(walk(&[0.0, 5.0, -4.0, 6.0]), vec![0.0]);
        // A loop inside: 0 → 5 → −4 → 2 → −3: (−4, 2) stays open.
        assert_eq!(
            walk(&[0.0, 5.0, -4.0, 2.0, -3.0]),
            vec![0.0, 5.0, -4.0, 2.0]
        );
        // ±5 repeated 50 times.
        let cycle: Vec<f64> = (0..101)
            .map(|k| match k {
                0 => 0.0,
                k if k % 2 == 1 => 5.0,
                _ => -5.0,
            })
            .collect();
        assert!(walk(&cycle).len() <= 2, "{:?}", walk(&cycle));
    }
}
