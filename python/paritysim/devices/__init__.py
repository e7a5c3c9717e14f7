"""Named devices: every thesis device and trial as a shipped TOML spec, with its provenance.

Like PyBaMM's parameter sets: pick a device by name, get a `paritysim.Simulation`:

```python
import paritysim as ps
ps.devices.list()                                    # names
spec = ps.devices.load("sreetharan2012_3_3_parity")  # §3.3 Drag PARITY, Control trial
ps.devices.info("sreetharan2012_3_3_parity")         # what the thesis states, what we chose
```

Names are ``sreetharan2012_<section>_<drivetrain>[_<trial>]`` for the thesis' devices;
``robobee_dual_linear`` is a RoboBee-class vehicle (one linear drive per wing) whose values cite
published sources or say they are representative estimates (``info(...).stated_in``). Each file is a plain spec
(`paritysim.load_spec` reads `path`); its header and `info` list which values
the thesis states (with § or table) and which are our choices, and why.

``cut_wings`` in `info` says whether the device survives cut-wing sweeps
(``wings.left.omega_ratio`` < 1). ``sreetharan2012_3_3_parity_linkage`` (the rod-crank linkage,
``examples/drag_parity.toml``) does not: its whippletree mode is unstable below K2 ≈ 377
mN·mm/rad (docs/findings.md §3), so asymmetric wings drive it out of the linkage's domain.
"""

from __future__ import annotations

import builtins
import functools
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ..spec import Simulation

__all__ = ["DeviceInfo", "as_simulation", "info", "list", "load", "metric_names", "path", "spec_paths"]


@dataclass(frozen=True)
class DeviceInfo:
    """Provenance of a shipped device."""

    name: str
    title: str
    section: str
    stated: tuple[str, ...]
    choices: tuple[str, ...]
    cut_wings: bool
    stated_in: str = "the thesis"

    def __str__(self) -> str:
        lines = [f"{self.name}: {self.title} ({self.section})", f"Stated in {self.stated_in}:"]
        lines += [f"  - {s}" for s in self.stated]
        lines += ["Our choices and why:"]
        lines += [f"  - {c}" for c in self.choices]
        lines.append(f"Survives cut-wing sweeps: {'yes' if self.cut_wings else 'no'}")
        return "\n".join(lines)


@functools.cache
def _index() -> dict[str, dict[str, Any]]:
    text = resources.files(__name__).joinpath("index.toml").read_text(encoding="utf-8")
    return tomllib.loads(text)


def list() -> builtins.list[str]:  # noqa: A001  (the PyBaMM-style name is the point)
    """Names of every shipped device, sorted."""
    return sorted(_index())


def _check(name: str) -> str:
    if not isinstance(name, str):
        from .._errors import invalid

        raise invalid("name", repr(name)[:60], "a device name (str; ps.devices.list() lists them)")
    if name not in _index():
        from .._errors import invalid, suggest

        raise invalid("name", repr(name), suggest(str(name), list(), listed_by="ps.devices.list()", what="a shipped device"))
    return name


def path(name: str) -> Path:
    """The TOML file of device ``name`` (raises ``InvalidParameterError`` for an unknown name)."""
    return Path(str(resources.files(__name__).joinpath(f"{_check(name)}.toml")))


def info(name: str) -> DeviceInfo:
    """The provenance of device ``name``: thesis statements, our choices, cut-wing robustness."""
    e = _index()[_check(name)]
    return DeviceInfo(name, e["title"], e["section"], tuple(e["stated"]), tuple(e["choices"]), bool(e["cut_wings"]), e.get("stated_in", "the thesis"))


def load(name: str) -> Simulation:
    """Device ``name`` as a `paritysim.Simulation` (see `list`)."""
    from ..spec import load_spec

    return load_spec(path(name))


def _name_or_file(source: Any, relative_to: str | Path = ".", field: str = "spec") -> Simulation:
    """What a CLI ``spec`` argument or study key names: a spec file (relative to ``relative_to``,
    the study's folder), else a shipped device. A file of a device's name wins, so a local copy
    can shadow it. Neither is an ``InvalidParameterError`` naming ``field``, with the nearest
    device names."""
    from .._errors import invalid, suggest
    from ..spec import _load_spec

    if not isinstance(source, str) or not source.strip():
        raise invalid(field, repr(source)[:60], "a named device (`paritysim devices`) or a spec file")
    file = Path(relative_to) / source
    named = source in _index()
    if file.is_file() or (not named and file.suffix == ".toml"):
        return _load_spec(file, field)  # a missing .toml: that it cannot be read
    if named:
        return load(source)
    raise invalid(field, repr(source), suggest(source, list(), listed_by="`paritysim devices`", what=f"a named device or a spec file (none at {file})"))


#: What every ``spec`` argument of the Python API accepts (the one rule, :func:`as_simulation`).
SPEC_ARGUMENT = "a paritysim.Simulation, its dict, a named device (ps.devices.list()) or a TOML spec file"


def as_simulation(spec: Any, field: str = "spec") -> Simulation:
    """The :class:`~paritysim.Simulation` a ``spec`` argument names: a ``Simulation``; its dict
    (:meth:`Simulation.from_dict`); a shipped device's name (``"sreetharan2012_3_3_parity"``,
    :func:`load`) or a TOML spec file (:func:`paritysim.load_spec`; a file wins over a device of
    the same name, as on the command line). Anything else, or a name that is neither, is an
    ``InvalidParameterError`` naming ``field`` (with the nearest device names). It lives with
    the device library, which it reads; the spec module knows no devices."""
    from collections.abc import Mapping
    from os import PathLike

    from .._errors import invalid
    from ..spec import Simulation, _load_spec

    if isinstance(spec, Simulation):
        return spec
    if isinstance(spec, Mapping):
        return Simulation.from_dict(dict(spec))
    if isinstance(spec, PathLike):
        return _load_spec(spec, field)
    if isinstance(spec, str):
        return _name_or_file(spec, field=field)
    raise invalid(field, type(spec).__name__, SPEC_ARGUMENT)


def spec_paths(spec: Any) -> Any:
    """Every parameter path of ``spec`` (anything :func:`as_simulation` reads: a device's name,
    too) as a Polars DataFrame: ``path``, ``unit``, ``allowed`` (type and range) and ``value``
    (JSON text); the names :func:`paritysim.sweep`, :func:`paritysim.calibrate` and
    :meth:`Simulation.with_paths` accept. ``paritysim.spec_paths`` is this function."""
    from .. import spec as _spec

    return _spec.spec_paths(as_simulation(spec))


def metric_names(spec: Any) -> builtins.list[str]:
    """The metrics ``spec``'s device reports (anything :func:`as_simulation` reads), in the
    core's order: what ``metrics=`` of :func:`paritysim.simulate`, :func:`paritysim.sweep` and
    :func:`paritysim.sensitivity`, and the constraints of :func:`paritysim.optimize`, accept.
    ``paritysim.metric_names`` is this function."""
    from .. import _core

    return builtins.list(_core.sweep_metric_names(as_simulation(spec).to_json()))
