"""Reproductions of the dissertation's trials, one module per thesis section.

Each function returns Polars DataFrames computed by the model; nothing is copied from the
thesis. ``REGISTRY`` maps the CLI names (``paritysim reproduce NAME``) to their runners.
"""

from __future__ import annotations

from .laminate_design import laminate_summary
from .section_2_3 import fig2_9

__all__ = ["fig2_9", "laminate_summary"]
