"""A user's experiment script for the experiments tests: a spring pulled back and forth, and a user
effect (slip of its mount at zero force), as a user writes them in a file that ``femast compare``
and ``femast diagnose`` load.  Tests that run in one process give each copy its own names, so the
registries never hold two scripts' effects under one name."""


def spring_script(experiment: str, effect: str) -> str:
    """The script's text, with the experiment named ``experiment`` and its effect ``effect``."""
    return f'''
"""A user experiment: a spring pulled back and forth, and a user effect (slip at zero force)."""
import numpy as np
from femast.effects import Effect, Implementation, register_effect
from femast.experiments import Column, Experiment, Parameter

def model(params, data, effects, options):
    u = data["F_N"] / params["k"]
    u = effects.apply("extension", u, data=data, params=params, options=options)
    return {{"u_m": u}}

def _slip(u, p, ctx):
    return u + p["s"] * np.tanh(ctx["data"]["F_N"] / 1.0)

experiment = Experiment(
    name="{experiment}", title="a spring pulled back and forth",
    columns=(Column("F_N", "N", "applied force"), Column("u_m", "m", "measured extension")),
    channels=("u_m",), parameters=(Parameter("k", "N/m", 1e4, 1.0, 1e8, "spring stiffness"),),
    model=model, hooks={{"extension": "u (n,) m"}}, error_unit="m")

register_effect(Effect(
    name="{effect}", title="slip of the spring mount", physics="The mount slips by +-s with the force sign.",
    signature="a step at zero force", acts_where=("near-zero load",),
    implementations={{"{experiment}": Implementation(
        hook="extension", apply=_slip,
        parameters=(Parameter("s", "m", 1e-4, 0.0, 1e-2, "half slip", scale=1e-4),))}}),
    replace_existing=True)
'''
