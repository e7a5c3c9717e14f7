"""Figure details a reader trips over (issue 33): duplicate legend entries, a redundant title,
a legend over the data, a solved knob left out."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import polars as pl

from paritysim.trials import flight, section_3_3, section_3_4


def _legend_texts(legend) -> list[str]:  # type: ignore[no-untyped-def]
    return [t.get_text() for t in legend.get_texts()]


def test_table_3_2_legend_has_no_duplicate_entries(tmp_path: Path) -> None:
    section_3_3.CLI_TRIALS["table3.2"](tmp_path)
    fig = section_3_3._plot_table(pl.read_parquet(tmp_path / "table3_2.parquet"))
    for ax in fig.axes:
        texts = _legend_texts(ax.get_legend())
        assert len(texts) == len(set(texts)) == 3 and texts.count("thesis") == 1, texts
    plt.close(fig)


def test_fig_3_12_has_one_title_and_its_legend_below_the_curves() -> None:
    df = section_3_4.trajectories().filter(pl.col("trial") == "1-Cut")
    fig = section_3_4._fig(df, "yaw", ("1-Cut",), "Fig. 3.12: yaw torque in the 1-Cut trial", "yaw torque (mN·mm)")
    (ax,) = fig.axes
    assert ax.get_title() == "" and ax.get_legend() is None  # the suptitle names the trial
    (legend,) = fig.legends
    fig.canvas.draw()
    # the figure legend lies wholly below the axes: it covers no peak
    assert legend.get_window_extent().y1 <= ax.get_window_extent().y0
    assert len(_legend_texts(legend)) == 4
    plt.close(fig)


def test_flight_trim_figure_shows_the_solved_dc_offset() -> None:
    df = flight.hover_trim()
    fig = flight._fig_trim(df, 1e-4)
    texts = " ".join(t.get_text() for t in fig.axes[0].texts)
    for offset in df["offset_v"]:
        assert f"DC offset {round(offset, 3) + 0.0:+.3f} V" in texts
    plt.close(fig)
