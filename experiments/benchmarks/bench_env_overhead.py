"""What an environment step costs beyond the simulation it wraps (issue 12/13: at most 5 %).

The kernel's entry point (`kernel.entry`) is replaced by a copy of a stored run's outputs, so what is
timed is the Python around it: the action's checks, the design, the kernel arrays, the cost and the
info dict. Prints that time for `WristEnv.step` and for a bare `simulate` call, in ms, and as a share
of one real simulation. Run on a quiet machine: `python experiments/benchmarks/bench_env_overhead.py`.
"""

from __future__ import annotations

import time

import numpy as np

from wrist_env import design
from wrist_env.envs.wrist import WristEnv
from wrist_env.solver import kernel
from wrist_env.solver import simulate as sim


def per_call_s(fn, n: int) -> float:
    start = time.perf_counter()
    for _ in range(n):
        fn()
    return (time.perf_counter() - start) / n


def main(participant: str = "P1", n: int = 500) -> None:
    env = WristEnv(participant, "calibrate")
    env.reset(seed=0)
    d = design.population()
    action = design.to_action(d)
    task = env.task
    sim.simulate(task.model, d, task.driver)  # load the compiled kernel first
    real = per_call_s(lambda: sim.simulate(task.model, d, task.driver), 10)
    stored = {}
    entry = kernel.entry  # the compiled entry point for a run's settings (`kernel.entry`)

    def capture(settings):
        def run(*args):
            entry(settings)(*args)
            stored["out"] = [np.array(x, copy=True) for x in args[8]]  # the run's Outputs (the 9th argument)

        return run

    def replay(settings):
        def run(*args):
            for dst, src in zip(args[8], stored["out"]):
                dst[...] = src

        return run

    kernel.entry = capture
    env.step(action)
    kernel.entry = replay
    try:
        step = per_call_s(lambda: env.step(action), n)
        bare = per_call_s(lambda: sim.simulate(task.model, d, task.driver), n)
    finally:
        kernel.entry = entry
    print(f"{participant} calibration trial: one simulation {real * 1e3:.2f} ms")
    print(
        f"the Python around the kernel: env.step {step * 1e3:.3f} ms ({100 * step / real:.1f} % of a simulation); "
        f"a bare simulate {bare * 1e3:.3f} ms ({100 * bare / real:.1f} %: it prepares the kernel arrays each call, "
        "which an environment does once)"
    )


if __name__ == "__main__":
    main()
