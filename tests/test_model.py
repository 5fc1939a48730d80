"""The `Model`'s layout checks: a model of another body or pair count is refused by name, never simulated
(the kernels do not check bounds)."""

from dataclasses import replace

import numpy as np
import pytest

from wrist_env.errors import InputError
from wrist_env.model import BONES, PAIRS


def test_a_model_with_another_body_count_is_refused_naming_the_field(built):
    p1 = built("P1")
    with pytest.raises(InputError, match=r"model 'P1': com has shape \(4, 3\).*\(%d, 3\)" % len(BONES)):
        replace(p1, com=p1.com[:4])
    with pytest.raises(InputError, match="sample_offsets"):
        replace(p1, sample_offsets=np.append(p1.sample_offsets, p1.sample_offsets[-1]))
    assert len(p1.sample_offsets) == len(PAIRS) + 1


def test_a_fibre_on_a_body_the_model_lacks_is_refused(built):
    p1 = built("P1")
    bones = p1.fibre_bones.copy()
    bones[0, 1] = len(BONES)
    with pytest.raises(InputError, match="fibre_bones holds body index"):
        replace(p1, fibre_bones=bones)
