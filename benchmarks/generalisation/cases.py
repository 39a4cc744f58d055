"""Catalogue of the generalisation cases and the data generator (numpy only).

A :class:`Case` names the rig, the load path, the number of samples, the noise model and the
hidden mechanisms (each ``(mechanism, form, {parameters})``, written with
:mod:`.mechanisms`), and what a correct diagnosis says:

* ``expect="effect"``: the single mechanism is in femast's library under the name ``effects[0]``
  (in another functional form than femast's);
* ``expect="pair"``: two library mechanisms at once (``effects`` both);
* ``expect="ool"``: a mechanism femast has no effect for (out of library);
* ``expect="time"``: a time-dependent mechanism femast has no effect for (creep): a correct
  diagnosis says that nothing in the library explains it, or names only effects that change with
  time, never a rate-independent one (friction);
* ``expect="null"``: the baseline physics only (``redraws`` noise draws).

:func:`generate` returns the data columns of one draw (``seed`` -> numpy ``default_rng``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import connection as conn
from . import mechanisms as mech
from . import noise as nz
from .rigs import (
    K_JOINTS,
    LATCH,
    hold_force,
    joint_moments,
    latch_law,
    latch_path,
    mast_path,
    roller_opening,
    top_translation,
    viscous_joint,
)

SIGMA_TRACKER_M = 50e-6  # laser tracker noise per axis (m), mast top
SIGMA_LOADCELL_N = 0.5  # load cell noise (N), latch pull
EQ15 = {"C": 2.5e-6, "sigma_T": 0.4, "sigma_d": 8e-6}  # cable compliance m/N, load-cell N, distance m
AR_PHI = 0.6  # lag-1 autocorrelation of the correlated noise
STUDENT_NU = 3.0  # degrees of freedom of the heavy-tailed noise
# joint test (a connection on an actuator): elastic stiffness, protocols, noise of the two channels
JT_K = 2.0e6  # N/m
JT_AMPS_N, JT_STEP_N = (2.0e3, 4.0e3, 6.0e3, 8.0e3), 40.0  # force protocol (N)
JT_AMPS_M, JT_STEP_M = (1.0e-3, 2.0e-3, 3.0e-3, 4.0e-3), 0.04e-3  # displacement protocol (m)
JT_SIGMA_U, JT_SIGMA_F = 20e-6, 20.0  # displacement transducer (m), load cell (N)
JT_QUANTUM_U, JT_QUANTUM_F = 10e-6, 10.0  # the resolution of a test recorded to 0.01 mm and 0.01 kN
SPIKES, SPIKE_N = 12, 10.0  # single-sample spikes per latch-pull data set, their largest size (N)


@dataclass(frozen=True)
class Case:
    """One benchmark case (see the module docstring)."""

    name: str
    experiment: str
    expect: str
    effects: tuple = ()
    mechanisms: tuple = ()
    noise: str = "white"
    level: float = 1.0
    n: int = 500
    path: str = "cycles30"
    redraws: int = 1
    amp: float = 10.0
    doc: str = ""
    tags: tuple = field(default_factory=tuple)


def _m(name, form, **params):
    return (name, form, params)


# moments in N m, rotations in rad (mast top); forces in N, positions in m (latch pull)
CASES = (
    # ---------------------------------------------------------------- mast top, one mechanism
    Case(
        "mt_friction_dahl",
        "mast-top",
        "effect",
        ("friction_hysteresis",),
        (_m("friction", "dahl", F_c=8.0, sigma=3e5, alpha=1.0),),
        level=0.5,
        doc="Dahl joint friction, smooth loops",
    ),
    Case(
        "mt_friction_boucwen",
        "mast-top",
        "effect",
        ("friction_hysteresis",),
        (_m("friction", "boucwen", F_y=10.0, u_y=5e-5, n=2.0),),
        path="biaxial",
        n=400,
        level=0.5,
        doc="Bouc-Wen joint friction, biaxial excursions",
    ),
    Case(
        "mt_friction_jenkins",
        "mast-top",
        "effect",
        ("friction_hysteresis",),
        (_m("friction", "jenkins", k_s=2.5e5, F_s=7.0),),
        noise="ar1",
        n=600,
        level=0.5,
        doc="elasto-slip joint (finite stick stiffness), AR(1) noise",
    ),
    Case(
        "mt_clearance_tanh",
        "mast-top",
        "effect",
        ("joint_clearance",),
        (_m("clearance", "tanh", c=1.0e-4, m0=3.0),),
        doc="clearance closing smoothly over ~10 % of the load",
    ),
    Case(
        "mt_clearance_hertz",
        "mast-top",
        "effect",
        ("joint_clearance",),
        (_m("clearance", "hertz", c=0.5e-4, k0=2e4, K=5.7e7),),
        noise="hetero",
        n=300,
        doc="play then Hertzian contact, heteroscedastic noise, 300 samples",
    ),
    Case(
        "mt_clearance_piecewise",
        "mast-top",
        "effect",
        ("joint_clearance",),
        (_m("clearance", "piecewise", c=0.5e-4, k0=2.5e4, k1=5e6),),
        level=0.4,
        n=800,
        doc="play with a soft inner spring then linear contact, low noise, 800 samples",
    ),
    Case(
        "mt_progressive_duffing",
        "mast-top",
        "effect",
        ("progressive_stiffness",),
        (_m("stiffening", "duffing", k3_rel=1.0e8),),
        amp=40.0,
        level=0.7,
        doc="cubic hardening of the joints",
    ),
    Case(
        "mt_progressive_asinh",
        "mast-top",
        "effect",
        ("progressive_stiffness",),
        (_m("stiffening", "asinh", m0=6.0),),
        noise="ar1",
        n=400,
        amp=40.0,
        level=0.7,
        doc="tangent stiffness growing with the load, AR(1) noise",
    ),
    Case(
        "mt_cable_loop_quadratic",
        "mast-top",
        "effect",
        ("cable_hysteresis",),
        (_m("cable_loop", "quadratic", eps=1.0),),
        amp=20.0,
        level=0.7,
        doc="shroud loop closing at zero, quadratic return",
    ),
    Case(
        "mt_cable_loop_power",
        "mast-top",
        "effect",
        ("cable_hysteresis",),
        (_m("cable_loop", "power", eps=1.0),),
        noise="hetero",
        amp=20.0,
        level=0.7,
        doc="shroud loop, power-law return branch",
    ),
    Case(
        "mt_pretension_exp",
        "mast-top",
        "effect",
        ("pretension_loss",),
        (_m("drift", "exp", lam=0.6, tau0=0.3),),
        path="onesided",
        amp=20.0,
        level=0.6,
        doc="creep relaxation of the shrouds",
    ),
    Case(
        "mt_pretension_step",
        "mast-top",
        "effect",
        ("pretension_loss",),
        (_m("drift", "step", lam=0.5),),
        noise="ar1",
        amp=20.0,
        doc="a shroud slips in its grip half-way",
    ),
    Case(
        "mt_beam_timoshenko",
        "mast-top",
        "effect",
        ("beam_flexibility",),
        (_m("beam", "timoshenko", EI=0.8e5, GA=2e5),),
        path="moments",
        doc="lattice mast as a Timoshenko beam (bending + shear), top moments in the path",
    ),
    Case(
        "mt_beam_stepped",
        "mast-top",
        "effect",
        ("beam_flexibility",),
        (_m("beam", "stepped", EI1=3e5, EI2=0.5e5, L1=2.0),),
        path="moments",
        n=400,
        doc="two-section (telescopic) beam, top moments in the path",
    ),
    # ---------------------------------------------------------------- mast top, pairs and out of library
    Case(
        "mt_pair_clearance_friction",
        "mast-top",
        "pair",
        ("joint_clearance", "friction_hysteresis"),
        (_m("clearance", "tanh", c=0.6e-4, m0=5.0), _m("friction", "jenkins", k_s=3e5, F_s=7.0)),
        doc="smooth clearance and elasto-slip friction together",
    ),
    Case(
        "mt_pair_stiffening_pretension",
        "mast-top",
        "pair",
        ("progressive_stiffness", "pretension_loss"),
        (_m("stiffening", "duffing", k3_rel=1.0e8), _m("drift", "exp", lam=0.5, tau0=0.3)),
        amp=30.0,
        doc="hardening joints and a pretension creeping away",
    ),
    Case(
        "mt_ool_thermal_drift",
        "mast-top",
        "ool",
        (),
        (_m("thermal", "sine", A=0.25e-3, cycles=1.3),),
        doc="thermal drift of the top, independent of the load",
    ),
    Case(
        "mt_ool_viscous",
        "mast-top",
        "ool",
        (),
        (_m("viscous", "kelvin", T=6.0),),
        path="variable_rate",
        doc="viscous (rate-dependent) joints, slow and fast cycles",
    ),
    # ---------------------------------------------------------------- latch pull, one mechanism
    Case(
        "lp_friction_dahl",
        "latch-pull",
        "effect",
        ("friction_hysteresis",),
        (_m("friction", "dahl", F_c=3.0, sigma=4e4, alpha=1.0),),
        noise="eq15",
        doc="Dahl friction of the bead/cable, Eq. 15 noise",
    ),
    Case(
        "lp_friction_jenkins",
        "latch-pull",
        "effect",
        ("friction_hysteresis",),
        (_m("friction", "jenkins", k_s=5e4, F_s=3.0),),
        doc="elasto-slip friction",
    ),
    Case(
        "lp_friction_boucwen",
        "latch-pull",
        "effect",
        ("friction_hysteresis",),
        (_m("friction", "boucwen", F_y=3.0, u_y=8e-5, n=2.0),),
        noise="ar1",
        n=450,
        doc="Bouc-Wen friction, AR(1) load-cell noise",
    ),
    Case(
        "lp_latch_band_gauss",
        "latch-pull",
        "effect",
        ("latch_hysteresis",),
        (_m("latch_band", "gauss", F_h=8.0, ell=4e-4),),
        noise="eq15",
        doc="seated-bead band, Gaussian fade",
    ),
    Case(
        "lp_latch_band_linear",
        "latch-pull",
        "effect",
        ("latch_hysteresis",),
        (_m("latch_band", "linear", F_h=7.0, ell=6e-4),),
        doc="seated-bead band, linear fade",
    ),
    Case(
        "lp_latch_band_lorentz",
        "latch-pull",
        "effect",
        ("latch_hysteresis",),
        (_m("latch_band", "lorentz", F_h=8.0, ell=2.5e-4),),
        noise="eq15",
        n=320,
        doc="seated-bead band, Lorentzian fade, 320 samples",
    ),
    Case(
        "lp_clearance_tanh",
        "latch-pull",
        "effect",
        ("joint_clearance",),
        (_m("clearance", "tanh", c=8e-5, m0=3.0),),
        noise="eq15",
        doc="latch body play, smooth",
    ),
    Case(
        "lp_clearance_piecewise",
        "latch-pull",
        "effect",
        ("joint_clearance",),
        (_m("clearance", "piecewise", c=8e-5, k0=3.75e4, k1=1e7),),
        level=0.5,
        n=700,
        doc="latch body play, piecewise-linear contact, low noise",
    ),
    Case(
        "lp_stretch_quadratic",
        "latch-pull",
        "effect",
        ("stretch_error",),
        (_m("stretch", "quadratic", eps=0.6, T_ref=30.0),),
        noise="eq15",
        doc="stiffening cable, linear stretch removed by Eq. 15",
    ),
    Case(
        "lp_stretch_twoslope",
        "latch-pull",
        "effect",
        ("stretch_error",),
        (_m("stretch", "twoslope", eps_pos=0.8, eps_neg=0.2),),
        doc="the two pulling cables' compliances wrong by different amounts",
    ),
    Case(
        "lp_cable_loop_quadratic",
        "latch-pull",
        "effect",
        ("cable_hysteresis",),
        (_m("cable_loop", "quadratic", eps=0.6, C_h=1e-5),),
        noise="eq15",
        doc="cable stretch loop",
    ),
    Case(
        "lp_cable_loop_power",
        "latch-pull",
        "effect",
        ("cable_hysteresis",),
        (_m("cable_loop", "power", eps=0.7, C_h=1e-5),),
        doc="cable stretch loop, power-law return",
    ),
    # ---------------------------------------------------------------- latch pull, pairs and out of library
    Case(
        "lp_pair_band_stretch",
        "latch-pull",
        "pair",
        ("latch_hysteresis", "stretch_error"),
        (_m("latch_band", "gauss", F_h=8.0, ell=4e-4), _m("stretch", "twoslope", eps_pos=0.8, eps_neg=0.2)),
        noise="eq15",
        doc="seated-bead band and a stretch-removal error",
    ),
    Case(
        "lp_pair_friction_clearance",
        "latch-pull",
        "pair",
        ("friction_hysteresis", "joint_clearance"),
        (
            _m("friction", "dahl", F_c=3.0, sigma=4e4, alpha=1.0),
            _m("clearance", "piecewise", c=8e-5, k0=3.75e4, k1=1e7),
        ),
        doc="Dahl friction and latch body play",
    ),
    Case(
        "lp_ool_ripple",
        "latch-pull",
        "ool",
        (),
        (_m("ripple", "sine", A=3.0, wavelength=3.5e-4),),
        doc="roller out-of-roundness: a force ripple with the bead position",
    ),
    Case(
        "lp_ool_zero_drift",
        "latch-pull",
        "ool",
        (),
        (_m("zero_drift", "sine", A=2.0),),
        noise="eq15",
        doc="load-cell zero drift during the test",
    ),
    # ---------------------------------------------------------------- the misses of real use (heavy tails, spikes,
    # mechanisms that look like a pair, creep, a mechanism about one axis)
    Case(
        "mt_guys_slack",
        "mast-top",
        "effect",
        ("progressive_stiffness",),
        (_m("guys", "slack", k_g_rel=2.0, theta_s=0.3e-4, sides=1),),
        amp=20.0,
        doc="a slack guy going taut past a rotation on one side: the joint stiffens that way (no gap, no friction)",
    ),
    Case(
        "mt_friction_preisach",
        "mast-top",
        "effect",
        ("friction_hysteresis",),
        (_m("preisach", "gauss", c=4e-5, M_max=40.0),),
        level=0.5,
        doc="micro-slip contacts that jump (Preisach relays): hysteresis with curved branches",
    ),
    Case(
        "mt_creep_log",
        "mast-top",
        "time",
        (),
        (_m("creep", "log", phi=0.08, t0=1.0),),
        path="holds",
        level=0.5,
        doc="logarithmic creep of the joints, loads held at every peak and at zero",
    ),
    Case(
        "mt_clearance_x_only",
        "mast-top",
        "effect",
        ("joint_clearance",),
        (_m("clearance", "hertz", c=0.5e-4, k0=2e4, K=5.7e7, joints=(0,)),),
        path="biaxial",
        doc="play then Hertzian contact in the joint about x only; both axes loaded",
    ),
    # ---------------------------------------------------------------- joint test: a connection on an actuator
    Case(
        "jt_bwbn_plain",
        "joint-test",
        "effect",
        ("friction_hysteresis",),
        (_m("bwbn", "smooth"),),
        doc="smooth Bouc-Wen hysteresis of a connection (no pinching, no degradation), displacement protocol",
    ),
    Case(
        "jt_bwbn_pinched",
        "joint-test",
        "pair",
        ("friction_hysteresis", "pinching"),
        (_m("bwbn", "slip-lock", zeta_s=0.85, p=2e5, q=0.1, psi=0.3e-3, lam=0.5),),
        doc="Bouc-Wen hysteresis pinched by a slip-lock function that grows with the energy (BWBN)",
    ),
    Case(
        "jt_bwbn_degrading",
        "joint-test",
        "pair",
        ("friction_hysteresis", "degradation"),
        (_m("bwbn", "energy", dnu=2e4, deta=4e4),),
        doc="Bouc-Wen hysteresis whose strength and stiffness fall with the dissipated energy (BWBN)",
    ),
    Case(
        "jt_clearance_hertz",
        "joint-test",
        "effect",
        ("joint_clearance",),
        (_m("clearance", "hertz", c=3e-4, k0=1e6, K=2.8e9),),
        doc="an elastic connection with a play, a soft centring spring and Hertzian contact, force protocol",
    ),
    Case("jt_null_white", "joint-test", "null", redraws=20, doc="an elastic connection, white noise"),
    Case(
        "jt_null_quantised",
        "joint-test",
        "null",
        noise="quantised",
        redraws=20,
        doc="an elastic connection recorded to 0.01 mm and 0.01 kN",
    ),
    # ---------------------------------------------------------------- nulls (20 redraws each)
    Case("mt_null_white", "mast-top", "null", redraws=20, doc="baseline only, white noise"),
    Case("mt_null_ar1", "mast-top", "null", noise="ar1", redraws=20, doc="baseline only, AR(1) noise"),
    Case(
        "mt_null_hetero",
        "mast-top",
        "null",
        noise="hetero",
        path="biaxial",
        n=300,
        redraws=20,
        doc="baseline only, heteroscedastic noise, 300 samples",
    ),
    Case("lp_null_white", "latch-pull", "null", redraws=20, doc="baseline only, white load-cell noise"),
    Case(
        "lp_null_eq15",
        "latch-pull",
        "null",
        noise="eq15",
        redraws=20,
        doc="baseline only, Eq. 15 stretch removal (heteroscedastic)",
    ),
    Case("lp_null_ar1", "latch-pull", "null", noise="ar1", n=400, redraws=20, doc="baseline only, AR(1) noise"),
    Case(
        "mt_null_student",
        "mast-top",
        "null",
        noise="student",
        n=66,
        redraws=20,
        doc="baseline only, 66 samples, heavy-tailed (Student-t, 3 degrees of freedom) noise",
    ),
    Case(
        "lp_null_spikes",
        "latch-pull",
        "null",
        noise="spikes",
        redraws=20,
        doc="baseline only, white load-cell noise and 12 single-sample spikes",
    ),
)


def get_case(name: str) -> Case:
    """The case called ``name``."""
    for c in CASES:
        if c.name == name:
            return c
    raise KeyError(f"no case {name!r}; known: {', '.join(c.name for c in CASES)}")


# =========================================================================== mast top
def _joint_rotation(m, k, mechs, t, tau):
    """Rotation (rad) of one bending joint under its moment history m (N m)."""
    u = None
    for name, form, p in mechs:
        if name == "friction":
            if form == "jenkins":
                u, _ = mech.jenkins_load_controlled(m, k, p["k_s"], p["F_s"])
            else:
                g = (
                    mech.dahl_tangent(p["F_c"], p["sigma"], p["alpha"])
                    if form == "dahl"
                    else mech.bouc_wen_tangent(p["F_y"], p["u_y"], p["n"])
                )
                u, _ = mech.smooth_load_controlled(m, k, g)
        elif name == "stiffening":
            u = (
                mech.duffing_rotation(m, k, p["k3_rel"] * k)
                if form == "duffing"
                else mech.asinh_rotation(m, k, p["m0"])
            )
        elif name == "cable_loop":
            u = (mech.loop_quadratic(m, p["eps"]) if form == "quadratic" else mech.loop_power(m, p["eps"])) / k
        elif name == "viscous":
            u = viscous_joint(m, t, k, p["T"] * k)
        elif name == "guys":
            u = mech.slack_guys_rotation(m, k, p["k_g_rel"] * k, p["theta_s"], p.get("sides", 2))
        elif name == "preisach":
            u = mech.preisach_joint_rotation(m, k, p["c"], p["M_max"])
        elif name == "creep":
            u = mech.log_creep_rotation(m, t, k, p["phi"], p["t0"])
    if u is None:
        u = m / k
    for name, form, p in mechs:
        if name == "drift":
            u = u * mech.compliance_drift(tau, p["lam"], form, p.get("tau0", 0.3))
        elif name == "clearance":
            if form == "tanh":
                u = u + mech.clearance_tanh(m, p["c"], p["m0"])
            elif form == "piecewise":
                u = u + mech.clearance_piecewise(m, p["c"], p["k0"], p["k1"])
            else:
                u = u + mech.clearance_hertz(m, p["c"], p["k0"], p["K"])
    return u


def _mast(case: Case, rng) -> dict:
    w, t = mast_path(case.path, case.n, rng, amplitude_N=case.amp)
    tau = (t - t[0]) / (t[-1] - t[0])
    M = joint_moments(w)
    theta = np.zeros_like(M)
    for j in (0, 1):  # a mechanism with "joints" acts on those bending joints only (0: about x, 1: about y)
        mechs = tuple(mm for mm in case.mechanisms if j in mm[2].get("joints", (0, 1)))
        theta[:, j] = _joint_rotation(M[:, j], K_JOINTS[j], mechs, t, tau)
    d = top_translation(theta)
    for name, form, p in case.mechanisms:
        if name == "beam":
            L = 3.651
            if form == "timoshenko":
                c_f, c_m = mech.cantilever_compliance(L, [(L, p["EI"])], shear_GA=p["GA"])
            else:
                c_f, c_m = mech.cantilever_compliance(L, [(p["L1"], p["EI1"]), (L - p["L1"], p["EI2"])])
            d[:, 0] += c_f * w[:, 0] + c_m * w[:, 4]
            d[:, 1] += c_f * w[:, 1] - c_m * w[:, 3]
        elif name == "thermal":
            a = np.radians(120.0)
            s = p["A"] * np.sin(2 * np.pi * p["cycles"] * tau + 0.7)
            d[:, 0] += s * np.cos(a)
            d[:, 1] += s * np.sin(a)
    sig = SIGMA_TRACKER_M * case.level
    if case.noise == "white":
        e = [nz.white(rng, case.n, sig) for _ in range(3)]
    elif case.noise == "ar1":
        e = [nz.ar1(rng, case.n, sig, AR_PHI) for _ in range(3)]
    elif case.noise == "hetero":  # vibration of the top grows with the cable load
        f = np.hypot(w[:, 0], w[:, 1])
        scale = 0.4 + 1.6 * f / max(f.max(), 1e-12)
        e = [nz.heteroscedastic(rng, scale, sig) for _ in range(3)]
    elif case.noise == "student":  # heavy tails (a tracker losing the reflector now and then)
        e = [nz.student_t(rng, case.n, sig, STUDENT_NU) for _ in range(3)]
    else:
        raise ValueError(f"noise {case.noise!r} is not a mast-top noise model (white, ar1, hetero, student)")
    cols = {c: w[:, i] for i, c in enumerate(("fx_N", "fy_N", "fz_N", "mx_Nm", "my_Nm", "mz_Nm"))}
    for i, c in enumerate(("dx_m", "dy_m", "dz_m")):
        cols[c] = d[:, i] + e[i]
    cols["t_s"] = t
    return cols


# =========================================================================== latch pull
def _friction_force(x, mechs):
    for name, form, p in mechs:
        if name == "friction":
            if form == "jenkins":
                return mech.jenkins_driven(x, p["k_s"], p["F_s"])
            g = (
                mech.dahl_tangent(p["F_c"], p["sigma"], p["alpha"])
                if form == "dahl"
                else mech.bouc_wen_tangent(p["F_y"], p["u_y"], p["n"])
            )
            return mech.smooth_driven(x, g, substeps=10)
    return np.zeros_like(x)


def latch_truth(case: Case, rng):
    """True bead positions x (m, relative to the latch), forces dT (N), direction (+1 out, -1 in,
    0 hold) and time (s) of a latch pull case, before the measurement."""
    segs = latch_path(case.n, rng)
    x = np.concatenate([s for _, s in segs])
    kind = np.concatenate([np.full(s.size, {"hold": 0, "out": 1, "in": -1}[k]) for k, s in segs])
    fr = _friction_force(x, case.mechanisms)
    dT = np.where(kind > 0, latch_law(x, 1), latch_law(x, -1)) + np.where(kind != 0, fr, 0.0)
    xb = LATCH["xb"]
    for name, form, p in case.mechanisms:
        if name == "latch_band":
            b = p["F_h"] * mech.fade(x + xb, p["ell"], form)
            dT = dT + np.where(kind > 0, b, np.where(kind < 0, -b, 0.0))
        elif name == "ripple":
            dT = dT + np.where(
                (kind != 0) & (roller_opening(x) > 0), p["A"] * np.sin(2 * np.pi * (x + xb) / p["wavelength"]), 0.0
            )
    dT = np.where(kind > 0, np.maximum(dT, 0.0), np.where(kind < 0, np.minimum(dT, 0.0), dT))
    # holds: pushed onto the backstop, released, pulled up to the force at which the bead moves
    # (the first sample of the next pass, still at x = -x_b: the top of the static band, Eq. 9)
    i = 0
    for k, s in segs:
        if k == "hold":
            nxt = i + s.size
            brk = dT[nxt] if nxt < x.size else 0.0
            dT[i:nxt] = hold_force(s.size, 40.0 * rng.uniform(0.8, 1.1), brk)
        i += s.size
    t = 0.2 * np.arange(x.size)
    return x, dT, kind, t


def _latch(case: Case, rng) -> dict:
    x, dT, kind, t = latch_truth(case, rng)
    tau = (t - t[0]) / (t[-1] - t[0])
    xm = x.copy()  # the position the rig's Eq. 15 would recover without noise
    for name, form, p in case.mechanisms:
        if name == "clearance":  # the latch body shifts with the sign of the force
            if form == "tanh":
                xm = xm + mech.clearance_tanh(dT, p["c"], p["m0"])
            elif form == "piecewise":
                xm = xm + mech.clearance_piecewise(dT, p["c"], p["k0"], p["k1"])
            else:
                xm = xm + mech.clearance_hertz(dT, p["c"], p["k0"], p["K"])
        elif name == "stretch":  # stretch left over by a linear Eq. 15 removal (m)
            C = EQ15["C"]
            if form == "quadratic":
                xm = xm + p["eps"] * C * dT * np.abs(dT) / p["T_ref"]
            else:
                xm = xm + C * np.where(dT > 0, p["eps_pos"], p["eps_neg"]) * dT
        elif name == "cable_loop":
            loop = mech.loop_quadratic(dT, p["eps"]) if form == "quadratic" else mech.loop_power(dT, p["eps"])
            xm = xm + p["C_h"] * (loop - dT)
    dTm = dT.copy()
    for name, _form, p in case.mechanisms:
        if name == "zero_drift":
            dTm = dTm + p["A"] * (tau + 0.6 * np.sin(2 * np.pi * 1.5 * tau))
    sig = SIGMA_LOADCELL_N * case.level
    if case.noise == "white":
        dTm = dTm + nz.white(rng, x.size, sig)
    elif case.noise == "ar1":
        dTm = dTm + nz.ar1(rng, x.size, sig, AR_PHI)
    elif case.noise == "eq15":
        xm, dTm = nz.eq15_measurement(
            rng, xm, dTm, EQ15["C"], EQ15["sigma_T"] * case.level, EQ15["sigma_d"] * case.level
        )
    elif case.noise == "spikes":  # white load-cell noise and single-sample spikes
        dTm = dTm + nz.white(rng, x.size, sig) + nz.spikes(rng, x.size, SPIKES, SPIKE_N * case.level)
    else:
        raise ValueError(f"noise {case.noise!r} is not a latch-pull noise model (white, ar1, eq15, spikes)")
    return {"x_mm": 1e3 * xm, "dT_N": dTm, "t_s": t}


# =========================================================================== joint test
def _joint(case: Case, rng) -> dict:
    """A connection cycled on an actuator: the BWBN connection driven through a displacement
    protocol (its force measured), or an elastic connection (with a clearance) driven through a
    force protocol; both channels measured with noise."""
    bw = [p for name, _, p in case.mechanisms if name == "bwbn"]
    if bw:
        u, _ = conn.cyclic_protocol(JT_AMPS_M, step=JT_STEP_M)
        F = conn.bwbn_driven(u, conn.BWBN(**bw[0]), substeps=8)
    else:
        F, _ = conn.cyclic_protocol(JT_AMPS_N, step=JT_STEP_N)
        u = F / JT_K
        for name, _form, p in case.mechanisms:
            if name == "clearance":
                u = u + mech.clearance_hertz(F, p["c"], p["k0"], p["K"])
    n = u.size
    if case.noise == "white":
        um = u + nz.white(rng, n, JT_SIGMA_U * case.level)
        Fm = F + nz.white(rng, n, JT_SIGMA_F * case.level)
    elif case.noise == "quantised":  # a little noise, then the recorder's resolution
        um = JT_QUANTUM_U * np.round((u + nz.white(rng, n, 0.3 * JT_QUANTUM_U)) / JT_QUANTUM_U)
        Fm = JT_QUANTUM_F * np.round((F + nz.white(rng, n, 0.3 * JT_QUANTUM_F)) / JT_QUANTUM_F)
    else:
        raise ValueError(f"noise {case.noise!r} is not a joint-test noise model (white, quantised)")
    return {"F_N": Fm, "u_m": um}


def generate(case: Case, seed: int) -> dict:
    """Data columns (in the experiment's units) of one draw of ``case``."""
    rng = np.random.default_rng(seed)
    if case.experiment == "joint-test":
        return _joint(case, rng)
    return _mast(case, rng) if case.experiment == "mast-top" else _latch(case, rng)
