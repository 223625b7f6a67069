"""craters.exact: products summed in a fixed order, so that their bytes do not depend on
the CPU (issue 34). The kernels against pure-Python sums in the same order (IEEE float
arithmetic, one rounding per operation: equal to the last bit), and the crater diffusion,
which decides the bytes of every degraded crater, the same whatever kernels OpenBLAS picks
(``OPENBLAS_CORETYPE``: the product it replaced changed with it)."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys

import numpy as np
import pytest

from craters.exact import abs2, dot, matmul, plane_residual


def _python_matmul(a, b):
    out = np.empty((a.shape[0], b.shape[1]))
    for i in range(a.shape[0]):
        for j in range(b.shape[1]):
            acc = 0.0
            for k in range(a.shape[1]):
                acc += float(a[i, k]) * float(b[k, j])
            out[i, j] = acc
    return out


def _digests(script: str, variable: str, value: str) -> set[str]:
    """What ``script`` prints in a fresh process without ``variable`` and with it set."""
    out = set()
    for setting in (None, value):
        env = {k: v for k, v in os.environ.items() if k != variable}
        if setting:
            env[variable] = setting
        done = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True,
                              text=True, timeout=300, check=True)
        out.add(done.stdout.strip())
    return out


def test_matmul_is_the_in_order_sum_to_the_last_bit():
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=(9, 31)), rng.normal(size=(31, 7)) * 1e3
    got = matmul(a, b)
    assert got.tobytes() == _python_matmul(a, b).tobytes()
    np.testing.assert_allclose(got, a @ b, rtol=1e-12, atol=1e-9)
    # rows and columns as 1-D arrays, as numpy's @ takes them
    assert matmul(a[0], b).shape == (7,) and matmul(a, b[:, 0]).shape == (9,)
    assert matmul(a[0], b[:, 0]).shape == ()


def test_dot_is_the_in_order_sum():
    rng = np.random.default_rng(4)
    a, b = rng.normal(size=1001), rng.normal(size=1001)
    acc = 0.0
    for x, y in zip(a.tolist(), b.tolist(), strict=True):
        acc += x * y
    assert dot(a, b) == acc


def test_bad_shapes_are_refused():
    with pytest.raises(ValueError, match="do not multiply"):
        matmul(np.ones((2, 3)), np.ones((2, 3)))
    with pytest.raises(ValueError, match="differ"):
        dot(np.ones(3), np.ones(4))


_DIFFUSED = """
import hashlib, numpy as np
from craters.diffusion import diffuse_profiles, diffusion_nodes
r = diffusion_nodes()
h = np.where(r < 1.0, r * r - 1.0, 0.1 * r ** -3.0)
print(hashlib.sha256(diffuse_profiles(np.stack([h, 0.5 * h]), [0.01, 0.2]).tobytes())
      .hexdigest())
"""


def _blas_digests(script: str) -> set[str]:
    """:func:`_digests` with OpenBLAS's kernels picked by the CPU and with Prescott's (its
    SSE3 kernels, which every x86-64 CPU runs)."""
    if os.uname().machine not in ("x86_64", "AMD64"):
        pytest.skip("OPENBLAS_CORETYPE names x86-64 kernels; this machine is "
                    f"{os.uname().machine} (the in-order tests still run)")
    return _digests(script, "OPENBLAS_CORETYPE", "Prescott")


def test_diffusion_does_not_depend_on_the_blas_kernels():
    digests = _blas_digests(_DIFFUSED)
    assert len(digests) == 1, digests
    assert len(next(iter(digests))) == len(hashlib.sha256().hexdigest())


def test_abs2_is_re2_plus_im2():
    rng = np.random.default_rng(5)
    z = rng.normal(size=(33, 17)) + 1j * rng.normal(size=(33, 17))
    got = abs2(z)
    assert got.tobytes() == (z.real * z.real + z.imag * z.imag).tobytes()
    np.testing.assert_allclose(got, np.abs(z) ** 2, rtol=1e-14)


_SPECTRUM = """
import hashlib, numpy as np
from dem import Dem
from dem.terrain import power_spectrum
z = np.random.default_rng(2).standard_normal((96, 80)).cumsum(axis=0)
print(hashlib.sha256(np.concatenate(power_spectrum(Dem(z, pixel_size_m=5.0))).tobytes())
      .hexdigest())
"""


def test_the_dem_spectrum_does_not_depend_on_numpys_simd_loops():
    # numpy's abs of complex numbers differs in the last bit between its AVX2 and SSE loops
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__

    if "X86_V3" not in __cpu_dispatch__ or not __cpu_features__.get("X86_V3"):
        pytest.skip("numpy has no AVX2 (X86_V3) loops to turn off on this machine")
    digests = _digests(_SPECTRUM, "NPY_DISABLE_CPU_FEATURES", "X86_V3")
    assert len(digests) == 1, digests


def test_plane_residual_is_the_least_squares_plane_removed():
    rng = np.random.default_rng(6)
    for shape in ((33, 17), (1, 9), (8, 1), (1, 1), (64, 64)):
        yy, xx = np.mgrid[0:shape[0], 0:shape[1]]
        z = 5e3 + 3.0 * xx - 0.7 * yy + rng.normal(size=shape)
        design = np.column_stack([np.ones(z.size), xx.ravel(), yy.ravel()])
        want = z - (design @ np.linalg.lstsq(design, z.ravel(), rcond=None)[0]) \
            .reshape(shape)
        np.testing.assert_allclose(plane_residual(z), want, rtol=0, atol=1e-9)
    with pytest.raises(ValueError, match="2-D"):
        plane_residual(np.ones(3))


def test_the_dem_spectrum_does_not_depend_on_the_blas_kernels():
    # its plane fit went through LAPACK: under Prescott's kernels it hashed 4870209c...,
    # under this machine's own 871b63c1... (2026-12-07, before craters.exact.plane_residual)
    digests = _blas_digests(_SPECTRUM)
    assert len(digests) == 1, digests


_RIMS = """
import hashlib, numpy as np, craters
from latlong.sensors.labels import rim_curves
rng = np.random.default_rng(7)
xy = rng.uniform(-50, 50, (20000, 2))
z = 0.13 * xy[:, 0] - 0.05 * xy[:, 1] + 0.3 * np.exp(-((np.hypot(*xy.T) - 10) / 2) ** 2)
cat = craters.make_catalog(x_m=[0.0, 20.0], y_m=[0.0, -15.0], diameter_m=[20.0, 12.0],
                           centre_x_m=[0.0, 20.0], centre_y_m=[0.0, -15.0],
                           centre_z_m=[1e3, 1e3 + 3.35], normal_x=[0.0, 0.0],
                           normal_y=[0.0, 0.0], normal_z=[1.0, 1.0])
rims = rim_curves(cat, np.column_stack([xy, z + 1e3]))
print(hashlib.sha256(np.concatenate([a.ravel() for a in rims]).tobytes()).hexdigest())
"""


def test_fitted_crater_rims_do_not_depend_on_the_blas_kernels():
    # the labels' rim planes came from lstsq and d @ axis: two hashes (93eb3e9e... with this
    # machine's kernels, 9fd0aa94... with Prescott's) before latlong.sensors.labels._plane_of
    digests = _blas_digests(_RIMS)
    assert len(digests) == 1, digests


def test_the_rim_plane_is_the_least_squares_plane():
    from latlong.sensors.labels import _plane_of

    rng = np.random.default_rng(8)
    t = rng.uniform(0, 2 * np.pi, 40)
    for radius in (10.0, 1e-3):  # a 1 mm rim too: the last frames of a descent
        x, y = radius * np.cos(t), radius * np.sin(t)
        h = 2.0 + 0.1 * x - 0.3 * y + rng.normal(scale=0.001 * radius, size=40)
        ok, a, b, c = _plane_of(x, y, h, radius)
        design = np.column_stack([np.ones(40), x, y])
        assert ok
        np.testing.assert_allclose([a, b, c], np.linalg.lstsq(design, h, rcond=None)[0],
                                   rtol=1e-9, atol=1e-12)
    assert not _plane_of(np.arange(9.0), np.arange(9.0), np.ones(9), 1.0)[0]  # collinear
