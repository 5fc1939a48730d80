"""Global sensitivity (`wrist_env.identification.sensitivity`): SALib's indices on functions whose indices are known,
then a small study of P1 through the vector environment."""

import numpy as np
import pytest

from wrist_env.cli import main
from wrist_env.identification import sensitivity


def ishigami(X, a=7.0, b=0.1):
    return np.sin(X[:, 0]) + a * np.sin(X[:, 1]) ** 2 + b * X[:, 2] ** 4 * np.sin(X[:, 0])


def test_sobol_indices_recover_the_ishigami_functions_closed_form():
    """Ishigami (a = 7, b = 0.1) on [-pi, pi]^3: S1 = 0.3139, 0.4424, 0 and ST = 0.5576, 0.4424, 0.2437
    (Sobol & Levitan 1999), within 0.05."""
    spec = sensitivity.problem(("x1", "x2", "x3"), (-np.pi, np.pi))
    X = sensitivity.sample("sobol", spec, 4096, seed=1)
    table = sensitivity.indices("sobol", spec, X, ishigami(X)[:, None], seed=1)
    np.testing.assert_allclose(table["S1"], [0.3139, 0.4424, 0.0], atol=0.05)
    np.testing.assert_allclose(table["ST"], [0.5576, 0.4424, 0.2437], atol=0.05)


def test_morris_screening_ranks_a_planted_function():
    """y = 4 x1 + x2² + 0 · x3 on [-1, 1]³: mu* of x1 is its slope over the whole range (4 × 2), x3's
    is 0, x2 in between."""
    spec = sensitivity.problem(("x1", "x2", "x3"))
    X = sensitivity.sample("morris", spec, 30, seed=2)
    Y = (4 * X[:, 0] + X[:, 1] ** 2)[:, None]
    mu = sensitivity.indices("morris", spec, X, Y, seed=2)["mu_star"].to_numpy()
    assert mu[0] == pytest.approx(8.0, rel=1e-9)
    assert 0.0 < mu[1] < mu[0] and mu[2] == 0.0


def test_sobol_needs_a_power_of_two():
    with pytest.raises(ValueError, match="power of 2"):
        sensitivity.sample("sobol", sensitivity.problem(), 100, seed=0)


def test_a_small_study_of_p1_writes_its_table_and_figure(tmp_path, capsys):
    """Morris with 2 trajectories (46 runs) on P1's calibration trial through the vector env: a row per
    output and material, finite non-negative mu*, a non-zero effect on the cost, and the figure."""
    code = main(["sensitivity", "P1", "--n", "2", "--motions", "calibrate", "--out", str(tmp_path)])
    assert code == 0
    import pandas as pd

    table = pd.read_csv(tmp_path / "sensitivity_P1_morris.csv")
    assert len(table) == len(sensitivity.OUTPUTS) * len(sensitivity.MATERIALS)
    assert set(table["output"]) == set(sensitivity.OUTPUTS) and set(table["material"]) == set(sensitivity.MATERIALS)
    assert np.all(np.isfinite(table["mu_star"])) and np.all(table["mu_star"] >= 0)
    assert table.loc[table["output"] == "cost", "mu_star"].max() > 0
    assert table["runs"].iloc[0] == 46 and 0.0 <= table["failed_share"].iloc[0] < 1.0
    assert (tmp_path / "sensitivity_P1_morris.png").stat().st_size > 10_000
    assert "P1 calibrate: cost mu_star" in capsys.readouterr().out


def test_a_motion_without_reference_kinematics_is_one_line_before_any_run(tmp_path, capsys, monkeypatch):
    """A folder participant's idealized sweep has no reference (its cost and errors are undefined): the
    study stops before building or simulating anything, with one line naming the participant, the motion
    and the motions that have one (it was `KeyError: 'error_p75'` after the runs)."""
    import dataclasses

    from wrist_env.participants import builtin
    from wrist_env.participants.folder import write_participant_folder

    folder = write_participant_folder(dataclasses.replace(builtin.source("P1"), name="S1"), tmp_path / "s1")
    monkeypatch.setattr(sensitivity, "task", lambda *a, **k: pytest.fail("a task was built"))
    code = main(["sensitivity", "S1", "--folder", str(folder), "--n", "2", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert (
        "participant 'S1' has no reference kinematics for the idealized motion (only the built-in participants' "
        "sweeps have one"
        in err
        and "motions with one: ['calibrate', 'validate']" in err
    ), err


@pytest.mark.parametrize(
    "method, n, seed, says",
    [
        ("morris", 0, 0, "n must be an integer in [2, 4,096]"),
        ("morris", 2_000_000, 0, "n must be an integer in [2, 4,096]"),
        (
            "sobol",
            3,
            0,
            "sobol needs n a power of 2 (Sobol' sequences), at least 2, but got 3: the nearest are 2 and 4",
        ),
        ("morris", 20, -1, "seed must be an integer in [0, 4,294,967,295], but got -1"),
    ],
)
def test_a_study_refuses_its_size_and_seed_before_anything_runs(method, n, seed, says, tmp_path):
    """Issue 53: n 2 million took 2.5 GB while sampling, n 0 and seed -1 were SALib's to fail on, sobol's
    n 3 a traceback; now one `InputError` before any sample or model."""
    from wrist_env.errors import InputError

    with pytest.raises(InputError) as refused:
        sensitivity.study("P1", method, n, seed=seed, out=tmp_path)
    assert says in str(refused.value)
    assert not any(tmp_path.iterdir())
