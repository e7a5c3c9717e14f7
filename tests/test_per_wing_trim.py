"""Per-wing drives (`dual_linear`) and the one-wing device (`single_linear`) in stability, flight
and trim (issue 35 item 1): what runs agrees with an independent path or a symmetry, what cannot
run refuses with a typed error naming the reason."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import paritysim as ps

AMP, OFF = "actuator.waveform.amplitude_v", "actuator.waveform.offset_v"


def robobee() -> ps.Simulation:
    return ps.devices.load("robobee_dual_linear")


def one_wing(spec: ps.Simulation | None = None) -> ps.Simulation:
    spec = spec or robobee()
    return spec.replace(wings=spec.wings[:1], configuration=ps.Configuration("single_wing"), drivetrain=ps.Drivetrain.single_linear(spec.drivetrain.transmission_ratio))


def stroke_drag(spec: ps.Simulation, fixed: str) -> ps.Simulation:
    wings = tuple(dataclasses.replace(w, aero=ps.Aero(kind="stroke_drag", omega1=w.aero.omega1, coefficient=3.46)) for w in spec.wings)
    return spec.replace(wings=wings, configuration=ps.Configuration(fixed))


@pytest.mark.parametrize(
    "spec",
    [
        stroke_drag(robobee(), "drag_parity_fixed"),
        stroke_drag(one_wing(), "single_wing_fixed"),
        ps.devices.load("sreetharan2012_3_3_parity"),
    ],
    ids=["dual_linear", "single_linear", "section_3_3"],
)
def test_trim_refuses_a_device_without_lift_naming_the_wing_aero(spec: ps.Simulation) -> None:
    # Eq. 2.16's stroke drag makes no lift: trim (lift = weight) has nothing to balance. It used
    # to fail with a KeyError on the missing lift metric.
    with pytest.raises(ps.InvalidParameterError, match=r"wings\[0\]\.aero\.kind"):
        ps.flight.trim(spec, progress=False)
    no_aero = spec.replace(wings=tuple(dataclasses.replace(w, aero=None) for w in spec.wings))
    with pytest.raises(ps.InvalidParameterError, match=r"wings\[0\]\.aero\.kind"):
        ps.flight.trim(no_aero, progress=False)


def test_a_drive_per_wing_trims_the_lift_asymmetry_and_mirrors() -> None:
    """A cut left wing tilts the lift (a yaw torque) that one shared gain cannot remove; the
    left drive's own gain can. Cutting the right wing instead is the mirror image: the right
    drive's gain trims to the same value."""
    left_cut = robobee().with_paths({"wings.left.omega_ratio": 0.8})
    shared = ps.flight.trim(left_cut, progress=False)
    assert shared.converged and abs(shared.scaled["yaw"]) > 1e-2  # lift and pitch only
    per_wing = ps.flight.trim(left_cut, knobs=[AMP, OFF, "actuator.side_gain[0]"], equations=["lift", "pitch", "yaw"], progress=False)
    assert per_wing.converged and all(abs(per_wing.scaled[e]) < 1e-4 for e in ("lift", "pitch", "yaw"))
    right_cut = robobee().with_paths({"wings.right.omega_ratio": 0.8})
    mirror = ps.flight.trim(right_cut, knobs=[AMP, OFF, "actuator.side_gain[1]"], equations=["lift", "pitch", "yaw"], progress=False)
    assert mirror.knobs["actuator.side_gain[1]"] == pytest.approx(per_wing.knobs["actuator.side_gain[0]"], rel=1e-6)
    assert mirror.knobs[AMP] == pytest.approx(per_wing.knobs[AMP], rel=1e-6)
    # Roll (the drag asymmetry) is not a solved equation; by the mirror it changes sign.
    assert mirror.residuals["roll"] == pytest.approx(-per_wing.residuals["roll"], abs=1e-6)


def test_the_one_wing_device_on_the_clamped_body_is_the_stand() -> None:
    """The flight model with the airframe clamped holds it still: the wing moves as on the
    torque stand (an independent path: crates/flight against the stand's integrator)."""
    spec = one_wing()
    stand = ps.simulate(spec, columns=[]).metrics
    clamped = ps.simulate(ps.flight.with_body(spec, mode="clamped"), columns=[]).metrics
    for key in ("wing_stroke_amplitude", "wing_rotation_amplitude", "lift_mean"):
        assert clamped[key] == pytest.approx(stand[key], rel=1e-6), key


def test_the_one_wing_device_trims_lift_to_weight() -> None:
    spec = one_wing()
    result = ps.flight.trim(spec, progress=False)
    assert result.converged
    body = ps.flight.body_of(ps.flight.with_body(spec, mode="clamped"))
    weight = (body["mass_mg"] + sum(body["wing_mass_mg"])) * float(np.linalg.norm(body["gravity_mm_per_ms2"]))
    # The trimmed drive, run again on the stand (not the clamped body), lifts the weight.
    lift = ps.simulate(result.spec, columns=[]).metrics["lift_mean"]
    assert lift == pytest.approx(weight, rel=1e-3)
    assert math.isfinite(result.residuals["roll"])  # one wing: a roll torque remains, reported


@pytest.mark.parametrize("spec", [robobee(), one_wing()], ids=["dual_linear", "single_linear"])
def test_floquet_runs_and_the_whippletree_linearisation_refuses(spec: ps.Simulation) -> None:
    multipliers = np.abs(ps.stability.floquet(spec).multipliers)
    assert multipliers.max() < 1.0  # damped, driven oscillators: a stable orbit
    with pytest.raises(ps.ConstraintError):
        ps.stability.linearise(spec)
