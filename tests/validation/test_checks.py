"""`validation.validate` refuses its load and frames before the model loads (issue 53); fast, unlike
`tests/test_validation.py`, which runs the checks."""

import math

import pytest

from wrist_env import validation
from wrist_env.errors import InputError
from wrist_env.validation import checks


@pytest.mark.parametrize(
    "kwargs, says",
    [
        ({"load_n": math.nan}, "load_n must be a finite number in [0, 1,000] (N, compressive), but got nan"),
        ({"load_n": -5.0}, "load_n must be a finite number in [0, 1,000] (N, compressive), but got -5.0"),
        ({"n_frames": 0}, "n_frames must be an integer in [1, 10,000], but got 0"),
    ],
)
def test_validate_refuses_a_load_or_frames_out_of_range_before_the_model_loads(kwargs, says, monkeypatch):
    """Issue 53: a NaN load failed only after the whole run, a negative one was accepted."""
    monkeypatch.setattr(checks, "load_model", lambda *a, **k: pytest.fail("the model was loaded"))
    with pytest.raises(InputError) as refused:
        validation.validate("P1", **kwargs)
    assert says in str(refused.value)
