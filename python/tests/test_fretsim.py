"""The Python package against the command line and against closed forms."""

import csv
import json
import math
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import fretsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENARIOS = ROOT / "scenarios"
BINARY = pathlib.Path(os.environ.get("FRETSIM_BIN", ROOT / "target" / "release" / "fretsim"))


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def test_steps_and_fields_equal_the_command_lines_files(tmp_path):
    """The same scenario through `fretsim run` and `fretsim.run`: every numeric column of
    steps.csv and of a field file agrees to the files' 10 digits."""
    assert BINARY.exists(), f"build the command first (cargo build --release): {BINARY}"
    scenario = SCENARIOS / "figure3_history.json"
    out = tmp_path / "cli"
    subprocess.run([BINARY, "run", scenario, "--out", out, "--quiet"], check=True)
    result = fretsim.run(scenario)
    header, rows = read_csv(out / "steps.csv")
    assert list(result.steps) == header
    for k, name in enumerate(header):
        column = [r[k] for r in rows]
        if name in ("regime", "solver"):
            assert list(result.steps[name]) == column
        else:
            np.testing.assert_allclose(result.steps[name], np.array(column, float), rtol=1e-9)
    header, rows = read_csv(out / "fields" / "t_2.000000.csv")
    for k, name in enumerate(header):
        np.testing.assert_allclose(
            result.fields["t_2.000000"][name], np.array([r[k] for r in rows], float), rtol=1e-9
        )
    summary = json.loads((out / "summary.json").read_text())
    assert result.summary["history"]["verdict"] == summary["history"]["verdict"]


def test_subsurface_maps_equal_the_command_lines_files(tmp_path):
    """The fields below the surface (`output.subsurface`) of `fretsim.run`, by field stem, are
    the command line's `subsurface/<stem>.csv` to their 10 digits, and reshape to (nz, nx)
    maps with x along the rows; at z = 0 under normal loading σzz is −p, Hertz's pressure."""
    scenario = SCENARIOS / "subsurface_map.json"
    out = tmp_path / "cli"
    subprocess.run([BINARY, "run", scenario, "--out", out, "--quiet"], check=True)
    result = fretsim.run(scenario)
    files = sorted(p.stem for p in (out / "subsurface").glob("*.csv"))
    assert sorted(result.subsurface) == files and "normal_loading" in files
    for stem in files:
        header, rows = read_csv(out / "subsurface" / f"{stem}.csv")
        assert list(result.subsurface[stem]) == header
        for k, name in enumerate(header):
            column = np.array([r[k] if r[k] else "nan" for r in rows], float)
            np.testing.assert_allclose(result.subsurface[stem][name], column, rtol=1e-9)
    table = result.subsurface["normal_loading"]
    x = table["x_m"].reshape(41, 80)
    z = table["z_m"].reshape(41, 80)
    assert np.all(x == x[0]) and np.all(z.T == z[:, 0])
    a = result.summary["normal_loading"]["half_width"]
    p0 = result.summary["normal_loading"]["peak_pressure"]
    hertz = p0 * np.sqrt(np.clip(1.0 - (x[0] / a) ** 2, 0.0, None))
    np.testing.assert_allclose(table["szz_Pa"].reshape(41, 80)[0], -hertz, atol=1e-6 * p0)


def test_fatigue_indicators_equal_the_command_lines_file(tmp_path):
    """`Result.fatigue` is the command line's `fatigue.csv` to its 10 digits; the largest slip
    amplitude is the last cycle's `max_local_slip_m`; without a complete cycle it is None."""
    scenario = SCENARIOS / "fretting_fatigue.json"
    out = tmp_path / "cli"
    subprocess.run([BINARY, "run", scenario, "--out", out, "--quiet"], check=True)
    result = fretsim.run(scenario)
    header, rows = read_csv(out / "fatigue.csv")
    assert list(result.fatigue) == header
    for k, name in enumerate(header):
        np.testing.assert_allclose(
            result.fatigue[name], np.array([r[k] for r in rows], float), rtol=1e-9
        )
    largest = result.fatigue["slip_amplitude_m"].max()
    assert largest == pytest.approx(result.cycles["max_local_slip_m"][-1], rel=1e-9)
    half = fretsim.load(scenario)
    half["tangential_history"] = {"unit": "fraction_of_limit", "points": [[0, 0], [1, 0.5]]}
    assert fretsim.run(half).fatigue is None


def test_cattaneo_mindlin_stick_zone_at_the_first_peak():
    """Uncoupled elastic contact (ν = 0.5): at the first peak Q = 0.6 ηP the stick zone is
    |x − c| ≤ a √(1 − Q/(ηP)) (Cattaneo–Mindlin)."""
    result = fretsim.run(SCENARIOS / "cattaneo_mindlin_uncoupled.json")
    steps = result.steps
    k = int(np.argmin(np.abs(steps["t_s"] - 1.0)))
    assert steps["Q_over_etaP"][k] == pytest.approx(0.6, abs=1e-12)
    a = steps["a_m"][k]
    half = 0.5 * (steps["stick_hi_m"][k] - steps["stick_lo_m"][k])
    assert half / a == pytest.approx(math.sqrt(1.0 - 0.6), abs=1e-8)


def test_bad_input_raises_scenario_error_naming_the_field():
    bad = fretsim.default_scenario()
    bad["friction"] = -1.0
    bad["punch"]["radius"] = 0.0
    with pytest.raises(fretsim.ScenarioError) as caught:
        fretsim.validate(bad)
    message, issues = caught.value.args
    assert {path for path, _ in issues} >= {"friction", "punch.radius"}
    assert "must be" in message
    with pytest.raises(fretsim.ScenarioError) as caught:
        fretsim.run({"friction": "high"})
    assert caught.value.args[1][0][0] == "friction"


def test_validate_fills_in_the_defaults():
    scenario = json.loads((SCENARIOS / "baseline.json").read_text())
    full = fretsim.validate(scenario)
    assert full["numerics"]["collocation_points"] > 0
    assert full["friction"] == scenario["friction"]


def test_out_writes_the_run_folder_and_never_a_users_folder(tmp_path):
    out = tmp_path / "run"
    result = fretsim.run(SCENARIOS / "baseline.json", out=out)
    manifest = json.loads((out / "fretsim-manifest.json").read_text())
    assert "summary.json" in manifest["files"]
    assert result.verdict is None
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep")
    with pytest.raises(fretsim.OutputError, match="not a fretsim output"):
        fretsim.run(SCENARIOS / "baseline.json", out=mine)
    assert (mine / "notes.txt").read_text() == "keep"


def test_a_failed_normal_loading_raises_solve_error():
    """PZT-4 at η = 0.1 with Γ = 2e−7 C/m: no state with one central stick zone exists, and
    the spectral solver alone is asked for (the general solver would load it by steps)."""
    scenario = json.loads((SCENARIOS / "baseline.json").read_text())
    scenario["friction"] = 0.1
    scenario["punch"]["electrode"]["charge"] = 2e-7
    scenario["numerics"] = {"solver": "spectral"}
    with pytest.raises(fretsim.SolveError, match="normal loading"):
        fretsim.run(scenario)
    del scenario["numerics"]
    summary = fretsim.run(scenario).summary["normal_loading"]
    assert summary["solver"] == "general"
    assert summary["zones"]["stick"] == 3


def test_run_many_keeps_the_order_and_returns_the_errors():
    base = json.loads((SCENARIOS / "baseline.json").read_text())
    etas = [0.2, 0.3, 0.4]
    scenarios = [dict(base, friction=eta) for eta in etas] + [dict(base, friction=-1.0)]
    results = fretsim.run_many(scenarios)
    ratios = [r.summary["normal_loading"]["stick_ratio"] for r in results[:3]]
    assert ratios == sorted(ratios), "b/a rises with η (the paper's Figure 8)"
    one = fretsim.run(scenarios[1])
    assert ratios[1] == one.summary["normal_loading"]["stick_ratio"]
    assert isinstance(results[3], fretsim.ScenarioError)


def test_the_tutorial_runs(tmp_path):
    pytest.importorskip("matplotlib")
    figure = tmp_path / "figure8.png"
    script = ROOT / "python" / "examples" / "figure8_stick_ratio.py"
    done = subprocess.run([sys.executable, script, figure], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert figure.stat().st_size > 10_000


def test_displacement_control_reaches_the_coulomb_plateau():
    """The punch's displacement prescribed (`"unit": "metre"`) beyond gross slip on the
    uncoupled cylinder: Q stops at ±ηP while δ goes on, the cycles are gross slip, and the
    energy ratio W/(4Q*δ*) is the closed form's 0.5187 (Mindlin–Deresiewicz plus the
    plateaus; the Rust test `displacement_control_into_gross_slip_...` derives it)."""
    result = fretsim.run(SCENARIOS / "displacement_gross_slip.json")
    ratio = result.steps["Q_over_etaP"]
    assert np.max(np.abs(ratio)) == pytest.approx(1.0, abs=1e-10)
    assert np.sum(np.abs(np.abs(ratio) - 1.0) < 1e-10) > 100
    assert list(result.cycles["regime"]) == ["gross_slip"] * len(result.cycles["regime"])
    assert result.cycles["energy_ratio"][1] == pytest.approx(0.5187, abs=1e-3)
