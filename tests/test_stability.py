"""paritysim.stability: §2.6 closed forms (eqs. 2.45, 2.50, 2.54 with ERRATA 7-10), Fig. 2.13,
Brockett's criterion, eq. 2.59, and the Floquet analysis of the full nonlinear model."""

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
from paritysim.cli import main
from paritysim.trials import REGISTRY
from paritysim.trials.section_2_6 import drag_parity_spec, hmf_spec, report_section

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


# ------------------------------------------------------------------ eq. 2.25


def test_det_m_is_exp_minus_two_beta0_on_a_random_grid() -> None:
    """Eq. 2.45 (Liouville) for every κ and t0, negative values included."""
    rng = np.random.default_rng(1)
    for beta0, kappa, t0 in zip(rng.uniform(-2, 6, 200), rng.uniform(-2, 12, 200), rng.uniform(-4, 4, 200), strict=True):
        m = st.hill_monodromy(beta0, kappa, t0)
        want = math.exp(-2 * beta0)
        scale = max(want, abs(m[0, 0] * m[1, 1]) + abs(m[0, 1] * m[1, 0]))
        assert abs(np.linalg.det(m) - want) / scale < 1e-9, (beta0, kappa, t0)


@pytest.mark.parametrize("beta0", [-1.0, 0.0, 0.4, 1.3, 3.0, 6.0])
def test_kappa_zero_monodromy_is_eq_2_50(beta0: float) -> None:
    m = st.hill_monodromy(beta0, 0.0)  # t0 = -pi/2
    want = np.array([[1.0, math.pi * math.exp(-beta0) * i0(beta0)], [0.0, math.exp(-2 * beta0)]])
    np.testing.assert_allclose(m, want, rtol=1e-9, atol=1e-12)
    f = st.hill_floquet(beta0, 0.0)
    np.testing.assert_allclose(sorted(np.abs(f["multipliers"])), sorted([1.0, math.exp(-2 * beta0)]), rtol=1e-9)


@pytest.mark.parametrize("beta0", [0.3, 1.0, 2.2])
def test_eq_2_54_limit_has_the_factor_pi(beta0: float) -> None:
    """ERRATA 10: lim x = x0 + xdot0 · π I0(β0) e^{-β0}/(1 - e^{-2β0})."""
    far = st.hill_solution(beta0, 0.0, [-math.pi / 2 + 60 * math.pi])[0]
    limit = math.pi * i0(beta0) * math.exp(-beta0) / (1 - math.exp(-2 * beta0))
    assert far[0, 1] == pytest.approx(limit, rel=1e-9)
    assert far[0, 1] / (limit / math.pi) == pytest.approx(math.pi, rel=1e-9)  # the printed form lacks π
    assert far[1, 1] == pytest.approx(0.0, abs=1e-9)


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


def test_stability_chart_frame() -> None:
    beta0, kappa = np.array([-0.5, 0.0, 1.0, 4.0]), np.array([-0.5, 0.1, 1.0, 3.0, 3.5])
    df = st.stability_chart(beta0, kappa)
    assert df.columns == ["beta0", "kappa", "a", "b", "spectral_radius", "region", "stable", "region_name", "brockett_bounded"]
    assert df.height == 20 and df["region"].dtype == pl.Int8
    assert df["beta0"].to_list() == np.repeat(beta0, 5).tolist() and df["kappa"].to_list() == np.tile(kappa, 4).tolist()
    for row in df.iter_rows(named=True):
        f = st.hill_floquet(row["beta0"], row["kappa"])
        assert (row["a"], row["b"], row["region"]) == (f["a"], f["b"], f["region"])
        assert row["region_name"] == st.REGIONS[row["region"]]
        if row["beta0"] < 0 or row["kappa"] < 0:
            assert not row["stable"]  # eq. 2.51
        if row["brockett_bounded"]:
            assert row["spectral_radius"] <= 1 + 1e-9  # Brockett's guarantee holds
    np.testing.assert_allclose(df["b"], np.exp(-2 * df["beta0"].to_numpy()), rtol=1e-9)


def test_brockett_closed_forms() -> None:
    s = math.sqrt(0.75)  # δ = 1/2: asin s = π/3
    b = st.brockett(0.5, 2.4, 1.0)
    assert b["bounded"] and b["n"] == 1
    assert b["interval"][1] == pytest.approx(2 * math.pi / (3 * s), rel=1e-12)
    assert st.brockett(0.5, 4 * math.pi / (3 * s), 1.0)["bounded"]
    assert not st.brockett(0.5, 3.5, 1.0)["bounded"]
    assert st.brockett(0.0, 123.4)["bounded"]
    assert not st.brockett(0.0, 1.0, -1.0)["bounded"]
    assert st.brockett_hill(0.5, 1.0)["delta"] == pytest.approx(0.25)


def test_hill_parameters_use_errata_7() -> None:
    p = st.hill_parameters(inertia=29.0, drag=31.3, transmission_ratio=2.5, arm_length_mm=2.5, k1=467.0, k2=20.0, stroke_amplitude=0.5, frequency_hz=110.0)
    w0 = 2 * math.pi * 0.110
    assert p["beta0"] == pytest.approx(2 * 31.3 * 0.5 / 29.0, rel=1e-14)  # 2ΩΦ/I = 2ΩTA/I
    assert p["kappa1"] == pytest.approx(467.0 / (2 * 29.0 * 2.5**2 * w0**2), rel=1e-14)
    assert p["kappa2"] == pytest.approx(20.0 / (2 * 29.0 * 2.5**2 * 2.5**2 * w0**2), rel=1e-14)
    assert p["beta_star"] == pytest.approx(2 / math.pi * p["beta0"] * w0, rel=1e-14)


def test_eq_2_59_closed_forms() -> None:
    h = st.lti_transfer(2.0, 0.3, [0.0, math.sqrt(0.3) / (2 * math.pi * 1e-3)])
    assert h[0] == 1.0
    assert abs(h[1]) == pytest.approx(math.sqrt(0.3) / 2.0, rel=1e-12)
    assert np.angle(h[1]) == pytest.approx(-math.pi / 2, abs=1e-12)


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
    assert frame.columns == ["re", "im", "modulus", "exponent_per_ms"] and frame.height == 4
    # Liouville for the whippletree block of a symmetric orbit: det = e^{-4 β0} per drive period
    # (two periods of eq. 2.25) with β0 = 2ΩΦ/I (ERRATA 7). With eq. 2.16 drag at 50 V the
    # determinant (~1e-2) is well above the finite-difference resolution (~1e-7).
    spec = drag_parity_spec(200.0, coefficient=1.0, volts=50.0)
    beta0 = st.linearise(spec)["hill"]["beta0"]
    det = np.prod(st.floquet(spec).whippletree_multipliers).real
    assert det == pytest.approx(math.exp(-4 * beta0), rel=1e-3)


def test_linear_map_with_k2_zero_has_a_unit_multiplier() -> None:
    f = st.floquet(drag_parity_spec(0.0, linear=True, coefficient=1.0, volts=50.0))
    w = f.whippletree_multipliers
    assert abs(w[0] - 1.0) < 1e-6
    beta0 = st.linearise(drag_parity_spec(0.0, linear=True, coefficient=1.0, volts=50.0))["hill"]["beta0"]
    assert w[1].real == pytest.approx(math.exp(-4 * beta0), rel=1e-3)  # eq. 2.50 over two periods
    assert f.stability == "marginal"


def test_hmf_is_stable() -> None:
    f = st.floquet(hmf_spec())
    assert f.asymptotically_stable and f.whippletree_multipliers is None and len(f.multipliers) == 2


def test_k2_sweep_frame() -> None:
    df = st.k2_sweep(drag_parity_spec(1.0), [1.0, 100.0, 500.0, 1000.0])
    assert df.columns == ["k2", "spectral_radius", "whippletree_radius", "max_exponent_per_ms", "slowest_decay_ms", "stability", "moduli"]
    assert df["stability"].to_list()[0] == "unstable" and df["stability"].to_list()[-1] == "asymptotic"
    assert (df["whippletree_radius"].diff().drop_nulls() < 0).all()
    single = st.floquet(drag_parity_spec(100.0))
    assert df["spectral_radius"][1] == single.spectral_radius


def test_lti_and_nonlinear_disturbance_responses_agree_at_low_amplitude() -> None:
    """Eq. 2.15 with eq. 2.16 drag: eq. 2.59 replaces the damping 2Ω|φ̇(t)|/I by its cycle
    mean, which neglects the modulation at twice the flapping frequency. Stated tolerance: 10 %
    in gain, 0.1 rad in phase."""
    spec = drag_parity_spec(200.0, linear=True, coefficient=1.0, volts=50.0)
    df = st.disturbance_response(spec, [30.0, 100.0, 300.0], amplitude=0.1)
    assert (df["drift"] < 1e-4).all()
    np.testing.assert_allclose(df["gain"], df["lti_gain"], rtol=0.1)
    np.testing.assert_allclose(df["phase_rad"], df["lti_phase_rad"], atol=0.1)
    larger = st.disturbance_response(spec, [100.0], amplitude=0.4)
    assert larger["gain"][0] == pytest.approx(df["gain"][1], rel=1e-3)


def test_hmf_transmits_roll_rigidly() -> None:
    """One rigid drivetrain: the roll torque on the wings reaches the body unattenuated."""
    df = st.disturbance_response(hmf_spec(), [300.0], amplitude=0.5)
    assert abs(df["gain"][0] - 1.0) < 1e-6 and abs(df["phase_rad"][0]) < 1e-6
    assert df["lti_gain"].null_count() == 1


# ------------------------------------------------------------------ CLI and report


def test_cli_trials_write_parquet_csv_png(tmp_path: Path) -> None:
    for name in ("fig2.13", "sec2.7", "floquet"):
        assert name in REGISTRY
    written = REGISTRY["floquet"](tmp_path)
    stems = {p.name for p in written}
    assert {"floquet.parquet", "floquet.csv", "floquet.png"} <= stems
    df = pl.read_parquet(tmp_path / "floquet.parquet")
    assert set(df["drivetrain"].unique()) == {"linkage (§3.3)", "eq. 2.15"}
    assert (tmp_path / "floquet.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["reproduce", "fig2.13", "sec2.7", "--out", str(tmp_path), "--quiet"]) == 0
    for stem in ("fig2_13", "sec2_7"):
        for ext in ("parquet", "csv", "png"):
            assert (tmp_path / f"{stem}.{ext}").stat().st_size > 1000
    assert pl.read_parquet(tmp_path / "fig2_13.parquet").height == 40_000


def test_report_section_lists_equations_and_errata() -> None:
    md = report_section()
    for token in ("2.45", "2.50", "2.52", "2.53", "2.54", "2.27", "Fig. 2.13", "2.57", "2.59", "ERRATA 7", "ERRATA 8", "ERRATA 9", "ERRATA 10", "300 Hz"):
        assert token in md, token
