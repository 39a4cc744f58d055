"""Element families of a model, as the analysis evaluates them (node labels turned into indices)."""

from __future__ import annotations

import copy

import numpy as np

from ..elements.beam_corot import BeamFamily, element_frame
from ..elements.truss import TrussFamily
from ..errors import ModelError


def build_families(model):
    """Element families (with node *indices*) from a model's beams, trusses and user families."""
    X = model.coordinates
    fams = []
    groups = {}
    for b in model.beams:
        groups.setdefault(("beam", b.family), []).append(b)
    for t in model.trusses:
        groups.setdefault(("truss", t.family), []).append(t)
    for (kind, name), specs in groups.items():
        nodes = np.array([[model.index(n) for n in s.nodes] for s in specs], dtype=np.int64)
        labels = np.array([s.label for s in specs])
        lengths = np.linalg.norm(X[nodes[:, 1]] - X[nodes[:, 0]], axis=1)
        if kind == "beam":
            E0 = np.empty((len(specs), 3, 3))
            for i, s in enumerate(specs):
                frame = element_frame(X[nodes[i, 0]], X[nodes[i, 1]], s.up)
                if frame is None:
                    raise ModelError(f"beam element {s.label}: up-vector parallel to the element")
                E0[i] = frame
            sec = [s.section for s in specs]
            fams.append(BeamFamily(nodes, E0, lengths, [c.E * c.A for c in sec], [c.G * c.J for c in sec],
                                   [c.E * c.Iy for c in sec], [c.E * c.Iz for c in sec], labels=labels, name=name))
        else:
            L0 = np.empty(len(specs))
            for i, s in enumerate(specs):
                if s.L0 is not None:
                    L0[i] = s.L0
                elif s.pretension is not None:
                    L0[i] = lengths[i] / (1.0 + s.pretension / s.EA)
                else:
                    L0[i] = lengths[i]
            fams.append(TrussFamily(nodes, L0, [s.EA for s in specs], [s.tension_only for s in specs],
                                    labels=labels, name=name))
    for fam in model.families:
        f = copy.copy(fam)
        f.nodes = np.ascontiguousarray(np.vectorize(model.index)(np.asarray(fam.nodes)), dtype=np.int64)
        fams.append(f)
    names = [f.name for f in fams]
    for n in set(names):
        if names.count(n) > 1:
            raise ModelError(f"two element families are named '{n}'; give them different names")
    return fams

