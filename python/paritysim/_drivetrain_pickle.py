"""Pickle support for :class:`paritysim.Drivetrain` (used by ``Drivetrain.__reduce__``)."""

from __future__ import annotations

from ._core import Drivetrain


def rebuild(name: str, args: list[float]) -> Drivetrain:
    """Re-create a drivetrain from its constructor name and arguments."""
    constructor = getattr(Drivetrain, name)
    return constructor(*args)  # type: ignore[no-any-return]
