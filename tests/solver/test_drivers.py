"""The drivers refuse sizes and values that would reach the solver as NaN or fill memory, before they touch
the model (issue 53): `model=None` below, since nothing of it may be read first."""

import math

import pytest

from wrist_env.errors import InputError
from wrist_env.solver import drivers


@pytest.mark.parametrize(
    "kwargs, says",
    [
        ({"n_frames": 3_000_000}, "n_frames must be an integer in [1, 10,000], but got 3000000"),
        ({"n_frames": 0}, "n_frames must be an integer in [1, 10,000], but got 0"),
        ({"n_frames": 1e8}, "n_frames must be an integer in [1, 10,000], but got 100000000.0"),
        ({"flexion_deg": math.nan}, "flexion_deg must be a finite number in [-90, 90] (deg), but got nan"),
        ({"extension_deg": 400.0}, "extension_deg must be a finite number in [-90, 90] (deg), but got 400.0"),
        ({"angles_deg": [0.0, math.nan]}, "angles_deg must be 1 to 10,000 finite angles within +-90 deg"),
        ({"angles_deg": []}, "angles_deg must be 1 to 10,000 finite angles"),
    ],
)
def test_an_idealized_sweep_out_of_bounds_is_refused(kwargs, says):
    with pytest.raises(InputError) as refused:
        drivers.idealized(None, **kwargs)
    assert says in str(refused.value)


def test_a_static_hold_of_too_many_frames_is_refused():
    with pytest.raises(InputError, match=r"n_frames must be an integer in \[1, 10,000\], but got 3000000"):
        drivers.static(None, 3_000_000)


@pytest.mark.parametrize("load_n", [math.nan, -5.0, [10.0, math.inf]])
def test_a_load_that_is_not_a_finite_push_is_refused(load_n):
    with pytest.raises(InputError, match="load_n must be finite and >= 0 N"):
        drivers.loaded(None, [[[1.0, 0, 0], [0, 1, 0], [0, 0, 1]]] * 2, load_n=load_n)


@pytest.mark.parametrize(
    "motion, kwargs, says",
    [
        ("sweep", {}, "motion must be one of ('calibrate', 'validate', 'idealized', 'static'), but got 'sweep'"),
        ("calibrate", {}, "the 'calibrate' motion is a trial's: give its trial"),
        ("static", {"trial": object()}, "the 'static' motion takes no trial"),
        ("idealized", {"n_frames": 0}, "n_frames must be an integer in [1, 10,000], but got 0"),
    ],
)
def test_a_motion_without_what_it_needs_is_refused(motion, kwargs, says):
    with pytest.raises(InputError) as refused:
        drivers.for_motion(None, motion, **kwargs)
    assert says in str(refused.value)


def test_each_motion_maps_to_its_driver(p1):
    """`for_motion` is the one map from a motion's name to a driver (the task's and `wrist-bench simulate`'s): the
    sweep is the loaded driver through 17 angles from 40° of flexion, the hold three identity frames, a trial the
    experimental driver through its capitate's poses under its load; a trial motion takes its trial's frames."""
    from wrist_env.participants import registry
    from wrist_env.solver import arrays

    sweep = drivers.for_motion(p1, "idealized")
    assert sweep.mode == arrays.LOADED and sweep.n_frames == 17 and sweep.angle_deg[0] == 40.0
    assert sweep.angle_deg[-1] == -40.0
    hold = drivers.for_motion(p1, "static")
    assert hold.mode == arrays.EXPERIMENTAL and hold.n_frames == 3 and not hold.load_n.any()
    trial = registry.trial("P1", "validate")
    driven = drivers.for_motion(p1, "validate", trial)
    assert driven.mode == arrays.EXPERIMENTAL and driven.n_frames == trial.n_frames
    assert (driven.load_n == trial.load_n).all() and driven.load_n.max() > 0
    with pytest.raises(InputError, match=f"has its trial's {trial.n_frames} frames, but got n_frames=5"):
        drivers.for_motion(p1, "validate", trial, n_frames=5)
