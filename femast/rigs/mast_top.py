"""Built-in experiment ``mast-top``: wrench on a mast top and its measured displacement (Rocaspect guyed mast).

Data format
-----------
=========  ====  ===========================================================================
column     unit  meaning
=========  ====  ===========================================================================
fx_N       N     change of the force on the mast top (base frame), x
fy_N       N     ... y
fz_N       N     ... z
mx_Nm      N m   change of the moment on the top, about the top point (base frame), x
my_Nm      N m   ... y
mz_Nm      N m   ... z
dx_m       m     measured displacement of the top (e.g. laser tracker), x
dy_m       m     ... y
dz_m       m     ... z
t_s        s     optional time
=========  ====  ===========================================================================

The wrench change ``dw`` is taken from a reference state (the Rocaspect paper, Sec. IV-C: the initial
pose of the platform), as is the displacement ``dc``.

Baseline model
--------------
The 3R model of the Rocaspect paper (Eqs. 4-7, Eq. 6 with the corrected sign, :mod:`femast.guyed.mast_3r`):
a rigid mast on three elastic base joints about the base axes,
``dc = J K^-1 J^T dw``.  The moments driving the joints are ``m = J^T dw`` (N m about the base
point O, along the base axes); the joint rotations ``theta = m / k``; the top translation
``dc_T = J_T theta``.  Fitted: the bending joint stiffnesses ``k_theta1, k_theta2`` (N m/rad).
The torsion joint (``k_theta3`` option, default rigid) does not move the top point.

Options: ``r_oc_m`` vector from the base O to the top C (m), default ``(0, 0, 3.651)`` (a
vertical mast from the origin, the Rocaspect paper's L); ``k_theta3_Nm_per_rad`` (inf); the mast tube for
the beam effect ``s_out_m`` = 0.1, ``s_in_m`` = 0.094, ``nu`` = 0.3.

Quantities and hooks (where effects act)
----------------------------------------
* ``load`` -- the moments ``m`` (n, 2) N m about x and y on the two bending joints (friction and
  hysteresis operators replace them); scale 1 kN m;
* ``displacement`` -- their rotations ``theta`` (n, 2) rad (clearance, progressive stiffness,
  stiffness loss); scale 1 mrad;
* ``top_displacement`` -- this rig's own hook: the top translation ``dc_T`` (n, 3) m (beam
  flexibility, user additions).

Every hook call passes ``data``, ``options``, ``params`` (baseline) and ``prep`` (``dw`` (n, 6),
``J`` (6, 3), ``m`` (n, 3) the unmodified joint moments, ``tau`` normalised time) besides what
the framework gives every effect (``load``, ``time``, ...; :mod:`femast.effects.base`), and from
``displacement`` on ``k`` (the joint stiffnesses).
"""

from __future__ import annotations

import numpy as np

from femast.effects import Quantity
from femast.experiments.core import Column, Experiment, Measured, Parameter, prepared
from femast.guyed.mast_3r import jacobian_3r

WRENCH = ("fx_N", "fy_N", "fz_N", "mx_Nm", "my_Nm", "mz_Nm")
DISPLACEMENT = ("dx_m", "dy_m", "dz_m")
L_MAST = 3.651  # m, the Rocaspect paper, Sec. IV-B-2


def _prepare(data: Measured, options: dict) -> dict:
    dw = np.column_stack([data[c] for c in WRENCH])
    J = jacobian_3r(np.asarray(options["r_oc_m"], dtype=float), printed_sign=bool(options.get("printed_sign", False)))
    m = dw @ J
    return {"dw": dw, "J": J, "m": m, "tau": data.tau}


def model(params: dict, data: Measured, effects, options: dict) -> dict:
    """3R mast-top model (Rocaspect paper, Eqs. 4-7) with effect hooks; returns ``{dx_m, dy_m, dz_m}`` in m.

    The bending joints' moments (about x and y) are the load of the effects, their rotations the
    displacement; the torsion joint is rigid and does not move the top point."""
    prep = prepared(data, _prepare, options)
    k = np.array([params["k_theta1"], params["k_theta2"], float(options["k_theta3_Nm_per_rad"])])
    ctx = dict(data=data, options=options, params=params, prep=prep)
    m_eff = prep["m"]
    if effects:
        m_eff = m_eff.copy()
        m_eff[:, :2] = effects.apply("load", prep["m"][:, :2], **ctx)
    theta = m_eff / k
    if effects:
        theta[:, :2] = effects.apply("displacement", theta[:, :2], k=k[:2], **ctx)
        d = effects.apply("top_displacement", theta @ prep["J"][:3].T, k=k, m_eff=m_eff, theta=theta, **ctx)
    else:
        d = theta @ prep["J"][:3].T
    return {"dx_m": d[:, 0], "dy_m": d[:, 1], "dz_m": d[:, 2]}


def initial_guess(data: Measured, options: dict) -> dict:
    """Linear least-squares compliances of the two bending joints (Eqs. 28-29) as the fit start."""
    prep = prepared(data, _prepare, options)
    JT = prep["J"][:3, :2]
    A = (prep["m"][:, None, :2] * JT[None, :, :]).reshape(-1, 2)  # d = sum_k J_T[:, k] m_k / k_k
    b = np.column_stack([data[c] for c in DISPLACEMENT]).ravel()
    comp = np.linalg.lstsq(A, b, rcond=None)[0]
    k = np.where(comp > 0, 1.0 / np.where(comp > 0, comp, 1.0), 2.5e5)
    return {"k_theta1": float(np.clip(k[0], 1e2, 1e10)), "k_theta2": float(np.clip(k[1], 1e2, 1e10))}


def load_measure(data: Measured, options: dict) -> np.ndarray:
    """The bending moments at the base (N m), (n, 2): the joint moments (m1, m2); the segmentation
    takes them along their principal direction."""
    return prepared(data, _prepare, options)["m"][:, :2]


def noise_covariates(data: Measured, params: dict, options: dict, fit=None) -> dict:
    """What the displacement noise may vary with: the size of the load, the bending moment
    at the base ``|(m1, m2)|`` (N m).  The wrench is measured too (load cells, whose error is
    commonly a share of the reading) and its error enters the displacement residual through the
    compliance; a loaded mast top also vibrates more.  Tested by ``diagnose``'s noise model
    (femast.experiments.noise) against a constant level; a component of the top displacement is not
    the load's size when the load turns (biaxial paths)."""
    prep = prepared(data, _prepare, options)
    g = np.hypot(prep["m"][:, 0], prep["m"][:, 1])
    return {c: {"size of the load (base bending moment)": g} for c in DISPLACEMENT}


def plot_measured(ax, data: Measured, predicted: dict, params: dict, options: dict) -> None:
    """Top view of the top's path, measured against model (the Rocaspect paper, Fig. 6 style), mm."""
    ax.plot(1e3 * data["dx_m"], 1e3 * data["dy_m"], ".", ms=2.5, color="0.35", label="measured")
    ax.plot(1e3 * predicted["dx_m"], 1e3 * predicted["dy_m"], "-", lw=1.2, color="C3", label="model")
    ax.set_xlabel("dx (mm)")
    ax.set_ylabel("dy (mm)")
    ax.set_title("mast top, plan view")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize=8)


_EXPERIMENT = Experiment(
    name="mast-top",
    title="mast-top wrench and displacement (the Rocaspect paper, 3R model)",
    columns=tuple(
        Column(c, u, d)
        for c, u, d in (
            ("fx_N", "N", "change of the force on the mast top, base frame, x"),
            ("fy_N", "N", "change of the force on the mast top, base frame, y"),
            ("fz_N", "N", "change of the force on the mast top, base frame, z"),
            ("mx_Nm", "N m", "change of the moment about the top point, base frame, x"),
            ("my_Nm", "N m", "change of the moment about the top point, base frame, y"),
            ("mz_Nm", "N m", "change of the moment about the top point, base frame, z"),
            ("dx_m", "m", "measured displacement of the top, x"),
            ("dy_m", "m", "measured displacement of the top, y"),
            ("dz_m", "m", "measured displacement of the top, z"),
        )
    ),
    channels=DISPLACEMENT,
    parameters=(
        Parameter("k_theta1", "N m/rad", 2.5e5, 1e2, 1e10, "stiffness of the base joint about x (Eq. 5)", scale=2.5e5),
        Parameter("k_theta2", "N m/rad", 2.5e5, 1e2, 1e10, "stiffness of the base joint about y (Eq. 5)", scale=2.5e5),
    ),
    model=model,
    options={
        "r_oc_m": (0.0, 0.0, L_MAST),
        "k_theta3_Nm_per_rad": np.inf,
        "s_out_m": 0.1,
        "s_in_m": 0.094,
        "nu": 0.3,
        "printed_sign": False,
    },
    renamed_options={"seed_sign": "printed_sign"},
    hooks={"top_displacement": "dc_T (n, 3) m: translation of the top point"},
    quantities={
        "load": Quantity("N m", axes=("x", "y"), symbol="M", scale=1e3, doc="moment on the base joint"),
        "displacement": Quantity("rad", axes=("x", "y"), scale=1e-3, doc="rotation of the base joint"),
    },
    doc=__doc__,
    prepare=_prepare,
    initial_guess=initial_guess,
    load_measure=load_measure,
    load_label="base bending moment (N m)",
    plot_measured=plot_measured,
    noise_covariates=noise_covariates,
    error_unit="m",
    min_rows=10,
    source="mast-top",
)

EXPERIMENT = _EXPERIMENT
