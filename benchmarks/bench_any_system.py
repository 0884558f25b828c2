"""Time of nb.shadow_hamiltonians for systems beyond the paper (one run; prints seconds, asserts nothing)."""

import time

import nambu_bch as nb

CASES = [("pendulum", "121", 4), ("exp-well", "121", 4), ("rational", "121", 4), ("henon-heiles", "121", 4),
         ("toda", "121", 2), ("fpu-beta", "121", 2), ("ho3-pair", "12321", 4), ("rigid-body-lp", "12321", 4)]

if __name__ == "__main__":
    for name, word, order in CASES:
        t = time.perf_counter()
        F = nb.shadow_hamiltonians(nb.model(name), word, order=order)
        print(f"{name:14s} {word} order {order}: exists={F.exists}  {time.perf_counter() - t:.2f} s", flush=True)
