"""`paritysim.continuation` and `ContinuationResult.follow` on bad input: a typed error naming the
argument (or setting) once, with what it must be, before anything runs (short branches only)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

import paritysim as ps
from paritysim.cli import main

PATH = "drivetrain.balance_spring"


@pytest.fixture(scope="module")
def linkage() -> ps.Simulation:
    return ps.devices.load("sreetharan2012_3_3_parity_linkage")


@pytest.mark.parametrize("index", ["a", -1, 1.7, 0, None])
def test_follow_on_a_branch_without_bifurcations_says_it_has_none(linkage: ps.Simulation, index: Any) -> None:
    branch = ps.continuation(linkage, PATH, start=1000.0, stop=900.0, max_points=5, progress=False, metrics=False)
    assert branch.bifurcations.height == 0
    with pytest.raises(ps.InvalidParameterError) as info:
        branch.follow(index, "wings[0].aero.omega1", stop=30.0)
    assert info.value.field == "bifurcation"
    assert f"invalid `bifurcation` = {index!r}: must be a row of `bifurcations`, but the branch has none (stop_reason MaxPoints)" in str(info.value)


def test_follow_names_the_rows_a_bifurcation_index_may_take(linkage: ps.Simulation) -> None:
    branch = ps.continuation(linkage, PATH, start=390.0, stop=360.0, max_points=40, progress=False, metrics=False)
    assert branch.bifurcations["kind"].to_list() == ["branch_point"]
    for index in ("a", -1, 1.7, 1, True):
        with pytest.raises(ps.InvalidParameterError) as info:
            branch.follow(index, "wings[0].aero.omega1", stop=30.0)  # type: ignore[arg-type]
        assert info.value.field == "bifurcation", index
        assert f"= {index!r}: must be a row of `bifurcations`: an integer in [0, 0] (the branch has 1)" in str(info.value)
    with pytest.raises(ps.InvalidParameterError) as info:  # row 0 exists: the core names its kind
        branch.follow(0, "wings[0].aero.omega1", stop=30.0)
    assert info.value.field == "bifurcation" and "branch_point" in str(info.value)


@pytest.mark.parametrize(("path", "allowed"), [(PATH, "a number in [0, 10000]"), ("options.samples_per_cycle", "an integer in [8, 1000000]")])
def test_an_out_of_range_start_names_the_path_once(linkage: ps.Simulation, path: str, allowed: str) -> None:
    with pytest.raises(ps.InvalidParameterError) as info:
        ps.continuation(linkage, path, start=-5.0, stop=900.0, max_points=3, progress=False)
    assert info.value.field == path
    assert f"invalid `{path}` = -5.0: must be {allowed}" in str(info.value)
    assert f"{path}.{path}" not in str(info.value)


@pytest.mark.parametrize(
    ("name", "value", "message"),
    [
        ("max_step", math.nan, "invalid `max_step` = nan: must be a finite number"),
        ("initial_step", math.inf, "invalid `initial_step` = inf: must be a finite number"),
        ("tolerance", "1e-9", "invalid `tolerance` = '1e-9': must be a real number"),
        ("parameter_scale", -math.inf, "invalid `parameter_scale` = -inf: must be a finite number"),
        # The ranges are the core's (written once there), naming the setting.
        ("max_step", -1.0, "invalid `max_step` = -1: must be finite and > 0"),
        ("max_points", 1.5, "invalid `max_points` = 1.5: must be a non-negative integer"),
        ("max_points", -3, "invalid `max_points` = -3: must be a non-negative integer"),
        ("max_points", 1, "invalid `max_points` = 1: must be in [2, 1000000]"),
        ("cyclic", -1, "invalid `cyclic` = -1: must be a non-negative integer"),
        ("cyclic", 4, "invalid `cyclic` = 4: must be a state index < 4"),  # 2 coordinates and their rates
        ("method", 3, "invalid `method` = 3: must be a text"),
        ("method", "arc", 'invalid `method` = arc: must be "arclength" or "natural"'),
        ("locate", "yes", "invalid `locate` = 'yes': must be True or False"),
        ("metrics", 1, "invalid `metrics` = 1: must be True or False"),
    ],
)
def test_each_setting_is_checked_by_name(linkage: ps.Simulation, name: str, value: Any, message: str) -> None:
    with pytest.raises(ps.InvalidParameterError) as info:
        ps.continuation(linkage, PATH, start=1000.0, stop=900.0, progress=False, **{name: value})
    assert info.value.field == name
    assert message in str(info.value)


def test_a_none_setting_takes_its_default(linkage: ps.Simulation) -> None:
    branch = ps.continuation(linkage, PATH, start=1000.0, stop=900.0, max_points=3, max_step=None, cyclic=None, progress=False, metrics=False)
    assert branch.branch.height == 3


def _study(tmp_path: Path, settings: str) -> str:
    study = tmp_path / "study.toml"
    study.write_text(f'spec = "sreetharan2012_3_3_parity_linkage"\npath = "{PATH}"\nstart = 1000.0\nstop = 900.0\n\n[settings]\n{settings}\n')
    return str(study)


def test_cli_settings_are_checked_by_name(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["continue", _study(tmp_path, "max_step = nan"), "--out", str(tmp_path / "out"), "--quiet"]) == 1
    assert "invalid `max_step` = nan: must be a finite number" in capsys.readouterr().err
    assert main(["continue", _study(tmp_path, "stop = 800.0"), "--out", str(tmp_path / "out"), "--quiet"]) == 1
    assert "invalid `settings.stop` = 800.0: must be given as `stop` at the top of the study" in capsys.readouterr().err
