"""The ligament catalogue: Table 2's eleven ligaments (the design's), the fixed ones outside the design (the
radial column's, the hamate's, the triquetrum's insertions), their measured properties and their sources —
the one owner. `design` builds the 27 design variables on the first eleven; the builder, the solver and the
outputs read the order of every per-bundle array from `ALL_LIGAMENT_NAMES`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "Ligament",
    "LIGAMENTS",
    "LIGAMENT_NAMES",
    "STIFFNESS_TZC",
    "SOURCE_TZC",
    "STIFFNESS_STT",
    "SOURCE_STT",
    "CH_RIG_FORCE_N",
    "CH_DISTRACTION_MM",
    "CH_BANDS",
    "STIFFNESS_CH",
    "SOURCE_CH",
    "CH_RIG_MOMENT_NMM",
    "CH_ROTATION_DEG",
    "CH_SHEAR_MM",
    "CH_JOINT_STIFFNESS",
    "FIXED_LIGAMENTS",
    "FIXED_REFERENCE_STRAIN",
    "COLUMN_LIGAMENTS",
    "HAMATE_LIGAMENTS",
    "BODY_LIGAMENTS",
    "ALL_LIGAMENTS",
    "ALL_LIGAMENT_NAMES",
    "INJURABLE",
    "RSC_INDEX",
]


@dataclass(frozen=True)
class Ligament:
    """One ligament of the catalogue: its name, fibre count, stiffness and source.

    Parameters
    ----------
    name : str
        The short name (e.g. "SLIL_v"), as the design variables and per-bundle arrays name it.
    full_name : str
        The anatomical name.
    fibres : int
        The fibre count (0 for the 2D RSC membrane).
    stiffness_mean, stiffness_sd : float
        The stiffness's population mean and SD, N/mm (Table 2's for the design's eleven).
    injurable : bool
        Whether the design has an injury scalar for it (`INJURABLE`).
    source : str
        The literature the stiffness comes from.
    """

    name: str
    full_name: str
    fibres: int
    stiffness_mean: float
    stiffness_sd: float
    injurable: bool
    source: str


LIGAMENTS = (
    Ligament("SLIL_v", "volar scapholunate interosseous ligament", 7, 33.0, 10.0, True, "Berger 2001"),
    Ligament("SLIL_p", "proximal (membranous) scapholunate interosseous ligament", 7, 25.0, 7.5, True, "Berger 2001"),
    Ligament("SLIL_d", "dorsal scapholunate interosseous ligament", 7, 79.0, 24.0, True, "Berger 2001"),
    Ligament("RSC", "radioscaphocapitate ligament", 0, 10.0, 3.0, True, "Berger 2001"),
    Ligament("LRL", "long radiolunate ligament", 4, 75.0, 23.0, True, "Berger 2001; Nagao 2005"),
    Ligament("SRL", "short radiolunate ligament", 4, 75.0, 23.0, False, "Nagao 2005"),
    Ligament("DRC", "dorsal radiocarpal ligament", 3, 75.0, 23.0, False, "Nagao 2005; Mizuseki 1989"),
    Ligament("RCL", "radial collateral ligament", 3, 10.0, 3.0, False, "Ringler 2013"),
    Ligament("SCL", "scaphocapitate ligament", 7, 40.0, 12.0, False, "Apergis 2013"),
    Ligament("UCL", "ulnocapitate ligament", 3, 75.0, 23.0, False, "Moritomo 2013"),
    Ligament("UL", "ulnolunate ligament", 3, 40.0, 12.0, False, "Nagao 2005"),
)
LIGAMENT_NAMES = tuple(lig.name for lig in LIGAMENTS)
STIFFNESS_TZC, SOURCE_TZC = 75.0, "Nagao 2005 (Table 2's palmar radiocarpal); Bajuri 2013"
STIFFNESS_STT, SOURCE_STT = 40.0, "Apergis 2013 (Table 2's SCL); Bajuri 2013"
"""No stiffness of the trapezocapitate or STT ligaments is published. As wrist FE models do for
ligaments without data (Bajuri & Abdul Kadir 2013, Computational Biomechanics of the Wrist Joint,
Springer: neighbours' properties, 40–350 N/mm in all), each takes a Table 2 neighbour's mean: the
trapezocapitate bands the short palmar radiocarpal ligaments' 75 N/mm (Nagao 2005), the palmar STT
ligament the scaphocapitate ligament's 40 N/mm (Apergis 2013), which shares its origin on the
scaphoid's distal pole; SD 30 % as in Table 2."""
CH_RIG_FORCE_N = 20.0
"""The force limit of Ritt et al.'s multiaxis rig (N; 0.5 N·m in rotation), under which they measured the
capitohamate joint's constraint (Ritt, Berger, Bishop & An 1996, J Hand Surg Br 21:451, as in their
lunotriquetral study: Ritt 1998, J Hand Surg Am 23:425)."""
CH_DISTRACTION_MM = 0.3
"""The capitohamate joint's distraction under `CH_RIG_FORCE_N` with its three interosseous ligaments
(deep, dorsal, palmar) intact (Ritt 1996)."""
CH_BANDS = 3
STIFFNESS_CH = CH_RIG_FORCE_N / CH_DISTRACTION_MM / CH_BANDS
"""Stiffness (N/mm) of each capitohamate interosseous band, from Ritt 1996's measured constraint: the
three bands resist distraction equally ("all three equal in distraction") and distraction pulls along
all three at once, so they act in parallel along the joint's normal: 20 N / 0.3 mm = 66.7 N/mm for
the three, 22.2 N/mm each. Their other roles come from where they lie, not from their stiffness: the
dorsal band at the joint's dorsal edge resists palmar rotation of the capitate (76 %) and palmar
translation (44 %); the deep band, distal between the facing surfaces, dorsal rotation (51 %) and
dorsal translation (63 %); their failure loads (deep 289 N, palmar 171 N, dorsal 133 N) rank their
strength, not their stiffness, and are not used. SD 30 % as in Table 2."""
SOURCE_CH = "Ritt 1996 (20 N / 0.3 mm distraction, three bands equal)"
CH_RIG_MOMENT_NMM = 500.0
"""The moment limit of Ritt et al.'s rig (N·mm: 0.5 N·m)."""
CH_ROTATION_DEG = 9.0
"""The capitohamate joint's dorsopalmar rotation (the capitate turning dorsally or palmarly on the hamate:
about the joint's normal, the radioulnar axis) under `CH_RIG_MOMENT_NMM`, each way (Ritt 1996)."""
CH_SHEAR_MM = 0.65
"""The joint's translation in its own plane under `CH_RIG_FORCE_N` (mm): the mean of Ritt 1996's four,
dorsopalmar 0.9 (palmar) and 0.5 (dorsal), proximodistal 0.8 and 0.4 mm. One value for the plane: the
two directions' means (0.7, 0.6 mm) differ by less than each direction's two ways, and a spring the same
every way in the plane needs only the joint's normal, which the geometry gives in any frame."""
CH_JOINT_STIFFNESS = (
    CH_RIG_FORCE_N / CH_SHEAR_MM,
    CH_RIG_FORCE_N / CH_SHEAR_MM,
    0.0,
    0.0,
    0.0,
    CH_RIG_MOMENT_NMM / float(np.radians(CH_ROTATION_DEG)),
)
"""The capitohamate joint's in-plane constraint (`solver.forces.joint_forces`), in the joint's axes
(two in its plane, then its normal, hamate to capitate): shifts (N/mm) then rotations (N·mm/rad). The
three bands (`HAMATE_LIGAMENTS`) are tension-only fibres across the joint: they resist its distraction
(and the rotations that open it) but, straight across a joint 2–3 mm wide, not a shear or a turn in its
plane, to first order (a fibre's end moved sideways by δ stretches it by δ²/2L). What Ritt 1996 measured
there, the ligaments' in-plane constraint, is this linear spring between the two bones at the joint's
centre: 20 N over 0.65 mm (30.8 N/mm) in the plane, 0.5 N·m over 9 deg (3.18 N·m/rad) about the normal;
nothing along the normal (the bands and the contact) nor
about the in-plane axes (they open the joint: the bands and the contact)."""
FIXED_LIGAMENTS = (
    Ligament("TC", "palmar triquetrocapitate ligament", 3, 20.0, 6.0, False, "Garcia-Elias 2017; Weaver 1994"),
    Ligament("TH", "palmar triquetrohamate ligament", 3, 20.0, 6.0, False, "Garcia-Elias 2017; Weaver 1994"),
    Ligament("TZC_p", "palmar trapezocapitate ligament", 3, STIFFNESS_TZC, 23.0, False, SOURCE_TZC),
    Ligament("TZC_d", "dorsal trapezocapitate ligament", 3, STIFFNESS_TZC, 23.0, False, SOURCE_TZC),
    Ligament("STT", "palmar scaphotrapeziotrapezoid ligament", 3, STIFFNESS_STT, 12.0, False, SOURCE_STT),
    Ligament(
        "CH_deep", "deep capitohamate interosseous ligament", 3, STIFFNESS_CH, 0.3 * STIFFNESS_CH, False, SOURCE_CH
    ),
    Ligament(
        "CH_d", "dorsal capitohamate interosseous ligament", 3, STIFFNESS_CH, 0.3 * STIFFNESS_CH, False, SOURCE_CH
    ),
    Ligament(
        "CH_p", "palmar capitohamate interosseous ligament", 3, STIFFNESS_CH, 0.3 * STIFFNESS_CH, False, SOURCE_CH
    ),
)
"""Ligaments outside the design: the radial column's (TZC_p, TZC_d, STT: `COLUMN_LIGAMENTS`,
stiffness above), the hamate's (CH_deep, CH_d, CH_p: `HAMATE_LIGAMENTS`, stiffness `STIFFNESS_CH`) and,
built with the distal row, the two insertions (capitate,
hamate) of the triquetrum–hamate–capitate ligament, the ulnar arm of the palmar arcuate
(midcarpal) ligament and the main passive stabilizer of the midcarpal joint in neutral
(Garcia-Elias 2017, Hand Clin 33:511; Weaver, Tencer & Trumble 1994, J Hand Surg Am 19:464;
its laxity is midcarpal instability: Lichtman 1981). No stiffness of it is published: the
ligament takes the mean of Table 2's radial palmar midcarpal ligament, the SCL (40 N/mm,
Apergis 2013), split equally between its two insertions, and `FIXED_REFERENCE_STRAIN`."""
FIXED_REFERENCE_STRAIN = 1.0
"""Reference strain of the fixed ligaments: just taut at neutral (the palmar ligaments are in
tension in the unloaded neutral wrist: Weaver 1994)."""
COLUMN_LIGAMENTS = ("TZC_p", "TZC_d", "STT")
"""The fixed ligaments that hold the radial column (`model.BODY_PARTS`): built in every variant."""
HAMATE_LIGAMENTS = ("CH_deep", "CH_d", "CH_p")
"""The fixed ligaments that hold the hamate to the capitate (`model.BODY_PARTS`): built in every variant."""
BODY_LIGAMENTS = COLUMN_LIGAMENTS + HAMATE_LIGAMENTS
"""The fixed ligaments that hold the distal row's free bodies: built in every variant (not TC and TH,
which `builder.params.BuildParams.fixed_ligaments` can leave out)."""
ALL_LIGAMENTS = LIGAMENTS + FIXED_LIGAMENTS
ALL_LIGAMENT_NAMES = tuple(lig.name for lig in ALL_LIGAMENTS)
"""The design's eleven ligaments, then the fixed ones: the order of every per-bundle output."""
INJURABLE = tuple(lig.name for lig in LIGAMENTS if lig.injurable)
RSC_INDEX = LIGAMENT_NAMES.index("RSC")
"""Index of the RSC, the one ligament modelled as a membrane, in `LIGAMENT_NAMES` and `ALL_LIGAMENT_NAMES`."""
