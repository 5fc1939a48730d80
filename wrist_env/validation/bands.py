"""The published numbers the checks, their figure and the research scripts share; each check's band and its
source are a row of `validation.chain.CHECKS`."""

from __future__ import annotations

SLIL = ("SLIL_v", "SLIL_p", "SLIL_d")
EXTENSION_30_DEG = -30.0  # flexion + / extension −, as the idealized driver's angle_deg
SL_DISSOCIATION_MM = 3.0  # clinical scapholunate dissociation: gap > 3 mm
RAINBOW_SCAPHOID = 0.72  # Rainbow 2013: scaphoid 70 % (flexion), 74 % (extension) of the capitate
RAINBOW_LUNATE = 0.44  # Rainbow 2013: lunate 46 % (flexion), 42 % (extension)
HAUG_2021_GAP_MM = (6.6, 1.6)  # Haug 2021: SL gap after SLIL transection in cadavers, mean and SD (mm)
NEUTRAL_LOAD_N = 100.0  # axial load of the load-share check: Hara 1992 loaded neutral wrists with up to 12 kg

VIEGAS_1993 = {"stt": 23, "sc": 28, "lc": 29, "th": 20}
"""Midcarpal load shares (%), Viegas 1993, in `model.MIDCARPAL` order."""
ULNAR_SHARE_PCT = (10.0, 25.0)  # Palmer & Werner 1984 (18.4 %), Hara 1992 (15 %)
