"""Floquet results name the mode behind each multiplier and print in one line (issue 33)."""

from __future__ import annotations

import numpy as np
import pytest

import paritysim as ps


def test_without_a_balance_spring_the_whippletree_angle_is_the_neutral_mode():
    result = ps.stability.floquet(ps.devices.load("sreetharan2012_3_3_parity"))  # K2 = 0
    assert result.stability == "marginal"
    assert result.neutral_modes == ["q2"] and result.dominant_mode == "q2"
    frame = result.frame
    assert frame["modulus"].to_numpy() == pytest.approx(np.sort(np.abs(result.multipliers))[::-1], abs=1e-9)
    assert frame["mode_share"][0] > 0.99  # a pure whippletree rotation
    text = repr(result)
    assert "\n" not in text and len(text) < 240
    assert text.startswith("FloquetResult(marginal: |ρ|max = 1 (q2), neutral: q2")


def test_the_linkage_whippletree_is_the_growing_mode():
    result = ps.stability.floquet(ps.devices.load("sreetharan2012_3_3_parity_linkage"))
    frame = result.frame
    assert frame["kind"].to_list().count("growing") == 1 and frame["kind"][0] == "growing"
    assert frame["mode"][0] == "q2" and result.neutral_modes == []
    # the growing multiplier is the whippletree block's (docs/findings.md §3: 1.78 at K2 = 1)
    assert frame["modulus"][0] == pytest.approx(abs(result.whippletree_multipliers[0]), rel=1e-9)
    assert frame["modulus"][0] == pytest.approx(1.78, abs=0.01)


def test_a_rotating_wing_parity_is_read_in_drivetrain_and_hinge_coordinates():
    """§3.4: the null-space coordinates are the wing angles; the strokes read as q1, q2."""
    result = ps.stability.floquet(ps.devices.load("sreetharan2012_3_4_parity"))
    names = ["q1", "q2", "left_psi", "right_psi"]
    assert result.coordinates == names + [f"{n}_dot" for n in names]
    # K2 = 0: the whippletree is the neutral mode, and its block carries the multiplier 1
    assert result.neutral_modes == ["q2"]
    assert result.whippletree_multipliers is not None
    assert abs(result.whippletree_multipliers[0]) == pytest.approx(1.0, abs=1e-6)
    # the change of coordinates keeps the multipliers
    assert np.sort(np.abs(np.linalg.eigvals(result.monodromy))) == pytest.approx(np.sort(np.abs(result.multipliers)), abs=1e-9)
    hmf = ps.stability.floquet(ps.devices.load("sreetharan2012_3_4_hmf"))
    assert "q2" not in hmf.coordinates and hmf.whippletree_multipliers is None  # no whippletree
    assert "left_psi" in hmf.coordinates
