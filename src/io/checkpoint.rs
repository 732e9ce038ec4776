//! Checkpoints of a run, and resuming from one (`fretsim run SCENARIO --resume DIR`).
//!
//! While a run solves its history, its staging folder (`.NAME.fretsim-new`, beside the output
//! folder, [`super::folder`]) holds `checkpoint/`: at every turning point of the load and at
//! the last step ([`crate::history::turning_points`]) the records of the steps since the last
//! checkpoint are appended to `records.jsonl` (one JSON record a line), and `state.json` is
//! replaced (written aside, then renamed) by the state after the step:
//!
//! - `fretsim_version` and `scenario` (the scenario as read): a checkpoint resumes only the
//!   same scenario with the same fretsim;
//! - `step`, the last step taken, and `records`, the number of lines of `records.jsonl` that
//!   belong to it (a run killed between the two writes leaves more lines, which the resumed
//!   run drops);
//! - `snapshots`: the states kept for the field files (turning points, snapshot instants, the
//!   previous step) and the handovers so far;
//! - `state`: everything the next step needs ([`HistoryState`]).
//!
//! Values shared by several states are written once (`crate::shared`). A run resumed from a
//! checkpoint takes the same steps, to the bit, as the run that wrote it would have taken, so
//! its output folder is byte for byte the uninterrupted run's. A resumed run reads the records
//! back a line at a time (into `steps.csv` and what the outputs take from them), never all at
//! once. The checkpoint is removed when the output folder is committed; a failed run's last
//! state is in its `failure.json`.

use serde::{Deserialize, Serialize};

use crate::error::Error;
use crate::history::{
    HistoryState, HistoryStateData, HistoryStateView, SolvedState, SolvedStateData, StepRecord,
};
use crate::io::summary::HandoverLog;
use crate::scenario::Scenario;

/// The states a run keeps for its field files and the handovers so far (see
/// `super::run::Snapshots`); `S` is [`SolvedState`], or [`SolvedStateData`] as read.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct Kept<S = SolvedState> {
    /// The last step and its state (a turning point once the next step begins a phase).
    pub(crate) previous: Option<(StepRecord, S)>,
    /// The turning points kept.
    pub(crate) turning: Vec<(StepRecord, S)>,
    /// The last two turning points after phase 3 (`output.turning_point_fields` =
    /// `first_and_last`).
    pub(crate) last: Vec<(StepRecord, S)>,
    /// The last step at each snapshot time.
    pub(crate) at_times: Vec<Option<(StepRecord, S)>>,
    /// The steps handed to the general solver.
    pub(crate) handovers: HandoverLog,
    /// The fretting-fatigue indicators under way (a run with a history).
    #[serde(default)]
    pub(crate) fatigue: Option<crate::fatigue::FatigueAnalysis>,
}

impl Kept<SolvedStateData> {
    /// The states read back, for the scenario's model.
    fn restore(self, scenario: &Scenario) -> Kept {
        let model = &scenario.model;
        let one = |(r, s): (StepRecord, SolvedStateData)| (r, SolvedState::restore(model, s));
        Kept {
            previous: self.previous.map(one),
            turning: self.turning.into_iter().map(one).collect(),
            last: self.last.into_iter().map(one).collect(),
            at_times: self.at_times.into_iter().map(|s| s.map(one)).collect(),
            handovers: self.handovers,
            fatigue: self.fatigue,
        }
    }
}

#[derive(Serialize)]
struct Written<'a> {
    fretsim_version: &'static str,
    scenario: serde_json::Value,
    step: usize,
    records: usize,
    snapshots: &'a Kept,
    state: HistoryStateView<'a>,
}

#[derive(Deserialize)]
struct Read {
    fretsim_version: String,
    scenario: serde_json::Value,
    step: usize,
    records: usize,
    snapshots: Kept<SolvedStateData>,
    state: HistoryStateData,
}

/// Where a written run puts what it writes while its history runs: its checkpoints, and the
/// files written as the steps are taken (`steps.csv`).
pub(crate) trait RunSink {
    /// Append `records` (JSON lines) to the records and replace the state by `state`.
    fn save(&mut self, state: &[u8], records: &[u8]) -> Result<(), Error>;
    /// Create the file `relative` of the output; its path and a writer.
    fn create(
        &mut self,
        relative: &str,
    ) -> Result<(std::path::PathBuf, Box<dyn std::io::Write>), Error>;
}

impl RunSink for super::folder::RunFolder {
    fn save(&mut self, state: &[u8], records: &[u8]) -> Result<(), Error> {
        self.save_checkpoint(state, records)
    }

    fn create(
        &mut self,
        relative: &str,
    ) -> Result<(std::path::PathBuf, Box<dyn std::io::Write>), Error> {
        let (path, writer) = super::folder::RunFolder::create(self, relative)?;
        Ok((path, Box::new(writer)))
    }
}

/// `state.json`'s text for the state after step `step`, with `records` records so far.
pub(crate) fn write_state(
    scenario: &Scenario,
    step: usize,
    records: usize,
    snapshots: &Kept,
    state: HistoryStateView<'_>,
) -> Vec<u8> {
    let written = Written {
        fretsim_version: env!("CARGO_PKG_VERSION"),
        scenario: serde_json::to_value(&scenario.raw).expect("a scenario is written"),
        step,
        records,
        snapshots,
        state,
    };
    crate::shared::write_shared(|| serde_json::to_vec(&written)).expect("a state is written")
}

/// Records as JSON lines.
pub(crate) fn write_records(records: &[StepRecord]) -> Vec<u8> {
    let mut out = Vec::new();
    for r in records {
        serde_json::to_writer(&mut out, r).expect("a record is written");
        out.push(b'\n');
    }
    out
}

/// What a run resumes from: the records of the steps taken, the kept states and the state
/// after the last step.
#[derive(Debug)]
pub struct Resume {
    /// The last step taken.
    pub step: usize,
    /// Its records (step 0 = end of normal loading), read back one at a time.
    pub(crate) records: RecordLines,
    pub(crate) snapshots: Kept,
    /// The state after the last step.
    pub state: HistoryState,
}

/// The records of a checkpoint: the first `count` lines of its `records.jsonl`, read from the
/// file opened before the claim of the folder (which replaces the file), one record at a time.
#[derive(Debug)]
pub(crate) struct RecordLines {
    file: std::fs::File,
    count: usize,
    /// The folder, for the messages.
    shown: std::path::PathBuf,
}

impl RecordLines {
    /// Each record in order, to `take`, and how many there were.
    pub(crate) fn replay(&mut self, mut take: impl FnMut(StepRecord)) -> Result<usize, Error> {
        use std::io::{BufRead, Seek};
        let mut each = || -> std::io::Result<()> {
            self.file.seek(std::io::SeekFrom::Start(0))?;
            let mut reader = std::io::BufReader::new(&self.file);
            let mut line = Vec::new();
            for _ in 0..self.count {
                line.clear();
                reader.read_until(b'\n', &mut line)?;
                take(serde_json::from_slice(strip_newline(&line))?);
            }
            Ok(())
        };
        each().map_err(|e| Error::Resume {
            path: self.shown.clone(),
            reason: format!("its records cannot be read again ({e})"),
        })?;
        Ok(self.count)
    }
}

/// A line without its newline.
fn strip_newline(line: &[u8]) -> &[u8] {
    line.strip_suffix(b"\n").unwrap_or(line)
}

/// The checkpoint in `state` (the bytes of `state.json`) and `records` (its `records.jsonl`,
/// read a line at a time), for `scenario`, with the length in bytes of the lines of
/// `records.jsonl` that belong to it (a run killed between the two writes of a checkpoint
/// leaves more); why not, when it was written for another scenario or version or cannot be
/// read (`shown`: the folder, for the messages).
pub fn read_checkpoint(
    scenario: &Scenario,
    state: &[u8],
    records: &mut std::fs::File,
    shown: &std::path::Path,
) -> Result<(Resume, u64), Error> {
    let refuse = |reason: String| Error::Resume {
        path: shown.to_path_buf(),
        reason,
    };
    let read: Read = crate::shared::read_shared(|| serde_json::from_slice(state))
        .map_err(|e| refuse(format!("its checkpoint cannot be read ({e})")))?;
    if read.fretsim_version != env!("CARGO_PKG_VERSION") {
        return Err(refuse(format!(
            "its checkpoint was written by fretsim {}, this is {}",
            read.fretsim_version,
            env!("CARGO_PKG_VERSION")
        )));
    }
    let ours = serde_json::to_value(&scenario.raw).expect("a scenario is written");
    if read.scenario != ours {
        return Err(refuse(
            "its checkpoint was written for another scenario (the scenario file changed, or \
             another one was given)"
                .into(),
        ));
    }
    // Every record is read (one at a time) before the run is resumed: a checkpoint that
    // cannot be replayed is refused while it is still in place.
    let unreadable = |e: std::io::Error| refuse(format!("its records cannot be read ({e})"));
    let mut reader = std::io::BufReader::new(&*records);
    let (mut lines, mut bytes, mut last_step) = (0, 0u64, None);
    let mut line = Vec::new();
    while lines < read.records {
        line.clear();
        let n = std::io::BufRead::read_until(&mut reader, b'\n', &mut line).map_err(unreadable)?;
        if n == 0 {
            break;
        }
        let record: StepRecord = serde_json::from_slice(strip_newline(&line))
            .map_err(|e| refuse(format!("a step of its checkpoint cannot be read ({e})")))?;
        last_step = Some(record.step);
        lines += 1;
        bytes += n as u64;
    }
    if lines < read.records {
        return Err(refuse(format!(
            "its checkpoint lists {} steps and holds {}",
            read.records, lines
        )));
    }
    if last_step != Some(read.step) {
        return Err(refuse(
            "its checkpoint's steps end elsewhere than its state".into(),
        ));
    }
    let file = records.try_clone().map_err(unreadable)?;
    let resume = Resume {
        step: read.step,
        records: RecordLines {
            file,
            count: read.records,
            shown: shown.to_path_buf(),
        },
        snapshots: read.snapshots.restore(scenario),
        state: HistoryState::restore(&scenario.model, read.state),
    };
    Ok((resume, bytes))
}
