"""One diagnosis: the command line and the Python call give the same diagnosis.json for a
recording whose sidecar leaves friction_on open (``diagnosis.run.diagnose_recording``), and
that document follows its shipped schema (``diagnosis/report/diagnosis.schema.json``)."""

from __future__ import annotations

import copy
import json
import logging

import pytest

from harvester.cli import main
from harvester.data.daq import write_recording
from harvester.diagnosis import DiagnosisSettings, diagnose_recording
from harvester.diagnosis.report.document import SCHEMA_VERSION, validate_document

from test_topology import CUT, DEVICE, frame_record

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::RuntimeWarning")

#: Cheap settings, the same for both calls.
OPTIONS = {"particles": 40, "chains": 1, "top": 1, "rounds": 1, "seed": 5,
           "candidates": ("coulomb_friction",)}


def _stable(doc: dict) -> dict:
    """The document without what differs between two runs of the same diagnosis (times)."""
    doc = copy.deepcopy(doc)

    def strip(x):
        if isinstance(x, dict):
            return {k: strip(v) for k, v in x.items()
                    if not (k.endswith("seconds") or k.startswith("runtime"))}
        if isinstance(x, list):
            return [strip(v) for v in x]
        return x
    return strip(doc)


@pytest.fixture(scope="module")
def both(tmp_path_factory):
    """diagnosis.json from ``harvester diagnose`` and from ``diagnose_recording`` of a
    frame-like record (friction on the ground) whose sidecar does not say friction_on."""
    root = tmp_path_factory.mktemp("one")
    path = root / "frame.csv"
    write_recording(frame_record("ground"), path)
    (root / "frame.yaml").write_text("M: {M}\nm: {m}\nk: {k}\nfiltered_at_hz: {c}\n".format(
        **DEVICE, c=CUT))
    out = root / "cli"
    code = main(["diagnose", str(path), "--baseline", "linear", "--out", str(out), "--fast",
                 "--no-figures", "--particles", "40", "--chains", "1", "--top", "1",
                 "--rounds", "1", "--seed", "5", "--candidates", "coulomb_friction"])
    logging.getLogger("harvester").handlers.clear()
    assert code == 0
    cli = json.loads((out / "diagnosis.json").read_text())
    settings = DiagnosisSettings.fast(**OPTIONS, figures=False)
    py = diagnose_recording(path, "linear", settings=settings, out_dir=root / "py")
    return cli, json.loads((root / "py" / "diagnosis.json").read_text()), py


def test_the_cli_and_python_give_the_same_diagnosis(both):
    cli, py_doc, py = both
    assert _stable(cli) == _stable(py_doc)
    # the contact was chosen (the sidecar is silent) and said, in both
    assert any("relative to the ground" in n or "relative to the base" in n
               for n in cli["notes"]), cli["notes"]
    assert py.verdict == cli["verdict"]


def test_diagnosis_json_follows_its_schema(both):
    cli, _, _ = both
    assert cli["schema_version"] == SCHEMA_VERSION
    validate_document(cli)
    # every threshold that shaped the verdict is recorded, e.g. the shape's bars
    shape = cli["thresholds"]["harvester.diagnosis.size.shape_terms"]
    assert shape["STAND_NATS"] > 0 and shape["BEAT_NATS"] > 0


def test_the_schema_refuses_a_broken_document(both):
    cli, _, _ = both
    for broken in ({k: v for k, v in cli.items() if k != "verdict"},
                   {**cli, "verdict": "fine"}, {**cli, "unknown_key": 1},
                   {**cli, "missing": "coulomb_friction"}):
        with pytest.raises(ValueError, match="does not follow schema"):
            validate_document(broken)
