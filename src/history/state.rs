//! What a run carries from one load step to the next ([`HistoryState`]): the spectral driver's
//! committed state and memory ([`DriverState`]) and, while the general solver holds the
//! steps, its run ([`GeneralRun`]). Plain data: written by serde ([`HistoryState`] is
//! `Serialize`; [`HistoryStateData`] is what is read back, [`HistoryState::restore`] rebuilds
//! the general solver for the model) and read back to the bit, so that a run continued from a
//! state read back takes the same steps, to the bit, as the run that wrote it.
//!
//! Values that several parts of the state share (a turning state in the memory, the recall
//! traces and the phase's base) are written once ([`crate::shared`]); the tables that only make
//! evaluations faster are written as what they were built with and rebuilt on reading.

use serde::{Deserialize, Serialize};

use crate::contact::ContactModel;

use super::driver::DriverState;
use super::general::{GeneralRun, GeneralRunData};
use super::turnings::Turnings;

/// Everything a step needs from the past.
#[derive(Debug, Clone)]
pub struct HistoryState {
    /// The spectral solver's committed state, memory, phase and displacement datum (while the
    /// general solver holds the steps: those of the step it took over at); `None` when the
    /// general solver took the normal loading, whose past the spectral memory cannot describe
    /// (then the general solver holds every step, [`super::NormalEnd`]). One of the two is
    /// always there.
    pub driver: Option<DriverState>,
    /// The general solver's run while it holds the steps.
    pub general: Option<GeneralRun>,
    /// The turning points of the load still remembered, with the spectral solver's state at
    /// each it took.
    pub turnings: Turnings,
}

/// A [`HistoryState`] as read back, before its general solver is rebuilt.
#[derive(Debug, Clone)]
pub struct HistoryStateData {
    driver: Option<DriverState>,
    general: Option<GeneralRunData>,
    turnings: Turnings,
}

/// A borrowed [`HistoryState`], as a run passes it to [`super::Observer::on_checkpoint`];
/// written as the state is.
#[derive(Debug, Clone, Copy)]
pub struct HistoryStateView<'a> {
    /// See [`HistoryState::driver`].
    pub driver: Option<&'a DriverState>,
    /// See [`HistoryState::general`].
    pub general: Option<&'a GeneralRun>,
    /// See [`HistoryState::turnings`].
    pub turnings: &'a Turnings,
}

#[derive(Serialize)]
struct Written<'a> {
    driver: Option<&'a DriverState>,
    general: Option<&'a GeneralRun>,
    turnings: &'a Turnings,
}

#[derive(Deserialize)]
struct Read {
    driver: Option<DriverState>,
    general: Option<GeneralRunData>,
    #[serde(default)]
    turnings: Turnings,
}

impl Serialize for HistoryStateView<'_> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let written = Written {
            driver: self.driver,
            general: self.general,
            turnings: self.turnings,
        };
        crate::shared::write_shared(|| written.serialize(serializer))
    }
}

impl Serialize for HistoryState {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.view().serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for HistoryStateData {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let Read {
            driver,
            general,
            turnings,
        } = crate::shared::read_shared(|| Read::deserialize(deserializer))?;
        Ok(Self {
            driver,
            general,
            turnings,
        })
    }
}

impl HistoryState {
    /// The state at the start of a run from a driver.
    pub fn new(driver: DriverState) -> Self {
        Self {
            turnings: Turnings::new(driver.state.tangential_load, Some(&driver)),
            driver: Some(driver),
            general: None,
        }
    }

    /// The borrowed view.
    pub fn view(&self) -> HistoryStateView<'_> {
        HistoryStateView {
            driver: self.driver.as_ref(),
            general: self.general.as_ref(),
            turnings: &self.turnings,
        }
    }

    /// The state read back as `data`, for `model` (the model of the run that wrote it).
    pub fn restore(model: &ContactModel, data: HistoryStateData) -> Self {
        Self {
            driver: data.driver,
            general: data.general.map(|run| GeneralRun::restore(model, run)),
            turnings: data.turnings,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::pressure::Discretisation;
    use crate::history::{
        LoadPoint, Observer, RunOptions, SolverChoice, StepRecord, continue_run,
        driver_after_normal_loading,
    };

    /// Keeps each checkpoint as written (JSON), with the step it follows.
    #[derive(Default)]
    struct Checkpoints(Vec<(usize, String)>);

    impl Observer for Checkpoints {
        fn on_checkpoint(&mut self, last: &StepRecord, state: HistoryStateView<'_>) {
            let json = serde_json::to_string(&state).expect("a state is written");
            self.0.push((last.step, json));
        }
    }

    fn written(records: &[StepRecord]) -> Vec<String> {
        records
            .iter()
            .map(|r| serde_json::to_string(r).expect("a record is written"))
            .collect()
    }

    /// A run of the default scenario's first `cycles`·4 + 1 load segments under `solver`,
    /// then, from each checkpoint it wrote (read back), the rest of the run again: the state
    /// read back writes the same text, and the steps after it are those of the uninterrupted
    /// run to the bit (every field of every record, written with the shortest text that reads
    /// back to the same `f64`).
    fn continue_from_every_checkpoint(solver: SolverChoice, segments: usize) {
        let sc = crate::scenario::default_scenario();
        let disc = Discretisation::new(sc.collocation_points);
        let start = HistoryState::new(driver_after_normal_loading(&sc, &disc));
        continue_from_every_checkpoint_of(&sc, start, solver, segments);
    }

    /// [`continue_from_every_checkpoint`] for scenario `sc` (its history) from `start`.
    fn continue_from_every_checkpoint_of(
        sc: &crate::scenario::Scenario,
        start: HistoryState,
        solver: SolverChoice,
        segments: usize,
    ) {
        let disc = Discretisation::new(sc.collocation_points);
        let history = sc.history.as_ref().expect("a history");
        let points: Vec<LoadPoint> = history
            .load_points()
            .into_iter()
            .take(segments * history.steps_per_segment)
            .collect();
        let options = RunOptions::new(solver);
        let mut state = start;
        let mut checkpoints = Checkpoints::default();
        let mut records = Vec::new();
        let failure = continue_run(
            &sc.model,
            &disc,
            &mut state,
            &points,
            options,
            &mut checkpoints,
            &mut records,
        );
        assert!(failure.is_none());
        assert!(
            checkpoints.0.len() >= 2,
            "{} checkpoints",
            checkpoints.0.len()
        );
        let all = written(&records);
        for (step, json) in &checkpoints.0 {
            let data: HistoryStateData = serde_json::from_str(json).expect("a state is read");
            let mut restored = HistoryState::restore(&sc.model, data);
            assert_eq!(
                &serde_json::to_string(&restored).unwrap(),
                json,
                "the state after step {step} reads back to the text it was written as"
            );
            let rest: Vec<LoadPoint> = points.iter().filter(|p| p.step > *step).copied().collect();
            let mut more = Vec::new();
            let failure = continue_run(
                &sc.model,
                &disc,
                &mut restored,
                &rest,
                options,
                &mut crate::history::NoObserver,
                &mut more,
            );
            assert!(failure.is_none());
            assert_eq!(written(&more), all[*step..], "the steps after step {step}");
        }
    }

    #[test]
    fn a_run_continued_from_a_checkpoint_read_back_takes_the_same_steps_to_the_bit() {
        continue_from_every_checkpoint(SolverChoice::Auto, 8);
    }

    #[test]
    fn a_general_solver_run_continued_from_a_checkpoint_takes_the_same_steps_to_the_bit() {
        continue_from_every_checkpoint(SolverChoice::General, 3);
    }

    /// A run from the unloaded punch (`normal_load` 0): the state a checkpoint holds is the
    /// general solver's from the first step, whose mesh is made for the contact it presses.
    #[test]
    fn a_run_from_the_unloaded_punch_continued_from_a_checkpoint_takes_the_same_steps() {
        let raw = crate::scenario::parse(
            r#"{ "name": "from_zero",
              "material": { "kind": "elastic", "shear_modulus": 27.3e9, "poisson_ratio": 0.3 },
              "punch": { "radius": 0.01 }, "friction": 0.3, "normal_load": 0.0,
              "tangential_history": { "unit": "newton_per_metre",
                "points": [[0, 0, 0], [1, 300, 2240], [2, -100, 2240], [3, 300, 2240]],
                "steps_per_segment": 5, "max_step": 1000 } }"#,
            std::path::Path::new("<test>"),
        )
        .expect("parses");
        continue_from_every_checkpoint_without_a_driver(
            &crate::scenario::validate(raw).expect("valid"),
        );
    }

    /// A run whose normal loading the general solver took (no spectral driver in the state).
    #[test]
    fn a_run_loaded_by_the_general_solver_continued_from_a_checkpoint_takes_the_same_steps() {
        continue_from_every_checkpoint_without_a_driver(&crate::history::default_scenario_with(
            0.1, 2e-7,
        ));
    }

    /// [`continue_from_every_checkpoint_of`] for a scenario whose run starts from the general
    /// solver's state (its normal loading, or the unloaded punch), under `auto`.
    fn continue_from_every_checkpoint_without_a_driver(sc: &crate::scenario::Scenario) {
        let disc = Discretisation::new(sc.collocation_points);
        let start = crate::history::NormalEnd::solve(
            &sc.model,
            &disc,
            sc.normal_load,
            SolverChoice::Auto,
            crate::history::general::INNER_SIZE,
        )
        .unwrap()
        .history_state();
        assert!(start.driver.is_none());
        continue_from_every_checkpoint_of(sc, start, SolverChoice::Auto, 3);
    }
}
