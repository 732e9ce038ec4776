//! The bulk stress σB (`tangential_history.bulk_stress`) end to end.

use std::path::Path;

use super::cli::{column, fretsim, read_csv, scenario_path};

/// Run `scenario` (a path) into a new folder; the exit code and stderr.
fn run(scenario: &Path, out: &Path) -> (i32, String) {
    let o = fretsim()
        .arg("run")
        .arg(scenario)
        .arg("--out")
        .arg(out)
        .arg("--quiet")
        .output()
        .unwrap();
    (
        o.status.code().unwrap(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// `scenarios/bulk_stress.json`: the uncoupled cylinder (ν = ½) with Q and σB raised in
/// proportion to ηP/2 and 5 MPa, then cycled in phase. The general solver takes every step
/// after the normal loading; `steps.csv` has σB; at Q* the stick zone is centred at
/// e = aσB/(2ηp0) = 0.0944a with half-width c = a√(1 − Q/(ηP)) (measured: 0.0950a and 0.7080a
/// against 0.7071a, within the default element of 6e−3 a).
#[test]
fn scenario_bulk_stress() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let (code, stderr) = run(&scenario_path("bulk_stress"), &out);
    assert_eq!(code, 0, "{stderr}");
    let (header, rows) = read_csv(&out.join("steps.csv"));
    let (t, sigma, lo, hi, a) = (
        column(&header, &rows, "t_s"),
        column(&header, &rows, "bulk_stress_Pa"),
        column(&header, &rows, "stick_lo_m"),
        column(&header, &rows, "stick_hi_m"),
        column(&header, &rows, "a_m"),
    );
    let k = t.iter().position(|&t| (t - 1.0).abs() < 1e-12).unwrap();
    assert!((sigma[k] - 5e6).abs() < 1e-3);
    // Hertz for μ = 27.3 GPa, ν = ½ (E* = 4μ), R = 10 mm, P = 2240 N/m.
    let (p, eta, r) = (2240.0, 0.3, 0.01);
    let a0 = (4.0 * p * r / (std::f64::consts::PI * 4.0 * 27.3e9)).sqrt();
    let p0 = 2.0 * p / (std::f64::consts::PI * a0);
    assert!((a[k] - a0).abs() < 1e-3 * a0);
    let e = a0 * 5e6 / (2.0 * eta * p0);
    let c = a0 * 0.5f64.sqrt();
    let (centre, half) = (0.5 * (lo[k] + hi[k]), 0.5 * (hi[k] - lo[k]));
    assert!((centre - e).abs() < 2e-3 * a0, "{} {}", centre / a0, e / a0);
    assert!((half - c).abs() < 3e-3 * a0, "{} {}", half / a0, c / a0);
    let text = std::fs::read_to_string(out.join("steps.csv")).unwrap();
    let solver = header.split(',').position(|c| c == "solver").unwrap();
    assert!(
        text.lines()
            .skip(2)
            .all(|l| l.split(',').nth(solver) == Some("general"))
    );
}

/// A bulk stress of zero at every point gives the files of the same history without one, to
/// the byte (`steps.csv` without the σB column, the field files).
#[test]
fn zero_bulk_stress_gives_the_same_files() {
    let tmp = tempfile::tempdir().unwrap();
    let plain = std::fs::read_to_string(scenario_path("cattaneo_mindlin_uncoupled")).unwrap();
    let zero = plain.replace(
        r#""steps_per_segment": 10"#,
        r#""steps_per_segment": 10,
    "bulk_stress": { "points": [0, 0, 0, 0, 0], "cycle": [0, 0] }"#,
    );
    assert_ne!(zero, plain);
    let file = tmp.path().join("zero.json");
    std::fs::write(&file, zero).unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    assert_eq!(run(&scenario_path("cattaneo_mindlin_uncoupled"), &a).0, 0);
    assert_eq!(run(&file, &b).0, 0);
    for name in [
        "steps.csv",
        "cycles.csv",
        "fields/normal_loading.csv",
        "fields/t_1.000000.csv",
    ] {
        assert!(
            std::fs::read(a.join(name)).unwrap() == std::fs::read(b.join(name)).unwrap(),
            "{name}"
        );
    }
}

/// The rules of `tangential_history.bulk_stress`, each named with its field (exit 2): one
/// value per point, finite; and the spectral solver refuses a history with a bulk stress.
#[test]
fn bulk_stress_rules_name_the_field() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(scenario_path("bulk_stress")).unwrap();
    let cases = [
        (
            text.replace("[0.0, 5.0e6]", "[5.0e6]"),
            "`tangential_history.bulk_stress.points` = 1 values is invalid; it must have one per \
             point of `tangential_history.points` (2)",
        ),
        (
            text.replace(
                r#""output""#,
                r#""numerics": { "solver": "spectral" }, "output""#,
            ),
            "`numerics.solver` = \"spectral\" is invalid with a history that has a bulk stress",
        ),
    ];
    for (k, (scenario, expected)) in cases.iter().enumerate() {
        let file = tmp.path().join(format!("bad{k}.json"));
        std::fs::write(&file, scenario).unwrap();
        let o = fretsim().arg("check").arg(&file).output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(expected), "{stderr}");
    }
}
