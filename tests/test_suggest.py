"""The one "did you mean" helper (`paritysim._errors.suggest`): a handful of close names, never the list."""

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
    assert suggest("lfit", ["lift", "drag"]).startswith("did you mean `lift`?")


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
