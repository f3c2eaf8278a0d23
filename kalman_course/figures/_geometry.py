"""Aides de tracé communes aux figures du filtrage non linéaire (ellipses de covariance)."""

from __future__ import annotations

import numpy as np


def ellipse_points(mean, cov, n_sigma: float = 1.0, n_points: int = 200) -> np.ndarray:
    r"""Points (n_points, 2) de l'ellipse :math:`(p - \mu)^T\Sigma^{-1}(p - \mu) = n_\sigma^2` (bloc 2×2)."""
    lam, V = np.linalg.eigh(np.asarray(cov, dtype=float)[:2, :2])
    t = np.linspace(0.0, 2.0 * np.pi, n_points)
    circle = np.stack([np.cos(t), np.sin(t)])
    return (np.asarray(mean, dtype=float)[:2, None] + n_sigma * (V * np.sqrt(np.clip(lam, 0, None))) @ circle).T


def draw_ellipse(ax, mean, cov, n_sigma: float = 1.0, **kwargs) -> None:
    """Trace l'ellipse à ``n_sigma`` écarts-types de la covariance 2×2 ``cov`` autour de ``mean``."""
    pts = ellipse_points(mean, cov, n_sigma)
    ax.plot(pts[:, 0], pts[:, 1], **kwargs)
