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
