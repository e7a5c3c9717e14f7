"""Shared output helpers of the trial modules.

Each CLI runner computes its trial once and writes the data, the figure and
``<stem>.claims.json`` (the thesis claims with their computed verdicts and the numbers the
report's text needs, :mod:`paritysim.claims`). The report sections read those files back
(:func:`results`) instead of recomputing.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import polars as pl

from .. import claims as cl


def write_trial(df: pl.DataFrame, out: Path, name: str, fig: Any) -> list[Path]:
    """Writes ``<name>.parquet``, ``<name>.csv`` and ``<name>.png`` (the figure) into ``out``."""
    from .. import plots

    written = [out / f"{name}.parquet", out / f"{name}.csv"]
    df.write_parquet(written[0])
    df.write_csv(written[1])
    written.append(plots.save(fig, out / f"{name}.png"))
    return written


def stem(trial: str) -> str:
    """File stem of a CLI trial name (``fig3.4`` -> ``fig3_4``)."""
    return trial.replace(".", "_").replace("-", "_")


def claims_path(out: Path, trial: str) -> Path:
    """Where trial ``trial`` keeps its claims in ``out``."""
    return out / f"{stem(trial)}.claims.json"


def write_claims(out: Path, trial: str, claims: list[cl.Claim], values: dict[str, Any] | None = None) -> Path:
    """Writes the claims and values of ``trial`` (see :func:`paritysim.claims.save`)."""
    return cl.save(claims_path(out, trial), claims, values)


def results(out: Path, trial: str) -> tuple[list[cl.Claim], dict[str, Any]]:
    """The claims and values ``trial`` wrote into ``out``; runs the trial first if it has not
    (so a report section never recomputes what ``reproduce`` already computed)."""
    path = claims_path(out, trial)
    if not path.exists():
        from . import REGISTRY

        REGISTRY[trial](out)
    return cl.load(path)
