"""The one "did you mean" helper (`paritysim._errors.suggest`): a handful of close names, never the list."""

import re

import paritysim as ps
from paritysim._errors import close_names, suggest


def _paths() -> list[str]:
    return list(ps.spec_paths(ps.devices.load("sreetharan2012_3_3_parity"))["path"])


def test_a_typo_names_the_intended_path_first_and_lists_at_most_five():
    paths = _paths()
    assert len(paths) > 50
    text = suggest("drivetrain.balance_stifness", paths, listed_by="ps.spec_paths(spec)")
    assert text.startswith("a known name: did you mean `drivetrain.balance_spring`?")
    assert f"lists all {len(paths)}" in text
    assert text.count("`") <= 2 * 5 + 2  # at most five names quoted
    assert close_names("options.max_wall", paths)[0] == "options.max_wall_ms"
    assert len(close_names("stiffness", paths, limit=5)) == 5


def test_a_deprecated_name_finds_its_successor_by_a_shared_word():
    assert close_names("balance_stiffness", _paths())[0] == "drivetrain.balance_spring"


def test_nothing_close_lists_nothing_long():
    paths = _paths()
    text = suggest("zzz", paths)
    assert "none close to `zzz`" in text and text.count("`") <= 8
    assert suggest("qqq", ["lift", "drag"]) == "one of: `lift`, `drag`"
    # Read after "must be": it began "did you mean", so messages said "must be did you mean".
    assert suggest("lfit", ["lift", "drag"]) == "one of: `lift`, `drag`: did you mean `lift`?"


def test_every_name_taking_argument_shows_a_handful_not_the_list():
    spec = ps.devices.load("sreetharan2012_3_3_parity")
    cases = [
        (lambda: ps.sweep(spec, {"drivetrain.balance_sprng": [0.0, 1.0]}, progress=False), "drivetrain.balance_spring"),
        (lambda: spec.with_paths({"actuator.force_per_vol": 1.0}), "actuator.force_per_volt"),
        (lambda: ps.calibrate(spec, {"left_stroke_amplitude": 0.6}, {"actuator.force_per_vol": (0.5, 2.0)}), "actuator.force_per_volt"),
        (lambda: ps.flight.trim(ps.devices.load("sreetharan2012_3_4_parity"), knobs=["actuator.waveform.amplitude"]), "actuator.waveform.amplitude_v"),
    ]
    for call, meant in cases:
        try:
            call()
        except ps.InvalidParameterError as exc:
            text = str(exc)
        else:
            raise AssertionError(f"no error for {meant}")
        assert f"did you mean `{meant}`?" in text, text
        assert text.count("`") <= 2 * 6 + 4, text  # the field, the value, at most five names
        assert len(text) < 600, text


def _message(call) -> str:  # type: ignore[no-untyped-def]
    try:
        call()
    except ps.InvalidParameterError as exc:
        return str(exc)
    raise AssertionError("no InvalidParameterError")


def test_each_name_taking_argument_names_the_meant_name():
    """A typo in every argument that takes a path or a name finds what was meant, through the
    one ranking of the Rust core (`schema::close`), with a handful of names at most."""
    import polars as pl

    spec = ps.devices.load("sreetharan2012_3_3_parity")
    hmf = ps.devices.load("sreetharan2012_3_4_hmf")
    target = pl.DataFrame({"time_ms": [0.0, 1.0], "right_phii": [0.0, 0.1]})
    cases = {
        "simulate metrics": (lambda: ps.simulate(spec, metrics=["left_stroke_amplitud"]), "left_stroke_amplitude"),
        "simulate columns": (lambda: ps.simulate(spec, columns=["right_phii"]), "right_phi"),
        "sweep metrics": (lambda: ps.sweep(spec, {"actuator.frequency_hz": [100.0]}, metrics=["left_stroke_amplitud"], progress=False), "left_stroke_amplitude"),
        "sweep labels": (lambda: ps.sweep(spec, pl.DataFrame({"actuator.frequency_hz": [100.0], "case": ["a"]}), labels=["cas"], progress=False), "case"),
        "calibrate targets": (lambda: ps.calibrate(spec, {"left_stroke_amplitud": 0.6}, {"actuator.force_per_volt": (0.5, 2.0)}, max_nfev=1), "left_stroke_amplitude"),
        "calibrate trajectory": (lambda: ps.calibrate(spec, target, {"actuator.force_per_volt": (0.5, 2.0)}, max_nfev=1), "right_phi"),
        "trim equations": (lambda: ps.flight.trim(ps.devices.load("sreetharan2012_3_4_parity"), equations=["lfit", "pitch"]), "lift"),
        "continuation path": (lambda: ps.continuation(hmf, "actuator.waveform.frequency_h", 130.0), "actuator.waveform.frequency_hz"),
        "continuation setting": (lambda: ps.continuation(hmf, "actuator.waveform.frequency_hz", 130.0, max_stpe=1.0), "max_step"),
        "device name": (lambda: ps.devices.load("sreetharan2012_3_3_parit"), "sreetharan2012_3_3_parity"),
        "spec field": (lambda: spec.options.with_fields("options", max_cylces=5), "max_cycles"),
    }
    for case, (call, meant) in cases.items():
        text = _message(call)
        assert f"did you mean `{meant}`?" in text, (case, text)
        assert text.count("`") <= 2 * 6 + 4 and len(text) < 700, (case, text)


def test_a_nonsense_name_lists_no_hundred_paths():
    spec = ps.devices.load("sreetharan2012_3_3_parity")
    for call in (
        lambda: ps.sweep(spec, {"qqqqqqqq.zzzzzz": [1.0]}, progress=False),
        lambda: spec.with_paths({"qqqqqqqq.zzzzzz": 1.0}),
        lambda: ps.flight.trim(ps.devices.load("sreetharan2012_3_4_parity"), knobs=["qqqqqqqq.zzzzzz"]),
        lambda: ps.simulate(spec, metrics=["qqqqqqqq_zzzzzz"]),
    ):
        text = _message(call)
        assert "none close to `qqqqqqqq" in text, text
        assert text.count("`") <= 2 * 3 + 6 and len(text) < 400, text
        assert re.search(r"lists all \d+\)|\d+ names", text), text  # where the whole list is, not the list
