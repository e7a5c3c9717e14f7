"""Reproducers of what the whole-surface fuzz (``benchmarks/fuzz_report.py``, issue 34) found on
the surface added in sessions 13-14: per-wing and one-wing drives, polynomial transmissions,
datasheet and laminate actuators, table calibration. Each was a foreign exception, an error
naming no field, or a run past its budget; each is now a typed error naming the argument."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

import paritysim as ps

ONE_WING = {
    "name": "one wing",
    "configuration": {"name": "single_wing_fixed"},
    "drivetrain": {"kind": "single_linear", "transmission_ratio": 2.67, "cubic_ratio": 5.0},
    "actuator": {"force_per_volt": 1.2, "stiffness": 300.0, "waveform": {"kind": "sine", "amplitude_v": 60.0, "frequency_hz": 120.0}},
    "options": {"min_cycles": 1, "max_cycles": 4, "samples_per_cycle": 24, "record_cycles": 1},
}


def one_wing() -> ps.Simulation:
    wing = ps.devices.load("sreetharan2012_3_3_parity").to_dict()["wings"][0]
    wing["aero"] = {"kind": "stroke_drag", "omega1": 10.0, "coefficient": 3.46}
    return ps.Simulation.from_dict({**ONE_WING, "wings": [wing]})


def test_from_blocked_force_refuses_the_fields_it_computes_by_name() -> None:
    # Was: TypeError "got multiple values for keyword argument 'stiffness'".
    for name in ("stiffness", "force_per_volt"):
        with pytest.raises(ps.InvalidParameterError) as info:
            ps.Actuator.from_blocked_force(120.0, 0.257, 100.0, **{name: 3.0})
        assert info.value.field == name


def test_from_laminate_checks_its_bimorph_and_mass_flag() -> None:
    # Was: AttributeError ('NoneType' object has no attribute 'stiffness_mn_per_mm').
    with pytest.raises(ps.InvalidParameterError) as info:
        ps.Actuator.from_laminate(None)
    assert info.value.field == "bimorph"
    bimorph = ps.laminate.Bimorph.design_for()
    # Was: a truthy "no" silently set mass_mg.
    with pytest.raises(ps.InvalidParameterError) as info:
        ps.Actuator.from_laminate(bimorph, mass="no")
    assert info.value.field == "mass"
    with pytest.raises(ps.InvalidParameterError) as info:
        ps.Actuator.from_laminate(bimorph, stiffness=1.0)
    assert info.value.field == "stiffness"
    # Still: mass=True reflects the bimorph's effective mass, a positive part of its active mass.
    actuator = ps.Actuator.from_laminate(bimorph, mass=True)
    assert 0.0 < actuator.mass_mg < bimorph.active_mass


@pytest.mark.parametrize("make", [ps.Drivetrain.single_linear, ps.Drivetrain.dual_linear])
@pytest.mark.parametrize("ratios", [3, "1.0", {"a": 1.0}])
def test_higher_odd_ratios_that_are_not_a_list_are_named(make, ratios) -> None:  # type: ignore[no-untyped-def]
    # Was: TypeError "'int' object is not iterable" (a str was split into characters).
    with pytest.raises(ps.InvalidParameterError) as info:
        make(2.67, cubic_ratio=5.0, higher_odd_ratios=ratios)
    assert info.value.field == "drivetrain.higher_odd_ratios"


def test_an_actuator_without_a_drivetrain_names_the_drivetrain() -> None:
    # Was: ConstraintError "an actuator needs a transmission" from simulate, naming no field.
    data = one_wing().to_dict()
    data["drivetrain"] = None
    with pytest.raises(ps.InvalidParameterError) as info:
        ps.simulate(ps.Simulation.from_dict(data))
    assert info.value.field == "drivetrain"
    with pytest.raises(ps.InvalidParameterError) as info:
        one_wing().replace(drivetrain=None)
    assert info.value.field == "drivetrain"
    # A device without an actuator still needs no drivetrain.
    data["actuator"] = None
    assert ps.Simulation.from_dict(data).drivetrain is None


def test_a_long_calibration_table_keeps_the_fit_within_its_budget() -> None:
    # Was: each point got the budget left, but the sweep of all rows ran on (a 1e5-row table
    # ran past the fuzz's 60 s with max_wall_ms = 20 s).
    rows = 20_000
    data = {"actuator.waveform.amplitude_v": [60.0] * rows, "wing_stroke_amplitude": [0.5] * rows}
    start = time.monotonic()
    with pytest.raises(ps.IntegrationError) as info:
        ps.calibrate(one_wing(), data=data, params={"actuator.force_per_volt": (0.8, 3.5)}, max_nfev=2, progress=False, max_wall_ms=1000.0, threads=1)
    assert info.value.field == "max_wall_ms"
    # 20000 points take ~100 s; the budget stops the fit after one more block of rows.
    assert time.monotonic() - start < 20.0


def test_an_airframe_point_far_outside_the_body_is_named() -> None:
    # Was (seed 34, case 279): a shoulder at 1e308 mm ran and failed with a step-size underflow
    # naming no field.
    spec = ps.load_spec(Path(__file__).resolve().parents[1] / "examples" / "free_flight.toml")
    for path in ("body.shoulders_mm[1][1]", "body.wing_center_of_mass_mm[0][2]"):
        with pytest.raises(ps.InvalidParameterError) as info:
            spec.with_paths({path: 1e308})
        assert info.value.field == path
    # The bound is the centre of mass's: 1e3 mm is still a spec.
    assert spec.with_paths({"body.shoulders_mm[1][1]": 1e3}).body.shoulders_mm[1][1] == 1e3


@pytest.mark.parametrize("kind", ["single_linear", "hmf_four_bar"])
def test_a_one_dof_drive_on_two_untied_wings_names_the_drivetrain(kind: str) -> None:
    # Was: ConstraintError naming no field (seed 51, case 1749). The Drag PARITY configuration
    # leaves the two strokes free, so one actuator through a 1-DOF drivetrain cannot drive both.
    spec = ps.devices.load("sreetharan2012_3_3_parity").to_dict()
    spec["drivetrain"] = {"kind": kind} if kind == "hmf_four_bar" else {"kind": kind, "transmission_ratio": 2.67}
    with pytest.raises(ps.ConstraintError) as info:
        ps.simulate(ps.Simulation.from_dict(spec))
    assert info.value.field == "drivetrain.kind"
    assert kind in str(info.value) and "hmf" in str(info.value)
    # The same drive on the configuration that ties the strokes builds.
    spec["configuration"] = {"name": "hmf"}
    ps.Simulation.from_dict(spec).validate()


def test_a_one_dof_drive_on_tied_wings_is_not_blamed_for_another_constraint() -> None:
    # The drivetrain is named only for the untied strokes: on the tied §3.4 HMF the 1-DOF four
    # bar is fine, and the forced drivetrain coordinates (rotating wings) are the cause.
    spec = ps.devices.load("sreetharan2012_3_4_hmf").to_dict()
    spec["drivetrain"] = {"kind": "hmf_four_bar"}
    spec["formulation"] = "drivetrain_coordinates"
    with pytest.raises(ps.ConstraintError) as info:
        ps.simulate(ps.Simulation.from_dict(spec))
    assert info.value.field != "drivetrain.kind"
    assert "drivetrain coordinates are not available" in str(info.value)
