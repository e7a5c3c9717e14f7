"""Sweep checkpoints: finished chunks flushed to ``path.parts/`` as they complete, the final
table at ``path``, each file stamped with the sweep's fingerprint so a re-run resumes only the
same sweep (``paritysim.sweep``'s ``checkpoint``).

Several writers may share one checkpoint (two sweeps in threads or processes, issue 34): part
names are unique per writer, every file is written to a temporary name and renamed, and the
loads, flushes and finishes of every writer in the checkpoint's directory take turns under an
``flock`` of that directory. A writer's finish deletes only the parts it wrote or loaded, and the
final table it writes holds its own rows followed by every stored row (of the final table found
then, or of a part it loaded) whose point is not in its grid: no writer deletes or replaces rows
another sweep sharing the checkpoint computed (those keep their own ``point`` numbers).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import uuid
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import polars as pl

from . import _core
from ._errors import invalid

_METADATA_KEY = "paritysim.sweep"
_FORMAT = 1

try:  # POSIX: writers of one directory take turns; elsewhere only the atomic renames protect
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]


def _refuse(path: Any, why: str) -> Exception:
    return invalid("checkpoint", str(path), f"a writable .parquet file path ({why})")


def _checked_path(path: Any) -> Path:
    """``path`` as a checkpoint file, its directory created: a typed error naming
    ``checkpoint`` for a path that is not text, is a directory, or cannot be written."""
    if isinstance(path, bytes) or not isinstance(path, (str, os.PathLike)):
        raise invalid("checkpoint", repr(path)[:60], "a file path (str or os.PathLike) ending in .parquet")
    try:
        file = Path(os.fspath(path))
    except TypeError as exc:
        raise invalid("checkpoint", repr(path)[:60], "a file path (str or os.PathLike) ending in .parquet") from exc
    if not str(file) or str(file).endswith(os.sep) or file.name in ("", ".", ".."):
        raise _refuse(path, "a file name, not a directory")
    if file.is_dir():
        raise _refuse(path, "it is a directory")
    parts = file.with_name(file.name + ".parts")
    if parts.exists() and not parts.is_dir():
        raise _refuse(path, f"{parts} is not a directory")
    try:
        file.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _refuse(path, f"its directory cannot be created: {exc.strerror or exc}") from exc
    if not os.access(file.parent, os.W_OK | os.X_OK):
        raise _refuse(path, f"{file.parent} is not writable")
    return file


class _Checkpoint:
    """``path`` (the final table) plus ``path.parts/`` (chunks flushed while running)."""

    def __init__(self, path: str | os.PathLike[str], fingerprint: str, names: Sequence[str] = ()) -> None:
        self.path = _checked_path(path)
        self.parts = self.path.with_name(self.path.name + ".parts")
        self.fingerprint = fingerprint
        self.names = list(names)  # the grid's columns: a row's key
        self._writer = uuid.uuid4().hex[:12]
        self._held: set[Path] = set()  # parts this writer wrote or loaded (deleted by finish)
        self._loaded_parts: list[pl.DataFrame] = []  # rows of the parts it loaded

    @contextlib.contextmanager
    def _turn(self) -> Iterator[None]:
        """Exclusive use of the checkpoint's directory among writers (threads and processes)."""
        if fcntl is None:
            yield
            return
        try:
            fd = os.open(self.path.parent, os.O_RDONLY)
        except OSError as exc:
            raise _refuse(self.path, f"its directory cannot be opened: {exc.strerror or exc}") from exc
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
            yield
        finally:
            os.close(fd)  # releases the lock

    def _read(self, file: Path) -> pl.DataFrame | None:
        """One stored table after checking its fingerprint (None: removed meanwhile)."""
        try:
            meta = pl.read_parquet_metadata(file)
        except FileNotFoundError:
            return None
        except (OSError, pl.exceptions.PolarsError) as exc:
            raise invalid("checkpoint", str(file), f"a checkpoint written by paritysim.sweep (it cannot be read: {str(exc)[:80]}); delete it or choose another path") from exc
        if meta.get(_METADATA_KEY) != self.fingerprint:
            raise invalid(
                "checkpoint",
                str(file),
                "a checkpoint written by the same sweep (same spec, options, parameter names, metrics and keep_cycle); "
                "delete it or choose another path",
            )
        try:
            return pl.read_parquet(file)
        except FileNotFoundError:
            return None
        except (OSError, pl.exceptions.PolarsError) as exc:
            raise invalid("checkpoint", str(file), f"a readable checkpoint ({str(exc)[:80]}); delete it or choose another path") from exc

    def load(self) -> pl.DataFrame | None:
        """Every finished row stored so far (final table and parts), or None."""
        frames = []
        with self._turn():
            df = self._read(self.path)
            if df is not None:
                frames.append(df)
            if self.parts.is_dir():
                for part in sorted(self.parts.glob("part-*.parquet")):
                    df = self._read(part)
                    if df is not None:
                        frames.append(df)
                        self._loaded_parts.append(df)
                        self._held.add(part)
        if not frames:
            return None
        return pl.concat(frames, how="vertical_relaxed")

    def _write(self, df: pl.DataFrame, file: Path) -> None:
        tmp = file.with_name(f".{file.name}.{uuid.uuid4().hex}.tmp")
        try:
            file.parent.mkdir(parents=True, exist_ok=True)
            df.write_parquet(tmp, metadata={_METADATA_KEY: self.fingerprint})
            os.replace(tmp, file)  # atomic: a killed run never leaves half a part
        except OSError as exc:
            with contextlib.suppress(OSError):
                tmp.unlink()
            raise _refuse(self.path, f"writing {file.name} failed: {exc.strerror or exc}") from exc

    def flush(self, df: pl.DataFrame) -> None:
        if df.height:
            part = self.parts / f"part-{int(df['point'][0]):09d}-{self._writer}-{uuid.uuid4().hex[:8]}.parquet"
            with self._turn():
                self._write(df, part)
            self._held.add(part)

    def finish(self, df: pl.DataFrame) -> None:
        with self._turn():
            kept = self._with_stored_rows(df)
            if kept is None:
                return
            self._write(kept, self.path)
            for part in self._held:
                with contextlib.suppress(FileNotFoundError):
                    part.unlink()
            with contextlib.suppress(OSError):
                self.parts.rmdir()  # only when no other writer still has parts there

    def _with_stored_rows(self, df: pl.DataFrame) -> pl.DataFrame | None:
        """``df`` followed by the stored rows (the final table now, the parts this writer loaded)
        whose points ``df`` lacks; None, with a warning, when the final table is now another
        sweep's (this sweep's rows then stay in its parts)."""
        try:
            final = self._read(self.path)
        except _core.InvalidParameterError:
            warnings.warn(
                f"checkpoint {self.path} was finished meanwhile by a different sweep; this sweep's rows stay in {self.parts}",
                RuntimeWarning,
                stacklevel=4,
            )
            return None
        stored = [f for f in (final, *self._loaded_parts) if f is not None and f.height]
        if not stored:
            return df
        seen = {_key(r) for r in df.select(self.names).rows()} if self.names else {()}
        extra = []
        for frame in stored:
            rows = frame.select(self.names).rows() if self.names else [()] * frame.height
            take = []
            for i, r in enumerate(rows):
                k = _key(r)
                if k not in seen:
                    seen.add(k)
                    take.append(i)
            if take:
                extra.append(frame[take])
        if not extra:
            return df
        try:
            return pl.concat([df, *extra], how="vertical_relaxed")
        except pl.exceptions.PolarsError:  # stored rows of another layout: this sweep's alone
            return df


def _fingerprint(spec: str, names: Sequence[str], metrics: Sequence[str], cycle: Sequence[str]) -> str:
    payload = {
        "format": _FORMAT,
        "version": _core.__version__,
        "spec": json.loads(spec),
        "parameters": list(names),
        "metrics": list(metrics),
        "cycle": list(cycle),
    }
    return hashlib.sha256(json.dumps(payload, sort_keys=True, default=repr).encode()).hexdigest()


def _key(row: Sequence[Any]) -> tuple[Any, ...]:
    # Parquet round trips floats exactly; NaN != NaN, so it gets a stand-in to match itself.
    return tuple(("nan",) if isinstance(v, float) and math.isnan(v) else v for v in row)


def _reuse(previous: pl.DataFrame, table: pl.DataFrame, rows: list[tuple[Any, ...]]) -> tuple[pl.DataFrame, list[int]]:
    """Rows of ``previous`` that match points of ``table`` (by parameter values), renumbered,
    and the points still to run."""
    names = table.columns
    stored = previous.select(names).rows() if names else [()] * previous.height
    index: dict[tuple[Any, ...], int] = {}
    for i, row in enumerate(stored):
        index.setdefault(_key(row), i)
    take, points, todo = [], [], []
    for i, row in enumerate(rows):
        j = index.get(_key(row))
        if j is None:
            todo.append(i)
        else:
            take.append(j)
            points.append(i)
    if not take:
        return previous.clear(), todo
    reused = previous[take].with_columns(pl.Series("point", points, dtype=pl.Int64))
    if names:  # keep the caller's dtypes for the parameter columns
        reused = reused.with_columns(table[points].get_columns())
    return reused, todo
