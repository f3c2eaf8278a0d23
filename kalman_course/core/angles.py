r"""Angles : repli dans :math:`(-\pi, \pi]` (résidus d'azimut, différences finies d'un angle)."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["wrap_angle"]


def wrap_angle(a: Any) -> np.ndarray:
    r"""Ramène des angles (rad) dans :math:`(-\pi, \pi]`."""
    a = np.asarray(a, dtype=float)
    # np.mod(·, 2π) est dans [0, 2π) : π − mod(π − a, 2π) est dans (−π, π]
    return np.pi - np.mod(np.pi - a, 2.0 * np.pi)
