"""What the time limit costs a student's function that ends in time (issue 26).

Run: ``.venv/bin/python benchmarks/bench_student_code.py``. A plain-Python filter loop
of the kind a student writes (eq. (5), one step per reading, with a bare ``except`` in
its loop) is timed called directly (the peer) and through ``student_code.call`` (ours),
interleaved so that both see the same machine load. Before its deadline the call runs
with no trace or profile hook, so the ratio should be 1 up to ``call``'s fixed cost
(copies of the inputs, the guard of the pack's modules: about 0.1 ms). Target: median
ratio ≤ 1.05. The stopping itself is tested, not benchmarked
(``tests/student_code/test_student_code_stopping.py``).
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from lqe_helpers.student_code import call

REPEATS = 21
STEPS = 2000


def student_filter(y, A, C, Q, R, z0, P0):
    """Eq. (5) as a student writes it, one reading at a time (cm; y shape (n, m))."""
    z, P = A @ z0, P0.copy()
    estimates = np.empty((len(y), len(z0)))
    for j in range(len(y)):
        try:
            S = C @ P @ C.T + R
            K = P @ C.T @ np.linalg.inv(S)
            z = z + K @ (y[j] - C @ z)
            estimates[j] = z
            P = A @ (P - K @ C @ P) @ A.T + Q
            z = A @ z
        except:  # noqa: E722 - a student's bare except, which the stop must outlast
            pass
    return estimates


def main() -> None:
    rng = np.random.default_rng(0)
    A = np.array([[1.0, 0.01], [0.0, 1.0]])
    C = np.array([[1.0, 0.0]])
    Q, R = np.eye(2) * 1e-3, np.eye(1) * 4.0
    y = rng.normal(size=(STEPS, 1))
    args = (y, A, C, Q, R, np.zeros(2), np.eye(2))
    ours, peer = [], []
    for _ in range(REPEATS):
        start = time.perf_counter()
        student_filter(*args)
        peer.append(time.perf_counter() - start)
        start = time.perf_counter()
        call(student_filter, *args)
        ours.append(time.perf_counter() - start)
    ratios = [a / b for a, b in zip(ours, peer, strict=True)]
    print(f"direct call (peer): median {statistics.median(peer) * 1e3:.2f} ms")
    print(f"student_code.call:  median {statistics.median(ours) * 1e3:.2f} ms")
    print(f"ratio: median {statistics.median(ratios):.3f} (target <= 1.05)")


if __name__ == "__main__":
    main()
