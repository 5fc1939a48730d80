"""`BuildParams` refuses anatomy variants that cannot be built, before anything is swept or cached (issue 53)."""

import math

import pytest

from wrist_env.builder.params import BuildParams, check_fossa_sweep
from wrist_env.errors import InputError


@pytest.mark.parametrize(
    "sweep, says",
    [
        ((math.nan, math.nan), "fossa_sweep_deg flexion must be a finite number in [0, 90]"),
        ((20.0, math.inf), "fossa_sweep_deg deviation must be a finite number in [0, 90]"),
        ((-5.0, 10.0), "but got -5.0"),
        ((20.0, 91.0), "but got 91.0"),
        ((20.0,), "must be two angles (flexion, deviation)"),
    ],
)
def test_a_fossa_sweep_out_of_range_is_refused(sweep, says):
    with pytest.raises(InputError) as refused:
        BuildParams(fossa_sweep_deg=sweep)
    assert says in str(refused.value)


def test_the_default_and_the_moulded_sweeps_are_taken():
    assert BuildParams().anatomy[0] == (20.0, 10.0)
    assert check_fossa_sweep([0, 0]) == (0.0, 0.0)
