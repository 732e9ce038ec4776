//! Checkpoints and `fretsim run SCENARIO --resume DIR`: a run killed part-way and resumed
//! (possibly more than once) writes its output folder byte for byte as the uninterrupted run
//! does; a checkpoint of another scenario is refused with exit 2 and left as it was; a folder
//! without a checkpoint is run from the start.

use std::path::Path;
use std::process::Output;

use crate::cli::{fretsim, scenario_path};
use crate::output_safety::{paused, paused_run, snapshot};

fn resume(scenario: Option<&Path>, dir: &Path, pause: Option<&str>) -> Output {
    let mut cmd = fretsim();
    cmd.arg("run");
    if let Some(s) = scenario {
        cmd.arg(s);
    }
    if let Some(stage) = pause {
        cmd.env("FRETSIM_PAUSE_AT", stage);
    }
    cmd.arg("--resume")
        .arg(dir)
        .arg("--quiet")
        .output()
        .unwrap()
}

fn full_run(scenario: Option<&Path>, out: &Path) {
    let mut cmd = fretsim();
    cmd.arg("run");
    if let Some(s) = scenario {
        cmd.arg(s);
    }
    let o = cmd.arg("--out").arg(out).arg("--quiet").output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The built-in run (three cycles, seven checkpoints) killed at its third checkpoint, resumed
/// and killed again at the resumed run's second checkpoint (the fifth of the run), then
/// resumed to the end: every file of the output folder (CSV, JSON, SVG, HTML, manifest) is
/// the uninterrupted run's, byte for byte, and no hidden folder is left beside it. The same
/// for a history that changes P, and the Figure-4 history with its PNG plots, killed once.
#[test]
fn a_run_killed_and_resumed_writes_the_uninterrupted_runs_output_byte_for_byte() {
    let tmp = tempfile::tempdir().unwrap();
    let full = tmp.path().join("full");
    let part = tmp.path().join("part");
    full_run(None, &full);
    killed(paused_run(None, &part, "checkpoint 3"));
    killed(paused_run_resuming(None, &part, "checkpoint 2"));
    let o = resume(None, &part, None);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(
        stderr.contains("resuming") && stderr.contains("after step"),
        "{stderr}"
    );
    assert_eq!(snapshot(&part), snapshot(&full));
    let hidden: Vec<_> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");

    // A history that changes P: the general solver's run (its mesh made for the last change
    // of P) is the checkpoint's state.
    let in_phase = scenario_path("normal_load_in_phase");
    let (full, part) = (tmp.path().join("full_p"), tmp.path().join("part_p"));
    full_run(Some(&in_phase), &full);
    killed(paused_run(Some(&in_phase), &part, "checkpoint 3"));
    let o = resume(Some(&in_phase), &part, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(snapshot(&part), snapshot(&full));

    let figure4 = scenario_path("figure4_fretting");
    let (full, part) = (tmp.path().join("full4"), tmp.path().join("part4"));
    full_run(Some(&figure4), &full);
    killed(paused_run(Some(&figure4), &part, "checkpoint 2"));
    let o = resume(Some(&figure4), &part, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(snapshot(&part), snapshot(&full));
}

/// The fields below the surface of a resumed run are the uninterrupted run's, byte for byte:
/// the history that changes P (element states of the general solver, whose loads are constant
/// on the elements) with a subsurface grid, killed at its third checkpoint and resumed.
#[test]
fn a_resumed_run_writes_the_same_fields_below_the_surface() {
    let tmp = tempfile::tempdir().unwrap();
    let mut v: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(scenario_path("normal_load_in_phase")).unwrap(),
    )
    .unwrap();
    v["output"]["subsurface"] = serde_json::json!({"depth": 1.0, "nx": 41, "nz": 11});
    let scenario = tmp.path().join("in_phase_subsurface.json");
    std::fs::write(&scenario, v.to_string()).unwrap();
    let (full, part) = (tmp.path().join("full"), tmp.path().join("part"));
    full_run(Some(&scenario), &full);
    assert!(full.join("subsurface/normal_loading.csv").exists());
    killed(paused_run(Some(&scenario), &part, "checkpoint 3"));
    let o = resume(Some(&scenario), &part, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(snapshot(&part), snapshot(&full));
}

/// A long run (the default contact's cycle 120 times, 4,810 steps: its plots draw the first
/// and the last steps) killed at its 220th checkpoint (step 4,390), with a partial line
/// appended to its checkpoint's records as a run killed between the two writes of a
/// checkpoint leaves one; resumed and killed again, then resumed to the end: the output is
/// the uninterrupted run's, byte for byte. The resumed runs read the records back a line at a
/// time and keep only the checkpoint's lines.
#[test]
fn a_long_run_killed_twice_with_a_partial_record_resumes_byte_for_byte() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = tmp.path().join("long.json");
    let text = fretsim::scenario::DEFAULT_SCENARIO.replace(r#""repeats": 3"#, r#""repeats": 120"#);
    std::fs::write(&scenario, text).unwrap();
    let full = tmp.path().join("full");
    let part = tmp.path().join("part");
    full_run(Some(&scenario), &full);
    killed(paused_run(Some(&scenario), &part, "checkpoint 220"));
    let records = tmp
        .path()
        .join(".part.fretsim-new/checkpoint/records.jsonl");
    let mut bytes = std::fs::read(&records).unwrap();
    bytes.extend_from_slice(br#"{"step":4391,"t":"#);
    std::fs::write(&records, bytes).unwrap();
    killed(paused_run_resuming(Some(&scenario), &part, "checkpoint 2"));
    let o = resume(Some(&scenario), &part, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(snapshot(&part), snapshot(&full));
}

/// Kill a run and wait for it to end (its lock is then released).
fn killed(mut child: std::process::Child) {
    child.kill().unwrap();
    child.wait().unwrap();
}

/// A resumed run that pauses at `stage`, started and waited for as [`paused_run`] does.
fn paused_run_resuming(scenario: Option<&Path>, dir: &Path, stage: &str) -> std::process::Child {
    let mut cmd = fretsim();
    cmd.arg("run");
    if let Some(s) = scenario {
        cmd.arg(s);
    }
    cmd.arg("--resume").arg(dir);
    paused(cmd, stage)
}

/// `--resume` with another scenario than the checkpoint's: exit 2, a message that says so,
/// and the interrupted run's checkpoint left exactly as it was (it can still be resumed).
#[test]
fn a_checkpoint_of_another_scenario_is_refused_and_left_as_it_was() {
    let tmp = tempfile::tempdir().unwrap();
    let part = tmp.path().join("part");
    killed(paused_run(None, &part, "checkpoint 2"));
    // The killed run's lock file is fretsim's, and the next run on the folder removes it.
    let unlocked = |dir: &Path| {
        let mut files = snapshot(dir);
        files.retain(|(name, _)| !name.ends_with(".fretsim-lock"));
        files
    };
    let before = unlocked(tmp.path());
    let o = resume(Some(&scenario_path("figure4_fretting")), &part, None);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("another scenario"), "{stderr}");
    assert_eq!(unlocked(tmp.path()), before);
    let o = resume(None, &part, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// `--resume` on a folder that holds no checkpoint runs from the start and says so; `--out`
/// and `--resume` together are a usage error.
#[test]
fn resume_without_a_checkpoint_runs_from_the_start() {
    let tmp = tempfile::tempdir().unwrap();
    let (full, fresh) = (tmp.path().join("full"), tmp.path().join("fresh"));
    full_run(None, &full);
    let o = resume(None, &fresh, None);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(stderr.contains("no checkpoint"), "{stderr}");
    assert_eq!(snapshot(&fresh), snapshot(&full));
    let o = fretsim()
        .args(["run", "--out"])
        .arg(&full)
        .arg("--resume")
        .arg(&fresh)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}
