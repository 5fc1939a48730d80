"""Build parameters (lengths mm, angles deg) and the command-line options that choose an anatomy variant."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from wrist_env.limits import (
    MAX_FOSSA_SWEEP_DEG,
    MAX_ULNAR_VARIANCE_MM,
    SWEEP_WHY,
    bounded_float,
    check_float,
    check_fossa_sweep,
)

if TYPE_CHECKING:
    import argparse

VARIANCE_WHY = "mm, + ulna plus; adults measure about -4 to +5"


def check_ulnar_variance(variance_mm: object, name: str = "ulnar_variance_mm") -> float:
    """The ulnar variance (mm) as a float if it is finite and within ± `MAX_ULNAR_VARIANCE_MM`; `InputError`
    naming the value."""
    return check_float(name, variance_mm, -MAX_ULNAR_VARIANCE_MM, MAX_ULNAR_VARIANCE_MM, VARIANCE_WHY)


TFC_MODULUS_RATIO = 0.25 / 0.64
"""The TFCC's stiffness relative to articular cartilage: the aggregate moduli of meniscal fibrocartilage
and of articular cartilage (0.25 and 0.64 MPa, Danso et al. 2018), for no modulus of the TFC disc is
published (it was indentation-tested, PMC4755783, without a value in the text)."""


@dataclass(frozen=True)
class BuildParams:
    """Build parameters (all lengths mm)."""

    contact_spacing_mm: float = 1.0
    grid_spacing_mm: float = 0.5
    grid_margin_mm: float = 3.0
    grnn_bandwidth_mm: float = 1.0
    max_thickness_mm: float = 1.1
    min_total_thickness_mm: float = 0.2
    membrane_along: int = 9
    membrane_across: int = 5
    seed: int = 0
    fossa_sweep_deg: tuple = (20.0, 10.0)
    """(flexion, deviation) half-ranges, deg, of the row's sweep that shapes the radius fossae
    ((0, 0): moulded to the neutral row; see `anatomy.radius_cap`)."""
    distal_row: bool = True
    """The triquetrum moves with the lunate and the trapezium, trapezoid and hamate with the
    capitate, bringing the STT and triquetrohamate contacts (`model.BODY_PARTS`) and the fixed
    TC and TH ligaments (`ligaments.FIXED_LIGAMENTS`); participant folders get these bones from
    the template (`anatomy.template.carry_parts`)."""
    fixed_ligaments: bool = True
    """Build the fixed TC and TH with the distal row (False: the lunate body is tied to the
    distal row by contact alone; for studying what they do)."""
    ulnar_variance_mm: float | None = None
    """The ulnar variance (mm, + ulna plus) to seat the ulna at: the ulna moved along the radius' long axis
    until `anatomy.ulnar_variance`'s corner rule gives it, before anything of the build is made from it
    (`anatomy.ulnar_variance.seat_ulna`). None: where the participant's bones put it (a participant
    folder may state it: participant.toml's `ulnar_variance_mm`, `registry.build_params`). Within
    ± `limits.MAX_ULNAR_VARIANCE_MM`; left out of `builder.digest.source_hash` when None, so the default
    parameters keep their models' keys. A built-in participant is seated at the adult mean
    (`participants.builtin.ULNAR_VARIANCE_MM`)."""
    tfc_disc_mm: float | None = None
    """The TFCC's thickness on the ulnar head (mm): the layer fills the ulnocarpal space up to this and no
    further (None: it fills it all). See `builder.pipeline.tfcc_thickness`."""
    tfc_modulus_ratio: float = TFC_MODULUS_RATIO
    """The TFCC layer's stiffness as a fraction of the radiocarpal cartilage's (the contact law's): it
    counts in the ulnocarpal pair's total thickness as its thickness / this ratio, two layers in series
    (`builder.contact_samples`). 1: cartilage; the default, fibrocartilage's (`TFC_MODULUS_RATIO`)."""
    ulnar_osteotomy_mm: float = 0.0
    """An ulnar osteotomy (mm, + lengthening, − shortening): the ulna moved along the radius' long axis after
    its TFCC layer is made at its seat, the disc unchanged, as Werner et al. 1986 changed the variance of
    cadaver wrists. Within ± `limits.MAX_ULNAR_VARIANCE_MM`."""

    def __post_init__(self):
        check_fossa_sweep(self.fossa_sweep_deg)  # refused before anything is built or cached from it
        if self.ulnar_variance_mm is not None:
            object.__setattr__(self, "ulnar_variance_mm", check_ulnar_variance(self.ulnar_variance_mm))
        object.__setattr__(
            self, "ulnar_osteotomy_mm", check_ulnar_variance(self.ulnar_osteotomy_mm, "ulnar_osteotomy_mm")
        )
        if self.tfc_disc_mm is not None:
            object.__setattr__(
                self, "tfc_disc_mm", check_float("tfc_disc_mm", self.tfc_disc_mm, 0.1, 10.0, "mm, the TFCC's thickness")
            )
        object.__setattr__(
            self,
            "tfc_modulus_ratio",
            check_float("tfc_modulus_ratio", self.tfc_modulus_ratio, 0.01, 10.0, "the TFCC's stiffness / cartilage's"),
        )

    @property
    def anatomy(self) -> tuple:
        """The template variant of these parameters: (fossa_sweep_deg, distal_row)."""
        return (tuple(float(a) for a in self.fossa_sweep_deg), bool(self.distal_row))


def add_anatomy_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the anatomy-variant options (`--fossa-sweep`, `--no-distal-row`) to an argparse parser."""
    d = BuildParams()
    parser.add_argument(
        "--fossa-sweep",
        nargs=2,
        type=bounded_float("fossa sweep half-range", 0.0, MAX_FOSSA_SWEEP_DEG, SWEEP_WHY),
        default=d.fossa_sweep_deg,
        metavar=("FLEXION", "DEVIATION"),
        help="anatomy variant: radius fossae as the envelope of the row swept +-these angles (deg); "
        f"0 0 moulds them to the neutral row (default {d.fossa_sweep_deg[0]:g} "
        f"{d.fossa_sweep_deg[1]:g})",
    )
    parser.add_argument(
        "--no-distal-row",
        dest="distal_row",
        action="store_false",
        help="anatomy variant: the five principal bones alone (no triquetrum, trapezium, trapezoid, "
        "hamate; no TC/TH ligaments)",
    )
    parser.add_argument(
        "--no-fixed-ligaments",
        dest="fixed_ligaments",
        action="store_false",
        help="anatomy variant: the distal row without the TC and TH ligaments",
    )


def anatomy_params(args: argparse.Namespace) -> BuildParams:
    """The `BuildParams` of parsed `add_anatomy_arguments` options."""
    return BuildParams(
        fossa_sweep_deg=tuple(float(a) for a in args.fossa_sweep),
        distal_row=bool(args.distal_row),
        fixed_ligaments=bool(args.fixed_ligaments),
    )
