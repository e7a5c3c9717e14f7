"""The named device library: every shipped device loads, simulates, matches its trial, and its
``cut_wings`` provenance flag agrees with what a cut-wing sweep does."""

from __future__ import annotations

import importlib
import math
import sys
from pathlib import Path

import pytest

import paritysim as ps

NAMES = ps.devices.list()


def test_the_linkage_variant_is_the_one_that_fails_on_cut_wings() -> None:
    assert [n for n in NAMES if not ps.devices.info(n).cut_wings] == ["sreetharan2012_3_3_parity_linkage"]


def test_every_thesis_section_has_devices() -> None:
    for prefix in ("sreetharan2012_3_3_parity", "sreetharan2012_3_3_hmf", "sreetharan2012_3_4_parity", "sreetharan2012_3_4_hmf", "sreetharan2012_2_5_", "sreetharan2012_2_6_"):
        assert any(n.startswith(prefix) for n in NAMES), prefix
    for trial in ("1cut", "2cut"):
        assert f"sreetharan2012_3_4_parity_{trial}" in NAMES


@pytest.mark.parametrize("name", NAMES)
def test_device_loads_simulates_and_has_provenance(name: str) -> None:
    spec = ps.devices.load(name)
    assert spec.name == name
    assert spec == ps.load_spec(ps.devices.path(name))  # a plain spec file
    info = ps.devices.info(name)
    assert info.stated and info.choices and info.section
    result = ps.simulate(spec.replace(options=spec.options.__class__(**{**spec.options.__dict__, "max_cycles": 40})))
    for wing in ("left", "right"):
        amplitude = result.metrics[f"{wing}_stroke_amplitude"]
        assert math.isfinite(amplitude) and 0.1 < amplitude < math.pi / 2, (wing, amplitude)  # flapping, not stalled or wild


def test_shipped_files_are_what_the_trials_build() -> None:
    """The TOMLs are generated from paritysim.trials; a drift between them fails here."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
    try:
        generate = importlib.import_module("generate_devices")
    finally:
        sys.path.pop(0)
    catalogue = generate.catalogue()
    assert sorted(catalogue) == NAMES
    for name, entry in catalogue.items():
        assert ps.devices.load(name).to_dict() == entry["spec"].to_dict(), name
        assert ps.devices.info(name).cut_wings == entry["cut_wings"], name


@pytest.mark.parametrize("name", NAMES)
def test_cut_wing_flag_matches_a_cut_wing_sweep(name: str) -> None:
    spec = ps.devices.load(name)
    with pytest.warns() if not ps.devices.info(name).cut_wings else _no_warning():
        df = ps.sweep(spec, {"wings.left.omega_ratio": [0.9, 0.6, 0.42]}, progress=False, options={"max_cycles": 120})
    # A cut-wing point that runs but needs more than max_cycles (the Dual PARITY at 0.42 from
    # rest) is "unconverged", not a failure of the device.
    survives = bool((df["status"] != "error").all())
    assert survives == ps.devices.info(name).cut_wings


class _no_warning:
    def __enter__(self) -> None:
        import warnings

        self._ctx = warnings.catch_warnings()
        self._ctx.__enter__()
        warnings.simplefilter("error", RuntimeWarning)
        warnings.filterwarnings("ignore", message=".*did not converge", category=RuntimeWarning)

    def __exit__(self, *exc: object) -> None:
        self._ctx.__exit__(*exc)


def test_unknown_device_names_the_shipped_ones() -> None:
    # A typo finds the device; a name close to none points to the list (not 17 names inline).
    with pytest.raises(ps.InvalidParameterError, match="sreetharan2012_3_3_parity"):
        ps.devices.load("sreetharan2012_3_3_parit")
    with pytest.raises(ps.InvalidParameterError, match=r"ps\.devices\.list\(\) lists all"):
        ps.devices.load("no_such_device")
