"""The closed-form random walk of the longerons' length tolerances (femast.adam.tolerance_walk):
the deployed tip errors of a 40-bay and a 350-bay ADAM mast at the 95th percentile, for tied and
seated joints, beside a Monte Carlo that chains the bays with exact rotations.

    python -m femast.benchmarks.tolerance_walk [--tolerance-mm 0.05] [--samples 20000 2000]

Prints, per mast and seat: the first-order walk (the issue-style figures: a bay tilting about its
bottom frame, c = 1, and about its mid-height, c = 1/2), the walk with the lean (the default), and
the Monte Carlo's 95th percentiles with their distribution-free 95 % intervals.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from femast.adam import BayParameters
from femast.adam.tolerance_walk import MID_HEIGHT, bay_pose, tolerance_walk
from femast.studies import percentile

ARCSEC = 180.0 / math.pi * 3600.0


def rotations(w: np.ndarray) -> np.ndarray:
    """(m, 3, 3) rotation matrices of small-or-not rotation vectors w (m, 3), Rodrigues."""
    th = np.linalg.norm(w, axis=1)
    k = w / np.where(th > 0, th, 1.0)[:, None]
    K = np.zeros((len(w), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
    K = K - np.swapaxes(K, 1, 2)
    s, c = np.sin(th)[:, None, None], np.cos(th)[:, None, None]
    return np.eye(3) + s * K + (1 - c) * K @ K


def chained_tips(n: int, samples: int, a: float, p: BayParameters, seat: str, rng) -> dict:
    """Tip errors of ``samples`` masts of n bays with longeron errors uniform in +-a (m): each
    bay's pose from bay_pose, the bays chained with exact rotations, the bay tilting about its
    mid-height.  {"axial" (m), "tilt" (rad), "lateral" (m)}: magnitudes per sample."""
    R = np.broadcast_to(np.eye(3), (samples, 3, 3)).copy()
    tip = np.zeros((samples, 3))
    for _ in range(n):
        h, w = bay_pose(rng.uniform(-a, a, (samples, 4)), p.b, seat)
        Rb = rotations(np.column_stack([w, np.zeros(samples)]))
        local = Rb @ np.array([0.0, 0.0, MID_HEIGHT * p.l])
        local[:, 2] += (1 - MID_HEIGHT) * p.l + h
        tip += np.einsum("mij,mj->mi", R, local)
        R = R @ Rb
    tilt = np.hypot(R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0]) / 2
    return {"axial": np.abs(tip[:, 2] - n * p.l), "tilt": tilt, "lateral": np.hypot(tip[:, 0], tip[:, 1])}


def row(label: str, q: dict) -> str:
    return f"  {label:<34} axial {q['axial'] * 1e6:8.0f} um   tilt {q['tilt'] * ARCSEC:6.0f} arcsec   lateral {q['lateral'] * 1e3:7.2f} mm"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tolerance-mm", type=float, default=0.05, help="longeron length tolerance +- (mm)")
    ap.add_argument("--samples", type=int, nargs=2, default=(20000, 10000), help="Monte Carlo masts: 40 and 350 bays")
    args = ap.parse_args(argv)
    a, p = args.tolerance_mm * 1e-3, BayParameters()
    print(
        f"Longeron lengths uniform in +-{args.tolerance_mm:g} mm, frame side {p.b:g} m, bay height {p.l:g} m; 95th percentiles"
    )
    rng = np.random.default_rng(2026)
    for n, samples in zip((40, 350), args.samples):
        for seat in ("tied", "seated"):
            print(f"{n} bays ({n * p.l:.2f} m), {seat} joints")
            print(
                row("closed form, first order, c = 1", tolerance_walk(n, a, p, seat, pivot=1.0, lean=False).quantiles())
            )
            print(row("closed form, first order, c = 1/2", tolerance_walk(n, a, p, seat, lean=False).quantiles()))
            print(row("closed form with the lean, c = 1/2", tolerance_walk(n, a, p, seat).quantiles()))
            t = time.process_time()
            mc = chained_tips(n, samples, a, p, seat, rng)
            parts = []
            for what, scale, unit in (("axial", 1e6, "um"), ("tilt", ARCSEC, "arcsec"), ("lateral", 1e3, "mm")):
                est = percentile(mc[what], 0.95)
                parts.append(
                    f"{what} {est['estimate'] * scale:.4g} [{est['low'] * scale:.4g}, {est['high'] * scale:.4g}] {unit}"
                )
            print(f"  Monte Carlo, {samples} masts ({time.process_time() - t:.0f} s CPU): " + ", ".join(parts))


if __name__ == "__main__":
    main()
