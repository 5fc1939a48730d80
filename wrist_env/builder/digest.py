"""The key of a built model (`source_hash`): a hash of everything a build depends on, computed without
loading the builder, so that finding a cached or shipped model imports none of it."""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict

import numpy as np

from wrist_env.anatomy.annotations import read_annotation_data
from wrist_env.builder.params import BuildParams
from wrist_env.model import BONES

BUILDER_VERSION = 9  # 9: the triquetrum a body of its own, its lunotriquetral ligaments (LT_v, LT_p, LT_d) and joint, the ulnotriquetral ligament (UT), its lunotriquetral, ulnotriquetral and triquetrohamate contacts ("ulnocarpal" split into ulnolunate and ulnotriquetral); 8: the hamate a body of its own, its capitohamate ligaments (CH_deep, CH_d, CH_p) and joint, its capitohamate and triquetrohamate contacts and grid; 7: the fossae end at the radius' ulnar border, the ulna seated by the corner rule on bone, the TFCC at fibrocartilage's stiffness; 6: the TFCC (the ulna's head closed and gridded, the ulnocarpal pair); 5: the radial column a body of its own (trapezium + trapezoid), its STT and trapeziocapitate contacts and ligaments; 2: distal row and triquetrum as body parts, swept fossae; 3: both by default, TC and TH; 4: the distal row seated (anatomy.midcarpal)


def source_hash(name: str, bones: dict, params: BuildParams) -> str:
    """Hash of everything a build depends on: bones, parameters, builder and annotation versions. A
    parameter left None (`BuildParams.ulnar_variance_mm`: the bones as given) is left out, so that adding
    an optional parameter keeps the keys of the models built without it (the shipped ones among them)."""
    h = hashlib.sha256()
    hashed = {k: v for k, v in asdict(params).items() if v is not None}
    h.update(json.dumps({"name": name, "params": hashed, "builder": BUILDER_VERSION}, sort_keys=True).encode())

    h.update(json.dumps(read_annotation_data(), sort_keys=True).encode())
    for bone in BONES:
        h.update(np.ascontiguousarray(np.round(bones[bone].vertices, 6)).tobytes())
        h.update(np.ascontiguousarray(bones[bone].faces).tobytes())
        h.update(np.ascontiguousarray(bones[bone].part).tobytes())
    return h.hexdigest()[:16]
