r"""La **porte de validation** : quelles détections d'un relevé peuvent venir de quelle piste.

Une piste prédite :math:`(\hat x_t, P_t)` annonce sa mesure :math:`C\hat x_t` avec la covariance
d'innovation :math:`S_t = CP_tC^T + R`. Pour une détection :math:`z_j` (notations du chapitre
« Fouillis et association ») :

.. math::

    \nu_{tj} = z_j - C\hat x_t,\qquad d^2_{tj} = \nu_{tj}^T S_t^{-1}\nu_{tj}\quad\text{(NIS)} .

Si :math:`z_j` vient de la cible, :math:`d^2_{tj}` suit une loi du :math:`\chi^2` à :math:`m` degrés de
liberté : la détection est **dans la porte** si :math:`d^2_{tj} \le \gamma`, avec
:math:`\gamma = \chi^2_m(P_G)` (le ``scipy.stats.chi2.ppf`` de scipy, calculé une fois par
:func:`~kalman_course.filters.gating.gate_threshold`) ; la vraie détection y tombe avec la probabilité
:math:`P_G`. La porte est l'ellipsoïde :math:`\{z : (z - C\hat x_t)^TS_t^{-1}(z - C\hat x_t) \le \gamma\}`,
de volume

.. math::

    V_t = \frac{\pi^{m/2}}{\Gamma(m/2 + 1)}\,\gamma^{m/2}\sqrt{\det S_t}

(l'aire :math:`\pi\gamma\sqrt{\det S_t}` d'une ellipse pour :math:`m = 2`) : un fouillis de densité
:math:`\lambda` y met en moyenne :math:`\lambda V_t` fausses détections.

Le calcul est vectorisé sur les :math:`T` pistes et les :math:`N` détections : une factorisation de
Cholesky par piste (:math:`S_t = L_tL_t^T`), les innovations blanchies :math:`L_t^{-1}\nu_{tj}` en une
résolution triangulaire empilée.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import scipy.special

from ..core.models import LinearGaussianModel
from ..core.results import freeze
from ..filters.gating import gate_threshold
from ..core.validation import (
    KalmanInputError,
    as_float_array,
    as_probability,
    check_instance,
    check_psd,
    shape_text,
)

__all__ = ["Gate", "validation_gate", "gate_threshold", "gate_volume", "Innovations", "innovations",
           "check_model", "check_tracks", "check_detections"]


class Gate(NamedTuple):
    r"""Résultat de :func:`validation_gate` (``T`` pistes, ``N`` détections, ``m`` composantes).

    ``inside`` (T, N) booléen : la détection ``j`` est dans la porte de la piste ``t``
    (:math:`d^2_{tj} \le \gamma`) ; ``nis`` (T, N) : :math:`d^2_{tj}` ; ``threshold`` : :math:`\gamma =
    \chi^2_m(P_G)` ; ``volume`` (T,) : volume :math:`V_t` de chaque porte (m² pour des positions planes)."""

    inside: np.ndarray
    nis: np.ndarray
    threshold: float
    volume: np.ndarray


class Innovations(NamedTuple):
    r"""Les grandeurs d'une porte, pour les calculs qui suivent (PDA, JPDA, affectation), avec
    :math:`S_t = L_tL_t^T` (Cholesky) : ``nu`` (T, N, m) innovations :math:`\nu_{tj}` ; ``S``, ``L`` (T, m, m) ;
    ``white`` (T, N, m) innovations blanchies :math:`w_{tj} = L_t^{-1}\nu_{tj}` ; ``G`` (T, m, n)
    :math:`G_t = L_t^{-1}CP_t` (d'où :math:`K_t = G_t^TL_t^{-1}` et :math:`K_tS_tK_t^T = G_t^TG_t`) ; ``nis``
    (T, N) :math:`d^2_{tj} = \lVert w_{tj}\rVert^2` ; ``log_det_S`` (T,)."""

    nu: np.ndarray
    S: np.ndarray
    L: np.ndarray
    white: np.ndarray
    G: np.ndarray
    nis: np.ndarray
    log_det_S: np.ndarray


# --------------------------------------------------------------------------- vérification des entrées


def check_model(model: Any) -> LinearGaussianModel:
    """``model`` : un :class:`~kalman_course.LinearGaussianModel` **constant** (l'association n'en lit que
    ``C`` et ``R``)."""
    check_instance("model", model, LinearGaussianModel, "construit par kc.LinearGaussianModel(A, C, Q, R) ou "
                   "kc.constant_velocity_model(dt, q, C, R)")
    if model.time_varying:
        raise KalmanInputError(
            f"« model » doit être un modèle constant : l'association d'un relevé n'utilise qu'une matrice C et "
            f"une matrice R ; reçu un modèle variable sur {model.n_steps} pas (passez model.at(k))."
        )
    return model


def check_tracks(x_pred: Any, P_pred: Any, n: int, *, single: bool = False) -> tuple[np.ndarray, np.ndarray]:
    r"""Pistes prédites : ``x_pred`` (T, n) et ``P_pred`` (T, n, n), symétriques semi-définies positives
    (``single`` : une piste, (n,) et (n, n), renvoyée avec un axe en tête). ``T = 0`` est permis (aucune
    piste) sauf pour une piste seule."""
    x = as_float_array("x_pred", x_pred)
    P = as_float_array("P_pred", P_pred)
    if single:
        if x.shape != (n,):
            raise KalmanInputError(f"« x_pred » doit être un vecteur de forme ({n},) (une piste) ; "
                                   f"reçu {shape_text(x.shape)}.")
        if P.shape != (n, n):
            raise KalmanInputError(f"« P_pred » doit être une matrice de forme ({n}, {n}) ; "
                                   f"reçu {shape_text(P.shape)}.")
        x, P = x[None], P[None]
    else:
        if x.ndim != 2 or x.shape[1] != n:
            hint = " (une seule piste : écrivez x_pred[None])" if x.shape == (n,) else ""
            raise KalmanInputError(f"« x_pred » doit être de forme (T, {n}) : une piste prédite par ligne ; "
                                   f"reçu {shape_text(x.shape)}{hint}.")
        T = x.shape[0]
        if P.shape != (T, n, n):
            raise KalmanInputError(f"« P_pred » doit être de forme ({T}, {n}, {n}) : une covariance par piste de "
                                   f"« x_pred » ; reçu {shape_text(P.shape)}.")
    if P.shape[0]:
        # symétrie et positivité de toutes à la fois, aux tolérances de check_psd (une valeur propre par
        # covariance, en pile) ; la première fautive est revérifiée seule, pour son message
        scale = np.maximum(1.0, np.abs(P).max(axis=(1, 2)))
        sym = 0.5 * (P + np.swapaxes(P, 1, 2))
        ok = np.abs(P - np.swapaxes(P, 1, 2)).max(axis=(1, 2)) <= 1e-9 * scale
        ok &= np.linalg.eigvalsh(sym)[:, 0] >= -1e-10 * scale
        if not ok.all():
            k = int(np.argmin(ok))
            check_psd("P_pred" if single else f"P_pred[{k}]", P[k])
        P = sym
    return x, P


def check_detections(detections: Any, m: int, name: str = "detections") -> np.ndarray:
    """Un relevé : ``detections`` (N, m), ``N ≥ 0`` (un relevé vide s'écrit ``np.empty((0, m))``)."""
    z = as_float_array(name, detections)
    if z.ndim == 1 and z.size == 0:
        return z.reshape(0, m)
    if z.ndim != 2 or z.shape[1] != m:
        hint = f" (une seule détection : écrivez [[…]], forme (1, {m}))" if z.shape == (m,) else ""
        raise KalmanInputError(f"« {name} » doit être de forme (N, {m}) : une détection de {m} composante(s) par "
                               f"ligne (N ≥ 0) ; reçu {shape_text(z.shape)}{hint}.")
    return z


# --------------------------------------------------------------------------- calculs


def gate_volume(gamma: float, log_det_S: np.ndarray, m: int) -> np.ndarray:
    r"""Volume :math:`\pi^{m/2}/\Gamma(m/2+1)\,\gamma^{m/2}\sqrt{\det S}` des portes (``log_det_S`` (T,))."""
    c_m = np.pi ** (m / 2) / scipy.special.gamma(m / 2 + 1)
    return c_m * gamma ** (m / 2) * np.exp(0.5 * log_det_S)


def innovations(C: np.ndarray, R: np.ndarray, x: np.ndarray, P: np.ndarray, z: np.ndarray) -> Innovations:
    r"""Innovations :math:`\nu_{tj} = z_j - C\hat x_t` (T, N, m), :math:`S_t = CP_tC^T + R = L_tL_t^T`, et, par
    **une** résolution triangulaire empilée, les innovations blanchies :math:`L_t^{-1}\nu_{tj}` et
    :math:`G_t = L_t^{-1}CP_t` ; sans vérification des entrées (le noyau des fonctions publiques et du
    pisteur). :math:`S` n'est jamais inversée."""
    N = z.shape[0]
    CP = C @ P                                                                # (T, m, n)
    nu = z[None, :, :] - (x @ C.T)[:, None, :]                                # (T, N, m)
    S = CP @ C.T + R
    S = 0.5 * (S + np.swapaxes(S, -1, -2))
    try:
        L = np.linalg.cholesky(S)
    except np.linalg.LinAlgError:
        raise KalmanInputError("La covariance d'innovation « S = C P_pred Cᵀ + R » d'une piste n'est pas définie "
                               "positive : vérifiez P_pred et R.") from None
    solved = np.linalg.solve(L, np.concatenate([np.swapaxes(nu, 1, 2), CP], axis=2))  # L⁻¹ [νᵀ | C P]
    white = np.swapaxes(solved[:, :, :N], 1, 2)                               # (T, N, m)
    nis = np.sum(white * white, axis=2)
    log_det_S = 2.0 * np.log(np.diagonal(L, axis1=1, axis2=2)).sum(axis=1)
    return Innovations(nu, S, L, white, solved[:, :, N:], nis, log_det_S)


def validation_gate(model: Any, x_pred: Any, P_pred: Any, detections: Any, *, gate_probability: Any) -> Gate:
    r"""La porte de validation de ``T`` pistes prédites sur un relevé de ``N`` détections.

    .. math::

        \nu_{tj} = z_j - C\hat x_t,\quad S_t = CP_tC^T + R,\quad d^2_{tj} = \nu_{tj}^TS_t^{-1}\nu_{tj},\quad
        \gamma = \chi^2_m(P_G),\quad V_t = \frac{\pi^{m/2}}{\Gamma(m/2+1)}\gamma^{m/2}\sqrt{\det S_t} .

    Paramètres
    ----------
    model : :class:`~kalman_course.LinearGaussianModel` constant — seuls ``C`` (m, n) et ``R`` (m, m) servent.
    x_pred : (T, n) — pistes prédites, une par ligne (``T ≥ 0``).
    P_pred : (T, n, n) — leurs covariances.
    detections : (N, m) — le relevé (``N ≥ 0``).
    gate_probability : :math:`P_G \in (0, 1)` — probabilité que la porte contienne la vraie détection.

    Renvoie :class:`Gate` ``(inside (T, N), nis (T, N), threshold, volume (T,))``.
    """
    model = check_model(model)
    p_gate = as_probability("gate_probability", gate_probability)
    x, P = check_tracks(x_pred, P_pred, model.n_state)
    z = check_detections(detections, model.n_obs)
    inn = innovations(model.C, model.R, x, P, z)
    gamma = gate_threshold(p_gate, model.n_obs)
    return Gate(freeze(inn.nis <= gamma, bool), freeze(inn.nis), gamma,
                freeze(gate_volume(gamma, inn.log_det_S, model.n_obs)))
