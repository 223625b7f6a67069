"""radius_spectrum on a synthetic body with a known degree spectrum (issue 16 item 5).

Random a_lm with S_l = A l^-2 for 1 <= l <= 40 (each degree's power exactly prescribed:
the a_lm of one degree are rescaled to sum to S_l), radius R + sum a_lm Y_lm on an M = 100
grid; prints the worst relative error over degrees 1-40 and the power above 40 relative
to the total. Run: python tests/benchmarks/measure_radius_spectrum.py
"""

import numpy as np
from scipy.special import sph_harm_y

from latlong import Body, LatLongGrid, radius_spectrum


def main() -> None:
    M, LMAX, R = 100, 40, 1000.0
    g = LatLongGrid(M)
    theta, phi = np.pi / 2 - g.latitudes(), g.longitudes()
    rng = np.random.default_rng(16)
    r = np.full(g.n_vertices, R)
    want = np.zeros(LMAX + 1)
    for deg in range(1, LMAX + 1):
        s_l = 4.0 * deg**-2.0  # m^2
        c = rng.normal(size=2 * deg + 1)
        c *= np.sqrt(s_l / np.sum(c**2))
        want[deg] = s_l
        for k, m in enumerate(range(-deg, deg + 1)):
            y = sph_harm_y(deg, abs(m), theta, phi)
            basis = np.sqrt(2) * (np.real(y) if m > 0 else np.imag(y)) if m else np.real(y)
            r += c[k] * basis
    body = Body(g, r, radius_m=R)
    _degrees, p = radius_spectrum(body, 60)
    err = np.abs(p[1 : LMAX + 1] / want[1:] - 1)
    print(
        f"worst relative error l=1..{LMAX}: {err.max():.4f} at l={1 + err.argmax()}; "
        f"l=11..40 worst {err[10:].max():.4f}; l<=10 worst {err[:10].max():.4f}"
    )
    print(f"power above l={LMAX}: {p[LMAX + 1 :].sum() / want.sum():.4f} of the prescribed total")


if __name__ == "__main__":
    main()
