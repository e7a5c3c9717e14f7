"""Pictures of free flight: attitude and position against time, the 3-D trajectory of the
centre of mass, and an animation of body and wings (MP4 through matplotlib's FFMpegWriter when
an ffmpeg binary is found, from the optional ``video`` extra's ``imageio-ffmpeg`` or the
system's ``PATH``; GIF through PillowWriter otherwise, or when asked for a ``.gif``).

Every function takes flight trajectories (``SimulationResult.trajectory`` of a spec with a
``body`` section, or frames with the same columns) keyed by a label, and returns a matplotlib
figure (save it with :func:`paritysim.plots.save`) or the path written.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import polars as pl
from matplotlib.figure import Figure

from . import tilt_angle, twist_angle

__all__ = ["animate", "attitude", "ffmpeg_path", "trajectory_3d"]


def ffmpeg_path() -> str | None:
    """An ffmpeg binary for MP4: ``imageio_ffmpeg``'s (``pip install paritysim[video]``), else
    one on ``PATH``; None without either."""
    import shutil

    try:
        import imageio_ffmpeg  # type: ignore[import-untyped,import-not-found,unused-ignore]

        exe = imageio_ffmpeg.get_ffmpeg_exe()
        if exe:
            return str(exe)
    except (ImportError, RuntimeError):
        pass
    return shutil.which("ffmpeg")


#: The columns each picture reads (a flight trajectory has them all).
_POSITION = ("time_ms", "body_x", "body_y", "body_z")
_ATTITUDE = ("body_qw", "body_qx", "body_qy", "body_qz")


def _frame(df: Any, needed: tuple[str, ...], field: str) -> pl.DataFrame:
    """``df`` when it is a non-empty frame with the ``needed`` columns, else an
    ``InvalidParameterError`` naming ``field``."""
    from .._errors import invalid

    if not isinstance(df, pl.DataFrame):
        raise invalid(field, type(df).__name__, "a flight trajectory (SimulationResult.trajectory of a spec with a moving body)")
    missing = [c for c in needed if c not in df.columns]
    if missing:
        raise invalid(field, f"<a frame without {', '.join(missing[:4])}>", "a flight trajectory: a spec with a moving body (ps.flight.with_body(spec, mode='free')) records the body's columns")
    if df.height < 2:
        raise invalid(field, f"<{df.height} rows>", "a trajectory of at least two samples")
    return df


def _frames(frames: Any, needed: tuple[str, ...]) -> dict[str, pl.DataFrame]:
    """``frames`` as a label -> trajectory mapping, each checked by :func:`_frame`."""
    from .._errors import invalid

    if not isinstance(frames, Mapping) or not frames:
        raise invalid("frames", type(frames).__name__, "a non-empty mapping {label: trajectory}, e.g. {'free': result.trajectory}")
    return {str(k): _frame(v, needed, f"frames[{k!r}]") for k, v in frames.items()}


def _wingbeats(df: pl.DataFrame, period_ms: float) -> np.ndarray:
    t = df["time_ms"].to_numpy()
    return (t - t[0]) / period_ms


def attitude(frames: Mapping[str, pl.DataFrame], period_ms: float, *, axes: tuple[str, ...] = ("roll", "yaw", "pitch"), position: bool = True, title: str = "") -> Figure:
    """Attitude (the twist about each body axis in ``axes`` and the tilt of the stroke axis,
    degrees) and, with ``position``, the centre of mass (mm) against wingbeats, one line per
    frame."""
    import matplotlib.pyplot as plt

    from .._errors import invalid, real

    frames = _frames(frames, _POSITION + _ATTITUDE if position else ("time_ms", *_ATTITUDE))
    period_ms = real("period_ms", period_ms)
    if not (np.isfinite(period_ms) and period_ms > 0):
        raise invalid("period_ms", period_ms, "the drive period, finite and > 0 ms (SimulationResult.period_ms)")
    rows = len(axes) + 1 + (1 if position else 0)
    fig, ax = plt.subplots(rows, 1, figsize=(9, 1.9 * rows + 0.6), sharex=True, constrained_layout=True, squeeze=False)
    ax = ax[:, 0]
    for i, (label, df) in enumerate(frames.items()):
        n = _wingbeats(df, period_ms)
        c = f"C{i}"
        for a, name in zip(ax, axes, strict=False):
            a.plot(n, np.degrees(twist_angle(df, name)), color=c, label=label)
        ax[len(axes)].plot(n, np.degrees(tilt_angle(df)), color=c, label=label)
        if position:
            for comp, ls in (("x", "-"), ("y", "--"), ("z", ":")):
                ax[-1].plot(n, df[f"body_{comp}"].to_numpy(), color=c, ls=ls, label=f"{label}: {comp}")
    for a, name in zip(ax, axes, strict=False):
        a.set_ylabel(f"{name} (deg)")
        a.grid(alpha=0.3)
    ax[len(axes)].set_ylabel("tilt of x̂ (deg)")
    ax[len(axes)].grid(alpha=0.3)
    if position:
        ax[-1].set_ylabel("centre of mass (mm)")
        ax[-1].grid(alpha=0.3)
        ax[-1].legend(fontsize=7, ncol=3)
    ax[0].legend(fontsize=8)
    ax[-1].set_xlabel("wingbeats after release")
    if title:
        fig.suptitle(title)
    return fig


def trajectory_3d(frames: Mapping[str, pl.DataFrame], *, title: str = "", arrows: int = 12, arrow_mm: float | None = None) -> Figure:
    """The centre of mass in the world (mm; x up under the default gravity) with the body's
    stroke axis drawn as arrows at ``arrows`` instants, one colour per frame."""
    import matplotlib.pyplot as plt

    from .._errors import whole

    frames = _frames(frames, _POSITION + _ATTITUDE)
    arrows = whole("arrows", arrows, 0, 10_000)
    fig = plt.figure(figsize=(7.5, 6.5), constrained_layout=True)
    ax = fig.add_subplot(projection="3d")
    span = 1.0  # the horizontal extent: arrows scaled to it stay readable after a long fall
    for df in frames.values():
        for c in ("body_y", "body_z"):
            span = max(span, float(np.ptp(df[c].to_numpy())))
    length = arrow_mm if arrow_mm is not None else 0.1 * span
    for i, (label, df) in enumerate(frames.items()):
        x, y, z = (df[c].to_numpy() for c in ("body_x", "body_y", "body_z"))
        # World axes drawn as (y, z, x) so the world x ("up") is the plot's vertical.
        ax.plot(y, z, x, color=f"C{i}", label=label)
        ax.scatter([y[0]], [z[0]], [x[0]], color=f"C{i}", marker="o", s=25)
        ax.scatter([y[-1]], [z[-1]], [x[-1]], color=f"C{i}", marker="x", s=35)
        k = np.linspace(0, len(df) - 1, arrows).astype(int)
        up = _body_axis(df, 0)[k] * length
        ax.quiver(y[k], z[k], x[k], up[:, 1], up[:, 2], up[:, 0], color=f"C{i}", alpha=0.6, arrow_length_ratio=0.25)
    ax.set_xlabel("world y (mm)")
    ax.set_ylabel("world z (mm)")
    ax.set_zlabel("world x, up (mm)")
    ax.legend(fontsize=8, loc="upper left")
    ax.set_title(title or "centre of mass (o release, x end); arrows: body stroke axis x̂")
    return fig


def _rotations(df: pl.DataFrame) -> np.ndarray:
    """Body-to-world rotation matrices (n, 3, 3) from the attitude quaternions."""
    w, x, y, z = (df[c].to_numpy() for c in ("body_qw", "body_qx", "body_qy", "body_qz"))
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


def _body_axis(df: pl.DataFrame, k: int) -> np.ndarray:
    return _rotations(df)[:, :, k]


def animate(df: pl.DataFrame, path: str | Path, *, shoulders_mm: tuple[tuple[float, float, float], ...] = ((6.0, 0.0, -1.5), (6.0, 0.0, 1.5)), span_mm: float = 16.0, body_mm: float = 18.0, frames: int = 60, fps: int = 15, dpi: int = 60, title: str = "") -> Path:
    """An animation of the body (black: a stick along x̂ through the centre of mass) and both wings
    (left blue, right red; schematic: the leading edge turned by the stroke φ about x̂ from
    ±ẑ, a chord turned by the rotation ψ), ``frames`` instants evenly over the trajectory, in a
    box that follows the centre of mass (grey: its path so far; dashed: world up).

    The format follows ``path``'s suffix: ``.mp4`` through matplotlib's FFMpegWriter (H.264)
    when :func:`ffmpeg_path` finds a binary; without one a ``UserWarning`` says so and the GIF
    is written next to it (``path`` with the suffix ``.gif``); ``.gif`` is a GIF
    (PillowWriter). Any other suffix is an ``InvalidParameterError`` on ``path``. Returns the
    path written."""
    import warnings

    import matplotlib.pyplot as plt
    from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter

    from .._errors import invalid, whole

    df = _frame(df, _POSITION + _ATTITUDE + tuple(f"{s}_{a}" for s in ("left", "right") for a in ("phi", "psi")), "df")
    frames = whole("frames", frames, 2, 100_000)
    fps = whole("fps", fps, 1, 1000)
    dpi = whole("dpi", dpi, 10, 2400)
    if isinstance(path, bytes) or not isinstance(path, str | os.PathLike):
        raise invalid("path", repr(path)[:60], "a .gif or .mp4 file path")
    path = Path(path)
    if path.suffix.lower() not in (".gif", ".mp4"):
        raise invalid("path", str(path), "a .gif or .mp4 file path")
    ffmpeg = ffmpeg_path() if path.suffix.lower() == ".mp4" else None
    if path.suffix.lower() == ".mp4" and ffmpeg is None:
        warnings.warn(
            f"no ffmpeg found for {path.name} (pip install 'paritysim[video]' for imageio-ffmpeg's, or put ffmpeg on PATH): writing a GIF instead",
            UserWarning,
            stacklevel=2,
        )
        path = path.with_suffix(".gif")
    path.parent.mkdir(parents=True, exist_ok=True)
    idx = np.linspace(0, len(df) - 1, frames).astype(int)
    rot = _rotations(df)
    com = np.column_stack([df[c].to_numpy() for c in ("body_x", "body_y", "body_z")])
    t = df["time_ms"].to_numpy() - df["time_ms"][0]
    phi = {s: df[f"{s}_phi"].to_numpy() for s in ("left", "right")}
    psi = {s: df[f"{s}_psi"].to_numpy() for s in ("left", "right")}
    fig = plt.figure(figsize=(4.0, 4.0))
    ax = fig.add_subplot(projection="3d")
    half = 0.6 * (body_mm + span_mm)

    def wing(side: str, i: int) -> np.ndarray:
        """Shoulder, tip, and the chord's trailing point of one wing (body frame)."""
        mirror = -1.0 if side == "left" else 1.0
        f, p = phi[side][i], psi[side][i]
        lead = np.array([0.0, -np.sin(f), mirror * np.cos(f)])
        chord = np.array([-np.cos(p), np.sin(p) * np.cos(f), mirror * np.sin(p) * np.sin(f)])
        root = np.array(shoulders_mm[0 if side == "left" else 1])
        return np.array([root, root + span_mm * lead, root + span_mm * lead + 0.3 * span_mm * chord, root + 0.3 * span_mm * chord, root])

    # No 3-D axes (drawing their ticks costs ten times the rest): a world "up" arrow and the
    # centre of mass's path so far show the motion; artists are made once and updated.
    ax.set_axis_off()
    (path_line,) = ax.plot([], [], [], color="0.6", lw=1)
    (up_line,) = ax.plot([], [], [], color="0.4", lw=1, ls="--")
    (body_line,) = ax.plot([], [], [], color="k", lw=3)
    wing_lines = {side: ax.plot([], [], [], color=colour, lw=2)[0] for side, colour in (("left", "C0"), ("right", "C3"))}
    label = ax.set_title("", fontsize=8)

    def draw(j: int) -> None:
        i = idx[j]
        r, c = rot[i], com[i]
        world = lambda pts: (r @ np.asarray(pts).T).T + c  # noqa: E731
        body = world([[-body_mm / 2, 0, 0], [body_mm / 2, 0, 0]])
        body_line.set_data_3d(body[:, 1], body[:, 2], body[:, 0])
        path_line.set_data_3d(com[: i + 1, 1], com[: i + 1, 2], com[: i + 1, 0])
        up_line.set_data_3d([c[1], c[1]], [c[2], c[2]], [c[0], c[0] + half])
        for side, line in wing_lines.items():
            w = world(wing(side, i))
            line.set_data_3d(w[:, 1], w[:, 2], w[:, 0])
        ax.set_xlim(c[1] - half, c[1] + half)
        ax.set_ylim(c[2] - half, c[2] + half)
        ax.set_zlim(c[0] - half, c[0] + half)
        label.set_text(f"{title}\nt = {t[i]:.1f} ms" if title else f"t = {t[i]:.1f} ms")

    anim = FuncAnimation(fig, draw, frames=len(idx))
    if ffmpeg is not None:
        import matplotlib as mpl

        with mpl.rc_context({"animation.ffmpeg_path": ffmpeg}):
            # yuv420p: the pixel format every player decodes (matplotlib crops h264 frames to
            # even sizes itself).
            writer = FFMpegWriter(fps=fps, codec="h264", extra_args=["-pix_fmt", "yuv420p"])
            anim.save(path, writer=writer, dpi=dpi)
    else:
        anim.save(path, writer=PillowWriter(fps=fps), dpi=dpi)
    plt.close(fig)
    return path

