"""Raising the typed errors from Python with the same attributes as the Rust side."""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from numbers import Integral, Real
from typing import Any

from . import _core
from ._core import InvalidParameterError


def invalid(field: str, value: Any, allowed: str) -> InvalidParameterError:
    """An ``InvalidParameterError`` worded like the Rust one, with ``.field`` and ``.kind`` set."""
    err = InvalidParameterError(f"invalid `{field}` = {value}: must be {allowed}")
    err.field = field  # type: ignore[attr-defined]
    err.kind = "InvalidParameter"  # type: ignore[attr-defined]
    return err


def real(field: str, value: Any) -> float:
    """``float(value)`` for a public argument, or an ``InvalidParameterError`` naming ``field``
    (the conversion's own error kept as ``__cause__``). Strings and booleans are not numbers."""
    if isinstance(value, (str, bytes, bool)):
        raise invalid(field, repr(value), "a real number")
    try:
        return float(value)
    except (TypeError, ValueError, OverflowError) as exc:
        raise invalid(field, repr(value), "a real number") from exc


def of_kind(field: str, value: Any, kind: str) -> Any:
    """``value`` as a record for the core reads it, checked for its ``kind`` by name before it is
    serialised (JSON has no NaN, and serde's type errors name only the record): ``"number"`` a
    finite float, ``"count"`` a non-negative int, ``"flag"`` a bool (numpy's too), ``"text"`` a
    str. The ranges are the core's, which names the field."""
    if kind == "number":
        number = real(field, value)
        if not math.isfinite(number):
            raise invalid(field, number, "a finite number")
        return number
    if kind == "count":
        if isinstance(value, bool) or not isinstance(value, Integral) or value < 0:
            raise invalid(field, repr(value), "a non-negative integer")
        return int(value)
    if kind == "flag":
        if not isinstance(value, bool) and type(value).__name__ != "bool_":
            raise invalid(field, repr(value), "True or False")
        return bool(value)
    if not isinstance(value, str):
        raise invalid(field, repr(value), "a text")
    return value


def whole(field: str, value: Any, lo: int = 0, hi: int = 2**53) -> int:
    """An integer argument in ``[lo, hi]`` (an integral float such as ``8.0`` is accepted), or an
    ``InvalidParameterError`` naming ``field``."""
    if isinstance(value, Real) and not isinstance(value, (bool, Integral)) and float(value).is_integer():
        value = int(value)
    if isinstance(value, bool) or not isinstance(value, Integral):
        raise invalid(field, repr(value), f"an integer in [{lo}, {hi}]")
    number = int(value)
    if not lo <= number <= hi:
        raise invalid(field, number, f"an integer in [{lo}, {hi}]")
    return number


def reals(field: str, value: Any) -> Any:
    """``np.asarray(value, float64)`` for a public array argument, or an
    ``InvalidParameterError`` naming ``field`` (strings, dicts and ragged lists are not numbers)."""
    import numpy as np

    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as exc:
        shown = repr(value)
        raise invalid(field, shown if len(shown) <= 60 else shown[:57] + "...", "a real number or an array of real numbers") from exc


def finite_reals(field: str, value: Any) -> Any:
    """`reals`, and every element finite: a NaN, an infinity or ``None`` (which numpy reads as
    NaN) is an ``InvalidParameterError`` naming ``field`` (``field[i]`` for an array element)."""
    import numpy as np

    a = reals(field, value)
    bad = ~np.isfinite(a)
    if bad.any():
        where = tuple(int(i) for i in np.argwhere(bad)[0])
        name = field + "".join(f"[{i}]" for i in where)
        raise invalid(name, repr(value) if a.ndim == 0 else a[where], "a finite real number")
    return a


def read_toml(field: str, path: Any, what: str) -> dict[str, Any]:
    """The table of the TOML file ``path`` (``what`` it should hold, e.g. ``"a sweep study"``),
    or an ``InvalidParameterError`` naming ``field``, the path and what was expected: a missing
    file, a directory, an unreadable file, bytes that are not UTF-8, malformed TOML."""
    import os
    import tomllib
    from pathlib import Path

    if isinstance(path, bytes) or not isinstance(path, str | os.PathLike):
        raise invalid(field, repr(path)[:60], f"the path of {what} (a UTF-8 TOML file)")
    file = Path(path)
    try:
        raw = file.read_bytes()
    except OSError as exc:
        raise invalid(field, str(file), f"a readable file holding {what} ({exc.strerror or exc})") from exc
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise invalid(field, str(file), f"a UTF-8 text file holding {what} ({exc.reason} at byte {exc.start})") from exc
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise invalid(field, str(file), f"{what} in valid TOML ({exc})") from exc


def read_study(path: Any, what: str, keys: Iterable[str], required: Iterable[str] = (), command: str = "") -> dict[str, Any]:
    """The table of a CLI study file (`read_toml`, ``field`` ``study``) with its keys checked:
    an unknown key is an ``InvalidParameterError`` naming it and the nearest ones, a missing
    ``required`` key one naming it."""
    data = read_toml("study", path, what)
    keys = list(keys)
    unknown = sorted(set(data) - set(keys))
    if unknown:
        raise invalid(unknown[0], "<unknown key>", suggest(unknown[0], keys, what="a key of the study file"))
    for key in required:
        if key not in data:
            raise invalid(key, "<missing>", f"given (see `paritysim {command} --help`)")
    return data


#: Environment variable bounding the bytes one call may allocate (see `memory_limit`).
MAX_BYTES_ENV = "PARITYSIM_MAX_BYTES"


def _proc_kib(path: str, key: str) -> int | None:
    try:
        with open(path, encoding="ascii") as f:
            for line in f:
                if line.startswith(key + ":"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def memory_limit() -> int:
    """Bytes one call may allocate for its arrays: ``$PARITYSIM_MAX_BYTES`` when set, else half
    of the memory available now (``MemAvailable``, and what an address-space limit
    ``RLIMIT_AS`` leaves to this process), at least 64 MB."""
    import os

    given = os.environ.get(MAX_BYTES_ENV)
    if given:
        try:
            return max(int(float(given)), 1)
        except (ValueError, OverflowError):
            raise invalid(MAX_BYTES_ENV, repr(given), "a number of bytes") from None
    available = _proc_kib("/proc/meminfo", "MemAvailable")
    if available is None:
        try:
            available = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        except (ValueError, OSError, AttributeError):
            available = 8 << 30
    try:
        import resource

        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft != resource.RLIM_INFINITY:
            used = _proc_kib("/proc/self/status", "VmSize") or 0
            available = min(available, max(soft - used, 0))
    except (ImportError, OSError, ValueError):
        pass
    return max(available // 2, 64 << 20)


def sized(field: str, value: Any, count: int, bytes_each: float, what: str) -> None:
    """Refuses, before anything is allocated, a call whose ``count`` items of about
    ``bytes_each`` bytes (``what``) exceed `memory_limit`: an ``InvalidParameterError`` naming
    ``field`` with the bytes needed and allowed."""
    need = int(count) * float(bytes_each)
    limit = memory_limit()
    if need > limit:
        raise invalid(
            field,
            value,
            f"small enough for {what} to fit in memory (~{need / 1e9:.3g} GB needed, {limit / 1e9:.3g} GB allowed: "
            f"half the available memory, or ${MAX_BYTES_ENV})",
        )


def close_names(name: str, valid: Iterable[str], limit: int = 5) -> list[str]:
    """At most ``limit`` names of ``valid`` close to ``name``, nearest first: a typo of the whole
    name or of its last path segment (``balance_spring`` in ``drivetrain.balance_spring``), then
    names that contain ``name``'s last segment, then names sharing a word with it. The Rust
    core's ranking (``paritysim_spec::schema::close``), the one of every "did you mean"."""
    return list(_core.spec_close_names(str(name), [str(v) for v in valid], int(limit)))


def suggest(name: str, valid: Iterable[str], listed_by: str | None = None, what: str = "a known name") -> str:
    """The ``allowed`` text for an unknown ``name`` among ``valid`` (paths, metrics, knobs,
    settings, columns): ``what`` it must be, the nearest name and at most five close ones, never
    the whole list unless it is that short. ``listed_by`` tells where the full list is (e.g.
    ``"ps.spec_paths(spec)"``).

    The one "did you mean" of paritysim: the Rust core's text (``schema::suggestion_for``) that
    the spec's own checks use; every argument that takes a name uses it."""
    names = [str(v) for v in dict.fromkeys(valid)]
    where = f"{listed_by} lists all {len(names)}" if listed_by else None
    return str(_core.spec_suggestion(str(name), names, what, where))


def unknown_name(field: str, name: Any, valid: Iterable[str], listed_by: str | None = None, what: str = "a known name") -> InvalidParameterError:
    """The ``InvalidParameterError`` of an unknown ``name`` given as ``field`` (`suggest`)."""
    return invalid(field, repr(name), suggest(str(name), valid, listed_by, what))


#: Points per call of an array path that is evaluated in chunks (`chunked`): the native call
#: holds several times its output while it runs (issue 34 measured ~20x), so a chunk of 16384
#: points peaks at tens of MB whatever the length of the arrays.
CHUNK_POINTS = 1 << 14


def _shifted(exc: BaseException, start: int, names: Iterable[str]) -> BaseException:
    """``exc`` of a chunk starting at element ``start``, its ``name[i]`` indices (message,
    ``.field``, ``.problems``) shifted to the whole array's."""
    pattern = re.compile(r"\b(" + "|".join(re.escape(n) for n in names) + r")\[(\d+)\]")

    def shift(text: Any) -> Any:
        return pattern.sub(lambda m: f"{m.group(1)}[{int(m.group(2)) + start}]", text) if isinstance(text, str) else text

    new = type(exc)(shift(str(exc)))
    for attr, value in vars(exc).items():
        if attr == "problems" and isinstance(value, list):
            value = [tuple(shift(v) for v in p) for p in value]
        setattr(new, attr, shift(value))
    return new


def chunked(call: Any, inputs: list[Any], names: Iterable[str]) -> dict[str, Any]:
    """``call(*inputs)`` (1-D arrays of equal length, every output's first axis per point)
    evaluated `CHUNK_POINTS` points at a time into outputs allocated once; an error's element
    index is the whole array's. Ctrl-C is seen between chunks."""
    import numpy as np

    from ._exceptions import ParitysimError

    n = int(inputs[0].size)
    if n <= CHUNK_POINTS:
        out: dict[str, Any] = call(*inputs)
        return out
    names = list(names)
    whole_out: dict[str, Any] = {}
    for start in range(0, n, CHUNK_POINTS):
        try:
            part = call(*(x[start : start + CHUNK_POINTS] for x in inputs))
        except ParitysimError as exc:
            raise _shifted(exc, start, names) from None
        for key, value in part.items():
            value = np.asarray(value)
            if key not in whole_out:
                whole_out[key] = np.empty((n, *value.shape[1:]), dtype=value.dtype)
            whole_out[key][start : start + value.shape[0]] = value
    return whole_out
