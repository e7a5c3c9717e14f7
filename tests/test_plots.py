"""Figure helpers: coincident compared curves stay visible, sweep labels carry units."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import pytest
import numpy as np

import paritysim as ps
from paritysim import plots


def test_pair_draws_both_curves_and_detects_coincidence() -> None:
    t = np.linspace(0.0, 1.0, 50)
    fig, ax = plt.subplots()
    assert plots.pair(ax, t, np.sin(t), np.sin(t) * (1 + 1e-6), ("left", "right"))
    assert not plots.pair(ax, t, np.sin(t), 1.1 * np.sin(t), ("a", "b"))
    lines = ax.get_lines()
    assert len(lines) == 4
    under, over = lines[0], lines[1]
    assert under.get_linewidth() > 2 * over.get_linewidth()  # the hidden curve is the wide one
    assert over.get_linestyle() != "-" and over.get_marker() == "o"
    assert "coincides" in under.get_label() and "coincides" not in lines[2].get_label()
    plt.close(fig)


def test_labels_carry_units() -> None:
    assert plots.label_with_unit("left_roll_aero_peak") == "left_roll_aero_peak (mN·mm)"
    assert plots.label_with_unit("actuator.frequency_hz") == "actuator.frequency_hz (Hz)"
    assert plots.label_with_unit("drivetrain.k2") == "drivetrain.k2 (mN·mm/rad)"
    assert plots.label_with_unit("wings[1].springs[5].stiffness") == "wings[1].springs[5].stiffness (mN·mm/rad)"
    assert plots.label_with_unit("wings.left.omega_ratio") == "wings.left.omega_ratio"  # dimensionless
    assert plots.label_with_unit("mean_actuator_power") == "mean_actuator_power (mW)"
    # The force and designer metrics (the units crates/dynamics/src/metrics/mod.rs states).
    assert plots.label_with_unit("lift_mean") == "lift_mean (mN)"
    assert plots.label_with_unit("left_lift_peak") == "left_lift_peak (mN)"
    assert plots.label_with_unit("lift_per_power") == "lift_per_power (mN/mW)"  # not a power
    assert plots.label_with_unit("actuator_power_per_weight") == "actuator_power_per_weight (mW/mN)"
    assert plots.label_with_unit("lift_to_weight") == "lift_to_weight"  # dimensionless


def test_a_spec_path_is_labelled_with_its_schema_unit() -> None:
    # The labels guessed from substrings: force_per_volt was "mN", hinge_damping "mN·mm/rad",
    # omega2 "mg·mm²", actuator.damping and drivetrain.balance_spring had none.
    for device in ("sreetharan2012_3_4_parity", "sreetharan2012_3_3_parity_linkage", "robobee_dual_linear"):
        for path, unit, _, _ in ps.spec_paths(device).iter_rows():
            shown = unit.replace(" ", "·").replace("^2", "²").replace("^3", "³")
            expected = path if unit in ("", "1") else f"{path} ({shown})"
            assert plots.label_with_unit(path) == expected, (device, path, unit)
    assert plots.label_with_unit("wings.left.springs.hinge_damping") == "wings.left.springs.hinge_damping (mN·mm·ms/rad)"
    assert plots.label_with_unit("actuator.voltage_v") == "actuator.voltage_v (V)"


def test_a_gradient_column_is_labelled_with_the_quotient_of_units() -> None:
    assert plots.label_with_unit("d(lift_mean)/d(actuator.force_per_volt)") == "d(lift_mean)/d(actuator.force_per_volt) (mN/(mN/V))"
    assert plots.label_with_unit("d(left_stroke_amplitude)/d(actuator.waveform.amplitude_v)") == "d(left_stroke_amplitude)/d(actuator.waveform.amplitude_v) (rad/V)"
    assert plots.label_with_unit("d(lift_mean)/d(drivetrain.arm_ratio)") == "d(lift_mean)/d(drivetrain.arm_ratio) (mN)"
    assert plots.label_with_unit("d(lift_to_weight)/d(drivetrain.arm_ratio)") == "d(lift_to_weight)/d(drivetrain.arm_ratio)"


def test_every_metric_of_a_blade_element_device_has_a_unit_or_is_a_ratio() -> None:
    from paritysim import _core

    spec = ps.flight.with_body(ps.devices.load("sreetharan2012_3_4_parity"))  # a weight: the weighed metrics too
    dimensionless = ("_pct", "lift_to_weight", "_ratio")
    for name in _core.sweep_metric_names(spec.to_json()):
        if not name.endswith(dimensionless):
            assert plots.label_with_unit(name) != name, name


def test_every_plot_path_saves_through_one_checked_writer(tmp_path: Path) -> None:
    # Each plot method wrote with its own savefig: a bad suffix was matplotlib's ValueError, a
    # missing folder FileNotFoundError in some and not others, a number a TypeError.
    import polars as pl

    result = ps.simulate("sreetharan2012_3_3_parity", progress=False)
    table = pl.DataFrame({"actuator.frequency_hz": [100.0, 110.0], "left_stroke_amplitude": [0.5, 0.6]})
    draw = {
        "simulation": lambda path: result.plot(path),
        "sweep": lambda path: ps.sweep.plot(table, "actuator.frequency_hz", "left_stroke_amplitude", path=path),
    }
    for name, plot in draw.items():
        written = tmp_path / name / "deep" / "figure.svg"
        fig = plot(written)
        assert written.read_text().lstrip().startswith("<?xml"), name  # the suffix's format
        assert plt.fignum_exists(fig.number), name  # the returned figure stays open
        plt.close(fig)
        for bad, phrase in ((tmp_path / "figure.foo", "suffix is a figure format"), (5, "a file path")):
            with pytest.raises(ps.InvalidParameterError, match=phrase) as info:
                plot(bad)
            assert info.value.field == "path", name
    plt.close("all")


def test_a_simulation_plots_lift_and_any_columns_by_unit() -> None:
    result = ps.simulate("sreetharan2012_3_4_parity", progress=False)
    default = result.plot()
    labels = [ax.get_ylabel() for ax in default.axes]
    assert labels == ["angle (deg)", "torque (mN·mm)", "lift (mN)"]
    total = [line for line in default.axes[2].lines if line.get_label() == "total"][0]
    np.testing.assert_allclose(total.get_ydata(), (result.trajectory["left_lift"] + result.trajectory["right_lift"]).to_numpy())
    chosen = result.plot(columns=["left_phi", "right_psi", "left_lift", "actuator_power", "aero_power"])
    assert [ax.get_ylabel() for ax in chosen.axes] == ["deg", "mN", "mW"]  # one panel per unit
    np.testing.assert_allclose(chosen.axes[0].lines[0].get_ydata(), np.degrees(result.trajectory["left_phi"].to_numpy()))
    with pytest.raises(ps.InvalidParameterError, match="left_lift") as info:
        result.plot(columns=["left_lif"])
    assert info.value.field == "columns[0]"
    # A device without aerodynamic lift keeps two panels.
    assert len(ps.simulate("sreetharan2012_3_3_parity", progress=False).plot().axes) == 2
    plt.close("all")


def test_columns_are_grouped_by_the_cores_units() -> None:
    # The units were guessed from names: left_phi_ddot went on the angle axis times 57.3,
    # q1_dot was labelled mm, body angles and rates shared the torque axis.
    hmf = ps.devices.load("sreetharan2012_3_4_hmf")
    result = ps.simulate(hmf, progress=False)
    assert result.units["left_phi_ddot"] == "rad/ms^2" and result.units["q1_dot"] == "mm/ms"
    # The work integral's rate is the power column (µJ/ms = mW): the units agree with the data.
    t, work, power = (result.trajectory[c].to_numpy() for c in ("time_ms", "work_actuator", "actuator_power"))
    np.testing.assert_allclose(np.gradient(work, t)[5:-5], power[5:-5], rtol=1e-2, atol=1e-2 * np.abs(power).max())
    fig = result.plot(columns=["left_phi_ddot", "q1_dot", "q2", "actuator_power"])
    assert [ax.get_ylabel() for ax in fig.axes] == ["rad/ms²", "mm/ms", "deg", "mW"]
    np.testing.assert_allclose(fig.axes[0].lines[0].get_ydata(), result.trajectory["left_phi_ddot"].to_numpy())  # not in degrees
    # A dual drivetrain's q2 is the right actuator's displacement (right_phi = -T q2), in mm.
    dual = ps.devices.load("robobee_dual_linear")
    run = ps.simulate(dual, progress=False)
    assert (run.units["q2"], run.units["q2_dot"]) == ("mm", "mm/ms")
    ratio = dual.drivetrain.transmission_ratio
    np.testing.assert_allclose(run.trajectory["right_phi"].to_numpy(), -ratio * run.trajectory["q2"].to_numpy(), rtol=1e-12, atol=1e-14)
    assert run.plot(columns=["q2"]).axes[0].get_ylabel() == "mm"
    flying = ps.simulate(ps.flight.with_body(hmf, mode="roll"), record_cycles=2, progress=False)
    fig = flying.plot(columns=["body_roll", "body_omega_roll", "body_torque_roll"])
    assert [ax.get_ylabel() for ax in fig.axes] == ["deg", "rad/ms", "mN·mm"]
    with pytest.raises(ps.InvalidParameterError, match="x axis") as info:
        result.plot(columns=["time_ms"])
    assert info.value.field == "columns[0]"
    plt.close("all")


def test_a_run_that_recorded_some_columns_plots_those() -> None:
    # The default figure needed every angle and torque: polars' ColumnNotFoundError.
    result = ps.simulate("sreetharan2012_3_4_hmf", columns=["left_phi", "right_phi", "actuator_force"], progress=False)
    fig = result.plot()
    assert [ax.get_ylabel() for ax in fig.axes] == ["deg", "mN"]
    plt.close("all")


def test_naming_time_ms_among_the_columns_is_no_error() -> None:
    # It was "must be a known name (none close to `time_ms`)", though every trajectory has it.
    result = ps.simulate("sreetharan2012_3_4_hmf", columns=["time_ms", "left_phi"], progress=False)
    assert result.trajectory.columns == ["time_ms", "left_phi"]


def test_trajectory_columns_are_labelled_with_the_cores_units() -> None:
    # The substring table read left_tau_aero_phi as an angle and knew no rates.
    expected = {
        "left_tau_aero_phi": "mN·mm", "left_tau_spring_psi": "mN·mm", "left_phi_dot": "rad/ms", "left_phi_ddot": "rad/ms²",
        "q1_dot": "mm/ms", "voltage": "V", "actuator_power": "mW", "work_aero": "µJ", "body_omega_roll": "rad/ms", "momentum_x": "mg·mm/ms",
    }
    for column, unit in expected.items():
        assert plots.label_with_unit(column) == f"{column} ({unit})"
