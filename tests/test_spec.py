"""The spec boundary: Python dataclasses generated from the Rust schema, round trips
Python <-> Rust <-> TOML, typed errors for unknown keys, the shipped JSON Schema."""

from __future__ import annotations

import dataclasses
import json
import math
import tomllib
from pathlib import Path
from typing import Any

import jsonschema
import pytest

import paritysim as ps
from paritysim import _core

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SCHEMA_FILE = Path(ps.__file__).with_name("spec.schema.json")


def _built_in_python() -> ps.Simulation:
    """A spec touching every kind of field, built from the Python classes."""
    wing = ps.Wing.from_moments(
        49.0,
        50.5,
        1.56,
        2.0,
        shoulder=ps.Shoulder(alpha2=2.0, alpha3=0.5),
        springs=ps.Springs(hinge=ps.Spring(stiffness=2.5, cubic=1.0), deviation=ps.Spring(stiffness=10.0)),
        aero=ps.Aero(kind="blade_element", omega1=46.8, omega2=3.0, omega3=12.0, omega4=9.0, rotational_damping=1.5),
        tunable_hinge=ps.TunableHinge(1.0, 0.5, 2.0),
    )
    return ps.Simulation(
        wings=(wing, wing),
        name="everything",
        configuration=ps.Configuration(name="drag_parity"),
        drivetrain=ps.Drivetrain.linear_differential(2.5, 2.5, arm_ratio=1.1, balance_spring=3.0),
        actuator=ps.Actuator(waveform=ps.Waveform(kind="sampled", times_ms=(0.0, 2.0, 5.0), voltages_v=(0.0, 90.0, -40.0), period_ms=9.0), dc_offset="ignore"),
        formulation="null_space",
        options=ps.Options(rtol=1e-7, max_cycles=40, perturbation={"target": "q2", "delta": 0.002, "phase": 0.25}),
    )


SPECS = [ps.load_spec(EXAMPLES / "drag_parity.toml"), ps.load_spec(EXAMPLES / "hmf.toml"), _built_in_python()]


@pytest.mark.parametrize("spec", SPECS, ids=["drag_parity", "hmf", "python"])
def test_specs_round_trip_python_rust_toml_unchanged(spec: ps.Simulation, tmp_path: Path) -> None:
    spec.validate()
    # Python -> Rust (canonical JSON) -> Python
    assert ps.Simulation.from_json(spec.to_json()) == spec
    canonical, notes = _core.spec_normalize(spec.to_json())
    assert notes == [] and _core.spec_normalize(canonical)[0] == canonical
    # -> TOML (written by Rust) -> Python, and TOML read by Python's tomllib agrees
    path = spec.save(tmp_path / "spec.toml")
    assert ps.load_spec(path) == spec
    assert ps.Simulation.from_dict(tomllib.loads(path.read_text())) == spec
    # the dict view is a copy: mutating it cannot change what the frozen spec simulates
    d = spec.to_dict()
    d["wings"][0]["inertia"][0][0] = -1.0
    assert ps.Simulation.from_json(spec.to_json()) == spec


def _schema_fields(name: str) -> list[str]:
    schema = json.loads(_core.spec_schema())
    d = schema if name == "Simulation" else schema["$defs"][name]
    if "oneOf" in d:
        names = ["kind"]
        for v in d["oneOf"]:
            names += [k for k in v["properties"] if k not in names]
        return names
    return list(d["properties"])


@pytest.mark.parametrize("cls", [ps.Simulation, ps.Wing, ps.Shoulder, ps.Spring, ps.Springs, ps.Aero, ps.TunableHinge, ps.Drivetrain, ps.Waveform, ps.Actuator, ps.Configuration, ps.Options])
def test_dataclass_fields_and_defaults_are_the_rust_ones(cls: type) -> None:
    assert sorted(f.name for f in dataclasses.fields(cls)) == sorted(_schema_fields(cls.__name__))
    if cls in (ps.Simulation, ps.Wing, ps.TunableHinge):
        return  # required fields: no all-default instance
    default = cls()
    # the defaults Rust fills in for an empty table are the Python defaults
    via_rust = ps.Simulation.from_dict({"wings": [{"inertia": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}], "configuration": {}, **_placement(cls, {})})
    assert _extract(cls, via_rust) == default


def _placement(cls: type, table: dict[str, Any]) -> dict[str, Any]:
    kinds = {ps.Drivetrain: "linkage_differential", ps.Aero: "stroke_drag", ps.Waveform: "sine"}
    if cls in kinds:
        table = {"kind": kinds[cls], **table}
    return {
        ps.Options: {"options": table},
        ps.Configuration: {},
        ps.Drivetrain: {"drivetrain": table},
        ps.Actuator: {"drivetrain": {"kind": "hmf_four_bar"}, "actuator": table},
        ps.Waveform: {"drivetrain": {"kind": "hmf_four_bar"}, "actuator": {"waveform": table}},
    }.get(cls, {})


def _extract(cls: type, spec: ps.Simulation) -> Any:
    w = spec.wings[0]
    return {
        ps.Options: spec.options,
        ps.Configuration: ps.Configuration(),
        ps.Drivetrain: spec.drivetrain,
        ps.Actuator: spec.actuator,
        ps.Waveform: spec.actuator.waveform if spec.actuator else None,
        ps.Shoulder: w.shoulder,
        ps.Springs: w.springs,
        ps.Spring: w.springs.hinge,
        ps.Aero: ps.Aero(),
    }[cls]


def test_the_thesis_actuator_constants_are_written_once() -> None:
    a = ps.Actuator()
    assert (a.stiffness, a.force_per_volt) == (467.0, 1.2)
    assert ps.Options().max_cycles == 300 and ps.Drivetrain().kind == "linkage_differential"


def test_shipped_schema_is_current_and_validates_every_example() -> None:
    shipped = json.loads(SCHEMA_FILE.read_text())
    assert shipped == json.loads(_core.spec_schema()), "run PARITYSIM_BLESS=1 cargo test -p paritysim-spec"
    validator = jsonschema.Draft202012Validator(shipped)
    checked = 0
    for path in sorted(EXAMPLES.glob("*.toml")):
        data = tomllib.loads(path.read_text())
        if "spec" in data:  # a sweep or continuation study: its spec (file or named device)
            source = ps.devices.path(data["spec"]) if data["spec"] in ps.devices.list() else path.parent / data["spec"]
            validator.validate(tomllib.loads(Path(source).read_text()))
            options = jsonschema.Draft202012Validator({"$defs": shipped["$defs"], "$ref": "#/$defs/Options"})
            options.validate(data.get("options", {}))
        else:
            validator.validate(data)
        checked += 1
    assert checked == len(list(EXAMPLES.glob("*.toml"))) >= 3
    # the schema carries the ranges: an editor flags an out-of-range value too
    bad = tomllib.loads((EXAMPLES / "hmf.toml").read_text())
    bad["drivetrain"]["crank_mm"] = -1.0
    assert not validator.is_valid(bad)


def test_unknown_keys_name_the_key_and_the_nearest_valid_one() -> None:
    good = SPECS[0].to_dict()
    with pytest.raises(ps.InvalidParameterError, match="did you mean `drivetrain`") as e:
        ps.Simulation.from_dict({**good, "drivetrian": good["drivetrain"]})
    assert e.value.field == "drivetrian"
    with pytest.raises(ps.InvalidParameterError, match="did you mean `balance_spring`") as e:
        ps.Drivetrain(kind="linkage_differential", balance_sprin=1.0)
    assert e.value.field == "Drivetrain.balance_sprin"
    with pytest.raises(ps.InvalidParameterError, match="did you mean `max_cycles`") as e:
        ps.simulate(SPECS[0], max_cycle=3)
    assert e.value.field == "options.max_cycle"
    with pytest.raises(ps.InvalidParameterError, match="did you mean `steady_tol`"):
        ps.sweep(SPECS[0], {"actuator.frequency_hz": [100.0]}, options={"steady_tl": 1e-6}, progress=False)
    with pytest.raises(ps.InvalidParameterError, match=r"did you mean `drivetrain\.balance_spring`"):
        ps.sweep(SPECS[0], {"drivetrain.balance_sprin": [1.0]}, progress=False)
    with pytest.raises(ps.InvalidParameterError, match="did you mean `left_stroke_amplitude`") as e:
        ps.calibrate(SPECS[0], {"left_stroke_amplitud": 0.5}, {"actuator.force_per_volt": (1.0, 1.4)}, max_nfev=1)
    assert e.value.field == "targets.left_stroke_amplitud"


def test_every_invalid_field_is_reported_at_once() -> None:
    d = SPECS[1].to_dict()
    d["drivetrain"]["rod_mm"] = 0.0
    d["options"]["max_cycles"] = True  # a bool is not a count
    d["wings"][1]["aero"]["omega1"] = math.nan
    with pytest.raises(ps.InvalidParameterError) as e:
        ps.Simulation.from_dict(d)
    problems = {p[0]: p[2] for p in e.value.problems}
    assert sorted(problems) == ["drivetrain.rod_mm", "options.max_cycles", "wings[1].aero.omega1"]
    assert "[1e-6, 100] mm" in problems["drivetrain.rod_mm"] and "integer" in problems["options.max_cycles"]
    assert e.value.field in problems


def test_an_empty_configuration_name_is_an_error_not_no_constraints() -> None:
    with pytest.raises(ps.InvalidParameterError, match="configuration.name"):
        SPECS[0].replace(configuration=ps.Configuration(name="")).validate()


def test_spec_paths_list_units_and_ranges_and_with_paths_uses_them() -> None:
    paths = ps.spec_paths(SPECS[0])
    row = paths.filter(paths["path"] == "drivetrain.balance_spring").row(0, named=True)
    assert row["unit"] == "mN mm/rad" and "[0, 10000]" in row["allowed"] and json.loads(row["value"]) == 1.0
    assert "wings[1].springs.hinge.stiffness" in paths["path"].to_list()
    changed = SPECS[0].with_paths({"drivetrain.balance_spring": 2.0, "wings.left.omega_ratio": 0.5})
    assert changed.drivetrain.balance_spring == 2.0
    assert changed.wings[0].aero.omega1 == 0.5 * SPECS[0].wings[0].aero.omega1
    assert changed.wings[1] == SPECS[0].wings[1]


def test_the_whippletree_preload_is_a_field_of_both_differentials() -> None:
    linear = ps.Drivetrain.linear_differential(2.5, 2.5, balance_spring=40.0, balance_preload=2.0)
    linkage = ps.Drivetrain.linkage_differential(balance_spring=400.0, balance_preload=-1.5)
    assert (linear.balance_preload, linkage.balance_preload) == (2.0, -1.5)
    assert ps.Drivetrain.linear_differential(2.5, 2.5).balance_preload == 0.0
    paths = ps.spec_paths(SPECS[0])
    row = paths.filter(paths["path"] == "drivetrain.balance_preload").row(0, named=True)
    assert row["unit"] == "mN mm" and "[-100, 100]" in row["allowed"]
    with pytest.raises(ps.InvalidParameterError, match=r"drivetrain\.balance_preload"):
        SPECS[0].with_paths({"drivetrain.balance_preload": 500.0})


def test_a_preload_shifts_the_strokes_by_the_closed_form() -> None:
    # §3.3 Control trial (equal wings, eq. 2.15): the whippletree holds q2 = P / K2, so the
    # mean strokes are ±T L P / K2 (crates/spec/tests/preload.rs derives it).
    spec = ps.devices.load("sreetharan2012_3_3_parity").with_paths({"drivetrain.balance_spring": 40.0, "drivetrain.balance_preload": 2.0})
    r = ps.simulate(spec, metrics=["left_stroke_mean", "right_stroke_mean", "q2_amplitude"])
    shift = spec.drivetrain.transmission_ratio * spec.drivetrain.arm_length_mm * 2.0 / 40.0
    assert r.metrics["left_stroke_mean"] == pytest.approx(shift, abs=1e-7)
    assert r.metrics["right_stroke_mean"] == pytest.approx(-shift, abs=1e-7)
    assert r.metrics["q2_amplitude"] < 1e-7


def test_old_spellings_still_load_with_a_deprecation_warning() -> None:
    with pytest.warns(DeprecationWarning, match="balance_spring"):
        old = ps.Simulation.from_dict({**SPECS[0].to_dict(), "drivetrain": {"kind": "linkage_differential", "balance_stiffness": 1.0}})
    assert old.drivetrain == SPECS[0].drivetrain
    with pytest.warns(DeprecationWarning, match="Springs"):
        wing = ps.Wing(inertia=SPECS[0].wings[0].inertia, springs=tuple(ps.Spring(stiffness=float(j == 5)) for j in range(6)))
    assert wing.springs == ps.Springs(hinge=ps.Spring(stiffness=1.0))
    with pytest.warns(DeprecationWarning, match="stiffness_at_zero"):
        d = _built_in_python().to_dict()
        d["wings"][0]["tunable_hinge"] = {"k0": 1.0, "k1": 0.5, "k2": 2.0}
        assert ps.Simulation.from_dict(d) == _built_in_python()


def test_spec_json_equals_the_asdict_formulation() -> None:
    """``Simulation.to_json`` walks the fields in one pass; it must write exactly what
    ``json.dumps(_plain(_strip_none(dataclasses.asdict(spec))))`` writes (the definition it
    replaced), for every shipped device and for Python-built values: numpy scalars, a NaN
    (written as text so Rust can name the field), nested tuples."""
    import numpy as np

    from paritysim import spec as spec_module

    def by_asdict(s: ps.Simulation) -> str:
        return json.dumps(spec_module._plain(spec_module._strip_none(dataclasses.asdict(s))), allow_nan=False)

    specs = [ps.devices.load(name) for name in ps.devices.list()]
    base = specs[0]
    specs.append(base.replace(options=dataclasses.replace(base.options, rtol=np.float64(1e-7), max_cycles=np.int64(7), steady_tol=float("nan"))))
    for s in specs:
        assert s.to_json() == by_asdict(s)
    assert '"steady_tol": "nan"' in specs[-1].to_json()


def test_replace_builds_a_section_given_as_a_mapping_and_keeps_specs_hashable() -> None:
    # A dict stayed a dict: validate() passed and ps.simulate raised AttributeError; a dict
    # waveform or a list of wings made the spec unhashable.
    spec = ps.devices.load("sreetharan2012_3_3_parity")
    tight = spec.replace(options={"rtol": 1e-9})
    assert isinstance(tight.options, ps.spec.Options) and tight.options.rtol == 1e-9
    assert tight.options.max_cycles == ps.spec.Options().max_cycles  # the others at their defaults
    assert ps.simulate(tight, metrics=["left_stroke_amplitude"], progress=False).converged
    waved = spec.replace(actuator=spec.actuator.replace(waveform={"kind": "sine", "amplitude_v": 90.0, "frequency_hz": 110.0}))
    assert waved == ps.Simulation.from_dict(waved.to_dict()) and isinstance(hash(waved), int)
    assert hash(spec.replace(wings=list(spec.wings))) == hash(spec)
    with pytest.raises(ps.InvalidParameterError, match="rtol") as info:
        spec.replace(options={"rtoll": 1e-9})
    assert info.value.field == "Options.rtoll"


def test_drivetrain_constructors_name_a_misspelt_field() -> None:
    # A bare TypeError from the **deprecated catch-all.
    with pytest.raises(ps.InvalidParameterError, match="did you mean `arm_ratio`") as info:
        ps.spec.Drivetrain.linear_differential(3.0, 2.5, arm_ratioo=1.0)
    assert info.value.field == "Drivetrain.arm_ratioo"


def test_wing_terms_names_its_index() -> None:
    device = ps.devices.load("sreetharan2012_3_4_parity")
    with pytest.raises(ps.InvalidParameterError, match=r"\[0, 1\]") as info:
        ps.dynamics.wing_terms(device, [0.1, 0.0, 0.2], [0.1, 0.0, 0.3], index=2)
    assert info.value.field == "index"


def test_every_omega_of_the_blade_element_is_in_mg_mm2() -> None:
    # Ω2 = ½ρ∬|x|³dA (mg/mm³ · mm⁵) was listed as mg·mm; M = Ω2 C ω|ω| is a torque in mN·mm only
    # in mg·mm² (docs/concepts.md's units table).
    table = ps.spec_paths("sreetharan2012_3_4_parity")
    units = dict(zip(table["path"], table["unit"], strict=True))
    assert [units[f"wings[0].aero.omega{k}"] for k in range(1, 5)] == ["mg mm^2"] * 4
