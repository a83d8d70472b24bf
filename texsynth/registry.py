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

__all__ = ["Param", "Method", "register", "methods", "get_method", "resolve"]


@dataclass(frozen=True)
class Param:
    """One typed parameter of a method.

    Parameters
    ----------
    name : str
        The keyword it is passed by (snake_case).
    type : type
        ``int``, ``float``, ``bool`` or ``str``.
    default : object
        Its value when not given (validated when the record is made).
    description : str
        One line for the panel's tooltip and the command line's help.
    min, max : float, optional
        Inclusive bounds of a number.
    choices : tuple of str
        The allowed values of a ``str`` parameter.
    label : str
        The panel's label; default the name, capitalised, with spaces.

    References
    ----------
    docs/ARCHITECTURE.md, Conventions, "Methods" (the panel and the operator properties are
    generated from these records).

    Examples
    --------
    >>> window = Param("window", int, 11, "Side of the window", min=3, max=41)
    >>> window.label, window.validate(7.0)
    ('Window', 7)
    >>> window.validate(1)
    Traceback (most recent call last):
    ...
    ValueError: parameter 'window' must be >= 3, got 1
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

    Parameters
    ----------
    name : str
        snake_case, unique (Blender's enum is its upper case).
    label, description : str
        The panel's name for it and one line on what it is good for.
    function : callable
        ``function(exemplar, width, height, rng, progress, **params)`` receives a float32
        array (H, W, C), the output size, a seeded ``numpy.random.Generator`` and a
        :class:`texsynth.progress.Progress`, and returns float32 (height, width, C) that tiles.
    params : tuple of Param
        Its parameters, in panel order.
    min_exemplar : int
        The smallest exemplar side the method accepts.
    memory : callable
        ``memory(exemplar_shape, width, height, params)``: the peak working bytes, checked
        against the budget before anything is allocated.
    cost : callable
        ``cost(exemplar_shape, width, height, params)``: the run time in seconds on the
        reference machine (``texsynth.budget`` scales it to this machine and checks it against
        the time budget).
    positions : bool
        The function returns ``(image, positions)``: int32 (height, width, 2) (row, col) into
        the exemplar, the pixel each output pixel was copied from (see
        ``texsynth.apply_positions``).

    References
    ----------
    docs/ARCHITECTURE.md, Conventions, "Methods" and "The method contract"
    (``tests/test_contract.py`` holds every registered method to it).

    Examples
    --------
    >>> import numpy as np
    >>> tile = Method("tile", "Tile", "Repeat the exemplar",
    ...               lambda e, w, h, rng, progress: np.resize(e, (h, w, e.shape[2])))
    >>> tile.memory((8, 8, 3), 16, 16, {})   # the default estimate: 64 bytes a value
    49152.0
    >>> tile.resolve({})
    {}
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
        """Defaults filled in and every value validated; unknown names raise ``ValueError``
        (:func:`resolve`)."""
        return resolve(self.params, params, f"method '{self.name}'")


def resolve(specs: tuple[Param, ...], values: dict, owner: str) -> dict:
    """Every parameter of ``specs``: its value from ``values`` or its default, validated.

    The one resolver of parameters: :meth:`Method.resolve` and the method modules' own public
    functions (``composite.compose``, ``cooccurrence.fit``) check their keywords here.

    Parameters
    ----------
    specs : tuple of Param
        The parameters, in order.
    values : dict
        The values given by name; each is coerced by :meth:`Param.validate`.
    owner : str
        Who takes them, as an unknown name's refusal says it ("method 'composite'").

    Returns
    -------
    dict
        Every name of ``specs``, in order, with its value.

    References
    ----------
    docs/ARCHITECTURE.md, Conventions, "Methods" (typed ``Param`` records).

    Examples
    --------
    >>> specs = (Param("sweeps", int, 30, "Sweeps", 1, 500),)
    >>> resolve(specs, {"sweeps": 4.0}, "the model")
    {'sweeps': 4}
    >>> resolve(specs, {"sweep": 4}, "the model")
    Traceback (most recent call last):
    ...
    ValueError: the model has no parameter 'sweep'; its parameters are: sweeps
    """
    known = {p.name for p in specs}
    unknown = sorted(set(values) - known)
    if unknown:
        raise ValueError(f"{owner} has no parameter {', '.join(map(repr, unknown))}; "
                         f"its parameters are: {', '.join(sorted(known)) or 'none'}")
    return {p.name: p.validate(values.get(p.name, p.default)) for p in specs}


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
    """Every registered method, in registration order (the panel's order).

    Returns
    -------
    tuple of Method

    References
    ----------
    docs/ARCHITECTURE.md, "Adding a method" (the order is ``texsynth/algorithms/__init__.py``'s).

    Examples
    --------
    >>> import texsynth
    >>> [m.name for m in texsynth.methods()][:3]
    ['heeger_bergen', 'efros_leung', 'multiscale_mrf']
    """
    return tuple(_METHODS.values())


def get_method(name: str) -> Method:
    """The registered method called ``name``, or ``ValueError`` listing the available ones.

    Parameters
    ----------
    name : str
        A method's ``name`` (see :func:`methods`).

    Returns
    -------
    Method

    References
    ----------
    docs/ARCHITECTURE.md, Conventions, "Methods".

    Examples
    --------
    >>> import texsynth
    >>> texsynth.get_method("efros_leung").positions
    True
    >>> texsynth.get_method("quilting")
    Traceback (most recent call last):
    ...
    ValueError: unknown method 'quilting'; available: heeger_bergen, ...
    """
    try:
        return _METHODS[name]
    except KeyError:
        raise ValueError(
            f"unknown method {name!r}; available: {', '.join(_METHODS)}"
        ) from None
