"""Modules that can be called like their main function (``ps.sweep(...)``, ``trials.section_3_4()``).

``paritysim.sweep`` is both the module (``import paritysim.sweep``, ``help(paritysim.sweep)``
shows the parameter paths) and, called, the `paritysim.sweep.sweep` function, so
existing ``ps.sweep(spec, grid)`` code keeps working.
"""

from __future__ import annotations

import sys
import types
from typing import Any


class _CallableModule(types.ModuleType):
    _call_name: str

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return getattr(self, self._call_name)(*args, **kwargs)


def make_callable(module_name: str, function_name: str) -> None:
    """Calling module ``module_name`` calls its ``function_name``."""
    module = sys.modules[module_name]
    module.__class__ = _CallableModule
    module._call_name = function_name  # type: ignore[attr-defined]
