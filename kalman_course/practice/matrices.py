"""Matrices aléatoires des cas cachés (graine fixe : les cas et donc les verdicts se reproduisent)."""

from __future__ import annotations

import numpy as np

__all__ = ["generator", "spd", "nonsymmetric", "gaussian"]


def generator(seed: int) -> np.random.Generator:
    """Le générateur d'un exercice (une graine par exercice)."""
    return np.random.default_rng(seed)


def spd(rng: np.random.Generator, n: int, scale: float = 1.0) -> np.ndarray:
    """Une matrice symétrique définie positive pleine, bien conditionnée, de taille ``scale``."""
    L = rng.standard_normal((n, n))
    return scale * (L @ L.T / n + 0.3 * np.eye(n))


def nonsymmetric(rng: np.random.Generator, n: int) -> np.ndarray:
    """Une transition non symétrique proche de l'identité (``A ≠ Aᵀ`` dès que n ≥ 2)."""
    A = np.eye(n) + 0.4 * rng.standard_normal((n, n))
    if n >= 2:
        A[0, 1] += 0.5  # garantit A ≠ Aᵀ
    return A


def gaussian(rng: np.random.Generator, n: int, scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Une moyenne (n,) et une covariance (n, n) pleines."""
    return rng.standard_normal(n), spd(rng, n, scale)
