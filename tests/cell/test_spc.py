"""``holecell spc``: capability from report.qif files of synthetic runs with a known process,
the I-MR rules, spc.csv and spc.html read back, and refusals."""

from __future__ import annotations

import csv
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from qif_reports import NOMINALS, gdt_report

from cell.cli import main
from cell.review.qif import write_qif
from cell.review.spc.bounded import rice_cpk
from cell.review.spc.stats import capability

N_RUNS = 40
ZONE_M, UPPER_M, MEAN_DEV_M = 3e-4, 2.2e-5, 1e-5  # the tolerances and bias of qif_reports
#: the moving-range sigma spreads Cpk ~1.3x more than the normal-theory formula says
#: (measured: 4000 samples of 40 normal values, sd 0.179 against 0.136)
MR_INFLATION = 1.35


def _runs(root: Path, n: int, seed: int = 11, **kw) -> Path:
    rng = np.random.default_rng(seed)
    for i in range(n):
        extra = {k: (v(i) if callable(v) else v) for k, v in kw.items()}
        d = root / f"run{i:03d}"
        d.mkdir(parents=True)
        write_qif(gdt_report(rng, 1.8e9 + 60.0 * i, **extra), d / "report.qif", NOMINALS)
    return root


def _csv(path: Path) -> dict[str, dict[str, str]]:
    with path.open() as fh:
        return {r["characteristic"]: r for r in csv.DictReader(fh)}


def _cpk_se(cpk: float, n: int) -> float:
    return MR_INFLATION * float(np.sqrt(1 / (9 * n) + cpk**2 / (2 * (n - 1))))


def test_cpk_of_a_known_process_within_its_sampling_error(tmp_path: Path, capsys) -> None:
    sigma_d, offset, sigma_p = 3e-6, 5e-5, 1.5e-5
    runs = _runs(
        tmp_path / "runs",
        N_RUNS,
        diameter_sigma_m=sigma_d,
        position_offset_m=offset,
        position_sigma_m=sigma_p,
    )
    assert main(["spc", str(runs)]) == 0
    rows = _csv(runs / "spc.csv")
    # diameter: N(10 um, 3 um) against 0 .. 22 um
    want = min(UPPER_M - MEAN_DEV_M, MEAN_DEV_M) / (3 * sigma_d)
    got = float(rows["H1.diameter"]["cpk"])
    assert abs(got - want) < 3 * _cpk_se(want, N_RUNS), (got, want)
    want_cp = UPPER_M / (6 * sigma_d)
    assert abs(float(rows["H1.diameter"]["cp"]) - want_cp) < 3 * _cpk_se(want_cp, N_RUNS)
    # position 2*hypot(dx, dy): dx ~ N(50 um, 15 um), dy ~ N(0, 15 um); one-sided, USL = zone
    rng = np.random.default_rng(0)
    v = 2 * np.hypot(rng.normal(offset, sigma_p, 10**6), rng.normal(0.0, 1.5e-5, 10**6))
    want = (ZONE_M - v.mean()) / (3 * v.std())
    got = float(rows["H1.position"]["cpk"])
    assert rows["H1.position"]["cp"] == "" and rows["H1.position"]["lsl_m"] == ""
    assert abs(got - want) < 3 * _cpk_se(want, N_RUNS), (got, want)
    assert float(rows["H1.position"]["lcl_m"]) >= 0.0
    # the Rice fit's percentile index against the process's own percentiles; its spread at 40
    # runs is 0.28 (measured over 500 samples of this process; mean 2.28 against 2.20)
    x50, xu = np.quantile(v, [0.5, 0.99865])
    want = (ZONE_M - x50) / (xu - x50)
    assert abs(float(rows["H1.position"]["cpk_rice"]) - want) < 3 * 0.28
    assert rows["H2.position"]["n"] == "0" and rows["H2.position"]["n_not_evaluated"] == "40"
    assert "H1.diameter" in capsys.readouterr().out


class _Page(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.rows: dict[str, int] = {}
        self.svgs, self.ooc_points, self.external = 0, 0, []

    def handle_starttag(self, tag: str, attrs: list) -> None:
        a = dict(attrs)
        if tag == "tr" and a.get("class") == "char":
            self.rows[a["data-char"]] = int(a["data-ooc"])
        self.svgs += tag == "svg"
        self.ooc_points += tag == "circle" and a.get("class") == "ooc"
        for key in ("src", "href"):
            if a.get(key, "").startswith(("http", "//")):
                self.external.append(a[key])
        if tag == "script":
            self.external.append("script")


def test_a_shifted_run_is_out_of_control_in_csv_and_html(tmp_path: Path) -> None:
    runs = _runs(
        tmp_path / "runs",
        25,
        position_offset_m=lambda i: 4e-5 + 1.2e-4 * (i == 12),
        position_sigma_m=5e-6,
    )
    out = tmp_path / "out"
    assert main(["spc", *sorted(str(p) for p in runs.iterdir()), "--out", str(out)]) == 0
    row = _csv(out / "spc.csv")["H1.position"]
    assert "run012:beyond_3sigma" in row["out_of_control"]
    page = _Page()
    page.feed((out / "spc.html").read_text())
    assert page.external == []
    assert set(page.rows) == {"H1.diameter", "H1.position", "H2.diameter", "H2.position"}
    assert page.rows["H1.position"] >= 1
    assert page.svgs == 4 and page.ooc_points >= 1  # I and MR chart of H1's two


def test_rules() -> None:
    x = np.r_[np.zeros(10), 1.0, 2.0, 3.0, 4.0, 5.0, 6.0] + np.tile([0.01, -0.01], 8)
    hits = capability(x, None, 10.0).out_of_control
    assert any("six_trend" in r for r in hits.values())
    y = np.r_[np.full(9, 1.0), np.full(9, -1.0)] + np.linspace(0, 0.1, 18)
    assert any("nine_same_side" in r for r in capability(y, None, None).out_of_control.values())
    flat = capability(np.tile([1.0, 1.1], 10), 0.0, 2.0)
    assert flat.out_of_control == {} and flat.cp == pytest.approx(2.0 / (6 * 0.1 / 1.128))


def test_refusals(tmp_path: Path, capsys) -> None:
    (tmp_path / "empty").mkdir()
    assert main(["spc", str(tmp_path / "empty")]) == 2
    assert "no report.qif" in capsys.readouterr().err
    runs = _runs(tmp_path / "runs", 3)
    text = (runs / "run002" / "report.qif").read_text()
    (runs / "run002" / "report.qif").write_text(
        text.replace(
            "<ToleranceValue>0.0003</ToleranceValue>", "<ToleranceValue>0.0004</ToleranceValue>"
        )
    )
    assert main(["spc", str(runs)]) == 2
    assert "H1.position: tolerance" in capsys.readouterr().err
    (runs / "run002" / "report.qif").write_text(text.replace("PASS", "GREAT"))
    assert main(["spc", str(runs)]) == 2
    assert "run002/report.qif: line" in capsys.readouterr().err


def test_rice_cpk_is_the_normal_one_far_from_zero_and_lower_near_it() -> None:
    rng = np.random.default_rng(4)
    far = 2 * np.hypot(rng.normal(2e-4, 1e-5, 4000), rng.normal(0.0, 1e-5, 4000))
    fit = rice_cpk(far, 5e-4)
    assert fit.cpk == pytest.approx((5e-4 - far.mean()) / (3 * far.std()), rel=0.05)
    assert fit.nu_m == pytest.approx(2e-4, rel=0.02) and fit.sigma_m == pytest.approx(
        1e-5, rel=0.05
    )
    centred = 2 * np.hypot(rng.normal(0.0, 1e-5, 4000), rng.normal(0.0, 1e-5, 4000))
    normal_cpk = (5e-4 - centred.mean()) / (3 * centred.std())
    x50, xu = np.quantile(centred, [0.5, 0.99865])
    fit = rice_cpk(centred, 5e-4)
    assert fit.cpk == pytest.approx((5e-4 - x50) / (xu - x50), rel=0.08)
    assert fit.cpk < 0.9 * normal_cpk  # the long upper tail the normal index ignores
    assert rice_cpk(np.full(10, 1e-5), 5e-4) is None and rice_cpk([1e-5] * 4, 5e-4) is None
