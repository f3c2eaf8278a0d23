r"""L'association probabiliste de données (PDA, Bar-Shalom & Tse 1975) : une piste, un relevé dans le
fouillis, une correction qui **moyenne** les détections de sa porte au lieu d'en choisir une.

**Hypothèses.** Un relevé contient au plus une détection de la cible (probabilité de détection
:math:`P_D`, qui tombe dans la porte avec la probabilité :math:`P_G`) et des fausses détections
poissonniennes, uniformes, de densité :math:`\lambda` (par unité de volume de mesure : par m² pour des
positions planes). Pour les :math:`N` détections du relevé, :math:`N + 1` hypothèses : aucune ne vient
de la cible (:math:`\theta_0`), ou c'est la :math:`j`-ième (:math:`\theta_j`). Leurs poids :

.. math::

    w_0 = 1 - P_DP_G,\qquad w_j = \frac{P_D\,\mathcal N(z_j; C\hat x^-, S)}{\lambda}\ \text{(dans la porte, 0 hors d'elle)},
    \qquad \beta_j = \frac{w_j}{\sum_{i=0}^N w_i}

(:math:`\mathcal N` : la densité gaussienne entière, non divisée par :math:`P_G`, comme dans Stone Soup).

**Correction.** Avec :math:`K = P^-C^TS^{-1}` et l'innovation combinée
:math:`\bar\nu = \sum_j\beta_j\nu_j` :

.. math::

    \hat x = \hat x^- + K\bar\nu,\qquad
    P = \beta_0P^- + (1 - \beta_0)(P^- - KSK^T) + K\Big(\sum_{j\ge1}\beta_j\nu_j\nu_j^T - \bar\nu\bar\nu^T\Big)K^T .

C'est la moyenne et la covariance du mélange des :math:`N + 1` corrections de Kalman (une par
hypothèse) ; le dernier terme, la **dispersion** des innovations, est ce que l'incertitude sur
l'origine de la mesure ajoute à la covariance.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..core.linalg import symmetrize
from ..core.results import freeze
from ..core.validation import as_positive_number, as_probability
from .gate import Innovations, check_detections, check_model, check_tracks, gate_threshold, innovations

__all__ = ["PDAUpdate", "pda_update", "association_weights", "combine", "check_clutter"]


class PDAUpdate(NamedTuple):
    r"""Résultat de :func:`pda_update` : ``x`` (n,) et ``P`` (n, n), l'estimation corrigée ; ``weights``
    (N + 1,) les probabilités :math:`\beta` (colonne 0 : aucune détection de la cible ; ``1 + j`` : la
    détection ``j``), de somme 1, nulles hors de la porte ; ``inside`` (N,) booléen : la porte."""

    x: np.ndarray
    P: np.ndarray
    weights: np.ndarray
    inside: np.ndarray


def check_clutter(detection_probability: Any, clutter_density: Any, gate_probability: Any) -> tuple[float, float, float]:
    r"""Les trois réglages du fouillis : :math:`P_D \in (0, 1]`, :math:`\lambda > 0`, :math:`P_G \in (0, 1)`."""
    return (as_probability("detection_probability", detection_probability, one=True),
            as_positive_number("clutter_density", clutter_density,
                               "une densité de fausses détections strictement positive (par unité de volume de "
                               "mesure : par m² pour des positions planes)"),
            as_probability("gate_probability", gate_probability))


def association_weights(inn: Innovations, m: int, p_detect: float, density: float, gamma: float,
                        p_gate: float) -> tuple[np.ndarray, np.ndarray]:
    r"""Poids non normalisés des hypothèses de chaque piste, ``w`` (T, N + 1) : :math:`w_{t0} = 1 - P_DP_G`,
    :math:`w_{tj} = P_D\,\mathcal N(z_j; C\hat x_t, S_t)/\lambda` dans la porte, 0 hors d'elle ; et la porte
    ``inside`` (T, N)."""
    inside = inn.nis <= gamma
    T, N = inside.shape
    w = np.empty((T, N + 1))
    w[:, 0] = 1.0 - p_detect * p_gate
    log_density = -0.5 * (inn.nis + inn.log_det_S[:, None] + m * np.log(2.0 * np.pi))
    w[:, 1:] = np.where(inside, p_detect / density * np.exp(log_density), 0.0)
    return w, inside


def combine(x: np.ndarray, P: np.ndarray, inn: Innovations, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""La correction PDA de ``T`` pistes, chacune avec ses probabilités ``beta`` (T, N + 1) :

    .. math::

        \hat x = \hat x^- + K\bar\nu,\qquad
        P = \beta_0P^- + (1-\beta_0)(P^- - KSK^T) + K\Big(\sum_j\beta_j\nu_j\nu_j^T - \bar\nu\bar\nu^T\Big)K^T,

    calculée avec les innovations blanchies :math:`w_j = L^{-1}\nu_j` et :math:`G = L^{-1}CP^-`
    (:class:`~.gate.Innovations`) : :math:`K\bar\nu = G^T\bar w`, :math:`KSK^T = G^TG` et
    :math:`K(\cdot)K^T = G^T(\sum_j\beta_jw_jw_j^T - \bar w\bar w^T)G` — aucune autre résolution.
    ``x`` (T, n), ``P`` (T, n, n) ; renvoie ``(x, P)`` de mêmes formes."""
    b0, bj = beta[:, 0], beta[:, 1:]
    W = inn.white                                                              # (T, N, m)
    w_bar = (bj[:, None, :] @ W)[:, 0, :]                                      # (T, m)
    spread = (np.swapaxes(W, 1, 2) * bj[:, None, :]) @ W - w_bar[:, :, None] * w_bar[:, None, :]
    Gt = np.swapaxes(inn.G, 1, 2)                                              # (T, n, m)
    x_new = x + (Gt @ w_bar[:, :, None])[:, :, 0]
    P_new = P - (1.0 - b0)[:, None, None] * (Gt @ inn.G) + Gt @ spread @ inn.G
    return x_new, symmetrize(P_new)


def pda_update(model: Any, x_pred: Any, P_pred: Any, detections: Any, *, detection_probability: Any,
               clutter_density: Any, gate_probability: Any) -> PDAUpdate:
    r"""La correction PDA d'une piste par un relevé dans le fouillis.

    .. math::

        w_0 = 1 - P_DP_G,\quad w_j = \frac{P_D\,\mathcal N(z_j; C\hat x^-, S)}{\lambda}\,\mathbb 1[d_j^2 \le \gamma],
        \quad \beta = \frac{w}{\sum_i w_i},

        \hat x = \hat x^- + K\bar\nu,\quad
        P = \beta_0P^- + (1 - \beta_0)(P^- - KSK^T) + K\Big(\sum_j\beta_j\nu_j\nu_j^T - \bar\nu\bar\nu^T\Big)K^T,

    :math:`K = P^-C^TS^{-1}`, :math:`\bar\nu = \sum_j \beta_j\nu_j`, :math:`\gamma = \chi^2_m(P_G)` (voir
    :func:`~kalman_course.validation_gate`).

    Paramètres
    ----------
    model : :class:`~kalman_course.LinearGaussianModel` constant (``C`` (m, n) et ``R`` (m, m)).
    x_pred : (n,), P_pred : (n, n) — la piste prédite.
    detections : (N, m) — le relevé (``N ≥ 0``).
    detection_probability : :math:`P_D \in (0, 1]`.
    clutter_density : :math:`\lambda > 0`, fausses détections attendues par relevé et par unité de volume de
        mesure (par m² pour des positions planes).
    gate_probability : :math:`P_G \in (0, 1)`.

    Renvoie :class:`PDAUpdate` ``(x (n,), P (n, n), weights (N + 1,), inside (N,))``.
    """
    model = check_model(model)
    p_detect, density, p_gate = check_clutter(detection_probability, clutter_density, gate_probability)
    x, P = check_tracks(x_pred, P_pred, model.n_state, single=True)
    z = check_detections(detections, model.n_obs)
    m = model.n_obs
    inn = innovations(model.C, model.R, x, P, z)
    w, inside = association_weights(inn, m, p_detect, density, gate_threshold(p_gate, m), p_gate)
    beta = w / w.sum(axis=1, keepdims=True)
    x_new, P_new = combine(x, P, inn, beta)
    return PDAUpdate(freeze(x_new[0]), freeze(P_new[0]), freeze(beta[0]), freeze(inside[0], bool))
