"""Every ``spec`` argument of the Python API reads the same things (``paritysim.devices.as_simulation``):
a Simulation, its dict, a shipped device's name or a TOML spec file; anything else is an
``InvalidParameterError`` naming ``spec``."""

from __future__ import annotations

from pathlib import Path

import pytest

import paritysim as ps
from paritysim.devices import as_simulation

NAME = "sreetharan2012_3_3_parity"


def test_a_name_a_dict_and_a_file_read_as_the_loaded_device(tmp_path: Path) -> None:
    spec = ps.devices.load(NAME)
    file = tmp_path / "mine.toml"
    spec.save(file)
    for source in (spec, spec.to_dict(), NAME, str(file), file):
        assert as_simulation(source) == spec


def test_a_file_next_to_the_caller_wins_over_the_device_of_its_name(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # A local copy of a device, edited, shadows the shipped one (as on the command line).
    edited = ps.devices.load(NAME).with_paths({"drivetrain.balance_spring": 123.0})
    edited.save(tmp_path / NAME)
    monkeypatch.chdir(tmp_path)
    assert as_simulation(NAME) == edited


@pytest.mark.parametrize("bad", [42, None, b"x", ["a"]])
def test_other_types_name_spec_and_what_it_accepts(bad: object) -> None:
    with pytest.raises(ps.InvalidParameterError, match="a named device") as info:
        ps.simulate(bad)  # type: ignore[arg-type]
    assert info.value.field == "spec"


def test_a_misspelt_device_name_suggests_the_nearest() -> None:
    with pytest.raises(ps.InvalidParameterError, match=NAME) as info:
        ps.simulate("sreetharan2012_3_3_parrity")
    assert info.value.field == "spec"


def test_simulate_of_a_name_equals_simulate_of_the_loaded_device() -> None:
    by_name = ps.simulate(NAME, record_cycles=1, progress=False)
    loaded = ps.simulate(ps.devices.load(NAME), record_cycles=1, progress=False)
    assert by_name.metrics == loaded.metrics


def test_every_entry_point_takes_a_name() -> None:
    # Each reads the name through the one rule: a misspelt one fails on `spec` before any work.
    calls = {
        "sweep": lambda s: ps.sweep(s, {"drivetrain.balance_spring": [1.0]}, progress=False),
        "sensitivity": lambda s: ps.sensitivity(s, params=["drivetrain.balance_spring"]),
        "optimize": lambda s: ps.optimize(s, objective="lift_mean", params={"drivetrain.balance_spring": (1.0, 2.0)}),
        "continuation": lambda s: ps.continuation(s, "drivetrain.balance_spring", 2.0, progress=False),
        "floquet": lambda s: ps.stability.floquet(s),
        "trim": lambda s: ps.flight.trim(s),
        "spec_paths": lambda s: ps.spec_paths(s),
    }
    for what, call in calls.items():
        with pytest.raises(ps.InvalidParameterError, match="nearest|did you mean|sreetharan") as info:
            call("sreetharan2012_3_3_parrity")
        assert info.value.field == "spec", what
    table = ps.spec_paths(NAME)
    assert "drivetrain.balance_spring" in table["path"].to_list()


def test_a_missing_file_is_an_error_on_spec(tmp_path: Path) -> None:
    for missing in (str(tmp_path / "nope.toml"), tmp_path / "nope.toml"):
        with pytest.raises(ps.InvalidParameterError, match="readable TOML file") as info:
            ps.sensitivity(missing, params=["drivetrain.balance_spring"])
        assert info.value.field == "spec"


def test_metric_names_are_the_metrics_a_run_reports() -> None:
    # docs/reference/metrics.md named ps.sweep_metric_names, which did not exist.
    for name in ("robobee_dual_linear", "sreetharan2012_3_4_parity_1cut"):
        names = ps.metric_names(name)
        assert names == ps.devices.metric_names(ps.devices.load(name))
        assert set(names) == set(ps.simulate(name, columns=[], progress=False).metrics)


@pytest.mark.parametrize(("path", "value", "allowed"), [("wings[0].aero.omega1", 0.0, "(0, 100000]"), ("wings[0].aero.omega2", -0.1, "[0, 1000000]"), ("wings[1].aero.force_parameter", -1.0, "[0, 100000]")])
def test_an_omega_out_of_range_names_its_spec_path_and_the_engines_range(path: str, value: float, allowed: str) -> None:
    # The schema gave Ω1 >= 0 and Ω2, Ω3 >= -1e6 where the engine needs Ω1 > 0, Ω2, Ω3 >= 0; the
    # engine's error named `wings[0].aero.omegas.omega2`, a path with_paths refused.
    spec = ps.devices.load("sreetharan2012_3_4_parity_1cut")
    with pytest.raises(ps.InvalidParameterError) as err:
        ps.simulate(spec.with_paths({path: value}), progress=False)
    assert err.value.field == path and allowed in str(err.value)
    spec.with_paths({err.value.field: 1.0})  # the named field is a path
