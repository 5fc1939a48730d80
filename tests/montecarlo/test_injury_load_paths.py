"""The probe of where each injury moves the load (`experiments/research/injury_load_paths.py`)."""

import importlib.util
from pathlib import Path

from wrist_env import ligaments
from wrist_env.model import PAIRS
from wrist_env.montecarlo.report import PREPRINT_TABLE5

PATH = Path(__file__).parents[2] / "experiments" / "research" / "injury_load_paths.py"


def _module():
    spec = importlib.util.spec_from_file_location("_injury_load_paths", PATH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _row(rs_pressure: float, rsc: float = 10.0, rl: float = 40.0) -> dict:
    pairs = dict.fromkeys(PAIRS, 5.0) | {"radiolunate": rl}
    bundles = dict.fromkeys(ligaments.ALL_LIGAMENT_NAMES, 1.0) | {"RSC": rsc}
    return {"rs_pressure": rs_pressure, "rs_area": 12.0, "pairs": pairs, "bundles": bundles, "slopes": (0.7, 0.4)}


def test_a_sign_against_the_preprints_is_said_with_where_the_load_went():
    module = _module()
    rows = {"intact": _row(1.0)} | {f"{lig} torn": _row(1.0) for lig in ligaments.INJURABLE}
    rows["RSC torn"] = _row(0.9, rsc=0.0, rl=47.5)  # the preprint's RSC estimate is positive
    lines = "\n".join(module.report("P1", rows, {"RSC": -0.06}))
    rsc = next(line for line in lines.splitlines() if line.startswith("- **RSC**"))
    assert PREPRINT_TABLE5["RSC"][0] > 0
    assert "falls by 0.100 MPa" in rsc and "(the other sign)" in rsc and "the study's -0.060 MPa (same sign)" in rsc
    assert "intact tension 10.0 N" in rsc and "radiolunate +7.5 N" in rsc.split("the contacts:")[1]
    assert "| RSC torn | -0.100 |" in lines
