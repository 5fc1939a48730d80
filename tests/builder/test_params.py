"""`BuildParams` refuses anatomy variants that cannot be built, before anything is swept or cached (issue 53)."""

import math

import pytest

from wrist_env.builder.params import BuildParams
from wrist_env.errors import InputError
from wrist_env.limits import check_fossa_sweep


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


@pytest.mark.parametrize("value", [math.nan, math.inf, -5.01, 7.0, "1", True])
def test_an_ulnar_variance_out_of_range_is_refused(value):
    with pytest.raises(InputError, match=r"ulnar_variance_mm must be a finite number in \[-5, 5\] \(mm, \+ ulna plus"):
        BuildParams(ulnar_variance_mm=value)


def test_an_ulnar_variance_is_kept_as_a_float():
    assert BuildParams(ulnar_variance_mm=2).ulnar_variance_mm == 2.0
    assert isinstance(BuildParams(ulnar_variance_mm=-5).ulnar_variance_mm, float)
    assert BuildParams().ulnar_variance_mm is None


def test_a_variance_left_none_is_left_out_of_the_hash_and_a_value_is_in_it():
    """A variance left None is left out of the hash (adding the field kept the keys of the models built
    before it); each variance is a model of its own."""
    from wrist_env.builder.digest import source_hash
    from wrist_env.participants import registry

    bones = registry.bones("P1")
    default = source_hash("P1", bones, BuildParams())
    seated = {v: source_hash("P1", bones, BuildParams(ulnar_variance_mm=v)) for v in (-2.5, 0.0, 2.5)}
    assert len({default, *seated.values()}) == 4
    assert source_hash("P1", bones, BuildParams(ulnar_variance_mm=0)) == seated[0.0]


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("tfc_disc_mm", 0.0, r"tfc_disc_mm must be a finite number in \[0.1, 10\]"),
        ("tfc_disc_mm", float("nan"), "tfc_disc_mm must be a finite number"),
        ("tfc_modulus_ratio", 0.0, r"tfc_modulus_ratio must be a finite number in \[0.01, 10\]"),
        ("ulnar_osteotomy_mm", 6.0, r"ulnar_osteotomy_mm must be a finite number in \[-5, 5\]"),
    ],
)
def test_tfcc_and_osteotomy_parameters_out_of_range_are_refused(field, value, message):
    with pytest.raises(InputError, match=message):
        BuildParams(**{field: value})
