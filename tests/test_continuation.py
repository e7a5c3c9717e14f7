"""`paritysim.continuation` on a device, checked against independent brute-force Floquet analysis
and direct simulation (the numerics are validated on closed forms in the Rust crate)."""

from __future__ import annotations

from pathlib import Path

import polars as pl
import pytest

import paritysim as ps
from paritysim.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture(scope="module")
def linkage() -> ps.Simulation:
    return ps.devices.load("sreetharan2012_3_3_parity_linkage")


@pytest.fixture(scope="module")
def branch(linkage: ps.Simulation) -> ps.ContinuationResult:
    return ps.continuation(linkage, "drivetrain.balance_spring", start=1000.0, stop=100.0)


def test_whippletree_boundary_matches_brute_force_floquet(linkage: ps.Simulation, branch: ps.ContinuationResult) -> None:
    assert branch.stop_reason == "ReachedStop"
    assert branch.bifurcations["kind"].to_list() == ["branch_point"]
    k_star = branch.bifurcations["drivetrain.balance_spring"][0]
    assert 300.0 < k_star < 450.0
    # independent: Newton shooting + monodromy at K2* ± 2 (ps.stability.k2_sweep)
    brute = ps.stability.k2_sweep(linkage, [k_star - 2.0, k_star + 2.0])
    below, above = brute["spectral_radius"].to_list()
    assert below > 1.0 > above, (below, above)
    # the critical multiplier is +1 at the located point
    assert branch.bifurcations["critical_modulus"][0] == pytest.approx(1.0, abs=1e-4)
    # stable above the boundary, unstable below, along the whole branch
    for row in branch.branch.iter_rows(named=True):
        k2 = row["drivetrain.balance_spring"]
        if abs(k2 - k_star) > 5.0:
            assert row["stability"] == ("stable" if k2 > k_star else "unstable"), row


def test_branch_metrics_equal_a_direct_simulation(linkage: ps.Simulation, branch: ps.ContinuationResult) -> None:
    """The orbit metrics of a stable branch point equal a converged `simulate` run there."""
    first = branch.branch.row(0, named=True)
    spec = linkage.with_paths({"drivetrain.balance_spring": first["drivetrain.balance_spring"]})
    direct = ps.simulate(spec, steady_state="shooting", rtol=1e-10, atol=1e-12)
    for name in ("left_stroke_amplitude", "right_stroke_amplitude", "left_roll_aero_peak", "actuator_force_peak"):
        assert first[name] == pytest.approx(direct.metrics[name], rel=1e-6), name
    floats = [c for c, t in branch.branch.schema.items() if t == pl.Float64]
    assert not any(branch.branch[c].is_nan().any() for c in floats)  # undefined metrics are null, not NaN


def test_bad_settings_and_paths_are_named(linkage: ps.Simulation) -> None:
    with pytest.raises(ps.InvalidParameterError, match="max_stpe") as info:
        ps.continuation(linkage, "drivetrain.balance_spring", 100.0, start=1000.0, max_stpe=0.1)
    assert "max_step" in str(info.value)
    with pytest.raises(ps.InvalidParameterError, match="balance_sprign"):
        ps.continuation(linkage, "drivetrain.balance_sprign", 100.0, start=1000.0)
    with pytest.raises(ps.InvalidParameterError, match="method"):
        ps.continuation(linkage, "drivetrain.balance_spring", 100.0, start=1000.0, method="newton")


def test_plot_marks_the_bifurcation(branch: ps.ContinuationResult, tmp_path: Path) -> None:
    fig = branch.plot("q2_amplitude", path=tmp_path / "b.png")
    ax = fig.axes[0]
    styles = {line.get_linestyle() for line in ax.get_lines()}
    assert {"-", "--"} <= styles  # stable solid, unstable dashed
    assert any("branch_point" in t.get_text() for t in ax.texts)
    assert (tmp_path / "b.png").read_bytes()[:4] == b"\x89PNG"


def test_cli_continue_writes_branch_and_plot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["continue", str(EXAMPLES / "continuation_whippletree.toml"), "--out", str(tmp_path)]) == 0
    assert "branch_point at 377" in capsys.readouterr().out
    for name in ("continuation_whippletree.parquet", "continuation_whippletree_bifurcations.csv", "continuation_whippletree.png"):
        assert (tmp_path / name).exists(), name
    bad = tmp_path / "bad.toml"
    bad.write_text('spec = "sreetharan2012_3_3_parity_linkage"\npath = "drivetrain.balance_spring"\nstop = 1.0\nstpo = 2\n')
    assert main(["continue", str(bad), "--out", str(tmp_path)]) == 1
    assert "stpo" in capsys.readouterr().err


def test_a_cut_wing_turns_the_boundary_into_a_fold_checked_by_brute_force() -> None:
    """The imperfect pitchfork: with Ω^L/Ω^R = 0.9 the stable orbit ends at a fold (the branch turns
    back, multiplier +1), not a branch point, and it never jumps onto another branch. Brute-force
    Floquet analysis brackets the fold: a stable orbit just above it, none (or an unstable one)
    just below. A corrector that jumps branches near the fold fails this."""
    from paritysim.trials.continuation_3_3 import FOLD_RATIO, OMEGA_RIGHT, PATH, START
    from paritysim.trials.section_2_6 import drag_parity_spec

    spec = drag_parity_spec(START, omega_left=OMEGA_RIGHT * FOLD_RATIO)
    branch = ps.continuation(spec, PATH, start=START, stop=300.0, metrics=False, max_points=40)
    assert branch.bifurcations["kind"].to_list()[:1] == ["fold"], branch.bifurcations
    k_fold = branch.bifurcations[PATH][0]
    assert branch.bifurcations["critical_modulus"][0] == pytest.approx(1.0, abs=1e-4)
    # past the fold the branch runs back up in K2 (the unstable side), never below the fold
    assert branch.branch[PATH].min() >= k_fold - 1e-6
    above = ps.stability.floquet(drag_parity_spec(k_fold + 3.0, omega_left=OMEGA_RIGHT * FOLD_RATIO))
    assert above.spectral_radius < 1.0
