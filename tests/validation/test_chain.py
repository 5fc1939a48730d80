"""The checks as a table (`validation.chain.CHECKS`): every row complete, the committed records in its order,
and the chain's handling of failed runs; fast (no simulation; `tests/test_validation.py` runs the checks)."""

import dataclasses
import json
import math
from pathlib import Path

import pytest

from wrist_env import validation
from wrist_env.validation import CHECKS, LOAD_MODES, CheckSpec, run_chain
from wrist_env.validation.simulations import RUNS, Simulations

RECORDS = Path(__file__).resolve().parents[2] / "experiments" / "figures"
WORDS = {"neutral": "100 N (the jig)", "ulnar_variance": ", ulnar variance +0.26 mm"}


def test_every_check_has_a_unique_id_a_band_a_unit_a_source_and_a_load_mode():
    ids = [c.id for c in CHECKS]
    fields = {f.name for f in dataclasses.fields(Simulations)}
    assert set(RUNS) == set(LOAD_MODES) and all(set(runs) <= fields for runs in RUNS.values()), RUNS
    assert len(ids) == len(set(ids)), ids
    for c in CHECKS:
        low, high = c.band
        assert isinstance(low, float | int) and isinstance(high, float | int), c.id
        assert math.isfinite(low) and low <= high and not math.isnan(high), (c.id, c.band)
        assert c.unit.strip() and c.source.strip() and c.description.strip(), c.id
        assert c.load in LOAD_MODES and callable(c.value), (c.id, c.load)
        c.description.format(**WORDS)  # its placeholders are the runs' words, no other


def test_the_committed_records_list_the_tables_checks_in_its_order():
    """The docs' validation page renders `experiments/figures/validation_P*.json` row by row: a row added to
    the table, or moved, without the records regenerated shows here."""
    for participant in ("P1", "P2", "P3"):
        record = json.loads((RECORDS / f"validation_{participant}.json").read_text())
        assert [c["id"] for c in record["checks"]] == [c.id for c in CHECKS], participant
        for row, check in zip(record["checks"], CHECKS, strict=True):
            assert row["unit"] == check.unit and row["source"] == check.source, check.id


class _FailedRuns:
    """Runs of which only the torn sweep failed: what `run_chain` reads of a `Simulations`."""

    words = WORDS

    def failure(self, load):
        return "SLIL-torn sweep run failed: NaN in the state" if load == "torn sweep" else None


def test_the_chain_runs_the_table_in_order_and_does_not_measure_a_failed_run():
    def must_not_run(s):
        raise AssertionError("a check of a failed run was measured")

    checks = (
        CheckSpec("a", "ran under {neutral}", (0.0, 2.0), "mm", "src a", "jig", lambda s: 1.5),
        CheckSpec("b", "torn", (3.0, math.inf), "mm", "src b", "torn sweep", must_not_run),
        CheckSpec("c", "out of band{ulnar_variance}", (0.0, 1.0), "N", "src c", "sweep", lambda s: 1.5),
    )
    rows = run_chain(_FailedRuns(), checks)
    assert [r.id for r in rows] == ["a", "b", "c"] and [r.passed for r in rows] == [True, False, False]
    assert rows[0].description == "ran under 100 N (the jig)" and rows[0].source == "src a"
    assert math.isnan(rows[1].value) and rows[1].description.endswith(
        "[not measured: SLIL-torn sweep run failed: NaN in the state]"
    )
    assert rows[2].description == "out of band, ulnar variance +0.26 mm" and rows[2].band == (0.0, 1.0)


def test_a_check_names_a_known_load_mode_and_a_band_that_runs_upwards():
    with pytest.raises(ValueError, match="load mode must be one of"):
        CheckSpec("x", "x", (0.0, 1.0), "mm", "src", "tendon", lambda s: 0.0)
    with pytest.raises(ValueError, match="runs backwards"):
        CheckSpec("x", "x", (2.0, 1.0), "mm", "src", "sweep", lambda s: 0.0)
    assert validation.SOURCES == {c.id: c.source for c in CHECKS}


def test_a_load_mode_fails_with_the_first_of_its_runs_that_failed():
    """As `validate` said before the chain: the torn sweep's check names the intact sweep's failure first."""
    from types import SimpleNamespace

    ran, nan = SimpleNamespace(ok=True, message="ok"), SimpleNamespace(ok=False, message="failed: NaN in the state")
    arrays = dict(flexion_deg=None, sl_gap_intact_mm=None, sl_gap_torn_mm=None, slil_force_n=None, shares_pct={})
    torn_only = Simulations(None, ran, nan, ran, "jig", **arrays)
    assert torn_only.failure("sweep") is None and torn_only.failure("jig") is None
    assert torn_only.failure("torn sweep") == "SLIL-torn sweep run failed: NaN in the state"
    both = Simulations(None, nan, nan, nan, "jig", **arrays)
    assert both.failure("torn sweep") == "intact sweep run failed: NaN in the state"
    assert both.failure("jig") == "neutral run failed: NaN in the state"
