"""Stohlman & Pellegrino's Sec. IV reproduced: the mock bay side's out-of-plane latch resonance
against the average cable tension, the unit's effective mass identified from Eq. 16, the model
curve against Eq. 16 (deviation in N against the fit's scatter) and the inverse use.

    python benchmarks/adam_vibration.py [--out benchmarks/out/adam_vibration]

Eq. 16 is read with f in Hz and T in lbf (see femast/adam/vibration.py: as printed, in N, it
gives 30-47 N where Figs. 13-14 show 125-210 N).
"""

import argparse
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from femast.adam import vibration as v


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--out", default="benchmarks/out/adam_vibration")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    fit = v.identify_unit_mass()
    print(
        f"Eq. 16 as printed at 65 / 80 Hz: {v.eq16_printed(65.0):.1f} / {v.eq16_printed(80.0):.1f} (N as printed), "
        f"with f in rad/s: {v.eq16_printed(2 * np.pi * 65):.0f} N; read in lbf: {v.eq16_tension(65.0):.1f} / "
        f"{v.eq16_tension(80.0):.1f} N (Fig. 14: 130-210 N over 65-80 Hz)"
    )
    print(
        f"identified unit mass {1e3 * fit.unit_mass:.2f} g (+- {1e3 * fit.sigma_unit_mass:.2f} g from the "
        f"Eq. 16 scatter), effective mass at the unit {1e3 * fit.effective_mass:.2f} g (cables lumped: "
        f"{1e3 * (fit.effective_mass - fit.unit_mass):.2f} g)"
    )
    print(f"{'T model (N)':>12} {'f model (Hz)':>13} {'T Eq.16 (N)':>12} {'dev (N)':>9}")
    for T, f, e in zip(fit.tension, fit.frequency, fit.eq16):
        print(f"{T:>12.2f} {f:>13.3f} {e:>12.2f} {T - e:>9.2f}")
    print(
        f"deviation over {v.EQ16_RANGE_N[0]:.0f}-{v.EQ16_RANGE_N[1]:.0f} N: max {fit.max_dev:.2f} N, RMS "
        f"{fit.rms_dev:.2f} N; the fit's standard deviation: 2 (as printed, N) = {v.EQ16_SD_N:.1f} N (lbf)"
    )
    rows = []
    for f_meas in (62.0, 70.0, 78.0):
        T, s = v.tension_from_frequency(f_meas, fit, sigma_f_hz=0.5)
        rows.append((f_meas, T, s))
        print(
            f"inverse: f = {f_meas:.1f} +- 0.5 Hz -> T = {T:.1f} +- {s:.1f} N (Eq. 16: {v.eq16_tension(f_meas):.1f} N)"
        )
    print(f"({time.perf_counter() - t0:.1f} s)")

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6))
    ax = axes[0]
    ff = np.linspace(58, 82, 200)
    ax.fill_between(
        ff,
        v.eq16_tension(ff) - v.EQ16_SD_N,
        v.eq16_tension(ff) + v.EQ16_SD_N,
        color="0.85",
        label="Eq. 16 +- 2 lbf (8.9 N)",
    )
    ax.plot(ff, v.eq16_tension(ff), "k-", label="Eq. 16, T in lbf (converted to N)")
    ax.plot(ff, v.eq16_printed(ff), "k:", label='Eq. 16 as printed ("N")')
    ax.plot(
        fit.frequency, fit.tension, "o", color="C3", label=f"femast mock side, unit mass {1e3 * fit.unit_mass:.1f} g"
    )
    ax.errorbar(
        [r[0] for r in rows],
        [r[1] for r in rows],
        yerr=[r[2] for r in rows],
        fmt="s",
        color="C0",
        capsize=3,
        label="inverse use: T(f +- 0.5 Hz)",
    )
    ax.set_xlabel("out-of-plane resonance of the latch (Hz)")
    ax.set_ylabel("average cable tension (N)")
    ax.set_title("ADAM mock bay side (Stohlman & Pellegrino, Sec. IV)")
    ax.legend(fontsize=8)
    ax = axes[1]
    ax.axhspan(-v.EQ16_SD_N, v.EQ16_SD_N, color="0.85", label="+- 8.9 N (2 lbf)")
    ax.axhspan(-2, 2, color="0.7", label="+- 2 N (as printed)")
    ax.plot(fit.tension, fit.deviation, "o-", color="C3")
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xlabel("average cable tension (N)")
    ax.set_ylabel("model - Eq. 16 (N)")
    ax.set_title(f"deviation: max {fit.max_dev:.1f} N, RMS {fit.rms_dev:.1f} N")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "adam_vibration.png", dpi=110)
    print(f"figure {out / 'adam_vibration.png'}")


if __name__ == "__main__":
    main()
