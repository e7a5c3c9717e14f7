"""`paritysim.stability` on bad input: shooting options and `disturbance_response`'s arguments
named before anything runs, and the chart plots on charts they cannot draw as a grid."""

from __future__ import annotations

import math
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
import polars as pl
import pytest

import paritysim as ps
from paritysim import stability as st
from paritysim.trials.section_2_6 import drag_parity_spec


@pytest.fixture(scope="module")
def linear() -> ps.Simulation:
    return ps.devices.load("sreetharan2012_2_6_parity_linear")


@pytest.mark.parametrize(
    ("name", "value", "allowed"),
    [
        ("rtol", "x", "a real number"),
        ("atol", math.nan, "a finite number"),
        ("tol", math.inf, "a finite number"),
        ("rtol", -1.0, "finite and > 0"),  # the ranges are the core's, named
        ("warmup_tol", -math.inf, "a finite number"),
        ("fd_step", "1e-5", "a real number"),
        ("t0", math.nan, "a finite number"),
        ("max_steps", 1.5, "a non-negative integer"),
        ("max_steps", 0, "> 0"),
        ("warmup_cycles", -1, "a non-negative integer"),
        ("fallback_cycles", 2.5, "a non-negative integer"),
        ("max_newton", "3", "a non-negative integer"),
        ("orbit_cycles", 1.5, "a non-negative integer"),
        ("orbit_cycles", 9, "an integer in [1, 8]"),
        ("method", "rk4", '"dop853" or "dopri5"'),
        ("method", 3, '"dop853" or "dopri5"'),
    ],
)
def test_shooting_options_are_checked_by_name(name: str, value: Any, allowed: str) -> None:
    with pytest.raises(ps.InvalidParameterError) as info:
        st.floquet(drag_parity_spec(500.0), **{name: value})
    assert info.value.field == name
    assert f": must be {allowed}" in str(info.value), str(info.value)


def test_every_shooting_entry_point_checks_its_options(linear: ps.Simulation) -> None:
    for call in (
        lambda: st.k2_sweep(linear, [1.0, 2.0], rtol="x"),
        lambda: st.linearise(linear, rtol="x"),
        lambda: st.disturbance_response(linear, [50.0], rtol="x"),
    ):
        with pytest.raises(ps.InvalidParameterError) as info:
            call()
        assert info.value.field == "rtol"


@pytest.mark.parametrize(("amplitude", "allowed"), [(-1, "finite and > 0"), (0.0, "finite and > 0"), (math.nan, "finite and > 0"), (math.inf, "finite and > 0"), ("big", "a real number")])
def test_disturbance_amplitude_is_named_before_any_run(linear: ps.Simulation, amplitude: Any, allowed: str) -> None:
    """Not a row per frequency blaming ``frequency_hz[i]`` for the amplitude."""
    with pytest.raises(ps.InvalidParameterError) as info:
        st.disturbance_response(linear, [0.0, 50.0], amplitude=amplitude)
    assert info.value.field == "amplitude"
    assert f"must be {allowed}" in str(info.value) and "frequency_hz" not in str(info.value)


def test_chart_map_of_one_value_on_an_axis_draws_its_points() -> None:
    for beta0, kappa in (([1.0], [0.1]), (np.linspace(0, 3, 5), [0.1]), ([0.5], np.linspace(-1, 3, 9))):
        chart = st.stability_chart(beta0, kappa)
        fig = st.plot_chart_map(chart)
        ax = fig.axes[0]
        coloured = ax.collections[0]
        assert len(coloured.get_offsets()) == chart.height  # every point, coloured by log10 |ρ|max
        assert np.allclose(coloured.get_array(), np.log10(chart.sort("beta0", "kappa")["spectral_radius"].to_numpy()))
        assert "Region I (stable)" in [t.get_text() for t in ax.get_legend().get_texts()]
        plt.close(fig)


def test_chart_map_places_points_whatever_the_order_of_the_axes() -> None:
    up = st.plot_chart_map(st.stability_chart([1.0, 3.0], [0.1, 0.5]))
    down = st.plot_chart_map(st.stability_chart([3.0, 1.0], [0.5, 0.1]))
    assert np.array_equal(up.axes[0].collections[0].get_array(), down.axes[0].collections[0].get_array())
    plt.close("all")


def test_chart_plots_name_the_columns_they_need() -> None:
    frame = pl.DataFrame({"a": [1]})
    with pytest.raises(ps.InvalidParameterError) as info:
        st.plot_chart_map(frame)
    assert info.value.field == "chart" and "the columns beta0, kappa, spectral_radius, stable" in str(info.value)
    with pytest.raises(ps.InvalidParameterError) as info:
        st.plot_fig2_13(frame)
    assert info.value.field == "chart" and "the columns a, b, region" in str(info.value)
    with pytest.raises(ps.InvalidParameterError) as info:
        st.plot_chart_map({"beta0": [1.0]})  # type: ignore[arg-type]
    assert info.value.field == "chart"
    with pytest.raises(ps.InvalidParameterError) as info:  # not a whole grid
        st.plot_chart_map(st.stability_chart([1.0, 3.0], [0.1, 0.5]).head(3))
    assert info.value.field == "chart" and "a whole beta0 x kappa grid" in str(info.value)
