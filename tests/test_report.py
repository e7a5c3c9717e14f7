"""The reproduction report: computed verdicts, outputs of the one ``reproduce --all`` run
(``reproduced`` fixture, conftest.py), and docs/errata.md as the target of every citation."""

from __future__ import annotations

import ast
import json
import math
import re
from pathlib import Path

import polars as pl
import pytest

from paritysim import InvalidParameterError
from paritysim import claims as cl
from paritysim.claims import Claim
from paritysim.trials import REGISTRY
from paritysim.trials import section_3_3 as s33

ROOT = Path(__file__).resolve().parents[1]
TRIALS_DIR = ROOT / "python" / "paritysim" / "trials"
ERRATA = ROOT / "docs" / "errata.md"
VERDICT_WORDS = re.compile(r"\b(" + "|".join(map(re.escape, cl.VERDICTS.values())) + r"|consistent|inconsistent|agrees|disagrees)\b", re.IGNORECASE)


# ------------------------------------------------------------------ the claims layer (fast)


def _strings(tree: ast.AST) -> list[tuple[int, str]]:
    """Every string constant of a module, f-string parts included, with its line."""
    return [(node.lineno, node.value) for node in ast.walk(tree) if isinstance(node, ast.Constant) and isinstance(node.value, str)]


def test_no_trial_writes_a_verdict_by_hand() -> None:
    """Verdict words come from :data:`paritysim.claims.VERDICTS` only: no string literal in
    ``paritysim/trials`` (docstrings and f-string fragments included) spells one out."""
    offenders = []
    files = sorted(TRIALS_DIR.glob("*.py"))
    assert len(files) >= 7
    for path in files:
        for line, text in _strings(ast.parse(path.read_text(), str(path))):
            if VERDICT_WORDS.search(text):
                offenders.append(f"{path.name}:{line}: {text[:60]!r}")
    assert not offenders, offenders


def test_the_scan_catches_a_hand_written_verdict() -> None:
    """The check above can fail: a typed verdict in an f-string is found."""
    tree = ast.parse('x = 1\nrow = f"| {x} | matches |"\n')
    assert any(VERDICT_WORDS.search(s) for _, s in _strings(tree))


def test_claim_verdicts_follow_from_their_criteria() -> None:
    assert Claim.near("a", 1.04, 1.0, 0.05).verdict == cl.VERDICTS[True]
    assert Claim.near("a", 1.06, 1.0, 0.05).verdict == cl.VERDICTS[False]
    assert Claim.near("a", 0.0031, 0.003, 0.5, rel=True).ok and not Claim.near("a", 0.0014, 0.003, 0.5, rel=True).ok
    assert not Claim.near("a", math.nan, 1.0, 1e9).ok  # NaN never matches
    assert Claim.between("b", 2.9, 0.3, 3.0, thesis="~1").ok and not Claim.between("b", 3.1, 0.3, 3.0, thesis="~1").ok
    assert not Claim.all_between("c", {"x": 1.0, "y": 0.1}, 0.3, 3.0, thesis="~1").ok
    assert not Claim.all_between("c", {}, 0.3, 3.0, thesis="~1").ok
    assert Claim.holds("d", False, computed="x", criterion="y").verdict == cl.VERDICTS[False]
    assert Claim.given("e", computed="60°", note="pinned").verdict == cl.VERDICTS[None]


def test_claims_round_trip_through_json(tmp_path: Path) -> None:
    claims = [Claim.near("a | b", 1.5, 1.0, 0.1, unit="ms"), Claim.between("c", math.nan, 0.0, 1.0, thesis="t")]
    claims_back, values = cl.load(cl.save(tmp_path / "x.claims.json", claims, {"k": [1, 2]}))
    assert values == {"k": [1, 2]}
    assert [c.to_dict() for c in claims_back] == [c.to_dict() for c in claims]
    assert math.isnan(claims_back[1].value) and claims_back[1].ok is False
    table = cl.render(claims)
    assert "a \\| b" in table and table.count("\n") == 3  # header, rule, two rows


# ------------------------------------------------------------------ docs/errata.md (fast)


def _anchors() -> set[str]:
    return set(re.findall(r'<a id="([^"]+)"></a>', ERRATA.read_text()))


def test_errata_doc_has_every_thesis_item_and_cites_existing_tests() -> None:
    anchors = _anchors()
    assert {str(n) for n in range(1, 15)} <= anchors
    cited = re.findall(r"`((?:crates|tests)/[\w/.-]+\.(?:rs|py))::(\w+)`", ERRATA.read_text())
    assert len(cited) >= 25
    missing = []
    for file, name in cited:
        source = (ROOT / file).read_text() if (ROOT / file).exists() else ""
        if not re.search(rf"\b(fn|def) {name}\b", source):
            missing.append(f"{file}::{name}")
    assert not missing, missing


def test_code_cites_errata_by_their_place_in_the_repository() -> None:
    """Comments cite ``docs/errata.md#N`` (an anchor that exists), never a bare "ERRATA N"."""
    anchors = _anchors()
    bare, dangling = [], []
    for path in [*ROOT.glob("crates/**/*.rs"), *ROOT.glob("python/**/*.py"), *ROOT.glob("examples/*.toml")]:
        text = path.read_text()
        for m in re.finditer(r"ERRATA\s+(item|items|\d)", text):
            bare.append(f"{path.relative_to(ROOT)}:{text[: m.start()].count(chr(10)) + 1}")
        for m in re.finditer(r"docs/errata\.md#(\w+)", text):
            if m.group(1) not in anchors:
                dangling.append(f"{path.relative_to(ROOT)}: #{m.group(1)}")
    assert not bare, bare
    assert not dangling, dangling


# ------------------------------------------------------------------ the report (one reproduce --all)

ROW = re.compile(r"^\| (?P<statement>[^|]*(?:\\\|[^|]*)*) \| (?P<thesis>.*?) \| (?P<computed>.*?) \| (?P<criterion>.*?) \| \*\*(?P<verdict>\w+)\*\* \|")


def _rows(report: str) -> list[dict[str, str]]:
    return [m.groupdict() for line in report.splitlines() if (m := ROW.match(line))]


@pytest.mark.slow
def test_every_rendered_verdict_follows_from_its_stated_tolerance(reproduced: Path) -> None:
    """For every tolerance claim in report.md, |computed − thesis| ≤ tolerance ⇔ the verdict."""
    rows = _rows((reproduced / "report.md").read_text())
    checked = 0
    for r in rows:
        tol = re.fullmatch(r"\\\|Δ\\\| ≤ ([-+0-9.e]+)(·\\\|thesis\\\|)?(?: .*)?", r["criterion"])
        delta = re.search(r"\(Δ = ([-+0-9.e]+)\)", r["computed"])
        if not (tol and delta):
            continue
        bound = float(tol.group(1)) * (abs(float(r["thesis"].split()[0])) if tol.group(2) else 1.0)
        text = delta.group(1)
        slack = 0.5 * 10.0 ** -len(text.split(".")[1]) if "." in text and "e" not in text else 1e-12
        if abs(abs(float(text)) - bound) <= slack:
            continue  # within the displayed precision of the bound
        assert r["verdict"] == cl.VERDICTS[abs(float(text)) <= bound], r
        checked += 1
    assert checked >= 40


@pytest.mark.slow
def test_report_lists_every_table_3_2_cell_with_the_trial_values(reproduced: Path) -> None:
    """Each printed cell appears once, with the value the table3.2 trial wrote (reused, not
    recomputed) and the thesis value quoted."""
    report = (reproduced / "report.md").read_text()
    table = pl.read_csv(reproduced / "table3_2.csv")
    assert table.columns == s33.TABLE_COLUMNS and table.height == 6
    rows = {r["statement"]: r for r in _rows(report)}
    for row in table.iter_rows(named=True):
        for key in s33.QUANTITIES:
            r = rows[f"Table 3.2 {row['drivetrain']} {row['trial']} {key}"]
            assert float(r["computed"].split()[0]) == pytest.approx(row[key], abs=5e-4)
            assert float(r["thesis"].split()[0]) == s33.THESIS_TABLE_3_2[(row["drivetrain"], row["trial"])][key]


@pytest.mark.slow
def test_table_3_2_hmf_imbalances_match_the_thesis(reproduced: Path) -> None:
    """A 1-DOF drivetrain gives imbalance 1 − Ω^L/Ω^R; with the ratios of docs/errata.md#11
    (0.599, 0.420, not 18.8/31.3) that is the printed 40.1 % and 58.0 %."""
    claims, _ = cl.load(reproduced / "table3_2.claims.json")
    hmf_pct = [c for c in claims if " HMF " in c.statement and c.statement.endswith("_pct")]
    assert len(hmf_pct) == 6 and all(c.ok for c in hmf_pct), [c.computed for c in hmf_pct]


@pytest.mark.slow
def test_reconciliation_agrees_with_the_claims(reproduced: Path) -> None:
    """The ERRATA 13 paragraph states, for the stated and the fitted set, the same verdicts as
    the Fig. 3.4 and calibration claims, and the recovery ranges from the same numbers."""
    report = (reproduced / "report.md").read_text()
    stated, fig34 = cl.load(reproduced / "fig3_4.claims.json")
    fitted, cal = cl.load(reproduced / "calibration3_2.claims.json")
    stated_line = next(line for line in report.splitlines() if line.startswith("- Stated parameters"))
    fitted_line = next(line for line in report.splitlines() if line.startswith("- Fitted to Table 3.2"))
    assert stated_line.endswith(f"**{stated[0].verdict}** ~1 ms.")
    recovery_claim = next(c for c in fitted if c.statement.startswith("Fig. 3.4: the kick decays"))
    assert fitted_line.endswith(f"**{recovery_claim.verdict}** ~1 ms.")
    taus = [r["time_constant_ms"] for r in fig34["recovery"]]
    assert f"{min(taus):.2f}-{max(taus):.2f} ms" in stated_line
    fit_taus = [r["time_constant_ms"] for r in cal["recovery"]]
    assert f"{min(fit_taus):.2f}-{max(fit_taus):.2f} ms" in fitted_line
    # physics: the fitted (lighter) wing recovers faster, and each set's ordering follows drag:
    # the Control trial (most drag) recovers fastest
    assert max(fit_taus) < min(taus)
    for rec in (fig34["recovery"], cal["recovery"]):
        by = {r["trial"]: r["time_constant_ms"] for r in rec}
        assert by["Control"] < by["1-Cut"] < by["2-Cut"]
    # the 1/β* damping time of eq. 2.59 is an independent estimate: same order (within 2x)
    for r in (*fig34["recovery"], *cal["recovery"]):
        assert 0.5 < r["time_constant_ms"] / r["inverse_beta_star_ms"] < 2.0, r
    conclusion = next(line for line in report.splitlines() if line.startswith("Conclusion (computed"))
    if stated[0].ok and not recovery_claim.ok:
        assert "No single parameter set reproduces both" in conclusion


@pytest.mark.slow
def test_report_links_resolve(reproduced: Path) -> None:
    report = (reproduced / "report.md").read_text()
    figures = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", report)
    assert len(figures) >= 12
    for figure in figures:
        assert (reproduced / figure).read_bytes()[:4] == b"\x89PNG", figure
    anchors = _anchors()
    cited = set(re.findall(r"docs/errata\.md#(\w+)", report))
    assert cited and cited <= anchors, cited - anchors
    # every trial wrote its claims, and the summary counts them
    section = report.split("## Summary of the claims")[1].split("\n## ")[0]
    summary = {line.split(" | ")[0].strip("| "): line for line in section.splitlines() if line.startswith("| ")}
    for path in reproduced.glob("*.claims.json"):
        n = len(json.loads(path.read_text())["claims"])
        counts = [int(x) for x in summary[path.name.removesuffix(".claims.json")].strip("| ").split(" | ")[1:]]
        assert sum(counts) == n


@pytest.mark.slow
def test_every_trial_wrote_its_files(reproduced: Path) -> None:
    """The CLI trials' data files (parquet + csv + png) with their documented columns."""
    from paritysim.trials._io import stem

    for name in REGISTRY:
        if name.startswith("calibration"):
            continue
        assert (reproduced / f"{stem(name)}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
        assert (reproduced / f"{stem(name)}.csv").stat().st_size > 100, name
    assert pl.read_parquet(reproduced / "fig2_9.parquet").columns == ["alpha2_deg", "alpha3_deg", "phi_deg", "theta_deg", "theta_w_deg", "reachable"]
    assert pl.read_parquet(reproduced / "fig2_12.parquet").columns == ["drivetrain", "time_ms", "tau_left", "tau_right"]
    assert pl.read_parquet(reproduced / "fig2_13.parquet").height == 40_000
    assert set(pl.read_parquet(reproduced / "floquet.parquet")["drivetrain"].unique()) == {"linkage (§3.3)", "eq. 2.15"}
    lift = pl.read_csv(reproduced / "lift_dual.csv", infer_schema_length=None)
    assert {"configuration", "number", "trial", "hinge_k2", "yaw_mean", "status"} <= set(lift.columns)
    assert set(lift["number"].to_list()) == {1, 3, 5, 6, 7, 8}
    lam = pl.read_csv(reproduced / "laminate.csv")
    row = dict(zip(lam["quantity"], lam["value"], strict=True))
    # the designed actuator reproduces the thesis' constants (solved, then re-evaluated)
    assert row["actuator stiffness"] == pytest.approx(467.0, rel=1e-6)
    assert row["actuator force per volt"] == pytest.approx(1.2, rel=1e-6)
    assert row["linkage sublaminate cure curvature (max)"] < 1e-12


def test_claims_files_are_read_and_written_by_any_path_with_typed_errors(tmp_path) -> None:
    from paritysim import claims

    claim = claims.Claim.holds("it holds", True, computed="yes", criterion="true")
    written = claims.save(str(tmp_path / "c.json"), [claim], {"x": 1.0})  # a str path too
    loaded, values = claims.load(str(written))
    assert loaded[0].statement == "it holds" and values == {"x": 1.0}
    (tmp_path / "empty.json").write_text("{}")
    for bad in (tmp_path / "missing.json", tmp_path / "empty.json"):
        with pytest.raises(InvalidParameterError) as info:
            claims.load(bad)
        assert info.value.field == "path"
