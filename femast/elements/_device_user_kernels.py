"""Device kernels with a user's law: a copy of :mod:`._device_kernels` in which ``_law`` is the user's
(:class:`femast.elements.cable_devices.UserDevice`), compiled on first use.

Private module: the public face is :mod:`femast.elements.cable_devices`.
"""

from __future__ import annotations

import inspect
import types

from . import _device_kernels

_USER_KERNELS = {}


def kernel_for_law(law):
    """:func:`._device_kernels.device_kernel` calling ``law`` (same signature as
    :func:`._device_laws.builtin_law`) instead of the built-in laws: a copy of that module's kernels,
    compiled on first use (not cached on disk: the law is the user's)."""
    if law not in _USER_KERNELS:
        name = _device_kernels.__name__
        src = inspect.getsource(_device_kernels).replace("@njit(cache=True)", "@njit")
        mod = types.ModuleType(name + "_user")
        mod.__package__ = _device_kernels.__package__
        exec(compile(src, f"<{name} with user law {getattr(law, '__name__', law)}>", "exec"), mod.__dict__)
        mod._law = law
        _USER_KERNELS[law] = mod.device_kernel
    return _USER_KERNELS[law]


__all__ = ["kernel_for_law"]
