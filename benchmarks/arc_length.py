"""Arc-length control: the von Mises truss, Lee's frame and Williams' toggle against
their independent references; writes benchmarks/out/arc_length.png and prints the errors.

    python benchmarks/arc_length.py
"""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
from femast.post import plotstyle  # noqa: E402  (the one femast figure style)

plotstyle.use()
import matplotlib.pyplot as plt
import numpy as np

from femast.verification import arclength as va
from femast.verification import references as ref


def main(out="benchmarks/out"):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(1, 4, figsize=(20, 4.8))
    vm = va.von_mises_truss()
    w = np.linspace(0, vm["w"].max(), 400)
    ax[0].plot(w / vm["h"], ref.von_mises_truss_load(w, 1.0, 0.1, 1e6) / vm["P_limit"], "k-", label="analytic")
    ax[0].plot(vm["w"] / vm["h"], vm["P"] / vm["P_limit"], "o", ms=4, label="femast, arc length")
    ax[0].set(xlabel="apex deflection / rise (-)", ylabel="P / P_limit (-)", title="von Mises truss (a = 1, h = 0.1)")
    err_vm = np.abs(vm["P"] - vm["P_exact"]).max() / vm["P_limit"]

    lee = va.lee_frame()
    path = ref.lee_frame_path(ds=0.1)
    P_lim, _ = ref.lee_frame_limit_load()
    for k, comp in ((1, "v"), (2, "u")):
        ax[k].plot(getattr(path, comp), path.load, "k-", label="elastica (reference)")
        ax[k].plot(lee[comp], lee["P"], "o", ms=3, label="femast, 10 el./member")
        ax[k].set(
            xlabel=f"load point {'vertical (down)' if comp == 'v' else 'horizontal'} displacement "
            "(length unit of L = 120)",
            ylabel="P (force unit of E = 7.2e6)",
            title=f"Lee's frame: P - {comp}",
        )
    inside = lee["v"] <= path.v.max()
    err_lee = max(path.distance(lee["P"][inside], lee[c][inside], P_lim, 90.0, c).max() for c in "vu")

    tog = va.williams_toggle(n_per_member=16)
    tpath = ref.williams_toggle_path()
    Pt, vt = ref.williams_toggle_limit_load()
    ax[3].plot(tpath.v, tpath.load, "k-", label="elastica (reference)")
    ax[3].plot(tog["v"], tog["P"], "o", ms=4, label="femast, 16 el./member")
    ax[3].set(xlabel="apex deflection (in)", ylabel="P (lb)", title="Williams' toggle")
    for a in ax:
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    fig.tight_layout()
    plotstyle.save(fig, out / "arc_length.png", dpi=100)
    pre = tog["v"] < 0.4
    print(f"von Mises truss: max |P - P_exact| / P_limit = {err_vm:.2e} over {len(vm['w'])} increments")
    print(
        f"Lee's frame: limit load {lee['P'].max():.1f} (elastica {P_lim:.1f}, Simo-Vu-Quoc 18532), "
        f"max path distance {100 * err_lee:.2f} % over {len(lee['v'])} increments"
    )
    print(
        f"Williams' toggle: limit load {tog['P'][pre].max():.3f} lb (elastica {Pt:.3f}), "
        f"max path distance {100 * tpath.distance(tog['P'], tog['v'], Pt, 0.6).max():.2f} %"
    )
    print(f"figure: {out / 'arc_length.png'}")


if __name__ == "__main__":
    main()
