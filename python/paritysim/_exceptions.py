"""The exception tree of paritysim, one class per kind of ``paritysim_error::Error``.

Defined here (plain Python, multiple bases) and re-exported by the native module as
``paritysim._core.<Name>``; the bindings pick the class for each error variant by one exhaustive
Rust ``match`` (``crates/python/src/errors.rs``), so a new variant does not compile until it has
a class. Attributes set on raised instances: ``kind``, ``field``, ``problems`` (every
``(field, value, allowed)`` of an invalid spec) and, for integration failures, ``time`` and
``state``. Importing this module does not import the native module.
"""

from __future__ import annotations

__all__ = [
    "ParitysimError",
    "InvalidParameterError",
    "OutOfDomainError",
    "GeometryError",
    "ShapeError",
    "ConstraintError",
    "SingularError",
    "IntegrationError",
    "CancelledError",
]


class ParitysimError(Exception):
    """Root of every error raised by paritysim."""


class InvalidParameterError(ParitysimError, ValueError):
    """A parameter is non-finite or outside its allowed range; `.field` names it
    (`.problems` lists every invalid field of a spec)."""


class OutOfDomainError(ParitysimError, ValueError):
    """Valid parameters, but the configuration is unreachable (e.g. a joint limit)."""


class GeometryError(ParitysimError, ValueError):
    """A geometric description (outline, layup) is malformed."""


class ShapeError(ParitysimError, ValueError):
    """Arrays or matrices have mismatching or wrong dimensions."""


class ConstraintError(ParitysimError, ValueError):
    """A constraint matrix is rank deficient or the initial state violates it."""


class SingularError(ParitysimError, ArithmeticError):
    """A linear system is singular at this configuration."""


class IntegrationError(ParitysimError, RuntimeError):
    """Time integration failed; `.time` and `.state` say where."""


class CancelledError(ParitysimError):
    """The work was cancelled by the caller."""


# The classes have always been reported as members of the native module (pickling, reprs).
for _name in __all__:
    globals()[_name].__module__ = "paritysim._core"
del _name
