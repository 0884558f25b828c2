"""Errors of a complex-coefficient splitting along long runs: the complex map and its real projection.

Prints the numbers docs/integrators.md ("Complex coefficients") quotes: for the Strang step 12321 of ho3 composed
at the complex times (1 + i)h/2 and (1 - i)h/2, x0 = (1, 1, 1), the largest |Q(x_n) - Q(x_0)| and the slope of that
modulus (``nambu_bch.numeric.check``, complex128) for Q = H, G and the truncated shadow pair H_S^[k], G_S^[k]
(alpha = 1/2), on the complex map and on its real projection x_{n+1} = Re Phi_h(x_n); then the slope of the
projected run's |H(x_n) - H(x_0)| at h and h/2.  These are errors of exact arithmetic carried out in complex128,
not timings: they do not depend on the machine's load.

Run:  python benchmarks/complex_drift.py
"""

from __future__ import annotations

from nambu_bch.numeric.complex_iterate import complex_check

S3 = "1:1/4+I/4,2:1/4+I/4,3:1/2+I/2,2:1/4+I/4,1:1/2,2:1/4-I/4,3:1/2-I/2,2:1/4-I/4,1:1/4-I/4"


def main() -> None:
    print("ho3, S_{(1+i)h/2} S_{(1-i)h/2} of 12321, h = 0.1, x0 = (1, 1, 1)")
    for t_end in (200, 2000):
        for order in (2, 4):
            for project in (False, True):
                r = complex_check("ho3", S3, 0.1, int(t_end / 0.1), [1.0, 1.0, 1.0], order=order, project=project)
                errors = ", ".join(f"{k} {v:.2e}" for k, v in r.max_abs_error.items())
                slopes = ", ".join(f"{k} {v:.1e}" for k, v in r.drift_rate.items())
                print(f"t = {t_end:5d}  k = {order}  {'Re Phi_h' if project else 'Phi_h   '}  max |dQ|: {errors};  slope: {slopes}")
    for h in (0.1, 0.05):
        r = complex_check("ho3", S3, h, int(1000 / h), [1.0, 1.0, 1.0], project=True, include=("H",))
        print(f"projected run, t = 1000, h = {h}: max |dH| {r.max_abs_error['H']:.2e}, slope {r.drift_rate['H']:.2e}")


if __name__ == "__main__":
    main()
