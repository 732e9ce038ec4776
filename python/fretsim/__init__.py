"""fretsim from Python: validate and solve fretting-contact scenarios, get numpy arrays.

A scenario is a dict (or JSON text, or a path to a JSON file) in the format of the
command line's scenario files (README, "Scenario file"). Nothing is written to disk unless
``run(..., out=FOLDER)`` asks for the output folder of ``fretsim run``.

>>> import fretsim
>>> result = fretsim.run(fretsim.default_scenario())
>>> result.steps["Q_over_etaP"].max() <= 0.5
True
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as np

from . import _core
from ._core import OutputError, ScenarioError, SolveError

__all__ = [
    "Result",
    "ScenarioError",
    "SolveError",
    "OutputError",
    "default_scenario",
    "load",
    "materials",
    "run",
    "run_many",
    "validate",
]

Scenario = Union[Dict[str, Any], str, "os.PathLike[str]"]


def _text(scenario: Scenario) -> tuple[str, str]:
    """The scenario as JSON text, and a label for messages."""
    if isinstance(scenario, dict):
        return json.dumps(scenario), "<dict>"
    if isinstance(scenario, os.PathLike) or (
        isinstance(scenario, str) and not scenario.lstrip().startswith("{")
    ):
        path = os.fspath(scenario)
        with open(path, encoding="utf-8") as f:
            return f.read(), path
    if isinstance(scenario, str):
        return scenario, "<text>"
    raise TypeError("a scenario is a dict, JSON text or a path to a JSON file")


def load(path: "Union[str, os.PathLike[str]]") -> Dict[str, Any]:
    """Read a scenario file into a dict (not validated)."""
    with open(os.fspath(path), encoding="utf-8") as f:
        return json.load(f)


def default_scenario() -> Dict[str, Any]:
    """The built-in scenario of ``fretsim run``: the paper's PZT-4 baseline with three cycles."""
    return json.loads(_core.default_scenario())


def materials() -> List[Dict[str, Any]]:
    """The material presets: name, source and constants (SI)."""
    return json.loads(_core.materials())


def validate(scenario: Scenario) -> Dict[str, Any]:
    """Check every rule; return the scenario with its defaults filled in.

    Raises ScenarioError, whose ``args`` are ``(message, [(json_path, rule), ...])``.
    """
    text, label = _text(scenario)
    return json.loads(_core.validate(text, label))


def _table(columns: Dict[str, list]) -> Dict[str, np.ndarray]:
    out = {}
    for name, values in columns.items():
        if name == "label":
            continue
        if values and isinstance(values[0], str):
            out[name] = np.array(values, dtype=str)
        elif any(v is None for v in values):
            out[name] = np.array([np.nan if v is None else v for v in values], dtype=float)
        elif values and all(isinstance(v, int) for v in values):
            out[name] = np.array(values, dtype=np.int64)
        else:
            out[name] = np.array(values, dtype=float)
    return out


@dataclass
class Result:
    """A solved scenario.

    ``steps``, ``cycles`` and each entry of ``fields`` map the column names of
    ``steps.csv``, ``cycles.csv`` and the field files (units in the names: ``Q_N_per_m``,
    ``x_m``, ``p_Pa``...) to numpy arrays; a missing value is NaN. ``fields`` is keyed by the
    field file's stem (``normal_loading``, ``t_2.000000``, ``step_00020``), ``labels`` gives
    each one's legend. ``subsurface`` holds, under ``output.subsurface``, the fields below the
    surface at the same instants, by the same stems: the columns of ``subsurface/<stem>.csv``
    (``x_m``, ``z_m``, ``sxx_Pa``, ``von_mises_Pa``...), one value per grid point, x
    varying fastest (``reshape(nz, nx)`` gives a map). ``fatigue`` holds the columns of
    ``fatigue.csv`` (the fretting-fatigue indicators of the last complete cycle on the field
    grid: ``slip_amplitude_m``, ``ruiz_f2_Pa_J_per_m2``, ``swt_Pa``...), or None without a
    complete cycle (or with ``output.fatigue`` false). ``failure`` is the error that stopped
    the history part-way, or None.
    """

    summary: Dict[str, Any]
    steps: Dict[str, np.ndarray]
    cycles: Dict[str, np.ndarray]
    fields: Dict[str, Dict[str, np.ndarray]]
    labels: Dict[str, str] = field(default_factory=dict)
    subsurface: Dict[str, Dict[str, np.ndarray]] = field(default_factory=dict)
    fatigue: Optional[Dict[str, np.ndarray]] = None
    failure: Optional[str] = None

    @property
    def verdict(self) -> Optional[Dict[str, Any]]:
        """Whether the cycles settle (the summary's ``history.verdict``), or None without a history."""
        history = self.summary.get("history")
        return None if history is None else history["verdict"]

    @classmethod
    def _from_core(cls, raw: Dict[str, Any]) -> "Result":
        fields = {stem: _table(cols) for stem, cols in raw["fields"].items()}
        labels = {stem: cols["label"] for stem, cols in raw["fields"].items()}
        return cls(
            summary=json.loads(raw["summary"]),
            steps=_table(raw["steps"]),
            cycles=_table(raw["cycles"]),
            fields=fields,
            labels=labels,
            subsurface={stem: _table(cols) for stem, cols in raw["subsurface"].items()},
            fatigue=None if raw["fatigue"] is None else _table(raw["fatigue"]),
            failure=raw["failure"],
        )


def run(scenario: Scenario, out: "Optional[Union[str, os.PathLike[str]]]" = None) -> Result:
    """Solve a scenario. With ``out``, also write the output folder of ``fretsim run``
    (a new folder or a previous fretsim output; anything else raises OutputError).

    Raises ScenarioError for bad input and SolveError when the normal loading fails. A history
    that stops part-way returns the steps solved, with ``failure`` set.
    """
    text, label = _text(scenario)
    raw = _core.run(text, label, None if out is None else os.fspath(out))
    return Result._from_core(raw)


def run_many(scenarios: Sequence[Scenario]) -> List[Union[Result, Exception]]:
    """Solve several scenarios in parallel (all cores); in order, each entry is a Result or
    the exception its scenario raised."""
    texts = [_text(s)[0] for s in scenarios]
    return [
        r if isinstance(r, Exception) else Result._from_core(r) for r in _core.run_many(texts)
    ]
