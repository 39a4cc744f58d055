"""Cable and shroud effects: progressive stiffness (the Rocaspect paper, Eq. 25), cable hysteresis, pretension
loss or error, and the stretch-removal error of a pull test (Stohlman & Pellegrino, Eq. 15).

Hooks as in :mod:`femast.effects.joints`.
"""

from __future__ import annotations

import numpy as np

from .base import Effect, Implementation, register_effect
from .operators import proportional_iwan, proportional_play
from .parameters import Parameter
from .quantities import unit_inverse

FE = ("bay-torsion", "tip-cycle")


# ----------------------------------------------------------------------------- progressive stiffness
def _progressive(u, p, ctx):
    a = np.abs(ctx["load"])
    return u / (1.0 + p["beta"] * a + p.get("beta2", 0.0) * a * a)


def _progressive_per_side(u, p, ctx):
    L = ctx["load"]
    return u / (1.0 + p["beta_p"] * np.maximum(L, 0.0) - p["beta_n"] * np.minimum(L, 0.0))


def _beta(L, lower=0.0, name="beta", what="relative stiffening per unit load"):
    return Parameter(
        name,
        unit_inverse(L.unit),
        0.1 / L.scale,
        lower * 100 / L.scale,
        100 / L.scale,
        what,
        scale=0.1 / L.scale,
        starts=(0.01 / L.scale, 1 / L.scale),
    )


def _progressive_params(q):
    return (_beta(q["load"]),)


def _progressive_per_side_params(q):
    L = q["load"]
    return (
        _beta(L, name="beta_p", what="relative stiffening per unit load, positive load (the shroud on that side)"),
        _beta(L, name="beta_n", what="relative stiffening per unit load, negative load (the shroud on that side)"),
    )


def _progressive_quadratic_params(q):
    L = q["load"]
    return (
        _beta(L, lower=-1.0),
        Parameter(
            "beta2",
            unit_inverse(L.unit, 2),
            0.0,
            0.0,
            1e4 / L.scale**2,
            "relative stiffening per unit load squared (the k2 tau^2 term of the Rocaspect paper's Eq. 25)",
            scale=1 / L.scale**2,
            starts=(1 / (10 * L.scale**2), 10 / L.scale**2),
        ),
    )


PROGRESSIVE_STIFFNESS = register_effect(
    Effect(
        name="progressive_stiffness",
        title="progressive, tension-dependent shroud/cable stiffness",
        physics=(
            "Dyneema shrouds stiffen with tension: EA(tau) = k0 + k1 tau + k2 tau^2 (the Rocaspect paper, Eq. 25, "
            ":mod:`femast.elements.shroud_law`).  The shroud that takes up a joint moment m gains tension in proportion "
            "to |m|, so to first order the joint's secant stiffness rises as k (1 + beta |m|), beta = k1 / "
            "(a EA(tau0)) with a the shroud lever arm (m) and tau0 the pretension.  The identified beta gives back "
            "the slope k1 of Eq. 25 for an assumed lever arm."
        ),
        signature="the structure is stiffer than the linear model at high load and softer near zero: the error is "
        "odd in the load, largest at the load peaks",
        acts_where=("peak",),
        source="the Rocaspect paper, Eq. 25",
        mechanism=Implementation(
            hook="displacement",
            needs=("load",),
            order=20,
            parameters=_progressive_params,
            apply=_progressive,
            form="linear",
            doc="u = u_linear / (1 + beta |L|) on every axis (secant stiffness rising with the load).",
            forms={
                "quadratic": Implementation(
                    hook="displacement",
                    needs=("load",),
                    order=20,
                    parameters=_progressive_quadratic_params,
                    apply=_progressive,
                    doc="u = u_linear / (1 + beta |L| + beta2 L^2): both terms of the Rocaspect paper's Eq. 25 (beta2 = "
                    "0: the linear form).",
                ),
                "per_side": Implementation(
                    hook="displacement",
                    needs=("load",),
                    order=20,
                    parameters=_progressive_per_side_params,
                    apply=_progressive_per_side,
                    from_baseline=True,
                    doc="u = u_linear / (1 + beta_p <L>+ + beta_n <-L>+): each sign of the load is taken up by "
                    "its own shroud or guy, stiffening by its own amount (a slack or differently tensioned guy "
                    "on one side: one-sided stiffening; beta_p = beta_n: the linear form).",
                ),
            },
        ),
    )
)


# ----------------------------------------------------------------------------- cable hysteresis
def _cable_hysteresis(L, p, ctx):
    return proportional_play(L, p["eta"])


def _cable_hysteresis_iwan(L, p, ctx):
    return proportional_iwan(L, p["eta"], p["beta"], p["alpha"])


_ETA = Parameter("eta", "-", 0.05, 0.0, 0.6, "loop half-width relative to the load", scale=0.05, starts=(0.01, 0.2))


def _iwan_eta(default, of, starts):
    """eta of the Iwan form: the largest friction threshold of a rope's fibre groups, relative to ``of``."""
    return Parameter(
        "eta",
        "-",
        default,
        0.0,
        0.99,
        f"largest friction threshold of the fibre groups relative to the {of}",
        scale=0.1,
        starts=starts,
    )


def _iwan_beta(starts):
    """beta of the Iwan form: the shape of the distribution of the fibre groups' thresholds."""
    return Parameter(
        "beta",
        "-",
        1.0,
        0.05,
        50.0,
        "shape of the threshold distribution P(e <= s) = (s / eta)^beta",
        scale=1.0,
        starts=starts,
    )


_ETA_IWAN = (
    _iwan_eta(0.3, "load", (0.6, 0.95, 0.3)),
    _iwan_beta((1.0, 3.0, 0.5)),
    Parameter("alpha", "-", 0.1, 0.0, 0.95, "share of the load without friction", scale=0.1, starts=(0.2, 0.0, 0.1)),
)


def _cable_hysteresis_latch_pull(x, p, ctx):
    dT = ctx["prep"]["dT"]
    T = np.abs(dT)
    lag = T - proportional_play(T, p["eta"])
    return x + np.sign(dT) * ctx["options"]["cable_compliance_m_per_N"] * lag


def _cable_hysteresis_latch_pull_iwan(x, p, ctx):
    dT = ctx["prep"]["dT"]
    T = np.abs(dT)
    lag = p["kappa"] * T - p["gain"] * proportional_iwan(T, p["eta"], p["beta"])
    return x + np.sign(dT) * ctx["options"]["cable_compliance_m_per_N"] * lag


CABLE_HYSTERESIS = register_effect(
    Effect(
        name="cable_hysteresis",
        title="cable hysteresis between loading and unloading",
        physics=(
            "A rope stretches less on loading than on unloading at the same tension (the Rocaspect paper, Fig. 4a: 'a "
            "significant difference between loading and unloading the shroud').  Modelled as friction between "
            "fibres whose normal force grows with the tension: a play operator of half-width eta |tau|, so the "
            "loop widens in proportion to the load and closes at zero load (unlike Coulomb friction, whose loop "
            "has a constant width)."
        ),
        signature="loading and unloading branches with different slopes, a loop whose width grows with the load "
        "and closes at zero; the error is largest at high load and just after reversals",
        acts_where=("peak", "reversal", "loading", "unloading"),
        source="Rocaspect guyed mast, Sec. IV-A, Fig. 4a",
        mechanism=Implementation(
            hook="load",
            order=45,
            parameters=(_ETA,),
            apply=_cable_hysteresis,
            form="play",
            doc="L -> play(L; eta |L|) on every axis: the cable- or shroud-supported connection is (1 - eta) / k "
            "compliant on loading and (1 + eta) / k on unloading.",
            forms={
                "iwan": Implementation(
                    hook="load",
                    order=45,
                    parameters=_ETA_IWAN,
                    apply=_cable_hysteresis_iwan,
                    doc="L -> alpha L + (1 - alpha) mean_j play(L; eta_j |L|), eta_j = eta q_j^(1/beta): a rope's fibre "
                    "groups with a distribution of friction coefficients (24 groups); smooth loops closing at zero "
                    "load, return branches curved (beta -> inf, alpha = 0: the play form).",
                )
            },
        ),
        implementations={
            "latch-pull": Implementation(
                hook="bead_position",
                order=45,
                parameters=(
                    Parameter(
                        "eta",
                        "-",
                        0.1,
                        0.0,
                        0.6,
                        "loop half-width of the test cable's stretch",
                        scale=0.1,
                        starts=(0.02, 0.3),
                    ),
                ),
                apply=_cable_hysteresis_latch_pull,
                form="play",
                doc="x_bead = x + sign(dT) c_cable (|dT| - play(|dT|; eta |dT|)): Eq. 15 removed the mean stretch "
                "c_cable |dT| (c_cable = L_cable / EA, option cable_compliance_m_per_N), the cable's own "
                "stretch lags it.",
                forms={
                    "iwan": Implementation(
                        hook="bead_position",
                        order=45,
                        parameters=(
                            _iwan_eta(0.5, "tension", (0.9, 0.3, 0.6)),
                            _iwan_beta((1.0, 4.0, 0.5)),
                            Parameter(
                                "gain",
                                "-",
                                1.0,
                                0.0,
                                20.0,
                                "hysteretic stretch compliance relative to c_cable",
                                scale=1.0,
                                starts=(3.0, 1.0, 6.0),
                            ),
                            Parameter(
                                "kappa",
                                "-",
                                1.0,
                                -20.0,
                                20.0,
                                "compliance Eq. 15 removed, relative to c_cable",
                                scale=1.0,
                                starts=(2.0, 1.0, 4.0),
                            ),
                        ),
                        apply=_cable_hysteresis_latch_pull_iwan,
                        from_baseline=True,  # the play form is centred on Eq. 15's line: see its doc
                        doc="x_bead = x + sign(dT) c_cable (kappa |dT| - gain P(|dT|)), P(T) = mean_j play(T; eta_j T), "
                        "eta_j = eta q_j^(1/beta): the test cable's stretch c_cable gain P(T) follows the tension "
                        "through fibre groups with a distribution of friction coefficients (smooth loops closing at "
                        "zero), Eq. 15 removed c_cable kappa T.  kappa = gain = 1, beta -> inf: the play form.  Fitted from the "
                        "baseline too: the play form's loop is centred on the line Eq. 15 removed, so a loop that "
                        "follows that line on loading and bows only on the return (a rope that creeps back) "
                        "gains nothing in it, and in this form it does.",
                    )
                },
            ),
        },
    )
)


# ----------------------------------------------------------------------------- pretension loss / error
def _pretension_fe(bay, p, ctx):
    return {**bay, "pretension": float(bay["pretension"]) + float(p["dT0"])}


def _stiffness_loss(u, p, ctx):
    tau = ctx["time"]
    if np.ndim(u) == 2:
        tau = tau[:, None]
    tc = p.get("t_c")
    if tc is not None:  # saturating (creep-like) loss, normalised to lam at the end of the test
        tau = -np.expm1(-tau / tc) / -np.expm1(-1.0 / tc)
    return u / (1.0 - p["lam"] * tau)


_LAM = Parameter("lam", "-", 0.1, 0.0, 0.9, "relative stiffness loss over the test", scale=0.1)


PRETENSION = register_effect(
    Effect(
        name="pretension_loss",
        title="pretension error or loss",
        physics=(
            "The stiffness of a guyed or cable-braced structure depends on the cable pretension (the Rocaspect paper, Table "
            "III: the 3R joint stiffness falls from 2.7e5 to 2.2e5 N m/rad between 1200 N and 400 N of shroud "
            "pretension; Stohlman & Pellegrino, Eq. 16 measures the ADAM cable pretension by vibration).  A pretension that creeps "
            "or slips during a test makes the stiffness fall with time; a pretension different from the assumed one "
            "shifts it (identifiable only in models that take the pretension as an input: bay-torsion, tip-cycle)."
        ),
        signature="the structure softens as the test goes on: the error grows with time in proportion to the load "
        "(pretension lost during the test); once the latches have released, the bay's moment is offset (a "
        "pretension set differently from the model's)",
        acts_where=("peak", "loading", "unloading", "zone (d) no contact"),
        source="Rocaspect guyed mast, Table III; Stohlman & Pellegrino, Eq. 16",
        mechanism=Implementation(
            hook="displacement",
            needs=("time",),
            order=60,
            parameters=(_LAM,),
            apply=_stiffness_loss,
            form="linear",
            doc="k(t) = k (1 - lam tau): u = u / (1 - lam tau), tau the normalised time in [0, 1] (t_s column or row "
            "index; per group, or across the files where time is continuous).",
            forms={
                "saturating": Implementation(
                    hook="displacement",
                    needs=("time",),
                    order=60,
                    parameters=(
                        _LAM,
                        Parameter(
                            "t_c",
                            "-",
                            0.3,
                            0.01,
                            100.0,
                            "time constant of the loss, as a fraction of the test's duration",
                            scale=0.3,
                            starts=(0.05, 3.0),
                        ),
                    ),
                    apply=_stiffness_loss,
                    doc="k(t) = k (1 - lam (1 - exp(-tau / t_c)) / (1 - exp(-1 / t_c))): a loss that levels off "
                    "(creep, slip of a termination); t_c -> inf is the linear form.",
                )
            },
        ),
        implementations={
            **{
                e: Implementation(
                    hook="bay_parameters",
                    order=60,
                    parameters=(
                        Parameter(
                            "dT0",
                            "N",
                            0.0,
                            -150.0,
                            150.0,
                            "error of the cable pretension against the nominal option pretension_N (< 0: a loss)",
                            scale=20.0,
                        ),
                    ),
                    apply=_pretension_fe,
                    doc="the FE cables are pretensioned to pretension_N + dT0 (a constant error or a loss before the "
                    "test, e.g. creep since the vibration measurement of Stohlman & Pellegrino, Eq. 16).",
                )
                for e in FE
            },
        },
    )
)


# ----------------------------------------------------------------------------- stretch-removal error (Eq. 15)
def _stretch_latch_pull(x, p, ctx):
    return x - p["c_s"] * ctx["prep"]["dT"]


STRETCH_ERROR = register_effect(
    Effect(
        name="stretch_error",
        title="cable stretch-removal error (Stohlman & Pellegrino, Eq. 15)",
        physics=(
            "Eq. 15 removes the stretch T L_cable / EA of the loaded test cable to get the bead position.  A wrong "
            "EA or L_cable (or the length change of the loaded cable, T (x - x_start) / EA) leaves a position error "
            "proportional to the force: x_bead = x - c_s dT, c_s the compliance error (m/N)."
        ),
        signature="the measured curve is sheared along x in proportion to the force: the error is largest at the "
        "force peaks and changes sign with the force",
        acts_where=("peak",),
        source="Stohlman & Pellegrino, Eq. 15",
        implementations={
            "latch-pull": Implementation(
                hook="bead_position",
                order=20,
                parameters=(
                    Parameter("c_s", "m/N", 1e-6, -1e-4, 1e-4, "compliance error of the stretch removal", scale=1e-6),
                ),
                apply=_stretch_latch_pull,
                doc="x_bead = x - c_s dT.",
            ),
        },
    )
)
