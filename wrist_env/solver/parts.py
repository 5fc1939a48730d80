"""What the second process of `precompile` compiles: the block mass's kernels (`tangent.tangent`,
`membrane.substep`, `preconditioner.block_mass`) for the exact argument types the preconditioned entry
point calls them with, so that the entry point, compiling meanwhile in the first process, loads each
from Numba's cache when it reaches it.

Run: `python -m wrist_env.solver.parts {smooth,trilinear} MODEL`, MODEL a model's path as `Model.save` wrote it
(what `precompile.compiling` runs, on the model it simulates).
"""

from __future__ import annotations

import sys

import numpy as np
from numba import typeof, types

from wrist_env.design import population
from wrist_env.model import N_BODIES, Model
from wrist_env.solver import arrays, membrane, preconditioner, step, tangent
from wrist_env.solver.precompile import NORMALS
from wrist_env.solver.settings import SolverSettings


def part_signatures(model: Model, settings: SolverSettings) -> list[tuple[object, tuple]]:
    """(kernel, argument types) of each part as the preconditioned entry point calls it, in the order in
    which the entry point reaches them after the force kernels, typed on `model`'s arrays (the types do not
    depend on the model's sizes)."""
    from wrist_env.solver.simulate import prepare, stiffness  # simulate starts this module's process

    p = prepare(model, settings, arrays.EXPERIMENTAL)
    R, x = np.zeros((N_BODIES, 3, 3)), np.zeros((N_BODIES, 3))
    nodes = np.zeros((len(p.model.membrane_nodes), 3))
    design = stiffness(p, population())
    state = step.State(R, x, np.zeros_like(x), np.zeros_like(x), nodes, np.zeros_like(nodes))
    work = step.new_work(p.grids, nodes)
    m = preconditioner.metric()
    smooth = types.literal(bool(settings.smooth_normals))  # a compile-time constant in the entry point

    def typed(*args):
        return tuple(a if isinstance(a, types.Type) else typeof(a) for a in args)

    return [
        (tangent.tangent, typed(state, p.system, design, work, m, smooth)),
        (membrane.substep, typed(state, p.system, design, membrane.new_scratch(nodes), smooth)),
        (preconditioner.block_mass, typed(R, p.bodies, p.settings, m)),
    ]  # fmt: skip


def compile_parts(model: Model, settings: SolverSettings) -> None:
    """Compile (or load from Numba's cache) each part for the entry point's argument types on `model`."""
    for dispatcher, signature in part_signatures(model, settings):
        dispatcher.compile(signature)


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] not in NORMALS:
        raise SystemExit(f"usage: python -m wrist_env.solver.parts {{{','.join(NORMALS)}}} MODEL")
    compile_parts(Model.load(sys.argv[2]), SolverSettings(smooth_normals=sys.argv[1] == NORMALS[0]))
