"""Wetting-ridge theory (bcfem.theory.ridge) against independent evaluations.

The reference quadrature here shares nothing with the module's contour method:
adaptive Gauss-Kronrod on the real axis (unit intervals) up to x = L, plus the
tail from the Hankel asymptotic expansions of both Bessel factors integrated by
QUADPACK's QAWF; its kernels come from a numerical 2x2 solve of the surface
balance instead of the module's elimination, and the layer compliance is
checked against a transfer matrix of the transformed Navier equations.
"""

import warnings

import numpy as np
import pytest
from scipy.integrate import IntegrationWarning, quad, quad_vec
from scipy.linalg import expm
from scipy.special import jv

from bcfem.theory import ridge

PAIRS = ((2, 0), (1, 0), (2, 1), (1, 1))  # u_z^n, u_z^t, u_r^n, u_r^t


def _asymptotic_factor(n, x):
    """Σ i^k a_k(n)/x^k: J_n(x) = sqrt(2/(πx)) Re[e^{i(x - nπ/2 - π/4)} S]."""
    total, term = 1.0 + 0j, 1.0 + 0j
    for k in range(1, 12):
        term = term * 1j * (4 * n * n - (2 * k - 1) ** 2) / (8 * k * x)
        total = total + term
    return total


def reference_integrals(rho, kernels, length=100.0):
    """{pair: ∫₀^∞ J_a(x) J_b(ρx) K_ab(x) dx} for smooth, non-oscillating kernels K_ab."""
    def near_integrand(x):
        k, far, close = kernels(x), jv([1, 2], x), jv([0, 1], rho * x)
        return np.array([far[a - 1] * close[b] * k[a, b] for a, b in PAIRS])

    near = quad_vec(near_integrand, 0.0, length, points=np.arange(1.0, length),
                    epsabs=1e-14, epsrel=1e-12, limit=5000)[0]
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IntegrationWarning)
        for index, (a, b) in enumerate(PAIRS):
            tail = 0.0
            # product of the two expansions: waves at (1+ρ)x and (1-ρ)x
            for omega, phase, conj in ((1 + rho, -(a + b + 1) * np.pi / 2, False),
                                       (1 - rho, -(a - b) * np.pi / 2, True)):
                def amplitude(x, a=a, b=b, phase=phase, conj=conj):
                    sb = _asymptotic_factor(b, rho * x)
                    sb = np.conj(sb) if conj else sb
                    return (_asymptotic_factor(a, x) * sb * np.exp(1j * phase) * kernels(x)[a, b]
                            / (np.pi * x * np.sqrt(rho)))

                if omega == 0.0:
                    tail += quad(lambda x: amplitude(x).real, length, np.inf, epsabs=1e-15)[0]
                    continue
                opts = dict(wvar=abs(omega), epsabs=1e-16, limlst=100)
                tail += quad(lambda x: amplitude(x).real, length, np.inf, weight="cos", **opts)[0]
                tail -= np.sign(omega) * quad(lambda x: amplitude(x).imag, length, np.inf,
                                              weight="sin", **opts)[0]
            out[a, b] = near[index] + tail
    return out


def reference_kernels(c, nu, thickness):
    """K_ab(x) from solving (I + M diag(0, γs k/μ)) μk[û_r, û_z] = M [σ̂_rz, σ̂_zz] numerically."""
    def kernels(x):
        m_tt, m_st, m_ss = map(float, ridge.layer_compliance(x * thickness if thickness else np.inf, nu))
        s = 0.0 if np.isinf(c) else x / ((1.0 - nu) * c)
        a00, a01, a10, a11 = 1.0, m_st * s, 0.0, 1.0 + m_ss * s  # I + M diag(0, s)
        det = a00 * a11 - a01 * a10
        inverse = ((a11 / det, -a01 / det), (-a10 / det, a00 / det))
        m = ((m_tt, m_st), (m_st, m_ss))
        r = [[-(inverse[i][0] * m[0][j] + inverse[i][1] * m[1][j]) for j in (0, 1)] for i in (0, 1)]
        # rows (û_r, û_z), columns (σ̂_rz ∝ J1, σ̂_zz ∝ J2)
        return {(2, 0): r[1][1], (1, 0): r[1][0], (2, 1): r[0][1], (1, 1): r[0][0]}
    return kernels


def responses(rho, c, nu, thickness=None):
    """{pair: value} of ring_responses at one ρ."""
    normal, tangential = ridge.ring_responses(rho, c, nu, thickness)
    return {(2, 0): float(normal.u_z), (1, 0): float(tangential.u_z),
            (2, 1): float(normal.u_r), (1, 1): float(tangential.u_r)}


@pytest.mark.parametrize("nu", [-0.5, 0.0, 0.3, 0.5])
@pytest.mark.parametrize("eta", [0.05, 0.5, 2.0, 6.0])
def test_layer_compliance_matches_transfer_matrix(nu, eta):
    # Hankel-transformed equilibrium and Hooke's law as y' = A y, y = (û_r, û_z, σ̂_rz, σ̂_zz)
    # at μ = k = 1; the rigid base sets û = 0 at depth η, so the top compliance is
    # Φ_ut Φ_tt⁻¹ with Φ = exp(Aη)
    a = np.array([[0, 1, 1, 0],
                  [-nu / (1 - nu), 0, 0, (1 - 2 * nu) / (2 * (1 - nu))],
                  [2 / (1 - nu), 0, 0, nu / (1 - nu)],
                  [0, 0, -1, 0]], dtype=float)
    phi = expm(a * eta)
    expected = phi[:2, 2:] @ np.linalg.inv(phi[2:, 2:])
    m_tt, m_st, m_ss = ridge.layer_compliance(eta, nu)
    np.testing.assert_allclose([[m_tt, m_st], [m_st, m_ss]], expected, rtol=1e-11, atol=1e-14)


@pytest.mark.parametrize("nu", [-0.5, 0.0, 0.3, 0.5])
def test_layer_compliance_limits(nu):
    m_tt, m_st, m_ss = ridge.layer_compliance(np.inf, nu)  # Boussinesq and Cerruti
    np.testing.assert_allclose([m_tt, m_st, m_ss], [1 - nu, (1 - 2 * nu) / 2, 1 - nu], rtol=1e-15)
    eta = 1e-4  # a thin layer shears (û_r = h σ_rz/μ) and compresses oedometrically
    m_tt, m_st, m_ss = ridge.layer_compliance(eta, nu)
    assert m_tt / eta == pytest.approx(1.0, rel=1e-6)
    if nu < 0.5:
        assert m_ss / eta == pytest.approx((1 - 2 * nu) / (2 * (1 - nu)), rel=1e-6)
    else:  # incompressible: lubrication-like û_z = h³k² σ̂_zz/(3μ)
        eta = 1e-3
        assert ridge.layer_compliance(eta, nu)[2] / eta**3 == pytest.approx(1 / 3, rel=1e-5)


def _dissertation_kernels(x, c, nu, half_thickness):
    """Eq. 5.17-5.18 as printed, r̃0 = r0/h: u_z and u_r kernels of the normal load."""
    r0 = 1.0 / half_thickness
    k = 3 - 4 * nu
    den = 8 * x**2 + r0**2 * (1 - 2 * nu) * k * (1 - np.cosh(4 * x / r0))
    f_r1 = x * r0 * (1 - 2 * nu) * (4 * x - r0 * k * np.sinh(4 * x / r0)) / den
    f_r2 = 1 - 8 * (1 - nu) * ((1 - 2 * nu) * (1 - nu) * r0**2 + 2 * x**2) / den
    f_z = ((-(5 - 12 * nu + 8 * nu**2) * r0**2 - 8 * x**2 - r0**2 * k * np.cosh(4 * x / r0))
           / (4 * x * r0 - r0**2 * k * np.sinh(4 * x / r0)))
    with np.errstate(invalid="ignore"):
        u_r = -(1 - 2 * nu) / 2 / (f_r1 / c + f_r2)
    return -(1 - nu) / (x / c + f_z), u_r


def test_dissertation_layer_is_twice_as_thick():
    x, c, thickness = np.array([0.3, 1.0, 2.5]), 4.0, 1.0
    for nu in (0.0, 0.3):
        ours = ridge._kernels(x, 1 / ((1 - nu) * c), nu, x * thickness)
        printed = _dissertation_kernels(x, c, nu, thickness / 2)  # -h <= z <= h
        np.testing.assert_allclose(printed, [ours[2, 0], ours[2, 1]], rtol=1e-12)
        as_used = _dissertation_kernels(x, c, nu, thickness)
        assert np.all(np.abs(as_used[0] - ours[2, 0]) > 1e-3)
    # at ν = 1/2 the printed u_r is 0/0; the limit is finite and nonzero
    printed = _dissertation_kernels(x, c, 0.5, thickness / 2)[1]
    ours = ridge._kernels(x, 1 / (0.5 * c), 0.5, x * thickness)[2, 1]
    assert np.all(np.isnan(printed)) and np.all(np.abs(ours) > 1e-3)


@pytest.mark.parametrize("rho, c, nu, thickness", [
    (0.3, 0.1, 0.3, None), (1.0, 10.0, 0.5, None), (1.5, 1e3, -0.3, None), (0.9, 1.0, 0.0, None),
    (0.7, 5.0, 0.5, 0.5), (1.0, 2.0, 0.3, 2.0), (2.0, np.inf, 0.25, 1.0)])
def test_against_independent_quadrature(rho, c, nu, thickness):
    got = responses(rho, c, nu, thickness)
    expected = reference_integrals(rho, reference_kernels(c, nu, thickness))
    for pair in PAIRS:
        if rho == 1.0 and pair == (1, 1):  # the tangential ring: u_r ~ log|ρ - 1|
            assert got[pair] == -np.inf
            continue
        assert got[pair] == pytest.approx(expected[pair], rel=1e-9, abs=1e-12), pair


@pytest.mark.parametrize("rho", [0.4, 0.95, 1.3, 4.0])
def test_bare_ring_loads_in_closed_form(rho):
    # c = ∞: Boussinesq ring + uniform disc and the Cerruti ring, elliptic integrals
    got = responses(rho, np.inf, 0.3)
    expected = reference_integrals(rho, reference_kernels(np.inf, 0.3, None))
    for pair in PAIRS:
        assert got[pair] == pytest.approx(expected[pair], rel=1e-9, abs=1e-12), pair


def test_large_c_tends_to_bare_ring_loads():
    rho = [0.0, 0.5, 0.9, 1.2, 3.0]
    bare = np.array(ridge.ring_responses(rho, np.inf, 0.3))
    gaps = [np.abs(np.array(ridge.ring_responses(rho, c, 0.3)) - bare).max() for c in (1e5, 1e6)]
    # 1 - w(x) = x/(c + x): the surface tension is a 1/c perturbation away from r0
    assert gaps[1] < 2e-6 and gaps[0] / gaps[1] == pytest.approx(10.0, rel=1e-3)


@pytest.mark.parametrize("nu", [-0.2, 0.3, 0.5])
@pytest.mark.parametrize("theta", [np.pi / 2, 1.0, 2.2])
def test_ridge_height_asymptote(nu, theta):
    for c in (1e3, 1e4, 1e5, 1e6):
        exact = ridge.ridge_height(c, nu, theta)
        assert abs(exact - ridge.ridge_height_asymptote(c, nu, theta)) < 2 * np.log(c) / c**2


def test_ridge_height_slope_refutes_eq_5_34():
    # eq. 5.34: u_z(r0) μ/((1-ν)γl) ≈ log c / π^{1/4} + const at θ = π/2
    rise = (ridge.ridge_height(1e6, 0.5) - ridge.ridge_height(1e3, 0.5)) / 0.5
    assert rise == pytest.approx(np.log(1e3) / np.pi + 1e-6 - 1e-3, rel=1e-5)
    assert abs(rise - np.log(1e3) / np.pi**0.25) > 2.0


@pytest.mark.parametrize("thickness", [None, 0.7])
def test_incompressible_limit_is_continuous(thickness):
    rho = [0.2, 1.0, 2.5]
    at_half = np.array(ridge.ring_responses(rho, 3.0, 0.5, thickness))
    near_half = np.array(ridge.ring_responses(rho, 3.0, 0.5 - 1e-7, thickness))
    finite = np.isfinite(at_half)
    assert np.all(np.isfinite(at_half[:, :, [0, 2]]))
    np.testing.assert_allclose(at_half[finite], near_half[finite], rtol=0, atol=1e-6)


def test_thick_layer_tends_to_half_space():
    rho, gaps = [0.0, 1.0, 2.0], []
    half = np.array(ridge.ring_responses(rho, 3.0, 0.3))
    for h in (25.0, 50.0):
        layer = np.array(ridge.ring_responses(rho, 3.0, 0.3, thickness=h))
        finite = np.isfinite(half)
        gaps.append(np.abs(layer[finite] - half[finite]).max())
    # a radial ring's far field falls like 1/h², a self-equilibrated normal one like 1/h³
    assert gaps[1] < 2e-4 and gaps[0] / gaps[1] > 3.5


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.5])
def test_thin_layer_compresses_oedometrically(nu):
    # under the drop, far from the edge, the Laplace pressure 2γl sinθ/r0 squeezes a
    # thin layer by p h (1-2ν)/(2μ(1-ν)): zero for an incompressible one
    theta, h = 1.2, 0.01
    u_z = float(ridge.surface_displacement(0.3, 3.0, nu, theta, thickness=h).u_z)
    assert u_z / h == pytest.approx(-np.sin(theta) * (1 - 2 * nu) / (1 - nu), abs=1e-4)


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.5])
@pytest.mark.parametrize("thickness", [None, 0.1, 1.0])
def test_signs_of_the_normal_load(nu, thickness):
    for c in (0.1, 10.0, 1e4):
        normal, _ = ridge.ring_responses([0.0, 1.0], c, nu, thickness)
        assert normal.u_z[0] < 0 < normal.u_z[1]  # pressed under the drop, a ridge at r0


def test_signs_of_the_ridge_with_the_shear_load():
    for c in (0.1, 10.0, 1e4):
        normal, tangential = ridge.ring_responses(1.0, c, 0.5)
        assert tangential.u_z == 0.0  # (1-2ν) M: an incompressible half-space ignores it
        for theta in (0.2, np.pi / 2, 2.9):
            assert ridge.ridge_height(c, 0.5, theta) == pytest.approx(np.sin(theta) * normal.u_z)
        for nu in (0.0, 0.3):  # an outward pull (θ > π/2) lifts the tip further
            for theta in (np.pi / 2, 2.0, 2.9):
                assert ridge.ridge_height(c, nu, theta) > 0
    # an inward pull (θ < π/2) sinks the tip of a compressible half-space by
    # (1-2ν) cosθ/4 (c → ∞); at c = 1 that beats the lift for θ = π/4
    assert ridge.ridge_height(1.0, 0.3, np.pi / 4) < 0 < ridge.ridge_height(1.0, 0.3, 1.2)


def test_zero_net_force_far_field():
    # the ring lifts with 2πr0 γl sinθ, the Laplace pressure pushes with the same: no
    # Boussinesq 1/r term; the second moment π r0³ γl sinθ gives u_z → (1-ν) r0³/(8 r³)
    rho = np.array([20.0, 40.0])
    normal, _ = ridge.ring_responses(rho, 100.0, 0.3)
    scaled = normal.u_z * rho**3 / ((1 - 0.3) / 8)
    assert abs(scaled[1] - 1) < 1e-3 and abs(scaled[1] - 1) < abs(scaled[0] - 1)


def test_membrane_limit():
    theta, rho = 1.0, [0.0, 0.5, 1.5]
    for nu in (0.3, 0.5):
        u_z = ridge.surface_displacement(rho, 1e-4, nu, theta).u_z / 1e-4
        np.testing.assert_allclose(u_z, ridge.membrane_deflection(rho, nu, theta), rtol=0, atol=2e-4)


def test_rejects_parameters_out_of_range():
    with pytest.raises(ValueError, match="nu"):
        ridge.ring_responses(0.5, 1.0, 0.6)
    with pytest.raises(ValueError, match="c ="):
        ridge.ring_responses(0.5, 0.0, 0.3)
    with pytest.raises(ValueError, match="thickness"):
        ridge.ring_responses(0.5, 1.0, 0.3, thickness=0.0)
