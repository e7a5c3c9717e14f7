"""paritysim.stability from Python: the bindings and the facade's frames, checked against
independent computations (scipy, numpy) where the Rust tests (crates/dynamics/tests/dynamics/
floquet/) do not already cover the physics: eqs. 2.45, 2.50, 2.54, Brockett's closed forms,
eq. 2.59, the κ = 0 linear map and the LTI/nonlinear agreement are tested there only."""

from __future__ import annotations

import math
from pathlib import Path

from typing import Any

import numpy as np
import polars as pl
import pytest
from scipy.special import i0

import paritysim as ps
from paritysim import stability as st
from paritysim.trials.section_2_6 import drag_parity_spec, hmf_spec

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


# ------------------------------------------------------------------ eq. 2.25


def test_solution_matrix_composes_and_starts_at_identity() -> None:
    t = np.array([0.3, 1.0, 2.5])
    pi = st.hill_solution(0.8, 1.7, t, t0=0.3)
    np.testing.assert_allclose(pi[0], np.eye(2), atol=1e-15)
    composed = st.hill_solution(0.8, 1.7, [2.5], t0=1.0)[0] @ pi[1]
    np.testing.assert_allclose(composed, pi[2], rtol=1e-11, atol=1e-12)


def test_region_one_is_the_unit_disc_errata_9() -> None:
    a, b = np.meshgrid(np.linspace(-2, 2, 81), np.linspace(-0.5, 2, 61))
    a, b = a.ravel(), b.ravel()
    reg = st.region(a, b)
    rho = np.array([np.abs(np.roots([1.0, -2 * x, y])).max() for x, y in zip(a, b, strict=True)])
    off_boundary = np.abs(rho - 1) > 1e-9
    assert np.array_equal((reg == 1)[off_boundary], (rho < 1)[off_boundary])
    # The printed Region III bound a > (b - 1)/2 would call this stable point unstable.
    f = st.hill_floquet(1.0, 0.05)
    assert f["a"] > (f["b"] - 1) / 2 and f["a"] ** 2 > f["b"] and f["region"] == 1 and f["spectral_radius"] < 1


def _monodromy_by_scipy(beta0: float, kappa: float) -> np.ndarray:
    """M(−π/2) of eq. 2.25 by an independent adaptive integrator (scipy DOP853); on
    [−π/2, π/2] |cos t| = cos t, so the right-hand side is smooth."""
    from scipy.integrate import solve_ivp

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        x = y.reshape(2, 2)
        return np.array([x[1], -kappa * x[0] - beta0 * math.cos(t) * x[1]]).ravel()

    sol = solve_ivp(rhs, (-math.pi / 2, math.pi / 2), np.eye(2).ravel(), method="DOP853", rtol=1e-12, atol=1e-14)
    return sol.y[:, -1].reshape(2, 2)


def test_stability_chart_matches_an_independent_integration() -> None:
    """Fig. 2.13 chart: (a, b) against scipy's integration of eq. 2.25, the region against the
    multipliers' moduli (numpy roots of eq. 2.36), and the undamped line β0 = 0 marginal
    (docs/errata.md#9: without the multipliers' error, det M = 1 + O(1e-16) puts half of it
    in Region II)."""
    beta0, kappa = np.array([-0.5, 0.0, 1.0, 4.0]), np.array([-0.5, 0.1, 1.0, 3.0, 3.5])
    df = st.stability_chart(beta0, kappa)
    assert df.columns == ["beta0", "kappa", "a", "b", "spectral_radius", "region", "stable", "multiplier_error", "marginal", "error", "region_name", "brockett_bounded"]
    assert df["error"].null_count() == df.height
    assert df["beta0"].to_list() == np.repeat(beta0, 5).tolist() and df["kappa"].to_list() == np.tile(kappa, 4).tolist()
    for row in df.iter_rows(named=True):
        m = _monodromy_by_scipy(row["beta0"], row["kappa"])
        a, b = 0.5 * np.trace(m), np.linalg.det(m)
        assert row["a"] == pytest.approx(a, rel=1e-8, abs=1e-9) and row["b"] == pytest.approx(b, rel=1e-8, abs=1e-12)
        rho = np.abs(np.roots([1.0, -2 * a, b])).max()
        assert row["spectral_radius"] == pytest.approx(rho, rel=1e-6)
        if row["beta0"] == 0.0 and row["kappa"] > 0:  # ẍ + κx = 0: |ρ| = 1
            assert row["marginal"] and row["region_name"] == "marginal" and not row["stable"]
        else:
            assert not row["marginal"]
            assert row["stable"] == (rho < 1) and (row["region"] == 1) == (rho < 1)
        if row["beta0"] < 0 or row["kappa"] < 0:
            assert not row["stable"]  # eq. 2.51
        if row["brockett_bounded"]:
            assert row["spectral_radius"] <= 1 + row["multiplier_error"]  # Brockett's guarantee holds
        assert 0 < row["multiplier_error"] < 1e-6  # √(round-off) near a double root, else ~1e-14


def test_a_failing_chart_point_is_marked_and_the_others_are_kept() -> None:
    """κ = -1e6 passes the axis checks but its solution overflows (growth e^{1000π}): that
    point is a marked row (region 0, ``failed``, NaN numbers, its error), the others equal a
    chart without it, and the map plot marks it."""
    df = st.stability_chart([0.5], [1.0, -1e6, 0.2])
    assert df["region"].to_list()[1] == 0 and df["region_name"].to_list()[1] == "failed"
    bad = df.row(1, named=True)
    assert math.isnan(bad["a"]) and math.isnan(bad["spectral_radius"]) and not bad["stable"] and not bad["brockett_bounded"]
    assert "overflow" in bad["error"] and "index 1" in bad["error"]
    good = st.stability_chart([0.5], [1.0, 0.2])
    kept = df.filter(pl.col("error").is_null())
    assert kept.drop("error").equals(good.drop("error"))
    fig = st.plot_chart_map(st.stability_chart([0.0, 0.5, 1.0], [-1e6, 0.5, 1.0, 2.0]))
    assert any("analysis failed (3 points" in t.get_text() for t in fig.axes[0].get_legend().get_texts())


def test_marginal_line_of_a_51_by_51_chart() -> None:
    """The issue's chart: 51 × 51 over β0 ∈ [−1, 4] (β0 = 0 on the grid), κ ∈ [0.05, 4]: every
    β0 = 0 point marginal, no other."""
    df = st.stability_chart(np.linspace(-1.0, 4.0, 51), np.linspace(0.05, 4.0, 51), brockett=False)
    assert (df.filter(pl.col("beta0") == 0.0)["region_name"] == "marginal").all()
    assert df.filter(pl.col("beta0") != 0.0)["marginal"].sum() == 0
    assert df["marginal"].sum() == 51


def test_hill_parameters_use_errata_7() -> None:
    p = st.hill_parameters(inertia=29.0, drag=31.3, transmission_ratio=2.5, arm_length_mm=2.5, k1=467.0, k2=20.0, stroke_amplitude=0.5, frequency_hz=110.0)
    w0 = 2 * math.pi * 0.110
    assert p["beta0"] == pytest.approx(2 * 31.3 * 0.5 / 29.0, rel=1e-14)  # 2ΩΦ/I = 2ΩTA/I
    assert p["kappa1"] == pytest.approx(467.0 / (2 * 29.0 * 2.5**2 * w0**2), rel=1e-14)
    assert p["kappa2"] == pytest.approx(20.0 / (2 * 29.0 * 2.5**2 * 2.5**2 * w0**2), rel=1e-14)
    assert p["beta_star"] == pytest.approx(2 / math.pi * p["beta0"] * w0, rel=1e-14)


def test_invalid_inputs_name_the_field() -> None:
    with pytest.raises(ps.InvalidParameterError) as e:
        st.hill_monodromy(float("nan"), 1.0)
    assert e.value.field == "beta0"
    with pytest.raises(ps.InvalidParameterError) as e:
        st.stability_chart([0.0, 1.0], [1.0, float("inf")])
    assert e.value.field == "kappa[1]"
    with pytest.raises(ps.InvalidParameterError) as e:
        st.brockett(-1.0, 1.0)
    assert e.value.field == "delta"
    with pytest.raises(ps.ShapeError):
        st.region([0.0, 1.0], [0.0])
    with pytest.raises(ps.InvalidParameterError) as e:
        st.hill_parameters(inertia=0.0, drag=1, transmission_ratio=1, arm_length_mm=1, k1=1, k2=1, stroke_amplitude=1, frequency_hz=1)
    assert e.value.field == "inertia"
    with pytest.raises(ps.InvalidParameterError) as e:
        st.floquet(drag_parity_spec(500.0), fd_step=-1.0)
    assert e.value.field == "fd_step"
    with pytest.raises(ps.InvalidParameterError) as e:
        st.floquet(drag_parity_spec(500.0), bogus=1.0)
    assert e.value.field == "options.bogus"
    with pytest.raises(ps.ConstraintError):
        st.floquet(drag_parity_spec(1.0).replace(actuator=None))
    with pytest.raises(ps.ConstraintError):
        st.linearise(hmf_spec())


# ------------------------------------------------------------------ the nonlinear model


def _device_part(spec: ps.Simulation) -> dict[str, Any]:
    return {k: v for k, v in spec.to_dict().items() if k not in ("name", "options")}


def test_trial_specs_are_the_examples() -> None:
    assert _device_part(drag_parity_spec(1.0)) == _device_part(ps.load_spec(EXAMPLES / "drag_parity.toml"))
    assert _device_part(hmf_spec()) == _device_part(ps.load_spec(EXAMPLES / "hmf.toml"))


def test_whippletree_mode_of_the_example_is_unstable_and_k2_stabilises_it() -> None:
    """docs/findings.md item 3, quantified: unstable at K2 = 1, stable at 500."""
    unstable = st.floquet(ps.load_spec(EXAMPLES / "drag_parity.toml"))
    stable = st.floquet(drag_parity_spec(500.0))
    assert unstable.stability == "unstable" and unstable.growth_time_ms > 0
    assert stable.asymptotically_stable and stable.slowest_decay_ms > 0
    assert unstable.coordinates == ["q1", "q2", "q1_dot", "q2_dot"]
    assert np.abs(unstable.whippletree_multipliers).max() == pytest.approx(unstable.spectral_radius, rel=1e-9)
    frame = stable.frame
    assert frame.columns == ["re", "im", "modulus", "exponent_per_ms", "kind", "mode", "mode_share"] and frame.height == 4
    # Liouville for the whippletree block of a symmetric orbit: det = e^{-4 β0} per drive period
    # (two periods of eq. 2.25) with β0 = 2ΩΦ/I (docs/errata.md#7). With eq. 2.16 drag at 50 V the
    # determinant (~1e-2) is well above the finite-difference resolution (~1e-7).
    spec = drag_parity_spec(200.0, coefficient=1.0, volts=50.0)
    beta0 = st.linearise(spec)["hill"]["beta0"]
    det = np.prod(st.floquet(spec).whippletree_multipliers).real
    assert det == pytest.approx(math.exp(-4 * beta0), rel=1e-3)


def test_hmf_is_stable() -> None:
    f = st.floquet(hmf_spec())
    assert f.asymptotically_stable and f.whippletree_multipliers is None and len(f.multipliers) == 2


def test_k2_sweep_frame() -> None:
    df = st.k2_sweep(drag_parity_spec(1.0), [1.0, 100.0, 500.0, 1000.0])
    assert df.columns == ["k2", "spectral_radius", "whippletree_radius", "max_exponent_per_ms", "slowest_decay_ms", "stability", "moduli", "error"]
    assert df["error"].null_count() == df.height
    assert df["stability"].to_list()[0] == "unstable" and df["stability"].to_list()[-1] == "asymptotic"
    assert (df["whippletree_radius"].diff().drop_nulls() < 0).all()
    single = st.floquet(drag_parity_spec(100.0))
    assert df["spectral_radius"][1] == single.spectral_radius


def test_a_failing_k2_is_a_row_with_its_error() -> None:
    """The K2 loop runs on the sweep engine: a bad value is its row (error naming ``k2[i]``,
    nulls elsewhere), the others are computed as on their own (formerly the first error raised)."""
    df = st.k2_sweep(drag_parity_spec(1.0), [-1.0, 100.0])
    assert df["error"][0] is not None and "k2[0]" in df["error"][0]
    assert df["spectral_radius"][0] is None and df["stability"][0] is None and df["moduli"][0].to_list() == []
    assert df["error"][1] is None
    assert df["spectral_radius"][1] == st.floquet(drag_parity_spec(100.0)).spectral_radius


# ------------------------------------------------------------------ CLI and report




@pytest.mark.slow
def test_report_claims_of_section_2_6_hold(reproduced: Path) -> None:
    """The closed forms of §2.6 (eqs. 2.45, 2.50, 2.54 with docs/errata.md#10, Region I of #9,
    eq. 2.51, Brockett) as the fig2.13 trial checked them for the report: all must hold."""
    from paritysim import claims as cl

    claims, values = cl.load(reproduced / "fig2_13.claims.json")
    assert len(claims) == 7 and all(c.ok for c in claims), [(c.statement, c.computed) for c in claims if not c.ok]
    assert {r["k2"] for r in values["devices"]} == {1.0, 500.0}
