"""Which materials an unmixing keeps: the bias of leaving some out, the subsets scored.

See :func:`sbrdf_xr.invert.unmix` (``select``, ``drop_bias``).
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np

__all__ = ["DROP_Z", "bias_ratio", "subsets_to_score"]

#: The bias bound takes the left-out material's scale up to ``|estimate| + DROP_Z sigma``.
DROP_Z = 2.0


def bias_ratio(x_full: np.ndarray, cov_full: np.ndarray, cols: list[int], cov: np.ndarray) -> float:
    """Largest bias the omission of the other columns can cause, over the uncertainty.

    Leaving out the columns ``D`` shifts the estimates of the kept ones ``S`` by
    ``-C_SD C_DD^-1 x_D`` (``C`` the covariance of the full fit, Seber & Lee 2003, *Linear
    Regression Analysis*, §9.2); with ``|x_D|`` up to ``|estimate| + DROP_Z sigma`` of the
    full fit, the bias on estimate ``i`` is at most ``sum_j |B_ij| (|x_j| + DROP_Z s_j)``.
    """
    k = x_full.size
    dropped = [j for j in range(k) if j not in cols]
    if not dropped:
        return 0.0
    b = cov_full[np.ix_(cols, dropped)] @ np.linalg.pinv(cov_full[np.ix_(dropped, dropped)])
    reach = np.abs(x_full[dropped]) + DROP_Z * np.sqrt(np.clip(np.diag(cov_full)[dropped], 0, None))
    bias = np.abs(b) @ reach
    sig = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
    return float(np.max(bias / sig))


def subsets_to_score(select: str | None, k: int, kmax: int, score: Any) -> list[tuple[int, ...]]:
    """The subsets to score: all up to ``kmax``, a forward greedy path, or the full set."""
    full = tuple(range(k))
    if select is None:
        return [full]
    if select == "all":
        every = [c for r in range(1, kmax + 1) for c in itertools.combinations(range(k), r)]
        return every if full in every else [*every, full]
    chosen: tuple[int, ...] = ()
    out: list[tuple[int, ...]] = []
    best = np.inf
    while len(chosen) < kmax:  # forward greedy addition while the criterion drops
        trial = [tuple(sorted((*chosen, j))) for j in range(k) if j not in chosen]
        out.extend(trial)
        cand = min(trial, key=score)
        if score(cand) >= best:
            break
        chosen, best = cand, score(cand)
    return list(dict.fromkeys([*out, full]))
