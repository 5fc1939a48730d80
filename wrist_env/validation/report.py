"""A validation report: its checks (strict JSON) and the table (its figure: `wrist_env.figures.validation`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from wrist_env.figures.validation import ValidationPanels
from wrist_env.validation.bands import HAUG_2021_GAP_MM, RAINBOW_LUNATE, RAINBOW_SCAPHOID, SL_DISSOCIATION_MM


@dataclass(frozen=True)
class Check:
    """One row: a model output against a published band (low <= value <= high passes; inf: unbounded).

    Parameters
    ----------
    id : str
        The check's id (`CheckSpec.id`).
    description : str
        What the value is, filled in from the runs.
    value : float
        The model's output, in `unit`; NaN when its runs failed.
    band : tuple of (float, float)
        (low, high), in `unit`; inf: unbounded.
    unit : str
        The unit of value and band ("deg", "mm", "%", ...).
    source : str
        The publication the band comes from.
    passed : bool
        Whether low <= value <= high.
    """

    id: str
    description: str
    value: float
    band: tuple[float, float]
    unit: str
    source: str
    passed: bool

    def to_dict(self) -> dict:
        return {
            "id": self.id,
            "description": self.description,
            "value": _num(self.value),
            "band": [_num(self.band[0]), _num(self.band[1])],
            "unit": self.unit,
            "source": self.source,
            "passed": bool(self.passed),
        }


@dataclass(frozen=True)
class Report:
    """The checks of one participant, the series behind them (for the figure) and the wall time.

    Parameters
    ----------
    participant : str
        The participant's (model's) name.
    rows : tuple of Check, length n_checks
        The checks, in the chain's order.
    series : dict
        The per-frame series behind the checks and the figure (`Simulations.series`: arrays of shape
        (n_frames,) or (n_frames, k), and each run's status).
    wall_seconds : float, default NaN
        Wall time of the validation, s.
    conditions : dict, default {}
        The anatomy variant (build parameters) and the compressive load (N) of the runs.

    Attributes
    ----------
    passed : bool
        Whether every check passed.
    """

    participant: str
    rows: tuple[Check, ...]
    series: dict = field(repr=False)
    wall_seconds: float = float("nan")
    conditions: dict = field(default_factory=dict)
    """The anatomy variant (build parameters) and the compressive load (N) of the runs."""

    @property
    def passed(self) -> bool:
        return all(r.passed for r in self.rows)

    def row(self, check_id: str) -> Check:
        return next(r for r in self.rows if r.id == check_id)

    def to_dict(self) -> dict:
        """Strict JSON: NaN and ±inf become None (a None band edge means unbounded)."""
        return {
            "participant": self.participant,
            "design": "population",
            "conditions": self.conditions,
            "passed": self.passed,
            "checks": [r.to_dict() for r in self.rows],
            "series": {k: (v if isinstance(v, str) else _list(v)) for k, v in self.series.items()},
            "wall_seconds": _num(round(self.wall_seconds, 3)),
        }


def _num(x):
    x = float(x) + 0.0  # + 0.0: no "-0.0"
    return x if math.isfinite(x) else None


def _list(a):
    return [_num(x) for x in np.asarray(a, dtype=np.float64).ravel()]


def _fmt(x: float) -> str:
    return f"{x:.3g}" if math.isfinite(x) else str(x)


def band_text(low: float, high: float) -> str:
    """A published band as the tables print it: "low-high", or "> low" when it has no upper edge (inf)."""
    return f"{_fmt(low)}-{_fmt(high)}" if math.isfinite(high) else f"> {_fmt(low)}"


def format_table(report: Report) -> str:
    """The checks as a plain-text table: check, value, band, unit, pass/FAIL, source.

    Parameters
    ----------
    report : Report
        A validation's report (`validate`).

    Returns
    -------
    str
        The table, a line per check under a title line naming the participant and the conditions, then
        the notes of checks not measured.
    """
    c = report.conditions
    lines = [
        f"{report.participant}, population design: the model against published measurements"
        + (
            f" (fossa sweep ±{c['fossa_sweep_deg']} deg, distal row {'on' if c['distal_row'] else 'off'}, "
            f"TC/TH {'on' if c.get('fixed_ligaments') else 'off'}, sweep load {c['load_n']:g} N, "
            f"load direction {c.get('load_direction', 'axial')})"
            if c
            else ""
        ),
        f"{'check':<24} {'value':>8}  {'band':<13} {'unit':<8} {'result':<6}  source",
    ]
    for r in report.rows:
        lines.append(
            f"{r.id:<24} {_fmt(r.value):>8}  {band_text(*r.band):<13} {r.unit:<8} {'pass' if r.passed else 'FAIL':<6}  "
            f"{r.source.split(' (')[0]}"
        )
    for r in report.rows:
        if "[not measured" in r.description:
            lines.append(f"{r.id}: {r.description}")
    n = sum(r.passed for r in report.rows)
    lines.append(f"{n}/{len(report.rows)} checks pass; {report.wall_seconds:.1f} s")
    return "\n".join(lines)


def figure_panels(report: Report) -> ValidationPanels:
    """What the validation figure draws of `report`: its sweep series, the model's slopes against Rainbow 2013's
    ratios, the SL gap lines and the note on the gap-growth check (and on runs that did not finish)."""
    growth = report.row("sl_gap_growth_mm")
    notes = [
        f"check: torn − intact at full extension {_fmt(growth.value)} mm "
        f"(band > {_fmt(growth.band[0])} mm): {'pass' if growth.passed else 'FAIL'}"
    ]
    s = report.series
    notes += [f"{k}: {s[k]}" for k in ("intact_status", "slil_torn_status") if s.get(k) != "ok"]
    return ValidationPanels(
        report.participant,
        s,
        {"scaphoid": report.row("scaphoid_slope").value, "lunate": report.row("lunate_slope").value},
        {"scaphoid": RAINBOW_SCAPHOID, "lunate": RAINBOW_LUNATE},
        SL_DISSOCIATION_MM,
        HAUG_2021_GAP_MM,
        notes,
        sum(r.passed for r in report.rows),
        len(report.rows),
    )
