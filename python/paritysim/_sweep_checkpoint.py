"""Sweep checkpoints: finished chunks flushed to ``path.parts/`` as they complete, the final
table at ``path``, each file stamped with the sweep's fingerprint so a re-run resumes only the
same sweep (``paritysim.sweep``'s ``checkpoint``)."""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import uuid
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import polars as pl

from . import _core
from ._errors import invalid

_METADATA_KEY = "paritysim.sweep"
_FORMAT = 1


class _Checkpoint:
    """``path`` (the final table) plus ``path.parts/`` (chunks flushed while running)."""

    def __init__(self, path: str | os.PathLike[str], fingerprint: str) -> None:
        self.path = Path(path)
        self.parts = self.path.with_name(self.path.name + ".parts")
        self.fingerprint = fingerprint

    def _check(self, file: Path) -> None:
        meta = pl.read_parquet_metadata(file)
        found = meta.get(_METADATA_KEY)
        if found != self.fingerprint:
            raise invalid(
                "checkpoint",
                str(file),
                "a checkpoint written by the same sweep (same spec, options, parameter names, metrics and keep_cycle); "
                "delete it or choose another path",
            )

    def load(self) -> pl.DataFrame | None:
        """Every finished row stored so far (final table and parts), or None."""
        frames = []
        if self.path.exists():
            self._check(self.path)
            frames.append(pl.read_parquet(self.path))
        if self.parts.is_dir():
            for part in sorted(self.parts.glob("part-*.parquet")):
                self._check(part)
                frames.append(pl.read_parquet(part))
        if not frames:
            return None
        return pl.concat(frames, how="vertical_relaxed")

    def _write(self, df: pl.DataFrame, file: Path) -> None:
        file.parent.mkdir(parents=True, exist_ok=True)
        tmp = file.with_name(f".{file.name}.{uuid.uuid4().hex}.tmp")
        df.write_parquet(tmp, metadata={_METADATA_KEY: self.fingerprint})
        os.replace(tmp, file)  # atomic: a killed run never leaves half a part

    def flush(self, df: pl.DataFrame) -> None:
        if df.height:
            self._write(df, self.parts / f"part-{int(df['point'][0]):09d}-{uuid.uuid4().hex[:8]}.parquet")

    def finish(self, df: pl.DataFrame) -> None:
        self._write(df, self.path)
        if self.parts.is_dir():
            for part in self.parts.glob("part-*.parquet"):
                part.unlink()
            with contextlib.suppress(OSError):
                self.parts.rmdir()


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
