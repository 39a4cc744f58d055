"""Many nodes, beams or trusses from arrays: ``model.nodes(X)``, ``model.beams(pairs, section)``,
``model.trusses(pairs, EA)``.

One vectorised check of the whole table replaces a Python call (and its checks) per element: the
1000-bay mast (4004 nodes, 12000 beams) builds in a few hundredths of a second instead of seconds.
The model holds exactly what the same calls of :meth:`Model.beam` / :meth:`Model.truss` make (the
same element specs, labels and order), so a model built either way solves bit for bit alike.

Example::

    import numpy as np
    import femast as fm
    m = fm.Model("ladder")
    n = np.asarray(m.nodes([[x, y, 0.0] for x in range(5) for y in (0.0, 1.0)]))
    tube = fm.circular_tube(0.02, 0.016, E=70e9)
    rails = m.beams(np.column_stack([n[0:-2], n[2:]]), tube, up=(0, 0, 1), family="rail")
    rungs = m.beams(n.reshape(-1, 2), tube, up=(1, 0, 0), family="rung")

Every value may be given once (shared by all the elements) or once per element (an array of
length n_elements); an error names the offending element (its row in the arrays) and its nodes.
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from .sections import Section
from .validation import MAX_MAGNITUDE


class ElementList(list):
    """The model's beam (or truss) element specs in the order they were added; calling it adds many
    elements from arrays (``model.beams(pairs, section)``, see :func:`add_beams`)."""

    def __init__(self, add=None):
        super().__init__()
        self._add = add

    def __call__(self, *args, **kwargs):
        return self._add(*args, **kwargs)


def _where(what, i, pairs):
    return f"{what}: element {i} (nodes {pairs[i, 0]}-{pairs[i, 1]})"


def node_rows(model, nodes, what: str):
    """The (n, 2) node *labels* ``nodes`` as (labels as Python-int pairs (n, 2) int64, node rows
    (n, 2)); a ModelError names the first element with a node that is not a whole-number label of
    the model."""
    try:
        a = np.asarray(nodes)
    except (TypeError, ValueError):
        raise ModelError(f"{what}: nodes must be an (n_elements, 2) array of node labels") from None
    if a.ndim == 1 and a.size == 2:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != 2:
        raise ModelError(
            f"{what}: nodes must be an (n_elements, 2) array of node labels (one row per element, "
            f"its two end nodes); got shape {a.shape}" + ("; transpose it" if a.ndim == 2 and a.shape[0] == 2 else "")
        )
    if a.dtype.kind not in "iuf" or a.dtype.kind == "b":
        raise ModelError(f"{what}: nodes must be whole-number node labels (got {a.dtype} values)")
    if a.dtype.kind == "f":
        bad = ~np.isfinite(a) | (a != np.round(a)) | (np.abs(a) > 2.0**62)
        if bad.any():
            i, j = np.argwhere(bad)[0]
            raise ModelError(
                f"{what}: element {i}: node {a[i, j]!r} is not a node label (a whole number); "
                "give the labels that model.node / model.nodes returned"
            )
    lab = a.astype(np.int64)
    known = np.asarray(model._node_labels, dtype=np.int64)
    order = np.argsort(known, kind="stable")
    sorted_ = known[order]
    pos = np.clip(np.searchsorted(sorted_, lab), 0, max(len(sorted_) - 1, 0))
    found = sorted_[pos] == lab if len(sorted_) else np.zeros(lab.shape, bool)
    if not found.all():
        i, j = np.argwhere(~found)[0]
        hint = f"known labels {known.min()}..{known.max()}" if len(known) else "the model has no nodes yet"
        raise ModelError(
            f"{_where(what, i, lab)}: unknown node {lab[i, j]} ({hint}); create it with "
            "model.node(x, y, z) or model.nodes(coords)"
        )
    return lab, order[pos]


def per_element(value, n: int, what: str, unit: str, *, lo=None, strict=True):
    """``value`` (one number or one per element) as a float array (n,); a ModelError names the element
    of a non-finite value, one beyond MAX_MAGNITUDE or one not above ``lo`` (at least, if not ``strict``)."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{what}: {value!r} is not a number or an array of numbers ({unit})") from None
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.shape != (n,):
        raise ModelError(f"{what}: give one value or one per element ({n}); got shape {a.shape}")
    bad = ~np.isfinite(a) | (np.abs(a) > MAX_MAGNITUDE)
    if lo is not None:
        bad |= ~(a > lo) if strict else ~(a >= lo)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        rule = "" if lo is None else (f" and {'>' if strict else '>='} {lo:g}")
        raise ModelError(
            f"{what} of element {i} = {a[i]!r} {unit} must be finite{rule} (within {MAX_MAGNITUDE:g} {unit})"
        )
    return a


def _names(value, n, what, default):
    if value is None:
        return [default] * n if isinstance(default, str) else list(default)
    if isinstance(value, str):
        return [value] * n
    names = list(value)
    if len(names) != n or not all(isinstance(s, str) for s in names):
        raise ModelError(f"{what}: family must be a name or one name (a string) per element ({n})")
    return names


def _lengths(model, rows):
    X = model.coordinates
    a, b = X[rows[:, 0]], X[rows[:, 1]]
    return a, b, np.sqrt(((b - a) ** 2).sum(axis=1))


def _check_lengths(a, b, L, what, labs, kind) -> None:
    """:func:`validation.element_length` of each element (vectorised: only suspects are checked one by one)."""
    from .validation import PRECISION, element_length

    far = np.maximum(np.abs(a).max(axis=1), np.abs(b).max(axis=1))
    for i in np.flatnonzero((L <= 1e-12 * np.maximum(1.0, far)) | (L < PRECISION * far)):
        element_length(float(L[i]), float(far[i]), _where(what, int(i), labs), kind, labs[i, 0], labs[i, 1])


def add_nodes(model, coords) -> list[int]:
    """Nodes at the rows of an (n, 3) array (m), labelled after the largest label so far; returns them."""
    from .validation import coordinates

    a = coordinates(coords, f"model '{model.name}': nodes()")
    start = (model._max_label + 1) if model._node_labels else 1
    labels = list(range(start, start + len(a)))
    n0 = len(model._node_labels)
    model._node_index.update(zip(labels, range(n0, n0 + len(a))))
    model._node_labels.extend(labels)
    model._node_xyz.extend(map(tuple, a.tolist()))
    if labels:
        model._max_label = labels[-1]
    return labels


def add_beams(
    model, nodes, section, up=(0.0, 0.0, 1.0), family="beam", mass_per_length=None, length_error_m=0.0, alpha_per_K=0.0
) -> np.ndarray:
    """One beam element per row of ``nodes`` ((n, 2) node labels), as :meth:`Model.beam` with ``n=1``.

    section : a Section, or one per element.  up : a global direction (3,) or one per element (n, 3)
    (the local y axis, made orthogonal to the element).  family : a name or one per element.
    mass_per_length (kg/m; None: section rho A), length_error_m (m), alpha_per_K (1/K): one value or
    one per element.  Returns the element labels (int64 array)."""
    what = f"model '{model.name}': beams()"
    from .specs import BeamSpec

    labs, rows = node_rows(model, nodes, what)
    n = len(labs)
    if isinstance(section, Section):
        secs = [section] * n
    else:
        try:
            secs = list(section)
        except TypeError:
            secs = None
        if secs is None or len(secs) != n:
            raise ModelError(
                f"{what}: section must be a femast Section or one per element ({n}); got {type(section).__name__}"
            )
        bad = [i for i, s in enumerate(secs) if not isinstance(s, Section)]
        if bad:
            raise ModelError(
                f"{_where(what, bad[0], labs)}: section must be a femast Section (got {type(secs[bad[0]]).__name__})"
            )
    try:
        u = np.asarray(up, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{what}: up-vector {up!r} must be 3 numbers or one row of 3 per element") from None
    if u.shape not in ((3,), (n, 3)):
        raise ModelError(
            f"{what}: up-vector must be one global direction (3,) or one per element ({n}, 3); got shape {u.shape}"
        )
    if not np.isfinite(u).all():
        i = 0 if u.ndim == 1 else int(np.argwhere(~np.isfinite(u))[0, 0])
        raise ModelError(
            f"{_where(what, i, labs)}: up-vector {u if u.ndim == 1 else u[i]} is not finite; "
            "give a finite global direction"
        )
    fams = _names(family, n, what, "beam")
    mpl = (
        [None] * n
        if mass_per_length is None
        else per_element(mass_per_length, n, f"{what}: mass_per_length", "kg/m", lo=0.0, strict=False).tolist()
    )
    a, b, L = _lengths(model, rows)
    _check_lengths(a, b, L, what, labs, "beam")
    e = (b - a) / L[:, None]
    U = np.broadcast_to(u, (n, 3))
    perp = U - (U * e).sum(axis=1)[:, None] * e
    par = np.sqrt((perp**2).sum(axis=1)) < 1e-6 * np.maximum(np.sqrt((U**2).sum(axis=1)), 1e-300)
    if par.any():
        i = int(np.flatnonzero(par)[0])
        raise ModelError(
            f"{_where(what, i, labs)}: up-vector {tuple(float(v) for v in U[i])} is parallel to the "
            f"element axis {tuple(float(v) for v in np.round(e[i], 6))}; choose an up-vector not "
            "along the beam"
        )
    lerr = per_element(length_error_m, n, f"{what}: length_error_m", "m")
    alpha = per_element(alpha_per_K, n, f"{what}: alpha_per_K", "1/K")
    first = model._next_element
    labels = np.arange(first, first + n, dtype=np.int64)
    ups = [u] * n if u.ndim == 1 else list(u)
    model.beams.extend(map(BeamSpec, labels.tolist(), map(tuple, labs.tolist()), secs, ups, fams, mpl))
    model._next_element += n
    _error_sources(model, labels, lerr, alpha)
    return labels


def add_trusses(
    model,
    nodes,
    EA,
    L0=None,
    pretension=None,
    tension_only=False,
    family=None,
    mass_per_length=0.0,
    length_error_m=0.0,
    alpha_per_K=0.0,
) -> np.ndarray:
    """One truss (or, ``tension_only``, cable) element per row of ``nodes`` ((n, 2) node labels), as
    :meth:`Model.truss`.  EA (N), L0 (m; None: from ``pretension`` or stress free), pretension (N),
    tension_only, mass_per_length (kg/m), length_error_m (m), alpha_per_K (1/K): one value or one
    per element; family: a name or one per element (None: "cable" or "truss").  Returns the labels."""
    what = f"model '{model.name}': trusses()"
    from .specs import TrussSpec

    labs, rows = node_rows(model, nodes, what)
    n = len(labs)
    EA = per_element(EA, n, f"{what}: EA", "N", lo=0.0)
    a, b, L = _lengths(model, rows)
    _check_lengths(a, b, L, what, labs, "truss")
    if L0 is not None and pretension is not None:
        raise ModelError(f"{what}: give L0 or pretension, not both")
    l0 = [None] * n if L0 is None else per_element(L0, n, f"{what}: unstretched length L0", "m", lo=0.0).tolist()
    if pretension is None:
        pre = [None] * n
    else:
        p = per_element(pretension, n, f"{what}: pretension", "N")
        if (p <= -EA).any():
            i = int(np.flatnonzero(p <= -EA)[0])
            raise ModelError(f"{_where(what, i, labs)}: pretension {p[i]} N <= -EA is impossible")
        pre = p.tolist()
    t = np.asarray(tension_only)
    if t.shape not in ((), (n,)) or t.dtype.kind != "b":
        raise ModelError(f"{what}: tension_only must be True/False or one bool per element ({n})")
    t = np.broadcast_to(t, (n,)).tolist()
    fams = _names(family, n, what, ["cable" if ti else "truss" for ti in t])
    mpl = per_element(mass_per_length, n, f"{what}: mass_per_length", "kg/m", lo=0.0, strict=False).tolist()
    lerr = per_element(length_error_m, n, f"{what}: length_error_m", "m")
    alpha = per_element(alpha_per_K, n, f"{what}: alpha_per_K", "1/K")
    first = model._next_element
    labels = np.arange(first, first + n, dtype=np.int64)
    model.trusses.extend(map(TrussSpec, labels.tolist(), map(tuple, labs.tolist()), EA.tolist(), l0, pre, t, fams, mpl))
    model._next_element += n
    _error_sources(model, labels, lerr, alpha)
    return labels


def _error_sources(model, labels, lerr, alpha):
    """The non-zero length errors and expansion coefficients, as the per-element builders set them."""
    on = lerr != 0.0
    if on.any():
        model.length_error(labels[on].tolist(), lerr[on])
    on = alpha != 0.0
    if on.any():
        model.thermal_expansion(alpha[on], elements=labels[on].tolist())
