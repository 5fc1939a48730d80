"""The published bands the model is checked against, and where each comes from."""

from __future__ import annotations

SLIL = ("SLIL_v", "SLIL_p", "SLIL_d")
EXTENSION_30_DEG = -30.0  # flexion + / extension −, as the idealized driver's angle_deg
SL_DISSOCIATION_MM = 3.0  # clinical scapholunate dissociation: gap > 3 mm
RAINBOW_SCAPHOID = 0.72  # Rainbow 2013: scaphoid 70 % (flexion), 74 % (extension) of the capitate
RAINBOW_LUNATE = 0.44  # Rainbow 2013: lunate 46 % (flexion), 42 % (extension)
NEUTRAL_LOAD_N = 100.0  # axial load of the load-share check: Hara 1992 loaded neutral wrists with up to 12 kg

VIEGAS_1993 = {"stt": 23, "sc": 28, "lc": 29, "th": 20}
"""Midcarpal load shares (%), Viegas 1993, in `model.MIDCARPAL` order."""
ULNAR_SHARE_PCT = (10.0, 25.0)  # Palmer & Werner 1984 (18.4 %), Hara 1992 (15 %)
LUNOTRIQUETRAL_DEG = 5.0  # Ruby 1988, Kobayashi 1997: a few degrees of LT rotation over +-40 deg (recalled)

RAINBOW = (
    "Rainbow et al. 2013, J Hand Surg Am 38:278-288 (in vivo CT, 12 wrists, extreme loaded flexion and "
    "extension: {} of the capitate's flexion / extension)"
)
SOURCES = {
    "scaphoid_slope": RAINBOW.format("scaphoid 70 % / 74 %"),
    "lunate_slope": RAINBOW.format("lunate 46 % / 42 %"),
    "scaphoid_above_lunate": RAINBOW.format("scaphoid 70-74 % against lunate 42-46 %"),
    "rs_rl_force_ratio": (
        "Hara et al. 1992, J Hand Surg Am 17:339-347 (neutral wrist: 50 % of the load through the "
        "scaphoid fossa, 35 % through the lunate fossa, ratio 1.43); Viegas, Tencer et al. "
        "(load transfer characteristics of the wrist): scaphoid/lunate fossa contact-area "
        "ratio 1.47"
    ),
    "sl_gap_growth_mm": (
        "Haug et al. 2021, Arch Orthop Trauma Surg 141:341-347 (8 axially loaded cadaver wrists: "
        "SL gap 6.6 +- 1.6 mm after SLIL transection); a gap > 3 mm is clinical SL dissociation"
    ),
    "rs_mean_pressure_mpa": (
        "Andreassen et al. preprint, Figure 3 / Table 5 scale (a no-regression band: Table 5's "
        "normalizer, mean RS pressure 0.65 MPa; cadaveric radiocarpal pressures of a few MPa, "
        "Hara 1992: peak 2.4 MPa on the scaphoid fossa under 10 kg)"
    ),
    **{
        f"midcarpal_{key}_share_pct": (
            f"Viegas, Patterson, Todd & McCarty 1993, J Hand Surg Am 18:14-18 (pressure-sensitive film, "
            f"cadaver wrists loaded axially in neutral: STT 23 %, SC 28 %, LC 29 %, TH 20 % of the midcarpal "
            f"load; {key.upper()} {pct} %, band +-10 points)"
        )
        for key, pct in VIEGAS_1993.items()
    },
    "ulnar_share_pct": (
        "Palmer & Werner 1984, Clin Orthop 187:26-35 (neutral ulnar variance: 18.4 % of the axial load "
        "through the ulna); Hara et al. 1992, J Hand Surg Am 17:339-347 (TFC 15 %)"
    ),
    "column_rotation_deg": (
        "Akhbari et al. 2019, J Orthop Res 37:2661-2670 (in-vivo CT, the distal row moves as one rigid "
        "body within 3 deg)"
    ),
    "hamate_rotation_deg": (
        "Akhbari et al. 2019, J Orthop Res 37:2661-2670 (in-vivo CT, the distal row moves as one rigid "
        "body within 3 deg); the capitohamate joint rotates ~9 deg under 0.5 N m with its ligaments "
        "intact (Ritt et al. 1996, J Hand Surg Br 21:451)"
    ),
    "lunotriquetral_rotation_deg": (
        "Ruby et al. 1988, J Hand Surg Am 13:1-10 (5 cadaver wrists, metal markers: the proximal row's "
        "bones less tightly bound than the distal row's but still moving together); Kobayashi et al. 1997, "
        "Hand Clin 13:143-149 (22 cadaver wrists: measurable relative motion between the proximal row's "
        "bones). Band: a few degrees between lunate and triquetrum over +-40 deg, as recalled from their "
        "figures (not read here: see the validation page)"
    ),
    "slil_force_30ext_n": (
        "Dimitris et al. 2015, J Hand Surg Am 40:1525-1533 (total SLIL force in active wrist "
        "motion ~20 N, 20.0 +- 3.3 N at 30 deg extension; the preprint's ref. 63)"
    ),
}
