"""Element families of a model, as the analysis evaluates them (node labels turned into indices)."""

from __future__ import annotations

import copy

import numpy as np

from ..elements.beam_corot import BeamFamily, element_frames
from ..elements.truss import TrussFamily
from ..errors import ModelError
from ..model.arrays import node_rows


def build_families(model):
    """Element families (with node *indices*) from a model's beams, trusses and user families."""
    X = model.coordinates
    fams = []
    groups = {}
    for i, b in enumerate(model.beams):
        groups.setdefault(("beam", b.family), []).append(i)
    for i, t in enumerate(model.trusses):
        groups.setdefault(("truss", t.family), []).append(i)
    for (kind, name), which in groups.items():
        every = model.beams if kind == "beam" else model.trusses
        specs = [every[i] for i in which]
        _, nodes = node_rows(model, [s.nodes for s in specs], f"{kind} family '{name}'")
        nodes = np.ascontiguousarray(nodes, dtype=np.int64)
        labels = np.array([s.label for s in specs])
        lengths = np.linalg.norm(X[nodes[:, 1]] - X[nodes[:, 0]], axis=1)
        if kind == "beam":
            E0, parallel = element_frames(X[nodes[:, 0]], X[nodes[:, 1]], np.array([s.up for s in specs], float))
            if parallel.any():
                raise ModelError(
                    f"beam element {labels[np.flatnonzero(parallel)[0]]}: up-vector parallel to the element"
                )
            sec = [s.section for s in specs]
            fams.append(
                BeamFamily(
                    nodes,
                    E0,
                    lengths,
                    [c.E * c.A for c in sec],
                    [c.G * c.J for c in sec],
                    [c.E * c.Iy for c in sec],
                    [c.E * c.Iz for c in sec],
                    labels=labels,
                    name=name,
                )
            )
        else:
            L0 = lengths.copy()
            given = np.array([s.L0 is not None for s in specs], bool)
            pre = np.array([s.pretension is not None and s.L0 is None for s in specs], bool)
            if given.any():
                L0[given] = [specs[i].L0 for i in np.flatnonzero(given)]
            if pre.any():
                k = np.flatnonzero(pre)
                L0[k] = lengths[k] / (
                    1.0 + np.array([specs[i].pretension for i in k]) / np.array([specs[i].EA for i in k])
                )
            fams.append(
                TrussFamily(nodes, L0, [s.EA for s in specs], [s.tension_only for s in specs], labels=labels, name=name)
            )
    for fam in model.families:
        f = copy.copy(fam)
        f.nodes = np.ascontiguousarray(np.vectorize(model.index)(np.asarray(fam.nodes)), dtype=np.int64)
        fams.append(f)
    names = [f.name for f in fams]
    for n in set(names):
        if names.count(n) > 1:
            raise ModelError(f"two element families are named '{n}'; give them different names")
    return fams
