"""The drawing's names of characteristics (``pmi_id``, from AP242 PMI by ``holecell
import-step``) carried into report.qif, which still validates against QIF 3.0."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from lxml import etree
from qif_reports import NOMINALS, gdt_report

from cell.review.qif import validate_file, write_qif

NS = {"q": "http://qifstandards.org/xsd/qif3"}


def test_pmi_ids_are_attributes_of_the_characteristic_items(tmp_path: Path) -> None:
    report = gdt_report(np.random.default_rng(5))
    named = {}
    for k, c in enumerate(report["characteristics"]):
        if k % 2 == 0:
            c["pmi_id"] = named[c["id"]] = (
                f"Position.{k}" if c["kind"] == "position" else "diameter"
            )
    assert named
    path = write_qif(report, tmp_path / "report.qif", NOMINALS)
    validate_file(path)
    root = etree.parse(str(path)).getroot()
    found = {}
    q = NS["q"]
    for item in root.iter(
        f"{{{q}}}PositionCharacteristicItem", f"{{{q}}}DiameterCharacteristicItem"
    ):
        attr = item.find("q:Attributes/q:AttributeStr[@name='pmi_id']", NS)
        if attr is not None:
            found[item.findtext("q:Name", "", NS)] = attr.get("value")
    assert found == named
