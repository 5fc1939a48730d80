import numpy as np
import pytest

from wrist_env.builder.contact_law import (
    ContactLawFit,
    TrilinearLaw,
    fit_contact_law,
    mooney_rivlin_confined_pressure,
)
from wrist_env.errors import InputError

C10, C01, D1 = 4.1, 0.41, 0.0475


@pytest.fixture(scope="module")
def fit() -> ContactLawFit:
    return fit_contact_law()


def test_fit_has_high_r2_and_matches_the_curve(fit):
    assert fit.r2 >= 0.99
    assert fit.strain.shape == fit.pressure.shape == (200,)
    assert fit.strain[-1] == pytest.approx(0.35)
    err = np.abs(fit.law.pressure(fit.strain) - fit.pressure).max()
    assert err < 0.02 * fit.pressure.max()


def test_fitted_law_is_monotone_and_zero_without_overclosure(fit):
    e = np.linspace(-0.2, 0.6, 20001)
    p = fit.law.pressure(e)
    assert np.all(np.diff(p) >= 0)
    assert np.all(p[e <= 0] == 0)
    assert np.all(p[e > 0] > 0)


def test_law_is_continuous_at_its_breakpoints(fit):
    law = fit.law
    for b in (law.e1, law.e2):
        lo, hi = law.pressure(b - 1e-12), law.pressure(b + 1e-12)
        assert hi - lo == pytest.approx(0.0, abs=1e-9)
    assert law.pressure(0.0) == 0.0
    assert law.pressure(1e-12) == pytest.approx(0.0, abs=1e-9)


def test_small_strain_tangent_is_the_confined_modulus():
    mu, bulk = 2 * (C10 + C01), 2 / D1
    aggregate = bulk + 4 * mu / 3
    h = 1e-6
    tangent = float(mooney_rivlin_confined_pressure(h, C10, C01, D1)) / h
    assert tangent == pytest.approx(aggregate, rel=0.005)
    assert mooney_rivlin_confined_pressure(0.0) == pytest.approx(0.0, abs=1e-12)


def test_mooney_rivlin_stress_is_dw_dlambda():
    """Central difference of the strain energy against the closed-form stress."""

    def energy(lam):
        i1 = lam ** (-2 / 3) * (2 + lam**2)
        i2 = lam ** (-4 / 3) * (1 + 2 * lam**2)
        return C10 * (i1 - 3) + C01 * (i2 - 3) + (lam - 1) ** 2 / D1

    strain = np.array([0.01, 0.1, 0.2, 0.3, 0.5])
    lam, h = 1 - strain, 1e-6
    numeric = -(energy(lam + h) - energy(lam - h)) / (2 * h)
    np.testing.assert_allclose(mooney_rivlin_confined_pressure(strain), numeric, rtol=1e-6)


def test_pressure_equals_manual_piecewise_evaluation():
    law = TrilinearLaw(e1=0.1, e2=0.25, k1=40.0, k2=60.0, k3=90.0)
    rng = np.random.default_rng(3)
    e = rng.uniform(-0.1, 0.5, 500)
    manual = []
    for x in e:
        if x <= 0:
            manual.append(0.0)
        elif x <= 0.1:
            manual.append(40 * x)
        elif x <= 0.25:
            manual.append(4.0 + 60 * (x - 0.1))
        else:
            manual.append(4.0 + 9.0 + 90 * (x - 0.25))
    np.testing.assert_allclose(law.pressure(e), manual, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(law.as_array(), [0.1, 0.25, 40.0, 60.0, 90.0])
    assert law.as_array().dtype == np.float64


def test_numba_kernel_agrees_with_pressure(fit):
    contact = pytest.importorskip("wrist_env.solver.contact")
    arr = fit.law.as_array()
    e = np.linspace(-0.1, 0.5, 101)
    kernel = np.array([contact.law_pressure(arr, x) for x in e])
    np.testing.assert_allclose(kernel, fit.law.pressure(e), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize(
    "params, match",
    [
        (dict(e1=0.0, e2=0.2, k1=1, k2=1, k3=1), r"0 < e1 < e2.*e1=0\.0"),
        (dict(e1=0.3, e2=0.2, k1=1, k2=1, k3=1), r"e1=0\.3, e2=0\.2"),
        (dict(e1=0.1, e2=0.2, k1=1, k2=-2.5, k3=1), r"k2 > 0.*k2=-2\.5"),
        (dict(e1=0.1, e2=0.2, k1=1, k2=1, k3=0.0), r"k3 > 0.*k3=0\.0"),
        (dict(e1=0.1, e2=np.nan, k1=1, k2=1, k3=1), r"finite"),
    ],
)
def test_bad_law_parameters_raise(params, match):
    with pytest.raises(InputError, match=match):
        TrilinearLaw(**params)


def test_bad_fit_and_curve_inputs_raise():
    with pytest.raises(InputError, match=r"max_strain=1\.2"):
        fit_contact_law(max_strain=1.2)
    with pytest.raises(InputError, match=r"n=3"):
        fit_contact_law(n=3)
    with pytest.raises(InputError, match=r"d1=-1"):
        mooney_rivlin_confined_pressure(0.1, d1=-1)
    with pytest.raises(InputError, match=r"< 1.*1\.5"):
        mooney_rivlin_confined_pressure([0.1, 1.5])
