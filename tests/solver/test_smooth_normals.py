"""Smooth contact normals (`SolverSettings.smooth_normals`): a continuous force field the Newton reference can balance."""

from dataclasses import replace

import numpy as np

from wrist_env import design
from wrist_env.participants import registry
from wrist_env.solver.contact import nodal_normals, sdf_lookup_scalar, sdf_lookup_smooth
from wrist_env.solver.drivers import experimental
from wrist_env.solver.equilibrium import nearest
from wrist_env.solver.settings import SolverSettings
from wrist_env.solver.simulate import simulate

SPACING = 0.5
ORIGIN = np.array([-6.0, -6.0, -6.0])
SHAPE = np.array([25, 25, 25])


def sphere_grid(radius=4.0):
    """Signed distance (mm) of a sphere at the origin sampled on a 0.5 mm grid, flattened C-order."""
    axes = [ORIGIN[i] + SPACING * np.arange(SHAPE[i]) for i in range(3)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    return (np.sqrt(X**2 + Y**2 + Z**2) - radius).astype(np.float32).ravel()


def test_smooth_gradient_is_the_sphere_normal_and_continuous_across_a_cell_face():
    """On a sphere's distance grid, the interpolated nodal gradient is the sphere's normal within 1°
    and changes by < 0.001° across a cell face, where the trilinear derivative jumps by 0.23°."""
    values = sphere_grid(radius=5.0)  # the probe (4.0, 1.1, 0.7) overcloses it by 0.8 mm
    normals = nodal_normals(values, np.array([0, len(values)]), SHAPE[None], np.array([SPACING]))
    face = ORIGIN[0] + SPACING * 20  # the x-face between cells 19 and 20 (x = 4.0 mm)
    eps = 1e-7

    def normal(lookup, x, y=1.1, z=0.7):
        if lookup is sdf_lookup_smooth:
            d, gx, gy, gz = sdf_lookup_smooth(values, normals, 0, SHAPE, ORIGIN, SPACING, x, y, z)
        else:
            d, gx, gy, gz = sdf_lookup_scalar(values, 0, SHAPE, ORIGIN, SPACING, x, y, z)
        g = np.array([gx, gy, gz])
        return g / np.linalg.norm(g)

    def angle(a, b):
        return np.degrees(np.arccos(np.clip(a @ b, -1.0, 1.0)))

    exact = np.array([face, 1.1, 0.7]) / np.linalg.norm([face, 1.1, 0.7])
    smooth_jump = angle(normal(sdf_lookup_smooth, face - eps), normal(sdf_lookup_smooth, face + eps))
    trilinear_jump = angle(normal(sdf_lookup_scalar, face - eps), normal(sdf_lookup_scalar, face + eps))
    assert angle(normal(sdf_lookup_smooth, face), exact) < 1.0
    assert smooth_jump < 1e-3 and trilinear_jump > 0.1, (smooth_jump, trilinear_jump)


def test_newton_balances_the_trial_with_smooth_normals(p1):
    """P1's population calibration trial: with smooth normals the Newton reference leaves less than
    0.01 N on the free bones in every frame (the field is continuous); with the trilinear derivative
    it cannot get below 0.1 N somewhere (a 1 N jump in a contact force for a 1e-7 mm move). Both start
    from the default solver's run (a trilinear explicit run would compile a solver of its own for
    nothing: Newton balances whichever field it is given)."""
    driver = experimental(p1, registry.trial("P1", "calibrate").pose("capitate"))
    result = simulate(p1, design.population(), driver)
    left = {}
    for smooth in (False, True):
        settings = replace(SolverSettings(), smooth_normals=smooth)
        left[smooth] = nearest(p1, design.population(), driver, result, settings).residual[:, 0].max()
    assert left[True] < 0.01 and left[False] > 0.1, left
