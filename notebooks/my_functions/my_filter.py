# Written by lqe_helpers.student_code.save: edit the notebook, not this file.
# Loaded in later notebooks by student_code.load('my_filter').
import numpy as np


def my_filter(y, A, C, Q, R, z0, P0):
    """Tutorial eq. (5). From ẑ = z0 and P = P0, for each reading y_j in turn:
    K = P Cᵀ (C P Cᵀ + R)⁻¹, then ẑ ← A ẑ + K (y_j − C A ẑ), then P ← A (P − K C P) Aᵀ + Q;
    keep each ẑ. Returns the estimates, shape (n, k)."""
    z = z0
    P = P0
    estimates = []
    for y_j in y:
        S = C @ P @ C.T + R                    # covariance of the innovation
        K = np.linalg.solve(S.T, C @ P.T).T    # K = P Cᵀ S⁻¹: the K with K S = P Cᵀ
        z = A @ z + K @ (y_j - C @ A @ z)      # predict with A, correct with y_j
        P = A @ (P - K @ C @ P) @ A.T + Q      # covariance for the next step
        estimates.append(z)
    return np.array(estimates)
