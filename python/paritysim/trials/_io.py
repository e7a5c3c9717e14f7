"""Shared output helper of the trial modules."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import polars as pl


def write_trial(df: pl.DataFrame, out: Path, name: str, fig: Any) -> list[Path]:
    """Writes ``<name>.parquet``, ``<name>.csv`` and ``<name>.png`` (the figure) into ``out``."""
    from .. import plots

    written = [out / f"{name}.parquet", out / f"{name}.csv"]
    df.write_parquet(written[0])
    df.write_csv(written[1])
    written.append(plots.save(fig, out / f"{name}.png"))
    return written
