"""Stabilised initial step: the guyed pin-based mast of docs/stabilize.md;
plots the strain and stabilisation energies and their ratio per increment.

    python benchmarks/stabilize_energy.py
"""

from pathlib import Path

import numpy as np

import femast as fm


def guyed_mast(stabilize=None, settle=True):
    """The pin-based mast of docs/stabilize.md: a 2 m bar on a pin, two guys 0.03 % slack at the start,
    pushed by 50 N sideways and 400 N down in a stabilised step ``load`` (``stabilize``: its
    :class:`femast.Stabilize`, default the default one), then an equilibrium step ``settle``."""
    m = fm.Model("guyed")
    base, top = m.node(0, 0, 0), m.node(0, 0, 2.0)
    left, right = m.node(-1.0, 0, 0), m.node(1.0, 0, 0)
    m.truss(base, top, EA=1e7, family="mast")
    span = np.hypot(1.0, 2.0)
    for anchor in (left, right):
        m.truss(anchor, top, EA=2e5, L0=span * 1.0003, tension_only=True, family=f"guy{anchor}")
        m.fix(anchor)
    m.fix(base)
    m.fix(top, "uy")
    m.step("load", initial_increment=0.1, stabilize=stabilize or fm.Stabilize()).load(top, fx=50.0, fz=-400.0)
    if settle:
        m.step("settle")
    return m


def main(out="benchmarks/out"):
    import matplotlib

    matplotlib.use("Agg")
    from femast.post import plotstyle  # the one femast figure style

    plotstyle.use()
    import matplotlib.pyplot as plt

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    m = guyed_mast()
    an = fm.Analysis(m, out / "stabilize", progress=True)
    res = an.run()
    sel = np.array(res.steps) == "load"
    t = res.scalar_history("time")[sel]
    Es = res.scalar_history("stabilization_energy")[sel]
    Ee = res.scalar_history("strain_energy")[sel]
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    ax[0].plot(t, Ee, "o-", label="strain energy")
    ax[0].plot(t, Es, "s-", label="stabilisation energy (dissipated)")
    ax[0].set(xlabel="step time (s)", ylabel="energy (J)", title="energies in the stabilised step")
    ax[0].legend()
    ax[1].semilogy(t, Es / Ee, "o-")
    ax[1].axhline(0.05, color="r", ls="--", label="5 % warning")
    ax[1].set(xlabel="step time (s)", ylabel="stabilisation / strain energy (-)", title="energy ratio")
    ax[1].legend()
    fig.tight_layout()
    plotstyle.save(fig, out / "stabilize_energy.png", dpi=100)
    print(
        f"final ratio {an.summary.steps[0]['stabilization_ratio']:.4f}; "
        f"lean stabilised {res.frame(int(np.flatnonzero(sel)[-1]))['U'][1, 0] * 1e3:.4f} mm, "
        f"equilibrium {res.frame(-1)['U'][1, 0] * 1e3:.4f} mm; figure {out / 'stabilize_energy.png'}"
    )


if __name__ == "__main__":
    main()
