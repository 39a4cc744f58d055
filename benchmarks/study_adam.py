"""A study script: the tip of an ADAM mast (Stohlman & Pellegrino) over the scatter of its joint friction,
cable pretension and longeron lengths, after pretensioning and one Table 1 cycle.

    femast study benchmarks/study_adam.py --samples 64 --workers 2     # 10 bays (ADAM_BAYS=40: 40)

Used by benchmarks/study_throughput.py (``adam_study(n_bays)``).  The scatter is illustrative
(the shape-accuracy study states the paper's): friction coefficient mu uniform 0.4-0.6, pretension
uniform +-10 % of 170 N, each longeron's unstressed length off by a normal 0.025 mm standard
deviation truncated at +-0.05 mm.
"""

import os

import femast.studies as st
from femast.adam import BayParameters, build_mast
from femast.adam.build import LONGERON_FAMILY
from femast.adam.steps import CONVERGENCE, add_initial_steps, add_table1_steps


def longeron_labels(model):
    """Element labels of the longerons, in building order."""
    return [b.label for b in model.beams if b.family == LONGERON_FAMILY]


def make_factory(n_bays: int, cycles: int = 1):
    def adam_mast(mu, pretension, dL_longeron):
        am = build_mast(n_bays, BayParameters().with_(mu=mu, pretension=pretension))
        am.model.length_error(longeron_labels(am.model), dL_longeron)
        add_initial_steps(am)
        add_table1_steps(am, cycles=cycles, increments=1)  # the throughput figures' runs: one increment per step
        return am.model

    return adam_mast


def adam_study(
    n_bays: int = 10, cycles: int = 1, sensitivity: bool = False, sampler: str = "sobol", seed: int = 1
) -> st.Study:
    """The study of an ``n_bays`` mast: tip displacement (m) and rotation (rad) at the end of every
    step relative to the pretensioned state; the residual twist after the cycle (rad)."""
    am = build_mast(n_bays)  # for the labels only
    n_long = len(longeron_labels(am.model))
    last = f"0b#{cycles}"
    return st.Study(
        model=make_factory(n_bays, cycles),
        inputs=[
            st.Uniform("mu", 0.4, 0.6),
            st.Uniform("pretension", 153.0, 187.0),
            st.TruncatedNormal("dL_longeron", 0.0, 0.025e-3, low=-0.05e-3, high=0.05e-3, size=n_long),
        ],
        outputs=[
            st.NodeOutput("tip_u", node=am.control, quantity="U", relative_to="pretension"),
            st.NodeOutput("tip_rot", node=am.control, quantity="URA", relative_to="pretension"),
            st.NodeOutput(
                "residual_rz", node=am.control, quantity="URA", components="z", at=last, relative_to="pretension"
            ),
        ],
        analysis={"convergence": CONVERGENCE},
        sampler=sampler,
        seed=seed,
        sensitivity=sensitivity,
        name=f"adam{n_bays}",
    )


study = adam_study(int(os.environ.get("ADAM_BAYS", "10")))
