"""The model checked against published wrist measurements (`wrist-bench validate`).

`validate(name)` runs three simulations of the population-mean design — an
intact idealized ±40° flexion–extension sweep and the same sweep with all
three SLIL bundles torn (one batched call), and the capitate held at neutral
under the idealized compressive load — once (`simulations.run_simulations`),
and compares the outputs of the chain of checks, one table (`chain.CHECKS`:
each row a band drawn from cadaveric and in-vivo studies, its unit, source,
load mode and measure), with their bands. Each row says where its band comes
from. A check whose simulation failed has value NaN (None in JSON), fails,
and names the solver's status in its description.
"""

from wrist_env.validation.bands import (
    EXTENSION_30_DEG,
    NEUTRAL_LOAD_N,
    RAINBOW_LUNATE,
    RAINBOW_SCAPHOID,
    SL_DISSOCIATION_MM,
    SLIL,
    ULNAR_SHARE_PCT,
    VIEGAS_1993,
)
from wrist_env.validation.chain import CHECKS, LOAD_MODES, SOURCES, CheckSpec, run_chain
from wrist_env.validation.checks import validate
from wrist_env.validation.measures import (
    at_angle,
    largest_rotation_deg,
    load_shares_pct,
    sl_gap_mm,
    slope,
    surface_gap_mm,
    with_tears,
)
from wrist_env.validation.report import Check, Report, format_table
from wrist_env.validation.simulations import Simulations, run_simulations

__all__ = [
    "CHECKS", "EXTENSION_30_DEG", "LOAD_MODES", "NEUTRAL_LOAD_N", "RAINBOW_LUNATE", "RAINBOW_SCAPHOID",
    "SL_DISSOCIATION_MM", "SLIL", "SOURCES", "ULNAR_SHARE_PCT", "VIEGAS_1993", "Check", "CheckSpec", "Report",
    "Simulations", "at_angle", "format_table", "largest_rotation_deg", "load_shares_pct", "run_chain",
    "run_simulations", "sl_gap_mm", "slope", "surface_gap_mm", "validate", "with_tears",
]  # fmt: skip
