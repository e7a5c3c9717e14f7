"""Figures styled like the thesis: labelled axes with units, legends, titles naming the figure."""

from __future__ import annotations

import functools
import os
import re
from pathlib import Path
from collections.abc import Sequence
from typing import Any

import matplotlib.pyplot as plt  # the backend stays the user's (the CLI picks Agg)
import numpy as np
import polars as pl
from matplotlib.axes import Axes
from matplotlib.figure import Figure

__all__ = ["COINCIDENCE_TOLERANCE", "calibration_table", "fig2_9", "label_with_unit", "pair", "save", "simulation"]

#: Two curves closer than this fraction of their peak are "coincident" for :func:`pair`.
COINCIDENCE_TOLERANCE = 0.01


def pair(ax: Axes, x: Any, under: Any, over: Any, labels: tuple[str, str], color: str | tuple[str, str] = "C0", linestyle: str = "-") -> bool:
    """Two compared curves that may lie on top of each other, both visible.

    ``under`` is drawn wide and translucent, ``over`` thin and dashed on top of it (with sparse
    markers), so a curve hidden exactly under another still shows. When they coincide (max
    difference below :data:`COINCIDENCE_TOLERANCE` of the peak, computed) the legend says so.
    Returns whether they coincide.
    """
    u, o = np.asarray(under, dtype=float), np.asarray(over, dtype=float)
    scale = max(float(np.nanmax(np.abs(u))), float(np.nanmax(np.abs(o))), 1e-300)
    coincide = bool(np.nanmax(np.abs(u - o)) <= COINCIDENCE_TOLERANCE * scale)
    cu, co = (color, color) if isinstance(color, str) else color
    note = " (coincides with the next)" if coincide else ""
    ax.plot(x, u, linestyle=linestyle, color=cu, lw=4.0, alpha=0.35, solid_capstyle="butt", label=labels[0] + note)
    every = max(1, len(o) // 12)
    ax.plot(x, o, linestyle=(0, (4, 2)) if linestyle == "-" else linestyle, color=co, lw=1.2, marker="o", ms=3, markevery=every, label=labels[1])
    return coincide


_UNITS = {
    "stroke": "rad", "rotation": "rad", "phi": "rad", "psi": "rad", "theta": "rad", "roll": "mN·mm", "yaw": "mN·mm",
    "pitch": "mN·mm", "torque": "mN·mm", "tau": "mN·mm", "power": "mW", "work": "µJ", "energy": "µJ", "force": "mN",
    "omega1": "mg·mm²", "omega2": "mg·mm²", "omega3": "mg·mm²", "omega4": "mg·mm²", "inertia": "mg·mm²",
    "balance_stiffness": "mN·mm/rad", "k2": "mN·mm/rad", "springs": "mN·mm/rad", "q1": "mm", "q2": "rad",
    "transmission_ratio": "rad/mm", "force_per_volt": "mN/V", "actuator.stiffness": "mN/mm", "time_ms": "ms",
    "lift": "mN",
}


@functools.lru_cache(maxsize=1)
def _shipped() -> tuple[Any, ...]:
    """The shipped devices (every drivetrain, actuator and aero kind among them) and one flying
    (the body's columns): where the unit tables below read the core's units."""
    from . import devices
    from .spec import Simulation

    specs = [devices.load(n) for n in devices.list()]
    return (*specs, Simulation.from_dict({**specs[0].to_dict(), "body": {"mode": "free"}}))


def _typeset(unit: str) -> str:
    """A unit as the core writes it (``mN*mm``, ``mg mm^2``, ``uJ/ms``, ``1``) as labels print
    it (``mN·mm``, ``mg·mm²``, ``mW``, no unit)."""
    if unit == "1":
        return ""
    text = unit.replace("uJ/ms", "mW").replace("uJ", "µJ").replace("*", "·").replace(" ", "·")
    return text.replace("^2", "²").replace("^3", "³")


@functools.lru_cache(maxsize=1)
def _spec_units() -> dict[str, str]:
    """Each spec path's unit as the schema states it (``ps.spec_paths``), wing paths as
    ``wings[*]``, typeset."""
    from . import _core

    units: dict[str, str] = {}
    for spec in _shipped():
        for path, unit, *_ in _core.spec_paths(spec.to_json()):
            units.setdefault(re.sub(r"^wings\[\d+\]", "wings[*]", path), _typeset(unit))
    return units


@functools.lru_cache(maxsize=1)
def _column_units() -> dict[str, str]:
    """Each trajectory column's unit as the core's column table defines it, typeset."""
    from . import _core

    units: dict[str, str] = {}
    for spec in _shipped():
        for column, unit in _core.trajectory_column_units(spec.to_json()):
            units.setdefault(column, _typeset(unit))
    return units


#: Spellings of a path that ``ps.sweep`` accepts besides the canonical one.
_PATH_ALIASES = {"actuator.frequency_hz": "actuator.waveform.frequency_hz", "actuator.amplitude_v": "actuator.waveform.amplitude_v", "actuator.voltage_v": "actuator.waveform.amplitude_v"}


def _path_unit(column: str) -> str | None:
    """The schema's unit of a spec-path column (``""`` for a dimensionless one), in the labels'
    typography (``mN·mm/rad³``); None when ``column`` is no known path."""
    path = _PATH_ALIASES.get(column, column)
    path = re.sub(r"^wings(\[\d+\]|\.left|\.right)", "wings[*]", path)
    return _spec_units().get(path)


def _unit_of(column: str) -> str:
    """The unit :func:`label_with_unit` puts in parentheses (``""``: none)."""
    label = label_with_unit(column)
    return label[len(column) + 2 : -1] if label != column else ""


def label_with_unit(column: str) -> str:
    """An axis label for a sweep or trajectory column: the name and its unit (mg-mm-ms-rad-V),
    e.g. ``left_roll_aero_peak (mN·mm)``, ``actuator.waveform.frequency_hz (Hz)``; a spec path
    takes the schema's unit (``ps.spec_paths``), a sweep's ``d(metric)/d(path)`` column the
    quotient of the two; ratios, counts and names without a known unit get none
    (``omega_ratio`` is dimensionless)."""
    derivative = re.fullmatch(r"d\((.+)\)/d\((.+)\)", column)
    if derivative:
        top, bottom = (_unit_of(c) for c in derivative.groups())
        if not (top or bottom):
            return column
        if not bottom:
            return f"{column} ({top})"
        return f"{column} ({top or '1'}/{bottom if '/' not in bottom and '·' not in bottom else f'({bottom})'})"
    if "." in column:
        unit = _path_unit(column)
        if unit is not None:
            return f"{column} ({unit})" if unit else column
    elif column in _column_units():
        unit = _column_units()[column]
        return f"{column} ({unit})" if unit else column
    name = column.lower()
    # The ratios of the designer metrics (crates/dynamics/src/metrics/mod.rs) before the
    # substrings, which would read `lift_per_power` as a power.
    ratios = {"lift_per_power": "mN/mW", "actuator_power_per_weight": "mW/mN", "lift_to_weight": "-"}
    if name in ratios:
        return column if ratios[name] == "-" else f"{column} ({ratios[name]})"
    suffixes = {"_hz": "Hz", "_v": "V", "_mm": "mm", "_ms": "ms", "_deg": "deg", "_pct": "%", "_mg": "mg", "_ratio": "-"}
    for suffix, unit in suffixes.items():
        if name.endswith(suffix):
            return column if unit == "-" else f"{column} ({unit})"
    if name.endswith(("cycles_run", "point", "_phase_lag")):
        return f"{column} (rad)" if name.endswith("_phase_lag") else column
    if name.startswith("wings") and (".springs." in name or ".springs[" in name):
        return f"{column} (mN·mm/rad{'³' if name.endswith('cubic') else ''})" if not name.endswith("rest_angle") else f"{column} (rad)"
    for key, unit in _UNITS.items():
        if key in name:
            return f"{column} ({unit})"
    return column


def fig2_9(df: pl.DataFrame, box_deg: dict[str, tuple[float, float]] | None = None) -> Figure:
    """Contour panels of theta_w over (phi, theta), one per shoulder configuration of ``df``;
    unreachable poses left blank. ``box_deg`` (``{"phi": (lo, hi), "theta": (lo, hi)}``) is
    drawn on the (90°, 45°) panel.

    ``df`` is the output of :func:`paritysim.trials.fig2_9`.
    """
    configs = df.select("alpha2_deg", "alpha3_deg").unique(maintain_order=True).rows()
    fig, axes = plt.subplots(1, len(configs), figsize=(5 * len(configs), 4.8), constrained_layout=True, squeeze=False)
    levels = np.arange(-90, 91, 10)
    for ax, (a2, a3), label in zip(axes[0], configs, "abcdefgh", strict=False):
        sub = df.filter((pl.col("alpha2_deg") == a2) & (pl.col("alpha3_deg") == a3))
        phi = np.unique(sub["phi_deg"].to_numpy())
        theta = np.unique(sub["theta_deg"].to_numpy())
        z = sub["theta_w_deg"].fill_null(np.nan).to_numpy().reshape(theta.size, phi.size)
        cs = ax.contourf(phi, theta, z, levels=levels, cmap="coolwarm", extend="both")
        ax.contour(phi, theta, z, levels=levels, colors="k", linewidths=0.4)
        if box_deg is not None and (a2, a3) == (90.0, 45.0):
            (p0, p1), (t0, t1) = box_deg["phi"], box_deg["theta"]
            ax.plot([p0, p1, p1, p0, p0], [t0, t0, t1, t1, t0], color="k", lw=2.0, label="walking box")
            ax.legend(loc="lower right")
        ax.set_title(f"({label}) $\\alpha_2$ = {a2:.0f}°, $\\alpha_3$ = {a3:.0f}°")
        ax.set_xlabel("input stroke $\\phi$ (deg)")
        ax.set_ylabel("input deviation $\\theta$ (deg)")
        ax.set_aspect("equal")
    fig.colorbar(cs, ax=axes[0].tolist(), label="wing deviation $\\theta_w$ (deg)")
    fig.suptitle("Fig. 2.9: spherical shoulder transmission map (blank: beyond the joint limit, eq. 2.10)")
    return fig


def simulation(result: object, columns: Any = None) -> Figure:
    """Stroke, deviation and rotation angles and the body roll torques of a simulation, and the
    wings' lift where the device computes it; or the trajectory ``columns`` against time, one
    panel per unit."""
    df = result.trajectory  # type: ignore[attr-defined]
    units: dict[str, str] = getattr(result, "units", {})
    name = getattr(getattr(result, "spec", None), "name", "") or "simulation"
    prefixes = [p for p in ("left", "right", "wing") if f"{p}_phi" in df.columns]
    needed = [f"{p}_{c}" for p in prefixes for c in ("psi", "theta", "roll_aero", "roll_inertial")] + ["roll_total"]
    if columns is None and (not prefixes or any(c not in df.columns for c in needed)):
        # A run that recorded some columns (ps.simulate(columns=...)): those, by unit.
        columns = [c for c in df.columns if c != "time_ms"]
        if not columns:
            from ._errors import invalid

            raise invalid("columns", "[]", "a run that recorded trajectory columns (ps.simulate(..., columns=None) records them all)")
    if columns is not None:
        return _columns_over_time(df, columns, name, units)
    t = df["time_ms"].to_numpy()
    lifts = [p for p in prefixes if f"{p}_lift" in df.columns]
    fig, axes = plt.subplots(3 if lifts else 2, 1, figsize=(10, 9.5 if lifts else 7), sharex=True, constrained_layout=True)
    ax_a, ax_t = axes[0], axes[1]
    if lifts:
        ax_l = axes[2]
        for p in lifts:
            ax_l.plot(t, df[f"{p}_lift"].to_numpy(), label=f"{p} wing")
        if len(lifts) > 1:
            ax_l.plot(t, sum(df[f"{p}_lift"].to_numpy() for p in lifts), "k", lw=1.5, label="total")
        ax_l.axhline(0.0, color="0.6", lw=0.6)
        ax_l.set_ylabel("lift (mN)")
        ax_l.legend(ncol=3, fontsize=8)
    for p in prefixes:
        ax_a.plot(t, np.degrees(df[f"{p}_phi"].to_numpy()), label=f"{p} stroke $\\phi$")
        if np.ptp(df[f"{p}_psi"].to_numpy()) > 1e-9:
            ax_a.plot(t, np.degrees(df[f"{p}_psi"].to_numpy()), "--", label=f"{p} rotation $\\psi$")
        if np.ptp(df[f"{p}_theta"].to_numpy()) > 1e-9:
            ax_a.plot(t, np.degrees(df[f"{p}_theta"].to_numpy()), ":", label=f"{p} deviation $\\theta$")
        ax_t.plot(t, df[f"{p}_roll_aero"].to_numpy(), label=f"{p} roll, aerodynamic")
        ax_t.plot(t, df[f"{p}_roll_inertial"].to_numpy(), ":", label=f"{p} roll, inertial")
    ax_t.plot(t, df["roll_total"].to_numpy(), "k", lw=1.5, label="net body roll")
    ax_a.set_ylabel("angle (deg)")
    ax_t.set_ylabel("torque (mN·mm)")
    axes[-1].set_xlabel("time (ms)")
    ax_a.legend(ncol=2, fontsize=8)
    ax_t.legend(ncol=2, fontsize=8)
    fig.suptitle(f"{name}: wing angles, body torques{' and lift' if lifts else ''} over the recorded cycles")
    return fig


def _columns_over_time(df: pl.DataFrame, columns: Any, name: str, units: dict[str, str]) -> Figure:
    """The trajectory ``columns`` against ``time_ms``, one panel per unit (the core's units;
    angles in degrees)."""
    from ._errors import invalid, suggest

    if isinstance(columns, str):
        columns = [columns]
    if isinstance(columns, bytes) or not isinstance(columns, Sequence) or not columns:
        raise invalid("columns", repr(columns)[:60], "a non-empty list of trajectory column names")
    recorded = [c for c in df.columns if c != "time_ms"]
    for i, c in enumerate(columns):
        if c == "time_ms":
            raise invalid(f"columns[{i}]", "'time_ms'", "a column to draw against time (time_ms is the x axis)")
        if c not in recorded:
            raise invalid(f"columns[{i}]", repr(c)[:60], suggest(str(c), recorded, what="a column of the trajectory (result.trajectory.columns)"))
    panels: dict[str, list[str]] = {}
    for c in columns:
        unit = units.get(c)
        unit = _typeset(unit) if unit is not None else label_with_unit(c)[len(c) :].strip(" ()")
        panels.setdefault(unit, []).append(c)
    t = df["time_ms"].to_numpy()
    fig, axes = plt.subplots(len(panels), 1, figsize=(10, 2.2 + 2.4 * len(panels)), sharex=True, constrained_layout=True, squeeze=False)
    for ax, (unit, cs) in zip(axes[:, 0], panels.items(), strict=True):
        degrees = unit == "rad"
        for c in cs:
            y = df[c].to_numpy()
            ax.plot(t, np.degrees(y) if degrees else y, label=c)
        ax.set_ylabel("deg" if degrees else unit or "value")
        ax.grid(alpha=0.3)
        ax.legend(ncol=2, fontsize=8)
    axes[-1, 0].set_xlabel("time (ms)")
    fig.suptitle(f"{name}: {', '.join(columns) if len(columns) <= 4 else f'{len(columns)} columns'} over the recorded cycles")
    return fig


def calibration_table(result: Any, x: str | None = None, line: str | None = None, path: str | Path | None = None) -> Figure:
    """Measured against predicted values of a table calibration (`paritysim.calibrate` with
    ``data=``), one panel per measured column: the measured rows as markers (filled: fitted,
    open: held out) and the model's prediction at the same operating points as a line, against
    the operating column ``x`` (default: the one with the most distinct values), one colour per
    operating line (the distinct values of ``line``, default every other operating column).
    Saved to ``path`` (PNG) when given."""
    from ._errors import invalid, suggest

    table: pl.DataFrame = result.table
    operating: list[str] = list(result.operating)
    if x is None:
        x = max(operating, key=lambda c: table[c].n_unique())
    elif x not in operating:
        raise invalid("x", repr(x), suggest(str(x), operating, what="an operating-point column of the data"))
    if line is not None and line not in operating:
        raise invalid("line", repr(line), suggest(str(line), operating, what="an operating-point column of the data"))
    groups = [line] if line is not None else [c for c in operating if c != x]
    columns = list(result.measured)
    fig, axes = plt.subplots(1, len(columns), figsize=(6.2 * len(columns), 4.2), constrained_layout=True, squeeze=False)
    keys = table.select(groups).unique(maintain_order=True).sort(groups).rows() if groups else [()]
    for ax, column in zip(axes[0], columns, strict=True):
        m = result.measured[column]
        for k, key in enumerate(keys):
            sub = table
            for g, v in zip(groups, key, strict=True):
                sub = sub.filter(pl.col(g) == v)
            sub = sub.sort(x)
            color = f"C{k % 10}"
            name = ", ".join(f"{g.rsplit('.', 1)[-1]} = {v:g}" for g, v in zip(groups, key, strict=True)) or "model"
            ax.plot(sub[x].to_numpy(), sub[f"predicted_{column}"].to_numpy(), "-", color=color, lw=1.4, label=name)
            for part, face in (("fit", color), ("holdout", "none")):
                s = sub.filter(pl.col("split") == part)
                ax.plot(s[x].to_numpy(), s[column].to_numpy(), "o", ms=5, mfc=face, mec=color, ls="none")
        ax.plot([], [], "ko", ms=5, ls="none", label="measured, fitted")
        ax.plot([], [], "o", mfc="none", mec="k", ms=5, ls="none", label="measured, held out")
        ax.plot([], [], "k-", lw=1.4, label="predicted")
        ax.set_xlabel(label_with_unit(x))
        unit = f" ({m.unit})" if m.unit else ""
        convention = f"{'2 × ' if m.peak_to_peak else ''}{m.metric}"
        ax.set_ylabel(f"{column}{unit}")
        rms = result.holdout_rms.get(column, float("nan"))
        held = f"held-out RMS {rms:.3g}{unit.strip(' ()') and ' ' + m.unit}" if np.isfinite(rms) else "nothing held out"
        ax.set_title(f"{column} = {convention}{unit}: {held}", fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
    fig.suptitle("Measured (markers) and predicted (lines) per operating line")
    if path is not None:
        save(fig, path, close=False)
    return fig


def save(fig: Figure, path: str | Path, *, close: bool = True, dpi: int = 150, field: str = "path") -> Path:
    """Saves a figure at ``dpi`` in the format of the path's suffix (PNG without one), making
    its folder, and closes it unless ``close=False`` (a plot method that returns the figure).
    A path that is not a path, a format matplotlib cannot write or a file that cannot be
    written is an ``InvalidParameterError`` naming ``field``: every plot's ``path=`` saves
    through here."""
    from ._errors import invalid

    if isinstance(path, bytes) or not isinstance(path, str | os.PathLike):
        raise invalid(field, repr(path)[:60], "a file path (str or os.PathLike), e.g. 'figure.png'")
    path = Path(path)
    formats = fig.canvas.get_supported_filetypes()
    suffix = path.suffix.lower().lstrip(".")
    if suffix and suffix not in formats:
        raise invalid(field, str(path), f"a file whose suffix is a figure format ({', '.join(f'.{k}' for k in sorted(formats))})")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=dpi, format=suffix or "png")
    except OSError as exc:
        raise invalid(field, str(path), f"a writable file path ({exc.strerror or exc})") from exc
    if close:
        plt.close(fig)
    return path
