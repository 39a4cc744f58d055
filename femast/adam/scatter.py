"""Per-element scatter of an ADAM mast: each ball joint's friction coefficient,
each latch's stiffness and friction, each bay side's cable pretension, and each member's length
error (lack of fit), around the nominal :class:`~femast.adam.parameters.BayParameters`.

    from femast.adam import build_mast
    from femast.adam.scatter import MastScatter

    rng = np.random.default_rng(1)
    sc = MastScatter(mu=rng.uniform(0.4, 0.6, (40, 4, 2)), longeron_dL=rng.uniform(-5e-5, 5e-5, (40, 4)))
    am = build_mast(40, scatter=sc)

Every field is ``None`` (nominal) or an array that broadcasts to its shape (a scalar: the same
value everywhere); the shapes, for a mast of n bays (corner k, side k as in
:mod:`femast.adam.build`):

=============== ============== ======= =========================================================
field           shape          unit    what
=============== ============== ======= =========================================================
mu              (n, 4, 2)      -       friction coefficient of the ball joint at bay j, corner k,
                                       bottom (0) / top (1) end of the longeron (Stohlman & Pellegrino, Sec. II.B.1)
latch_k         (n, 4)         N/m     latch roller stiffness k of bay j, side k (Stohlman & Pellegrino, Eq. 10)
latch_mu        (n, 4)         -       latch roller friction coefficient (Stohlman & Pellegrino, Eq. 14)
pretension      (n, 4)         N       cable pretension of bay j, side k (latch cable and arms)
longeron_dL     (n, 4)         m       length error of the longeron of bay j at corner k
batten_dL       (n + 1, 4)     m       length error of the batten of frame i on side k
arm_dL          (n, 4, 2)      m       length error of the two arm cables of bay j, side k
cable_dL        (n, 4, 2)      m       length error of the latch cable of bay j, side k, section
                                       0 (through the backstop) and 1
=============== ============== ======= =========================================================

A length error dL makes the member stress free at its nominal length + dL (femast/model/thermal.py).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ..errors import ModelError

_SHAPES = {
    "mu": (0, 4, 2),
    "latch_k": (0, 4),
    "latch_mu": (0, 4),
    "pretension": (0, 4),
    "longeron_dL": (0, 4),
    "batten_dL": (1, 4),
    "arm_dL": (0, 4, 2),
    "cable_dL": (0, 4, 2),
}
_UNITS = {
    "mu": "-",
    "latch_k": "N/m",
    "latch_mu": "-",
    "pretension": "N",
    "longeron_dL": "m",
    "batten_dL": "m",
    "arm_dL": "m",
    "cable_dL": "m",
}
_INDEX = {
    "mu": ("bay", "corner", "end"),
    "latch_k": ("bay", "side"),
    "latch_mu": ("bay", "side"),
    "pretension": ("bay", "side"),
    "longeron_dL": ("bay", "corner"),
    "batten_dL": ("frame", "side"),
    "arm_dL": ("bay", "side", "arm"),
    "cable_dL": ("bay", "side", "section"),
}
#: A length error beyond this fraction of the member is a units slip (mm given as m), not scatter.
MAX_LENGTH_ERROR_FRACTION = 0.05


@dataclass
class MastScatter:
    """Per-element values of an ADAM mast (module docstring).  ``None``: the nominal value."""

    mu: object = None
    latch_k: object = None
    latch_mu: object = None
    pretension: object = None
    longeron_dL: object = None
    batten_dL: object = None
    arm_dL: object = None
    cable_dL: object = None

    @classmethod
    def from_dict(cls, values: dict) -> MastScatter:
        """From a dict of the field names (e.g. one sample of a study); unknown names raise."""
        if isinstance(values, MastScatter):
            return values
        unknown = sorted(set(values) - set(_SHAPES))
        if unknown:
            raise ModelError(
                f"MastScatter: unknown item(s) {', '.join(map(repr, unknown))}; the items are {', '.join(_SHAPES)}"
            )
        return cls(**values)

    @staticmethod
    def shape(name: str, n_bays: int) -> tuple:
        """Full shape of field ``name`` for a mast of ``n_bays`` bays."""
        s = _SHAPES[name]
        return (n_bays + s[0],) + s[1:]

    def resolve(self, n_bays: int, params) -> dict:
        """{field: full array} with the nominal values of ``params`` (:class:`BayParameters`) where a
        field is None, each value checked; raises :class:`ModelError` naming the item and index."""
        nominal = {
            "mu": params.mu,
            "latch_k": params.latch.k,
            "latch_mu": params.latch.mu,
            "pretension": params.pretension,
            "longeron_dL": 0.0,
            "batten_dL": 0.0,
            "arm_dL": 0.0,
            "cable_dL": 0.0,
        }
        out = {}
        for f in fields(self):
            name = f.name
            v = getattr(self, name)
            shape = self.shape(name, n_bays)
            try:
                a = np.broadcast_to(np.asarray(nominal[name] if v is None else v, dtype=float), shape).copy()
            except (TypeError, ValueError):
                raise ModelError(
                    f"MastScatter.{name}: give a number or an array of shape {shape} "
                    f"({' x '.join(_INDEX[name])}) in {_UNITS[name]}; got "
                    f"{np.shape(v) if not isinstance(v, str) else repr(v)}"
                ) from None
            out[name] = a
        L = {
            "longeron_dL": params.l,
            "batten_dL": params.b - 2 * params.corner,
            "arm_dL": 0.5 * params.diagonal,
            "cable_dL": 0.5 * params.diagonal,
        }
        rules = {
            "mu": (lambda a: a >= 0, "must be >= 0 (a friction coefficient)"),
            "latch_k": (lambda a: a > 0, "must be > 0 N/m"),
            "latch_mu": (lambda a: a >= 0, "must be >= 0 (a friction coefficient)"),
            "pretension": (
                lambda a: (a > 0) & (a < 0.05 * params.cable_EA),
                f"must be > 0 N and below 5 % strain of the cables ({0.05 * params.cable_EA:g} N)",
            ),
        }
        for name, length in L.items():
            lim = MAX_LENGTH_ERROR_FRACTION * length
            rules[name] = (
                lambda a, lim=lim: np.abs(a) <= lim,
                f"is beyond {MAX_LENGTH_ERROR_FRACTION:.0%} of the member ({lim:.4g} m): give it in m",
            )
        for name, (ok, rule) in rules.items():
            a = out[name]
            bad = np.argwhere(~(np.isfinite(a) & ok(a)))
            if bad.size:
                idx = tuple(int(i) for i in bad[0])
                where = ", ".join(f"{w} {i}" for w, i in zip(_INDEX[name], idx))
                raise ModelError(
                    f"MastScatter.{name}[{', '.join(map(str, idx))}] ({where}) = {float(a[idx])!r} "
                    f"{_UNITS[name]} {rule}".replace(" - ", " ")
                )
        return out


def latch_array(values: dict, params) -> np.ndarray:
    """(n_bays * 4, 6) latch parameter rows [r, x_backstop, k, mu, h, R] with each latch's k and mu."""
    base = params.latch.as_array()
    k, mu = values["latch_k"].ravel(), values["latch_mu"].ravel()
    rows = np.tile(base, (k.size, 1))
    rows[:, 2] = k
    rows[:, 3] = mu
    return rows


def is_nominal(values: dict, params) -> bool:
    """True if the resolved values are all the nominal ones (no scatter)."""
    return (
        np.all(values["mu"] == params.mu)
        and np.all(values["latch_k"] == params.latch.k)
        and np.all(values["latch_mu"] == params.latch.mu)
        and np.all(values["pretension"] == params.pretension)
        and not any(np.any(values[n]) for n in ("longeron_dL", "batten_dL", "arm_dL", "cable_dL"))
    )


__all__ = ["MastScatter", "latch_array", "is_nominal", "MAX_LENGTH_ERROR_FRACTION"]
