"""The paper's Figure 8: the stick-zone ratio b/a at the end of normal loading against the
friction coefficient, for a conducting and an insulating punch on PZT-4.

    python python/examples/figure8_stick_ratio.py [figure8.png]

Eight friction coefficients for each punch, solved in parallel by fretsim.run_many.
"""

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import fretsim  # noqa: E402

ETAS = np.linspace(0.1, 0.8, 8)
ELECTRODES = {
    "conducting, Γ = 6e−7 C/m": {"kind": "conducting", "charge": 6e-7},
    "insulating": {"kind": "insulating"},
}


def scenario(eta: float, electrode: dict) -> dict:
    return {
        "name": "figure8",
        "material": {"kind": "preset", "name": "pzt4"},
        "punch": {"radius": 0.06, "electrode": electrode},
        "friction": float(eta),
        "normal_load": 2000.0,
    }


def stick_ratios() -> dict:
    """b/a against η for each electrode (NaN where the normal loading fails)."""
    out = {}
    for label, electrode in ELECTRODES.items():
        results = fretsim.run_many([scenario(eta, electrode) for eta in ETAS])
        out[label] = np.array(
            [
                np.nan
                if isinstance(r, Exception)
                else r.summary["normal_loading"]["stick_ratio"]
                for r in results
            ]
        )
    return out


def main(path: str) -> None:
    ratios = stick_ratios()
    fig, ax = plt.subplots(figsize=(4.5, 3.4))
    for (label, b_over_a), marker in zip(ratios.items(), "os"):
        ax.plot(ETAS, b_over_a, marker=marker, label=label)
    ax.set_xlabel("friction coefficient η")
    ax.set_ylabel("stick-zone ratio b/a")
    ax.set_ylim(0, 1)
    ax.legend(frameon=False)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    for label, b_over_a in ratios.items():
        print(label, np.round(b_over_a, 4))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "figure8.png")
