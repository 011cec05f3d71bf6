"""A test oracle: the tutorial's eqs. (5) and (7) as plain, readable loops.

Deliberately simple: one line of code per line of the tutorial, no batch axes, no
numerical refinements. The pack's fast engine (:func:`lqe_helpers.filter.kalman_filter`,
:func:`lqe_helpers.prediction.predict_ahead`) is tested equal to these to 1e-10
(``tests/test_reference.py``), and the checks' tests use them as the worked answers.

These loops answer tasks of notebooks 01 and 05, so they live here, outside the package,
and stay out of the student pack (which ships only the tests ``PACK_TESTS`` of
``lqe_helpers/authoring/student_pack.py`` lists). Imported by tests as ``reference_loops``
(pytest puts ``tests/`` on ``sys.path``).
"""

from __future__ import annotations

import numpy as np

from lqe_helpers import validation


def lqe_filter(y: np.ndarray, A: np.ndarray, C: np.ndarray, Q: np.ndarray, R: np.ndarray,
               z0: np.ndarray, P0: np.ndarray) -> np.ndarray:
    """The Linear Quadratic Estimator of Tutorial eq. (5), one measurement at a time.

    Starting from ``ẑ = z0`` and ``P = P0``, for each measurement ``y_j``::

        K = P Cᵀ (C P Cᵀ + R)⁻¹
        ẑ ← A ẑ + K (y_j − C A ẑ)
        P ← A (P − K C P) Aᵀ + Q

    With ``S = C P Cᵀ + R`` the gain ``K = P Cᵀ S⁻¹`` is the matrix that solves
    ``K S = P Cᵀ``. ``np.linalg.solve`` solves from the left, so it is given the
    transposed equation ``Sᵀ Kᵀ = C Pᵀ`` and its answer is transposed back. This is the
    same K as ``P @ C.T @ np.linalg.inv(S)`` up to rounding, but it stays accurate to
    about 1e-13 when S is nearly singular (two senses reading the same position under
    P0 = diag(10⁵) cm²), where the explicit inverse loses four more digits.

    Parameters
    ----------
    y : array_like, shape (n, m)
        Measurements (cm): n time steps of m sensors. For one sensor pass a column,
        shape (n, 1); a 1-D y is refused so that "n steps of one sensor" and "one step
        of n sensors" cannot be confused.
    A : array_like, shape (k, k)
        Transition matrix (Tutorial eq. (1)).
    C : array_like, shape (m, k)
        Observation matrix (Tutorial eq. (2)): one row per sensor.
    Q : array_like, shape (k, k)
        Process noise covariance.
    R : array_like, shape (m, m)
        Sensor noise covariance (cm²).
    z0 : array_like, shape (k,)
        Initial state estimate.
    P0 : array_like, shape (k, k)
        Initial covariance.

    Returns
    -------
    ndarray, shape (n, k)
        Row j is the estimate ``ẑ`` after measurement ``y_j`` (``z0`` itself is not a row).

    Raises
    ------
    ValueError
        If an input is not finite or the shapes do not fit together.
    """
    y, A, C, Q, R, z0, P0 = _checked(y, A, C, Q, R, z0, P0)
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


def student_lqe_filter(y, A, C, Q, R, z0, P0) -> np.ndarray:
    """Eq. (5) as a student writes it in notebook 01: :func:`lqe_filter` without its checks.

    The gain with the explicit inverse ``P Cᵀ (C P Cᵀ + R)⁻¹`` and no input check, so
    numpy broadcasts what the oracle refuses (a reading of one sensor against a model of
    two) and NaN readings pass through: what the checks and explorers must cope with.
    Estimates (n, k), row j after reading ``y[j]``.
    """
    z, P, rows = np.array(z0, dtype=float), np.array(P0, dtype=float), []
    for y_j in y:
        K = P @ C.T @ np.linalg.inv(C @ P @ C.T + R)
        z = A @ z + K @ (y_j - C @ A @ z)
        P = A @ (P - K @ C @ P) @ A.T + Q
        rows.append(z)
    return np.array(rows)


def filterpy_run(y: np.ndarray, A, C, Q, R, z0, P0) -> dict[str, np.ndarray]:
    """Eq. (5) by filterpy (an independent implementation), started from the prior A·z0.

    After each ``update(y_j)`` the posterior mean and covariance, the gain, the residual
    and its covariance; after each ``predict()`` the prior of the next step. Returns
    arrays by name, each with a leading axis of n: ``estimates`` (n, k), ``gains``
    (n, k, m), ``estimate_covariances`` and ``covariances`` (n, k, k), ``innovations``
    (n, m) and ``innovation_covariances`` (n, m, m).
    """
    from filterpy.kalman import KalmanFilter

    A, C = np.asarray(A, dtype=float), np.asarray(C, dtype=float)
    kf = KalmanFilter(dim_x=A.shape[0], dim_z=C.shape[0])
    kf.F, kf.H, kf.Q, kf.R = A, C, Q, R
    kf.x, kf.P = A @ z0, np.array(P0, dtype=float)
    out: dict[str, list[np.ndarray]] = {name: [] for name in (
        "estimates", "gains", "estimate_covariances", "covariances", "innovations",
        "innovation_covariances")}
    for y_j in y:
        kf.update(y_j)
        out["estimates"].append(kf.x.copy())
        out["gains"].append(kf.K.copy())
        out["estimate_covariances"].append(kf.P.copy())
        out["innovations"].append(kf.y.copy())
        out["innovation_covariances"].append(kf.S.copy())
        kf.predict()
        out["covariances"].append(kf.P.copy())
    return {name: np.array(values) for name, values in out.items()}


def compensate(estimates: np.ndarray, A: np.ndarray, delay_steps: int) -> np.ndarray:
    """Delay compensation of Tutorial eq. (7): ``z*_j = A^δ ẑ_{j−δ}``.

    Parameters
    ----------
    estimates : array_like, shape (n, k)
        Estimates ``ẑ`` of a filter fed the delayed signal, one row per sample.
    A : array_like, shape (k, k)
        Transition matrix of one sample.
    delay_steps : int
        Delay δ in samples, 0 <= δ < n.

    Returns
    -------
    ndarray, shape (n, k)
        Row j is ``A^δ`` times row ``j − δ`` of ``estimates``; the first δ rows are NaN
        because no estimate that old exists yet (the tutorial's hint).

    Raises
    ------
    ValueError
        If a shape does not fit or ``delay_steps`` is not a whole number in [0, n).
    """
    estimates = validation.finite_array("estimates", estimates, min_ndim=2)
    if estimates.ndim != 2:
        raise ValueError(f"estimates must have shape (n, k), got shape {estimates.shape}")
    n, k = estimates.shape
    A = validation.square_matrix("A", A, size=k)
    if A.ndim != 2:
        raise ValueError(f"A must have shape ({k}, {k}), got shape {A.shape}")
    delay_steps = validation.count("delay_steps", delay_steps, minimum=0, maximum=n - 1)
    A_delta = np.linalg.matrix_power(A, delay_steps)
    z_star = np.full((n, k), np.nan)
    for j in range(delay_steps, n):
        z_star[j] = A_delta @ estimates[j - delay_steps]
    return z_star


def _checked(y, A, C, Q, R, z0, P0) -> tuple[np.ndarray, ...]:
    """The inputs of :func:`lqe_filter` as float arrays, or a ``ValueError`` naming the misfit."""
    y = validation.finite_array("y", y, min_ndim=1)
    if y.ndim != 2:
        raise ValueError(
            f"y must have shape (n, m): n time steps of m sensors (for one sensor a column "
            f"of shape (n, 1)), got shape {y.shape}")
    m = y.shape[1]
    A = validation.square_matrix("A", A)
    if A.ndim != 2:
        raise ValueError(f"A must have shape (k, k), got shape {A.shape}")
    k = A.shape[0]
    expected = {"C": (m, k), "Q": (k, k), "R": (m, m), "z0": (k,), "P0": (k, k)}
    arrays = {}
    for name, value in {"C": C, "Q": Q, "R": R, "z0": z0, "P0": P0}.items():
        arrays[name] = validation.finite_array(name, value)
        if arrays[name].shape != expected[name]:
            raise ValueError(
                f"{name} must have shape {expected[name]} for y of shape {y.shape} "
                f"(m = {m} sensors) and A of shape {A.shape} (k = {k} states), "
                f"got shape {arrays[name].shape}")
    return y, A, arrays["C"], arrays["Q"], arrays["R"], arrays["z0"], arrays["P0"]
