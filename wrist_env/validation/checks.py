"""`validate`: the population design's runs, simulated once, and the chain of checks (`validation.chain.CHECKS`)
against published bands."""

from __future__ import annotations

import time

from wrist_env import design as design_mod
from wrist_env.builder.params import BuildParams
from wrist_env.limits import MAX_FRAMES, MAX_LOAD_N, check_float, check_int
from wrist_env.model import Model
from wrist_env.participants.registry import load_model
from wrist_env.solver.drivers import IDEALIZED_LOAD_N
from wrist_env.solver.settings import DEFAULT_LOADS, JIG
from wrist_env.validation.chain import CHECKS, run_chain
from wrist_env.validation.report import Report
from wrist_env.validation.simulations import run_simulations


def validate(
    name: str,
    *,
    model: Model | None = None,
    d: design_mod.Design | None = None,
    n_frames: int = 17,
    params: BuildParams | None = None,
    load_n: float = IDEALIZED_LOAD_N,
    load_direction: str = DEFAULT_LOADS,
    neutral_load: str = JIG,
    settings=None,
) -> Report:
    """Run the published-measurement checks on participant `name` (population design by default).

    The load and the frames are checked before the model loads (a NaN load used to fail the whole run).
    The runs are simulated once (`simulations.run_simulations`); the checks, `chain.CHECKS` in order, read
    them.

    Parameters
    ----------
    name : str
        A registered participant's name.
    model : Model, optional
        The model to check (default: the participant's, built or loaded with `params`).
    d : Design, optional
        The design simulated (default: the population design, `design.population()`).
    n_frames : int, default 17
        Frames of the idealized sweep, in [1, `limits.MAX_FRAMES`].
    params : BuildParams, optional
        Build parameters (the anatomy variant), default the default build.
    load_n : float, default `drivers.IDEALIZED_LOAD_N`
        The compressive load of the sweeps, N; the neutral pose takes `NEUTRAL_LOAD_N`.
    load_direction : str, default `settings.DEFAULT_LOADS`
        The loads' direction in the sweeps (`settings.LOAD_DIRECTIONS`).
    neutral_load : str, default `settings.JIG`
        The load at neutral, where RS/RL and the midcarpal and ulnar shares are measured: by default their
        experiments' (`settings.JIG`: the hand loaded axially in a jig, as Palmer & Werner 1984, Tencer
        1988, Hara 1992 and Viegas 1993 loaded it), not the tendons'.
    settings : SolverSettings, optional
        The solver's settings (`settings.SolverSettings`), default its defaults.

    Returns
    -------
    Report
        The checks (value, band, unit, source, pass), the series behind them, the conditions and the wall
        time.

    Raises
    ------
    InputError
        `load_n` not a finite number in [0, `limits.MAX_LOAD_N`] N, or `n_frames` out of range.
    ParticipantError
        An unknown participant (when no `model` is given).

    Examples
    --------
    .. code-block:: python

        from wrist_env.validation import format_table, validate

        report = validate("P1")
        print(format_table(report))
    """

    start = time.perf_counter()
    load_n = check_float("load_n", load_n, 0.0, MAX_LOAD_N, "N, compressive")
    n_frames = check_int("n_frames", n_frames, 1, MAX_FRAMES)
    params = params or BuildParams()
    model = model if model is not None else load_model(name, params)
    runs = run_simulations(
        model,
        d if d is not None else design_mod.population(),
        n_frames=n_frames,
        load_n=load_n,
        load_direction=load_direction,
        neutral_load=neutral_load,
        settings=settings,
    )
    conditions = {
        "fossa_sweep_deg": list(params.anatomy[0]),
        "distal_row": params.anatomy[1],
        "fixed_ligaments": bool(params.fixed_ligaments and params.distal_row),
        "load_n": float(load_n),
        "load_direction": load_direction,
    }
    return Report(model.name, run_chain(runs, CHECKS), runs.series(), time.perf_counter() - start, conditions)
