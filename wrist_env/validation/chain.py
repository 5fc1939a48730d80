"""The validation checks as one table (`CHECKS`): each row a published band, its unit and source, the load mode
of the runs it reads and the pure function of the shared runs (`simulations.Simulations`) that measures it.

`validate` simulates once and runs the chain (`run_chain`) in the table's order, which is the record's and the
printed table's. A check is added by a function here and a row in `CHECKS` (docs/validation.md, "The checks
are a table"); `tests/validation/test_chain.py` holds every row to a band, a unit, a source and a load mode.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from wrist_env.model import HAMATE, MIDCARPAL, TRAPEZIUM
from wrist_env.validation.bands import (
    EXTENSION_30_DEG,
    SL_DISSOCIATION_MM,
    ULNAR_SHARE_PCT,
    VIEGAS_1993,
)
from wrist_env.validation.measures import at_angle, largest_rotation_deg, slope
from wrist_env.validation.report import Check
from wrist_env.validation.simulations import LOAD_MODES, RL, RS, Simulations


@dataclass(frozen=True)
class CheckSpec:
    """One check: what it measures, against which published band, on which runs.

    Parameters
    ----------
    id : str
        The check's id, as the record and the table name it.
    description : str
        What the value is, as the record and the table say it; "{neutral}" and "{ulnar_variance}" are filled
        in from the runs (`Simulations.words`).
    band : tuple of (float, float)
        (low, high), in `unit`: low <= value <= high passes (inf: unbounded).
    unit : str
        The unit of the value and the band ("deg", "mm", "%", ...).
    source : str
        The publication the band comes from.
    load : str
        A key of `simulations.LOAD_MODES`, the runs it reads.
    value : callable
        ``value(s: Simulations) -> float``, the measure in `unit`, a pure function of the runs; not called
        when they failed (the check then fails, NaN, with the solver's status).

    Raises
    ------
    ValueError
        An unknown load mode, or a band whose low is above its high.
    """

    id: str
    description: str
    band: tuple[float, float]
    unit: str
    source: str
    load: str
    value: Callable[[Simulations], float]

    def __post_init__(self):
        if self.load not in LOAD_MODES:
            raise ValueError(f"check {self.id}: load mode must be one of {sorted(LOAD_MODES)}, not {self.load!r}")
        if not self.band[0] <= self.band[1]:
            raise ValueError(f"check {self.id}: band {self.band} runs backwards")


def _scaphoid_slope(s: Simulations) -> float:
    return slope(s.flexion_deg[:, 0], s.flexion_deg[:, 1])


def _lunate_slope(s: Simulations) -> float:
    return slope(s.flexion_deg[:, 0], s.flexion_deg[:, 2])


def _scaphoid_above_lunate(s: Simulations) -> float:
    return _scaphoid_slope(s) - _lunate_slope(s)


def _rs_rl_force_ratio(s: Simulations) -> float:
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(s.neutral.contact[0, RS, 3] / s.neutral.contact[0, RL, 3])


def _share_pct(articulation: str) -> Callable[[Simulations], float]:
    """The neutral run's load share (%) of `articulation` (a `model.MIDCARPAL` name or "ulnocarpal")."""

    def share(s: Simulations) -> float:
        return s.shares_pct[articulation]

    return share


def _rotation_deg(body: int) -> Callable[[Simulations], float]:
    """The intact sweep's largest rotation (deg) of `body` relative to the capitate (`largest_rotation_deg`)."""

    def rotation(s: Simulations) -> float:
        return largest_rotation_deg(s.intact.poses, body)

    return rotation


def _sl_gap_growth_mm(s: Simulations) -> float:
    return s.sl_gap_torn_mm[-1] - s.sl_gap_intact_mm[-1]


def _rs_mean_pressure_mpa(s: Simulations) -> float:
    return np.nanmean(s.intact.contact[:, RS, 0])


def _slil_force_30ext_n(s: Simulations) -> float:
    return at_angle(s.intact.angle_deg, s.slil_force_n, EXTENSION_30_DEG)


_RAINBOW = (
    "Rainbow et al. 2013, J Hand Surg Am 38:278-288 (in vivo CT, 12 wrists, extreme loaded flexion and "
    "extension: {} of the capitate's flexion / extension)"
)
_AKHBARI = (
    "Akhbari et al. 2019, J Orthop Res 37:2661-2670 (in-vivo CT, the distal row moves as one rigid body within 3 deg)"
)
_SWEEP = "idealized +-40 deg sweep"
_INF = math.inf

CHECKS: tuple[CheckSpec, ...] = (
    CheckSpec(
        "scaphoid_slope",
        f"scaphoid flexion per degree of capitate flexion (least squares, {_SWEEP})",
        (0.55, 0.95),
        "deg/deg",
        _RAINBOW.format("scaphoid 70 % / 74 %"),
        "sweep",
        _scaphoid_slope,
    ),
    CheckSpec(
        "lunate_slope",
        f"lunate flexion per degree of capitate flexion (least squares, {_SWEEP})",
        (0.30, 0.75),
        "deg/deg",
        _RAINBOW.format("lunate 46 % / 42 %"),
        "sweep",
        _lunate_slope,
    ),
    CheckSpec(
        "scaphoid_above_lunate",
        "scaphoid slope minus lunate slope",
        (0.0, _INF),
        "deg/deg",
        _RAINBOW.format("scaphoid 70-74 % against lunate 42-46 %"),
        "sweep",
        _scaphoid_above_lunate,
    ),
    CheckSpec(
        "rs_rl_force_ratio",
        "radioscaphoid / radiolunate contact force, capitate held at neutral under {neutral}",
        (1.1, 2.0),
        "ratio",
        "Hara et al. 1992, J Hand Surg Am 17:339-347 (neutral wrist: 50 % of the load through the scaphoid fossa, "
        "35 % through the lunate fossa, ratio 1.43); Viegas, Tencer et al. (load transfer characteristics of the "
        "wrist): scaphoid/lunate fossa contact-area ratio 1.47",
        "jig",
        _rs_rl_force_ratio,
    ),
    *(
        CheckSpec(
            f"midcarpal_{key}_share_pct",
            f"{articulation}'s share of the midcarpal contact force, neutral, {{neutral}}",
            (pct - 10.0, pct + 10.0),
            "%",
            f"Viegas, Patterson, Todd & McCarty 1993, J Hand Surg Am 18:14-18 (pressure-sensitive film, cadaver "
            f"wrists loaded axially in neutral: STT 23 %, SC 28 %, LC 29 %, TH 20 % of the midcarpal load; "
            f"{key.upper()} {pct} %, band +-10 points)",
            "jig",
            _share_pct(articulation),
        )
        for (key, pct), articulation in zip(VIEGAS_1993.items(), MIDCARPAL, strict=True)
    ),
    CheckSpec(
        "ulnar_share_pct",
        "ulnocarpal share of the radiocarpal + ulnocarpal contact force, neutral, {neutral}{ulnar_variance}",
        ULNAR_SHARE_PCT,
        "%",
        "Palmer & Werner 1984, Clin Orthop 187:26-35 (neutral ulnar variance: 18.4 % of the axial load through the "
        "ulna); Hara et al. 1992, J Hand Surg Am 17:339-347 (TFC 15 %)",
        "jig",
        _share_pct("ulnocarpal"),
    ),
    CheckSpec(
        "column_rotation_deg",
        "largest rotation of the radial column (trapezium + trapezoid) relative to the capitate over the sweep",
        (0.0, 3.0),
        "deg",
        _AKHBARI,
        "sweep",
        _rotation_deg(TRAPEZIUM),
    ),
    CheckSpec(
        "hamate_rotation_deg",
        "largest rotation of the hamate relative to the capitate over the sweep",
        (0.0, 3.0),
        "deg",
        f"{_AKHBARI}; the capitohamate joint rotates ~9 deg under 0.5 N m with its ligaments intact (Ritt et al. "
        "1996, J Hand Surg Br 21:451)",
        "sweep",
        _rotation_deg(HAMATE),
    ),
    CheckSpec(
        "sl_gap_growth_mm",
        "SL gap at full extension (last frame), all three SLIL bundles torn minus intact",
        (SL_DISSOCIATION_MM, _INF),
        "mm",
        "Haug et al. 2021, Arch Orthop Trauma Surg 141:341-347 (8 axially loaded cadaver wrists: SL gap 6.6 +- 1.6 "
        "mm after SLIL transection); a gap > 3 mm is clinical SL dissociation",
        "torn sweep",
        _sl_gap_growth_mm,
    ),
    CheckSpec(
        "rs_mean_pressure_mpa",
        "radioscaphoid mean contact pressure, mean over the sweep's frames",
        (0.2, 3.0),
        "MPa",
        "Andreassen et al. preprint, Figure 3 / Table 5 scale (a no-regression band: Table 5's normalizer, mean RS "
        "pressure 0.65 MPa; cadaveric radiocarpal pressures of a few MPa, Hara 1992: peak 2.4 MPa on the scaphoid "
        "fossa under 10 kg)",
        "sweep",
        _rs_mean_pressure_mpa,
    ),
    CheckSpec(
        "slil_force_30ext_n",
        "total SLIL force (SLIL_v + SLIL_p + SLIL_d) at 30 deg extension",
        (10.0, 40.0),
        "N",
        "Dimitris et al. 2015, J Hand Surg Am 40:1525-1533 (total SLIL force in active wrist motion ~20 N, "
        "20.0 +- 3.3 N at 30 deg extension; the preprint's ref. 63)",
        "sweep",
        _slil_force_30ext_n,
    ),
)
"""The checks, in the record's and the table's order."""

SOURCES = {c.id: c.source for c in CHECKS}
"""Each check's source, by id."""


def _row(check_id, description, value, band, unit, failed=None, source=None) -> Check:
    """A measured row: `failed` (why its runs could not be measured) makes it NaN, failing, and says so in its
    description; the source is the table's unless given."""
    if failed:
        description = f"{description} [not measured: {failed}]"
        value = float("nan")
    value = float(value)
    passed = math.isfinite(value) and band[0] <= value <= band[1]
    source = SOURCES[check_id] if source is None else source
    return Check(check_id, description, value, (float(band[0]), float(band[1])), unit, source, passed)


def run_chain(s: Simulations, checks: tuple[CheckSpec, ...] = CHECKS) -> tuple[Check, ...]:
    """Each check of `checks` measured on the runs `s`, in order.

    Parameters
    ----------
    s : Simulations
        The population design's runs and shared measures (`run_simulations`).
    checks : tuple of CheckSpec, default `CHECKS`
        The chain.

    Returns
    -------
    tuple of Check, length n_checks
        One row per check; a check whose runs failed has value NaN, fails, and says the solver's status.
    """
    words = s.words
    rows = []
    for c in checks:
        failed = s.failure(c.load)
        value = math.nan if failed else c.value(s)
        rows.append(_row(c.id, c.description.format(**words), value, c.band, c.unit, failed, c.source))
    return tuple(rows)
