"""The method registry: every synthesis algorithm describes itself here.

A :class:`Method` carries a name, a label, a description, typed :class:`Param` records, its
function and its memory estimate. The Blender operators and panel are generated from
:func:`methods`, so adding an algorithm means adding one module (or package) under
``texsynth/algorithms/`` that calls :func:`register`, and its import line in
``texsynth/algorithms/__init__.py``; nothing else changes.

This module imports nothing of the project's: ``texsynth/__init__.py`` imports
``texsynth.algorithms``, which fills the registry, before anyone can ask it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

__all__ = ["Param", "Method", "register", "methods", "get_method"]


@dataclass(frozen=True)
class Param:
    """One typed parameter of a method.

    ``type`` is ``int``, ``float``, ``bool`` or ``str``; a ``str`` parameter lists its allowed
    values in ``choices``. ``min``/``max`` bound numbers (inclusive).
    """

    name: str
    type: type
    default: Any
    description: str
    min: float | None = None
    max: float | None = None
    choices: tuple[str, ...] = ()
    label: str = ""

    def __post_init__(self):
        if not self.label:
            object.__setattr__(self, "label", self.name.replace("_", " ").capitalize())
        self.validate(self.default)

    def validate(self, value: Any) -> Any:
        """Return ``value`` coerced to this parameter's type, or raise ``ValueError``."""
        if self.type is bool:
            if not isinstance(value, (bool, int)) or value not in (0, 1):
                raise ValueError(f"parameter '{self.name}' must be True or False, got {value!r}")
            return bool(value)
        if self.type is str:
            if value not in self.choices:
                raise ValueError(f"parameter '{self.name}' must be one of "
                                 f"{', '.join(self.choices)}; got {value!r}")
            return value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"parameter '{self.name}' must be a number, got {value!r}")
        if self.type is int:
            if not math.isfinite(value) or int(value) != value:
                raise ValueError(f"parameter '{self.name}' must be a whole number, got {value!r}")
            value = int(value)
        else:
            value = float(value)
            if value != value:
                raise ValueError(f"parameter '{self.name}' must not be NaN")
        if self.min is not None and value < self.min:
            raise ValueError(f"parameter '{self.name}' must be >= {self.min}, got {value}")
        if self.max is not None and value > self.max:
            raise ValueError(f"parameter '{self.name}' must be <= {self.max}, got {value}")
        return value


@dataclass(frozen=True)
class Method:
    """A synthesis algorithm.

    ``function(exemplar, width, height, rng, progress, **params)`` receives a float32 array
    (H, W, C), the output size, a seeded ``numpy.random.Generator`` and a
    :class:`texsynth.progress.Progress`, and returns float32 (height, width, C) that tiles.
    ``min_exemplar`` is the smallest exemplar side the method accepts;
    ``memory(exemplar_shape, width, height, params)`` estimates the peak working bytes, checked
    against the budget before anything is allocated; ``cost(exemplar_shape, width, height,
    params)`` predicts the run time in seconds on the reference machine (``texsynth.budget``
    scales it to this machine's speed and checks it against the time budget).
    """

    name: str
    label: str
    description: str
    function: Callable[..., Any]
    params: tuple[Param, ...] = ()
    min_exemplar: int = 8
    memory: Callable[[tuple, int, int, dict], float] = (
        lambda shape, width, height, params: 64.0 * width * height * shape[2]
    )
    cost: Callable[[tuple, int, int, dict], float] = (
        lambda shape, width, height, params: 1e-6 * width * height * shape[2]
    )
    #: The function returns ``(image, positions)``: int32 (height, width, 2) (row, col) into the
    #: exemplar, the pixel each output pixel was copied from (see ``texsynth.apply_positions``).
    positions: bool = False

    def param(self, name: str) -> Param:
        for p in self.params:
            if p.name == name:
                return p
        raise KeyError(name)

    def resolve(self, params: dict) -> dict:
        """Defaults filled in and every value validated; unknown names raise ``ValueError``."""
        known = {p.name for p in self.params}
        unknown = sorted(set(params) - known)
        if unknown:
            raise ValueError(
                f"method '{self.name}' has no parameter {', '.join(map(repr, unknown))}; "
                f"its parameters are: {', '.join(sorted(known)) or 'none'}"
            )
        return {p.name: p.validate(params.get(p.name, p.default)) for p in self.params}


_METHODS: dict[str, Method] = {}


def register(method: Method) -> Method:
    """Add ``method`` to the registry (names are unique, snake_case)."""
    if not method.name.isidentifier() or method.name.lower() != method.name:
        raise ValueError(f"method names are snake_case identifiers, got {method.name!r}")
    if method.name in _METHODS:
        raise ValueError(f"method {method.name!r} is registered twice")
    _METHODS[method.name] = method
    return method


def methods() -> tuple[Method, ...]:
    """Every registered method, in registration order (the panel's order)."""
    return tuple(_METHODS.values())


def get_method(name: str) -> Method:
    """The registered method called ``name``, or ``ValueError`` listing the available ones."""
    try:
        return _METHODS[name]
    except KeyError:
        raise ValueError(
            f"unknown method {name!r}; available: {', '.join(_METHODS)}"
        ) from None
