r"""Scénario « suivi d'un tag radio (UWB) » : un tag à vitesse constante dans une pièce de 10 m × 8 m,
quatre ancres fixes aux coins qui mesurent leur distance au tag (notes « algorithme EKF tag »).

Le tag parcourt un huit à environ 1 m/s (:func:`tag_trajectory`) ; le filtre le modélise à vitesse
constante avec une accélération blanche. État :math:`x = [p_x, p_y, v_x, v_y]` (m, m/s), mesure :math:`y = [\lVert p - a_1\rVert, \dots, \lVert p - a_4\rVert]`
(m). La ligne :math:`i` de la jacobienne :math:`H` est le vecteur unitaire de l'ancre :math:`a_i` vers le tag :

.. math::

    H_{i,:} = \Big[\tfrac{(p - a_i)^T}{\lVert p - a_i\rVert},\ 0,\ 0\Big].

Pour les curseurs du chapitre : :func:`tag_data` donne les données (fixes, graine :data:`TAG_SEED`),
:func:`run_tag_ekf` refait le filtrage pour un couple (bruit d'accélération, bruit de distance) du filtre,
:func:`position_rmse` le résume.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from ..filters.extended import extended_kalman_filter
from ..filters.unscented import unscented_kalman_filter
from ..core.models import NonlinearModel
from ..core.results import FilterResult, freeze_fields
from ..core.simulation import as_generator
from ..tables import Table
from ..core.validation import KalmanInputError, as_float_array, shape_text
from ..core.motion import constant_velocity

__all__ = [
    "TAG_ANCHORS",
    "TAG_ROOM",
    "TAG_DT",
    "TAG_ACCEL_STD",
    "TAG_RANGE_STD",
    "TAG_N_STEPS",
    "TAG_SEED",
    "TAG_PATH_PERIOD",
    "TAG_X0",
    "TAG_P0",
    "TAG_TRANSIENT_STEPS",
    "TAG_UKF_ALPHA",
    "TAG_UKF_BETA",
    "TAG_UKF_KAPPA",
    "TagData",
    "tag_trajectory",
    "tag_ranges",
    "tag_ranges_jacobian",
    "tag_model",
    "tag_data",
    "run_tag_ekf",
    "run_tag_ukf",
    "position_rmse",
    "TagComparison",
    "tag_comparison",
    "rmse_grid",
    "rmse_table",
]

#: Dimensions de la pièce (m) : :math:`L \times l`.
TAG_ROOM = (10.0, 8.0)
#: Ancres aux quatre coins de la pièce (m), forme (4, 2).
TAG_ANCHORS = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 8.0], [0.0, 8.0]])
TAG_ANCHORS.setflags(write=False)
#: Période d'échantillonnage (s).
TAG_DT = 0.1
#: Écart-type de l'accélération (m/s²) du modèle du filtre (réglage nominal de :math:`Q`).
TAG_ACCEL_STD = 0.5
#: Écart-type du bruit des distances mesurées (m).
TAG_RANGE_STD = 0.10
#: Nombre de pas simulés (30 s).
TAG_N_STEPS = 300
#: Graine du bruit des distances du chapitre.
TAG_SEED = 2026
#: Période (s) du huit parcouru par le tag.
TAG_PATH_PERIOD = 30.0
#: Estimation initiale du filtre : le centre de la pièce, à l'arrêt.
TAG_X0 = np.array([5.0, 4.0, 0.0, 0.0])
TAG_X0.setflags(write=False)
#: Covariance initiale du filtre : 3 m d'écart-type sur la position, 1 m/s sur la vitesse.
TAG_P0 = np.diag([9.0, 9.0, 1.0, 1.0])
TAG_P0.setflags(write=False)
#: Pas ignorés par :func:`position_rmse` (régime transitoire, 2 s).
TAG_TRANSIENT_STEPS = 20
#: Points sigma de l'UKF du tag : :math:`\alpha = 0{,}1`, :math:`\beta = 2`, :math:`\kappa = 3 - n` (n = 4).
TAG_UKF_ALPHA = 0.1
TAG_UKF_BETA = 2.0
TAG_UKF_KAPPA = -1.0


def tag_ranges(x: np.ndarray, anchors: np.ndarray = TAG_ANCHORS) -> np.ndarray:
    r"""Distances du tag aux ancres :math:`h(x)_i = \lVert p - a_i\rVert` (m) : forme (n_ancres,) pour un
    état (4,), (N, n_ancres) pour une pile d'états (N, 4) (modèle vectorisé)."""
    x = np.asarray(x)
    return np.linalg.norm(x[..., None, :2] - anchors, axis=-1)


def tag_ranges_jacobian(x: np.ndarray, anchors: np.ndarray = TAG_ANCHORS) -> np.ndarray:
    r"""Jacobienne :math:`H = \partial h/\partial x` (n_ancres, 4) : lignes = vecteurs unitaires ancre → tag."""
    d = x[:2] - anchors
    H = np.zeros((anchors.shape[0], 4))
    H[:, :2] = d / np.linalg.norm(d, axis=1, keepdims=True)
    return H


def tag_model(
    accel_std: float = TAG_ACCEL_STD,
    range_std: float = TAG_RANGE_STD,
    dt: float = TAG_DT,
    anchors: Any = TAG_ANCHORS,
) -> NonlinearModel:
    r"""Modèle du tag : dynamique linéaire à vitesse constante, distances non linéaires.

    :math:`f(x) = Fx` (jacobienne :math:`F` constante), :math:`Q = \sigma_a^2GG^T`,
    :math:`h` = :func:`tag_ranges` (jacobienne :func:`tag_ranges_jacobian`), :math:`R = \sigma_r^2 I`.
    Modèle vectorisé : ``f`` et ``h`` acceptent aussi une pile d'états (N, 4).
    ``accel_std`` (m/s²) et ``range_std`` (m) sont les réglages du filtre (pas forcément ceux des données).
    """
    for name, value in (("accel_std", accel_std), ("range_std", range_std), ("dt", dt)):
        if not (np.isscalar(value) and np.isfinite(value) and value > 0):
            raise KalmanInputError(f"« {name} » doit être un réel strictement positif ; reçu {value!r}.")
    A = np.array(anchors, dtype=float)
    if A.ndim != 2 or A.shape[1] != 2 or A.shape[0] < 1:
        raise KalmanInputError(f"« anchors » doit être de forme (N, 2) ; reçu {shape_text(A.shape)}.")
    F, Q = constant_velocity(dt, accel_std=accel_std)
    return NonlinearModel(
        f=lambda x, u: x.dot(F.T),  # un état (4,) ou une pile (N, 4)
        h=lambda x: tag_ranges(x, A),
        Q=Q,
        R=range_std**2 * np.eye(A.shape[0]),
        f_jacobian=F,
        h_jacobian=lambda x: tag_ranges_jacobian(x, A),
        vectorized=True,
    )


@dataclass(frozen=True, eq=False)
class TagData:
    r"""Données du scénario : ``t`` (T,) instants (s), ``x_true`` (T, 4) états vrais, ``y`` (T, N) distances
    mesurées (m), ``anchors`` (N, 2), ``dt`` (s), ``x0`` (4,) et ``P0`` (4, 4) l'initialisation du filtre."""

    t: np.ndarray
    x_true: np.ndarray
    y: np.ndarray
    anchors: np.ndarray
    dt: float
    x0: np.ndarray
    P0: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "t", "x_true", "y", "anchors", "x0", "P0")


def tag_trajectory(t: Any) -> np.ndarray:
    r"""Trajectoire vraie du tag : un huit (courbe de Lissajous) parcouru en :data:`TAG_PATH_PERIOD` secondes,

    .. math::

        p_x(t) = 5 + 3{,}5\cos\omega t,\qquad p_y(t) = 4 + 2{,}5\sin 2\omega t,\qquad \omega = 2\pi/30\ \text{rad/s},

    avec sa vitesse exacte ; forme (T, 4) pour ``t`` (T,) en secondes. Vitesse jusqu'à 1,05 m/s,
    accélération jusqu'à 0,44 m/s² : le modèle à vitesse constante du filtre n'est qu'une approximation,
    que le bruit d'accélération :math:`\sigma_a` = 0,5 m/s² doit couvrir.
    """
    t = np.asarray(t, dtype=float)
    w = 2.0 * np.pi / TAG_PATH_PERIOD
    return np.stack(
        [
            5.0 + 3.5 * np.cos(w * t),
            4.0 + 2.5 * np.sin(2.0 * w * t),
            -3.5 * w * np.sin(w * t),
            5.0 * w * np.cos(2.0 * w * t),
        ],
        axis=-1,
    )


def tag_data(n_steps: int = TAG_N_STEPS, rng: Any = TAG_SEED) -> TagData:
    r"""Trajectoire vraie (:func:`tag_trajectory`, échantillonnée à :data:`TAG_DT`) et distances bruitées
    (:math:`\sigma_r` = :data:`TAG_RANGE_STD`, graine ``rng``). Le filtre part du centre de la pièce, à l'arrêt
    (:data:`TAG_X0`, :data:`TAG_P0`), alors que le tag est en :math:`(8{,}5 ; 4)` m et avance à 1 m/s."""
    gen = as_generator(rng)
    if not isinstance(n_steps, (int, np.integer)) or isinstance(n_steps, bool) or n_steps < 1:
        raise KalmanInputError(f"« n_steps » doit être un entier ≥ 1 ; reçu {n_steps!r}.")
    t = TAG_DT * np.arange(1, n_steps + 1)
    x_true = tag_trajectory(t)
    ranges = np.array([tag_ranges(x) for x in x_true])
    y = ranges + TAG_RANGE_STD * gen.standard_normal(ranges.shape)
    return TagData(t=t, x_true=x_true, y=y, anchors=TAG_ANCHORS, dt=TAG_DT, x0=TAG_X0, P0=TAG_P0)


def run_tag_ekf(
    accel_std: float = TAG_ACCEL_STD, range_std: float = TAG_RANGE_STD, data: TagData | None = None
) -> FilterResult:
    """EKF sur les données du tag avec les réglages ``accel_std`` (m/s²) et ``range_std`` (m) du filtre."""
    data = tag_data() if data is None else data
    model = tag_model(accel_std, range_std, data.dt, data.anchors)
    return extended_kalman_filter(model, data.y, data.x0, data.P0)


def run_tag_ukf(
    accel_std: float = TAG_ACCEL_STD,
    range_std: float = TAG_RANGE_STD,
    data: TagData | None = None,
    *,
    alpha: float = TAG_UKF_ALPHA,
    beta: float = TAG_UKF_BETA,
    kappa: float = TAG_UKF_KAPPA,
) -> FilterResult:
    r"""Même problème avec le filtre de Kalman unscented du paquet
    (:func:`~kalman_course.unscented_kalman_filter`), points sigma :math:`(\alpha, \beta, \kappa)`
    (par défaut :math:`0{,}1`, 2 et :math:`3 - n = -1`)."""
    data = tag_data() if data is None else data
    model = tag_model(accel_std, range_std, data.dt, data.anchors)
    return unscented_kalman_filter(model, data.y, data.x0, data.P0, alpha=alpha, beta=beta, kappa=kappa)


def position_rmse(x_est: Any, x_true: Any, skip: int = TAG_TRANSIENT_STEPS) -> float:
    r"""Erreur quadratique moyenne de position (m), :math:`\sqrt{\frac1{T-s}\sum_{k\ge s}\lVert\hat p_k - p_k\rVert^2}`,
    en ignorant les ``skip`` premiers pas (régime transitoire)."""
    est, true = as_float_array("x_est", x_est), as_float_array("x_true", x_true)
    for name, arr in (("x_est", est), ("x_true", true)):
        if arr.ndim != 2 or arr.shape[1] < 2:
            raise KalmanInputError(
                f"« {name} » doit être une suite d'états (T, n), n ≥ 2, la position dans les deux premières "
                f"colonnes ; reçu {shape_text(arr.shape)}."
            )
    if est.shape != true.shape:
        raise KalmanInputError(
            f"« x_est » et « x_true » doivent avoir la même forme ; reçu {est.shape} et {true.shape}."
        )
    e = est[skip:, :2] - true[skip:, :2]
    if e.shape[0] == 0:
        raise KalmanInputError(f"« skip » = {skip} ne laisse aucun pas pour l'erreur quadratique moyenne.")
    return float(np.sqrt(np.mean(np.sum(e**2, axis=1))))


@dataclass(frozen=True, eq=False)
class TagComparison:
    r"""L'EKF et l'UKF du tag sur les mêmes mesures (réglages nominaux) : ``data``, ``ekf``, ``ukf`` ;
    ``ekf_error``, ``ukf_error`` (T,) : erreurs de position :math:`\lVert\hat p_k - p_k\rVert` (m) ;
    ``gap`` (T,) : écart :math:`\lVert\hat p^{\text{EKF}}_k - \hat p^{\text{UKF}}_k\rVert` (m) ;
    ``ekf_rmse``, ``ukf_rmse`` : :func:`position_rmse` (m, régime transitoire exclu)."""

    data: TagData
    ekf: FilterResult
    ukf: FilterResult
    ekf_error: np.ndarray
    ukf_error: np.ndarray
    gap: np.ndarray
    ekf_rmse: float
    ukf_rmse: float

    def __post_init__(self) -> None:
        freeze_fields(self, "ekf_error", "ukf_error", "gap")


@lru_cache(maxsize=1)
def tag_comparison() -> TagComparison:
    """L'EKF et l'UKF sur les données du tag (:func:`tag_data`) avec les réglages nominaux ; calculé une
    fois par processus (le chapitre de l'UKF et sa figure le partagent ; le résultat est immuable)."""
    data = tag_data()
    ekf, ukf = run_tag_ekf(data=data), run_tag_ukf(data=data)
    return TagComparison(
        data, ekf, ukf,
        ekf_error=np.linalg.norm(ekf.x[:, :2] - data.x_true[:, :2], axis=1),
        ukf_error=np.linalg.norm(ukf.x[:, :2] - data.x_true[:, :2], axis=1),
        gap=np.linalg.norm(ekf.x[:, :2] - ukf.x[:, :2], axis=1),
        ekf_rmse=position_rmse(ekf.x, data.x_true), ukf_rmse=position_rmse(ukf.x, data.x_true),
    )


def rmse_grid(accel_stds: Any, range_stds: Any, data: TagData | None = None) -> np.ndarray:
    r"""Erreur quadratique moyenne de position (m) de l'EKF pour chaque réglage :
    tableau (len(accel_stds), len(range_stds)), ligne = :math:`\sigma_a` (m/s²), colonne = :math:`\sigma_r` (m)."""
    data = tag_data() if data is None else data
    return np.array(
        [[position_rmse(run_tag_ekf(q, r, data).x, data.x_true) for r in range_stds] for q in accel_stds]
    )


def rmse_table(accel_stds: Any, range_stds: Any, data: TagData | None = None) -> Table:
    r""":func:`rmse_grid` en tableau (centimètres) : une ligne par :math:`\sigma_a`, une colonne par :math:`\sigma_r`."""
    grid = 100 * rmse_grid(accel_stds, range_stds, data)
    from ..numbers import format_spec  # Babel, chargé à l'affichage seulement

    headers = [r"$\sigma_a$ (m/s²) ↓ · $\sigma_r$ (m) →"] + [format_spec(r, "g") for r in range_stds]
    columns = [[format_spec(q, "g") for q in accel_stds]] + [grid[:, j] for j in range(grid.shape[1])]
    return Table(headers, columns, [None] + ["{:.1f}"] * grid.shape[1])
