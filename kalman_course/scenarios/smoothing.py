r"""Scénario du chapitre « Lissage » : une cible sur une droite, à vitesse presque constante, suivie par
un capteur de position qui se tait pendant vingt secondes.

État :math:`x = [p, v]` (m, m/s), pas :math:`\Delta t = 1` s, accélération blanche continue de densité
:math:`q` (m²/s³) :

.. math::

    A = \begin{bmatrix} 1 & \Delta t \\ 0 & 1 \end{bmatrix},\qquad
    Q = q\begin{bmatrix} \Delta t^3/3 & \Delta t^2/2 \\ \Delta t^2/2 & \Delta t \end{bmatrix},\qquad
    C = [1\ \ 0],\qquad R = \sigma^2 .

La vérité est simulée avec le même modèle (graine fixe) ; les relevés des instants
:data:`GAP` manquent. Le filtre (:func:`~kalman_course.kalman_filter`) et le lisseur
(:func:`~kalman_course.rts_smoother`) sont ceux du paquet ; le chapitre, ses figures et ses tests
appellent :func:`target_run`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..core.models import LinearGaussianModel
from ..core.motion import constant_velocity
from ..core.results import FilterResult, freeze_fields
from ..core.simulation import simulate
from ..filters.kalman import kalman_filter
from ..filters.smoothers import SmootherResult, rts_smoother

__all__ = [
    "TARGET_DT",
    "TARGET_Q",
    "TARGET_SIGMA",
    "TARGET_STEPS",
    "TARGET_GAP",
    "TARGET_SEED",
    "TARGET_X0",
    "TARGET_P0",
    "target_model",
    "TargetRun",
    "target_run",
]

#: Pas de temps (s).
TARGET_DT = 1.0
#: Densité spectrale de l'accélération blanche (m²/s³).
TARGET_Q = 0.02
#: Écart-type du capteur de position (m).
TARGET_SIGMA = 2.0
#: Nombre de relevés.
TARGET_STEPS = 100
#: Relevés perdus : indices ``GAP[0]`` à ``GAP[1] - 1`` (instants 41 à 60 s).
TARGET_GAP = (40, 60)
#: Graine de la trajectoire et des relevés.
TARGET_SEED = 1965
#: État vrai initial (m, m/s) et a priori du filtre.
TARGET_X0 = np.array([0.0, 1.0])
TARGET_X0.setflags(write=False)
TARGET_P0 = np.diag([25.0, 1.0])
TARGET_P0.setflags(write=False)


def target_model(q: float = TARGET_Q, sigma: float = TARGET_SIGMA, dt: float = TARGET_DT) -> LinearGaussianModel:
    r"""Modèle à vitesse presque constante (voir le module) : :math:`A`, :math:`Q` d'une accélération
    blanche continue de densité ``q``, mesure de la position d'écart-type ``sigma``."""
    A, Q = constant_velocity(dt, q, dim=1)
    return LinearGaussianModel(A, [[1.0, 0.0]], Q, sigma**2)


@dataclass(frozen=True, eq=False)
class TargetRun:
    r"""Une exécution du scénario : ``time`` (T,) en s, ``truth`` (T, 2), ``y`` (T,) (NaN dans le trou),
    ``filtered`` (:class:`~kalman_course.FilterResult`), ``smoothed``
    (:class:`~kalman_course.SmootherResult`), ``gap`` (indices du trou), et les erreurs quadratiques
    moyennes de position (m) du filtre et du lisseur, sur tout l'horizon et dans le trou."""

    time: np.ndarray
    truth: np.ndarray
    y: np.ndarray
    filtered: FilterResult
    smoothed: SmootherResult
    gap: tuple[int, int]
    rmse_filter: float
    rmse_smoother: float
    rmse_filter_gap: float
    rmse_smoother_gap: float

    def __post_init__(self) -> None:
        freeze_fields(self, "time", "truth", "y")


def _rmse(estimate: np.ndarray, truth: np.ndarray) -> float:
    return float(np.sqrt(np.mean((estimate - truth) ** 2)))


@lru_cache(maxsize=8)
def target_run(gap: tuple[int, int] = TARGET_GAP, n_steps: int = TARGET_STEPS, seed: int = TARGET_SEED) -> TargetRun:
    """Simule la cible, retire les relevés du trou ``gap`` (indices ``gap[0]`` à ``gap[1] - 1``), filtre
    et lisse. Résultat mis en cache (mêmes arguments, même objet)."""
    model = target_model()
    sim = simulate(model, TARGET_X0, n_steps, rng=seed)
    y = np.array(sim.y[:, 0])
    y[gap[0]:gap[1]] = np.nan
    x0 = TARGET_X0 + np.array([3.0, -0.5])  # l'a priori du filtre n'est pas la vérité
    filtered = kalman_filter(model, y, x0, TARGET_P0)
    smoothed = rts_smoother(model, filtered, x0, TARGET_P0)
    p = sim.x[:, 0]
    inside = slice(*gap)
    return TargetRun(
        time=TARGET_DT * np.arange(1, n_steps + 1), truth=sim.x, y=y, filtered=filtered, smoothed=smoothed,
        gap=tuple(gap), rmse_filter=_rmse(filtered.x[:, 0], p), rmse_smoother=_rmse(smoothed.x[:, 0], p),
        rmse_filter_gap=_rmse(filtered.x[inside, 0], p[inside]),
        rmse_smoother_gap=_rmse(smoothed.x[inside, 0], p[inside]),
    )
