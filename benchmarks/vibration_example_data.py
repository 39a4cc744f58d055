"""Writes femast/examples/vibration_example.csv (package data): the paper's calibration on the mock bay side,
nine pretension settings 120-200 N, the latch's out-of-plane resonance, with a
hidden pretension loss of 15 N (the cables carry 15 N less than the settings say) and 0.12 Hz of
measurement noise.

The generator shares no code with femast's FE model or effects: the resonance is the closed form
of a point mass on four taut strings, f = sqrt(4 T / (L m)) / (2 pi), with L half the diagonal of
the bay side (b = 0.25 m, l = 0.171 m), m the unit's 21.1 g plus half of each section's steel
cable (1.33e-3 kg/m).

    python benchmarks/vibration_example_data.py
"""

import math
from pathlib import Path

import numpy as np

B, L_BAY = 0.25, 6.84 / 40
HALF_DIAGONAL = 0.5 * math.hypot(B, L_BAY)
CABLE = 7850.0 * 3.4006e4 / 200e9  # kg/m
MASS = 0.0211 + 4 * 0.5 * CABLE * HALF_DIAGONAL
LOSS = 15.0  # N, hidden
NOISE = 0.12  # Hz


EXAMPLE = Path(__file__).resolve().parents[1] / "femast" / "examples" / "vibration_example.csv"


def main(path=EXAMPLE):
    rng = np.random.default_rng(18)
    settings = np.arange(120.0, 201.0, 10.0)
    T = settings - LOSS
    f = np.sqrt(4 * T / (HALF_DIAGONAL * MASS)) / (2 * math.pi) + NOISE * rng.standard_normal(settings.size)
    with open(path, "w") as fh:
        fh.write(
            "# vibration example: out-of-plane resonance of the latch (mode 1) at nine pretension settings, "
            "synthetic. A mock\n"
        )
        fh.write(
            "# bay side of Stohlman & Pellegrino, Fig. 11 (inline sensors); from python -m "
            "femast.benchmarks.vibration_example_data\n"
        )
        fh.write("mode,f_Hz,pretension_N\n")
        for s, fr in zip(settings, f):
            fh.write(f"1,{fr:.3f},{s:.1f}\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
