//! fretsim never deletes, replaces or writes into anything it did not write: refused output
//! folders (exit 2, untouched), the atomic replacement of a previous output under a kill at
//! every stage, the lock against two runs on one folder, and the exit statuses of failures.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};

use crate::cli::{fretsim, scenario_path};

/// Every file under `dir` with its contents, sorted: a folder's complete state.
pub(crate) fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<(String, Vec<u8>)>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                out.push((
                    format!("{}/", p.strip_prefix(root).unwrap().display()),
                    vec![],
                ));
                walk(root, &p, out);
            } else {
                let rel = p.strip_prefix(root).unwrap().display().to_string();
                out.push((rel, std::fs::read(&p).unwrap()));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

fn hidden(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect()
}

/// The names a complete output's manifest lists, checked against the folder: every listed
/// file is there and nothing else is.
fn complete_output(dir: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join("fretsim-manifest.json")).unwrap();
    let manifest: serde_json::Value = serde_json::from_str(&text).unwrap();
    let listed: Vec<String> = manifest["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap().to_string())
        .collect();
    let mut present: Vec<String> = snapshot(dir)
        .into_iter()
        .map(|(n, _)| n)
        .filter(|n| !n.ends_with('/') && n != "fretsim-manifest.json")
        .collect();
    present.sort();
    assert_eq!(present, listed, "{}", dir.display());
    listed
}

fn run_into(scenario: Option<&Path>, out: &Path) -> std::process::Output {
    let mut cmd = fretsim();
    cmd.arg("run");
    if let Some(s) = scenario {
        cmd.arg(s);
    }
    cmd.arg("--out").arg(out).arg("--quiet").output().unwrap()
}

/// Each folder that is not fretsim's, or that is protected, is refused before the solve with
/// exit 2 and a message naming it, and is left exactly as it was, with nothing hidden added.
#[test]
fn refused_output_folders_exit_2_and_are_left_untouched() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path().canonicalize().unwrap();
    let study = root.join("study");
    std::fs::create_dir(&study).unwrap();
    let scenario = study.join("s.json");
    std::fs::copy(scenario_path("figure5_frictionless"), &scenario).unwrap();
    std::fs::write(study.join("notes.txt"), "mine").unwrap();
    let victim = study.join("victim");
    std::fs::create_dir(&victim).unwrap();
    std::fs::write(victim.join("notes.txt"), "mine").unwrap();
    std::fs::write(study.join("file"), "mine").unwrap();
    let home = study.join("home");
    std::fs::create_dir(&home).unwrap();
    let cases: [(&str, &str); 7] = [
        ("victim", "not a fretsim output"),
        (".", "current folder"),
        ("..", "current folder"),
        ("victim/..", "current folder"),
        ("/", "root folder"),
        ("file", "is a file"),
        ("home", "home folder"),
    ];
    let before = snapshot(&root);
    for (out, expected) in cases {
        let o = fretsim()
            .current_dir(&study)
            .env("HOME", &home)
            .args(["run", "s.json", "--out", out])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "--out {out}: {stderr}");
        assert!(
            stderr.contains(&format!("will not write into {out}:")) && stderr.contains(expected),
            "--out {out}: {stderr}"
        );
    }
    // The scenario's own folder, from elsewhere, and an ancestor of it.
    for out in [&study, &root] {
        let o = run_into(Some(&scenario), out);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains("holds the scenario file"), "{stderr}");
    }
    assert_eq!(snapshot(&root), before);
}

/// A scenario `name` is a plain name: with separators or dots it would write outside `output/`.
#[test]
fn a_scenario_name_with_a_path_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(scenario_path("figure5_frictionless")).unwrap();
    let raw: serde_json::Value = serde_json::from_str(&text).unwrap();
    for name in ["", ".", "..", "../x", "a/b", "/tmp/x"] {
        let mut v = raw.clone();
        v["name"] = serde_json::json!(name);
        let file = tmp.path().join("s.json");
        std::fs::write(&file, v.to_string()).unwrap();
        let o = fretsim()
            .current_dir(tmp.path())
            .args(["run", "s.json"])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "name {name:?}: {stderr}");
        assert!(stderr.contains("`name`"), "name {name:?}: {stderr}");
    }
    assert_eq!(
        snapshot(tmp.path()).len(),
        1,
        "only the scenario file is there"
    );
}

/// A previous fretsim output is replaced as a whole: a file the new run does not write is gone;
/// a file that the user added to it makes it refused.
#[test]
fn a_previous_output_is_replaced_as_a_whole_and_a_users_file_protects_it() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    assert!(run_into(None, &out).status.success());
    assert!(complete_output(&out).contains(&"steps.csv".to_string()));
    // The built-in scenario has a history; figure 5 has none, so no steps.csv.
    assert!(
        run_into(Some(&scenario_path("figure5_frictionless")), &out)
            .status
            .success()
    );
    assert!(!complete_output(&out).contains(&"steps.csv".to_string()));
    assert!(!out.join("steps.csv").exists());
    assert!(hidden(tmp.path()).is_empty());
    std::fs::write(out.join("fields/my_notes.txt"), "mine").unwrap();
    let before = snapshot(tmp.path());
    let o = run_into(Some(&scenario_path("figure5_frictionless")), &out);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("`fields/my_notes.txt`"));
    assert_eq!(snapshot(tmp.path()), before);
}

/// The files below the surface are fretsim's like the others: listed in the manifest, gone
/// when a later run into the folder does not ask for them, and a user's file among them
/// protects the folder.
#[test]
fn subsurface_files_are_listed_and_a_users_file_among_them_protects_the_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let with_subsurface = scenario_path("subsurface_map");
    assert!(run_into(Some(&with_subsurface), &out).status.success());
    let listed = complete_output(&out);
    assert!(listed.contains(&"subsurface/normal_loading.csv".to_string()));
    assert!(listed.contains(&"plots/subsurface_normal_loading_von_mises.svg".to_string()));
    assert!(
        run_into(Some(&scenario_path("figure5_frictionless")), &out)
            .status
            .success()
    );
    complete_output(&out);
    assert!(!out.join("subsurface").exists());
    assert!(run_into(Some(&with_subsurface), &out).status.success());
    std::fs::write(out.join("subsurface/my_grid.csv"), "mine").unwrap();
    let before = snapshot(tmp.path());
    let o = run_into(Some(&with_subsurface), &out);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("`subsurface/my_grid.csv`"));
    assert_eq!(snapshot(tmp.path()), before);
}

/// Start a run that pauses at `stage` (the `FRETSIM_PAUSE_AT` hook) and wait until it is there.
pub(crate) fn paused_run(scenario: Option<&Path>, out: &Path, stage: &str) -> Child {
    let mut cmd = fretsim();
    cmd.arg("run");
    if let Some(s) = scenario {
        cmd.arg(s);
    }
    cmd.arg("--out").arg(out);
    paused(cmd, stage)
}

/// Start `cmd` (a run) so that it pauses at `stage` and wait until it is there.
pub(crate) fn paused(mut cmd: Command, stage: &str) -> Child {
    let mut child = cmd
        .arg("--quiet")
        .env("FRETSIM_PAUSE_AT", stage)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let mut lines = BufReader::new(stderr).lines();
    let wanted = format!("fretsim: paused at {stage}");
    loop {
        match lines.next() {
            Some(Ok(line)) if line == wanted => break,
            Some(Ok(_)) => continue,
            _ => panic!("the run ended before it paused at {stage}"),
        }
    }
    child
}

/// A run killed at each stage (in the solve, while writing, just before and just after the
/// swap) leaves at the target the complete old output or the complete new one, and a later run
/// on the same target removes every hidden leftover.
#[test]
fn a_run_killed_at_any_stage_leaves_a_complete_output_and_no_lasting_leftovers() {
    let old_scenario = scenario_path("figure5_frictionless");
    for (stage, new_expected) in [
        ("solve", false),
        ("write", false),
        ("swap", false),
        ("cleanup", true),
    ] {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("out");
        assert!(run_into(Some(&old_scenario), &out).status.success());
        let old = snapshot(&out);
        let mut child = paused_run(None, &out, stage);
        child.kill().unwrap();
        child.wait().unwrap();
        let files = complete_output(&out);
        if new_expected {
            assert!(files.contains(&"steps.csv".to_string()), "{stage}");
        } else {
            assert_eq!(snapshot(&out), old, "{stage}: the old output is intact");
        }
        // The next run cleans what the killed one left.
        assert!(run_into(Some(&old_scenario), &out).status.success());
        assert_eq!(hidden(tmp.path()), Vec::<String>::new(), "{stage}");
        complete_output(&out);
    }
}

/// Two runs on one folder: the second is refused while the first holds the lock, with a clear
/// message, and the first completes.
#[test]
fn a_second_run_on_the_same_folder_is_refused_while_the_first_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let mut first = paused_run(None, &out, "solve");
    let o = run_into(Some(&scenario_path("figure5_frictionless")), &out);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("another fretsim process is writing it"),
        "{stderr}"
    );
    first.kill().unwrap();
    first.wait().unwrap();
    assert!(!out.exists());
    // The lock dies with its process.
    assert!(run_into(None, &out).status.success());
    assert!(hidden(tmp.path()).is_empty());
}

/// An output folder that cannot be created is reported before the solve starts (the run never
/// reaches the pause before its solve) and nothing is left.
#[test]
fn an_unwritable_output_folder_is_reported_before_the_solve() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("plain-file");
    std::fs::write(&file, "x").unwrap();
    let o = fretsim()
        .args(["run", "--out"])
        .arg(file.join("out"))
        .env("FRETSIM_PAUSE_AT", "solve")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(!stderr.contains("paused at solve"), "{stderr}");
    assert!(stderr.contains("cannot write"), "{stderr}");
    assert_eq!(snapshot(tmp.path()).len(), 1);
}

/// When the normal loading fails the run exits 1 and still writes `failure.json`: PZT-4 at
/// η = 0.1 with Γ = 2e−7 C/m, below the charge the pressure carries (Γ1 = 5.0e−7 C/m), where
/// no state with one central stick zone exists, and the spectral solver alone is asked for
/// (`auto` has the general solver load it by steps).
#[test]
fn a_failed_normal_loading_exits_1_with_failure_json() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(scenario_path("baseline")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["friction"] = serde_json::json!(0.1);
    v["punch"]["electrode"]["charge"] = serde_json::json!(2e-7);
    v["numerics"] = serde_json::json!({ "solver": "spectral" });
    let file = tmp.path().join("s.json");
    std::fs::write(&file, v.to_string()).unwrap();
    let out = tmp.path().join("out");
    let o = run_into(Some(&file), &out);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("normal loading"), "{stderr}");
    assert!(stderr.contains("failure.json"), "{stderr}");
    assert_eq!(complete_output(&out), ["failure.json"]);
    let f: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("failure.json")).unwrap()).unwrap();
    assert!(f["error"].as_str().unwrap().starts_with("normal loading"));
    assert!(f["last_accepted_step"].is_null());
}

fn sweep_into(out: &Path, extra: &[&str]) -> Command {
    let mut cmd = fretsim();
    cmd.arg("sweep")
        .arg(scenario_path("figure5_frictionless"))
        .args(["--quiet", "--vary", "normal_load=1000:2000:2", "--out"])
        .arg(out)
        .args(extra);
    cmd
}

/// A sweep folder follows the same rules: a folder that is not a fretsim sweep is refused, a
/// variant's folder that holds a user's file is refused before any variant is solved, and the
/// shards of one sweep share one folder, each writing its own file.
#[test]
fn sweep_folders_follow_the_same_rules_and_shards_share_one() {
    let tmp = tempfile::tempdir().unwrap();
    let victim = tmp.path().join("victim");
    std::fs::create_dir(&victim).unwrap();
    std::fs::write(victim.join("notes.txt"), "mine").unwrap();
    let before = snapshot(tmp.path());
    let o = sweep_into(&victim, &[]).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("not a fretsim output"));
    assert_eq!(snapshot(tmp.path()), before);

    let out = tmp.path().join("sw");
    let shards: Vec<Child> = ["1/2", "2/2"]
        .iter()
        .map(|s| sweep_into(&out, &["--shard", s]).spawn().unwrap())
        .collect();
    for mut c in shards {
        assert!(c.wait().unwrap().success());
    }
    for f in ["sweep-1-of-2.csv", "sweep-2-of-2.csv"] {
        assert_eq!(
            std::fs::read_to_string(out.join(f))
                .unwrap()
                .lines()
                .count(),
            2
        );
    }
    assert!(sweep_into(&out, &["--runs"]).status().unwrap().success());
    complete_output(&out.join("variant_0001"));
    std::fs::write(out.join("variant_0001/notes.txt"), "mine").unwrap();
    let before = snapshot(tmp.path());
    let o = sweep_into(&out, &["--runs"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("variant_0001") && stderr.contains("`notes.txt`"),
        "{stderr}"
    );
    assert_eq!(snapshot(tmp.path()), before);
    assert!(hidden(&out).is_empty(), "{:?}", hidden(&out));
}
