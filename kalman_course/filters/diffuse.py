r"""Filtre de Kalman à initialisation diffuse exacte : aucun a priori sur l'état (filtre augmenté de de Jong).

Convention (Durbin & Koopman 2012, § 5.2 ; statsmodels ``use_exact_diffuse=True``) : l'état
:math:`x_1` de la première mesure ``y[0]`` n'a **aucun a priori**. On l'écrit :math:`x_1 = \delta`,
:math:`\delta` inconnu de loi « plate » (limite de :math:`\mathcal N(0, \kappa I)` quand
:math:`\kappa \to \infty`).

**Idée** (de Jong 1991). Sachant :math:`\delta`, c'est un filtre de Kalman ordinaire parti de
:math:`\hat x_{1\mid 0} = \delta`, :math:`P_{1\mid 0} = 0`. Les covariances ne dépendent pas de
:math:`\delta` et les moyennes en sont des fonctions affines :

.. math::

    \hat x_{k\mid k-1} = a^-_k + X^-_k\,\delta,\qquad \hat x_{k\mid k} = a_k + X_k\,\delta,\qquad
    \nu_k = v_k - E_k\,\delta,\quad E_k = C X^-_k,

où :math:`a` est la moyenne du filtre parti de :math:`\delta = 0` et où les :math:`n` colonnes de
:math:`X` suivent les mêmes équations sans mesure ni commande (:math:`X^-_1 = I`,
:math:`X_k = X^-_k - K_kE_k`, :math:`X^-_{k+1} = AX_k`). Le moteur filtre donc la **matrice**
:math:`[a \mid X]` de forme :math:`(n, 1+n)` (la famille :func:`diffuse_family`).

Les innovations étant indépendantes de covariances :math:`S_k`, la vraisemblance de :math:`\delta` au vu
de :math:`y_1, \dots, y_k` est gaussienne, d'information et de vecteur d'information

.. math::

    J_k = \sum_{j \le k} E_j^T S_j^{-1} E_j,\qquad h_k = \sum_{j \le k} E_j^T S_j^{-1} v_j,

et, dès que :math:`J_k` est inversible (l'état est alors **déterminé** par les mesures),
:math:`\delta \mid y_{1:k} \sim \mathcal N(J_k^{-1}h_k,\ J_k^{-1})`. Par la loi des espérances et des
variances totales, l'estimation exacte de l'initialisation diffuse est

.. math::

    \hat x_{k\mid k} = a_k + X_k J_k^{-1}h_k,\qquad P_{k\mid k} = P^{a}_{k} + X_k J_k^{-1} X_k^T,

:math:`P^a_k` étant la covariance du filtre conditionnel. Avant que :math:`J_k` soit inversible, l'état
n'est pas déterminé : les lignes du résultat valent NaN (comme pour le SRIF parti de
:math:`\mathcal R_{xx} = 0`). Le nombre de ces pas est le :math:`d` de Durbin & Koopman.

Ce module n'importe pas matplotlib.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.linalg import correct, psd_solve, symmetrize
from ..core.models import LinearGaussianModel, ModelBatch
from ..core.results import FilterResult
from ..core.validation import KalmanInputError
from .engine import Correction, FilterFamily, gaussian_moments, run_filter

__all__ = ["DIFFUSE_RTOL", "DiffuseFilterResult", "diffuse_family", "diffuse_kalman_filter", "is_determined"]

#: Seuil relatif de rang de l'information :math:`J_k` (après mise à l'échelle de sa diagonale) : en
#: deçà, l'état n'est pas tenu pour déterminé par les mesures.
DIFFUSE_RTOL = 1e-10


# --------------------------------------------------------------------------- la famille augmentée


def diffuse_family() -> FilterFamily:
    r"""Les étapes du filtre augmenté pour le moteur : état interne :math:`([a \mid X], P)`, moyenne
    de forme ``(n, 1+n)`` (colonne 0 : :math:`a`, colonnes 1 à n : :math:`X`).

    La première prédiction ne part pas d'un a priori : elle pose :math:`[a^-_1 \mid X^-_1] = [0 \mid I]`,
    :math:`P_{1\mid 0} = 0` (l'état de la première mesure est :math:`\delta` ; la commande ``u[0]``
    est absorbée dans :math:`\delta`). Les suivantes sont celles du filtre de Kalman, la commande
    :math:`Bu` n'agissant que sur la colonne :math:`a`.

    Mode en lot (:func:`~kalman_course.filters.engine.run_filter_runs`) : ``N`` séries filtrées par le même
    modèle, ou une même série filtrée par les ``G`` modèles d'un
    :class:`~kalman_course.core.models.ModelBatch` (un tirage par modèle : matrices (G, …)), sans commande.
    """

    def prior(model, x0, P0):
        if isinstance(model, ModelBatch):
            raise KalmanInputError("« model » : un lot de modèles (ModelBatch) se filtre par run_filter_runs.")
        return None  # avant la première mesure : aucune information

    def start(n, lead=()):  # [a⁻₁ | X⁻₁] = [0 | I], P₁|₀ = 0
        xa = np.zeros(lead + (n, n + 1))
        xa[..., 1:] = np.eye(n)
        return xa, np.zeros(lead + (n, n))

    def predict_step(model: LinearGaussianModel, state, u):
        if state is None:
            return start(model.n_state)
        xa, P = state
        A = model.A
        xa_pred = A.dot(xa)
        if u is not None:
            xa_pred[:, 0] += model.B.dot(u)
        return xa_pred, symmetrize(A.dot(P).dot(A.T) + model.Q)

    def update_step(model: LinearGaussianModel, state, y, idx):
        xa_pred, P_pred = state
        if idx is None:
            C, R = model.C, model.R
        else:
            C, R = model.C[idx], model.R[np.ix_(idx, idx)]
        # innovations de toutes les colonnes : [v | -E] = [y | 0] - C [a | X]
        V = -C.dot(xa_pred)
        V[:, 0] += y
        xa, P, K, S = correct(xa_pred, P_pred, V, C, R)
        return (xa, P), Correction(K, V[:, 0], S)

    def prior_many(model, x0, P0, N, shared=False):
        return start(model.n_state, (N,))

    def predict_many(model, state, u, k):
        if k == 0:  # l'état de la première mesure : δ, sans a priori (l'état de départ le pose déjà)
            return state
        xa, P = state
        A = model.A
        At = np.swapaxes(A, -1, -2)
        xa_pred = A @ xa
        if u is not None:
            xa_pred[..., 0] += u @ np.swapaxes(model.B, -1, -2)
        return xa_pred, symmetrize(A @ P @ At + model.Q)

    def update_many(model, state, Y, idx, k):
        xa_pred, P_pred = state
        C, R = model.C, model.R
        if idx is not None:
            C, R = C[..., idx, :], R[..., idx[:, None], idx]
        V = -(C @ xa_pred)                                           # [v | -E] (N, m_k, 1+n)
        V[..., 0] += Y
        PCt = P_pred @ np.swapaxes(C, -1, -2)
        S = C @ PCt + R
        K = np.swapaxes(psd_solve(S, np.swapaxes(PCt, -1, -2), where=f"correction par y[{k}]"), -1, -2)
        xa = xa_pred + K @ V
        P = symmetrize(P_pred - K @ np.swapaxes(PCt, -1, -2))
        return (xa, P), Correction(K, V[..., 0], S)

    return FilterFamily(
        name="filtre de Kalman à initialisation diffuse",
        model_type=(LinearGaussianModel, ModelBatch),
        model_hint="l'initialisation diffuse exacte n'existe ici que pour un modèle linéaire",
        prior=prior,
        predict=predict_step,
        update=update_step,
        moments=gaussian_moments,  # l'état est déjà ([a | X], P) : le moteur le range tel quel
        state_shape=lambda model: (model.n_state, model.n_state + 1),
        prior_many=prior_many,
        predict_many=predict_many,
        update_many=update_many,
    )


# --------------------------------------------------------------------------- résultat


@dataclass(frozen=True, eq=False, repr=False)
class DiffuseFilterResult(FilterResult):
    r"""Résultat de :func:`diffuse_kalman_filter` : un :class:`~kalman_course.FilterResult` (estimations
    exactes de l'initialisation diffuse, lignes NaN tant que l'état n'est pas déterminé) et les pièces du filtre
    augmenté dont se servent le lisseur et la vraisemblance.

    Attributs supplémentaires
    -------------------------
    augmented : FilterResult
        Le filtre conditionnel augmenté : ``x``, ``x_pred`` de forme (T, n, 1+n) (colonne 0 :
        :math:`a`, colonnes 1 à n : :math:`X`), ``P``, ``P_pred`` (T, n, n) : :math:`P^a` ;
        ``innovation`` (T, m) : :math:`v_k` ; ``S`` (T, m, m) : :math:`S_k` ; ``K`` : gains.
    information : (T, n, n)
        :math:`J_k = \sum_{j\le k} E_j^TS_j^{-1}E_j`, information sur :math:`\delta` après ``y[k]``.
    information_vector : (T, n)
        :math:`h_k = \sum_{j\le k} E_j^TS_j^{-1}v_j`.
    n_diffuse : int
        :math:`d` : nombre de pas du début dont la prédiction n'est pas déterminée (1 pour le
        niveau local, 2 pour la tendance locale) ; ``T`` si l'état n'est jamais déterminé.
    """

    augmented: FilterResult | None = None
    information: np.ndarray | None = None
    information_vector: np.ndarray | None = None
    n_diffuse: int = 0

    def __post_init__(self) -> None:
        super().__post_init__()  # fige tous les tableaux, ceux du filtre augmenté compris
        object.__setattr__(self, "n_diffuse", int(self.n_diffuse))

    def after_diffuse(self) -> FilterResult:
        r"""Les pas :math:`k \ge d` (prédiction déterminée), en :class:`~kalman_course.FilterResult`
        ordinaire : c'est sur eux que portent les tests des innovations (NIS, blancheur)."""
        d = self.n_diffuse
        return FilterResult(x=self.x[d:], P=self.P[d:], x_pred=self.x_pred[d:], P_pred=self.P_pred[d:],
                            K=self.K[d:], innovation=self.innovation[d:], S=self.S[d:],
                            observed=self.observed[d:], n_iter=self.n_iter[d:])


# --------------------------------------------------------------------------- calculs


def is_determined(J: np.ndarray) -> np.ndarray:
    r"""Pour chaque information :math:`J_k` (…, n, n) : vrai si elle est de rang plein.

    La diagonale est d'abord ramenée à 1 (:math:`D^{-1/2}JD^{-1/2}`, indépendant des unités des états) ;
    :math:`J_k` est de rang plein si la plus petite valeur propre dépasse :data:`DIFFUSE_RTOL`."""
    J = np.asarray(J, dtype=float)
    d = np.diagonal(J, axis1=-2, axis2=-1)
    ok = (d > 0).all(axis=-1)
    out = np.zeros(J.shape[:-2], dtype=bool)
    if ok.any():
        s = np.sqrt(d[ok])
        scaled = J[ok] / (s[..., :, None] * s[..., None, :])
        out[ok] = np.linalg.eigvalsh(scaled)[..., 0] > DIFFUSE_RTOL
    return out


def masked_innovations(innovation: np.ndarray, S: np.ndarray, observed: np.ndarray):
    r"""Innovations et covariances « complétées » pour un calcul en bloc : composantes manquantes mises à 0,
    bloc manquant de :math:`S` remplacé par l'identité (les termes quadratiques et le
    :math:`\log|S|` se réduisent ainsi aux composantes observées). ``innovation`` (…, T, m),
    ``S`` (…, T, m, m), ``observed`` (…, T, m) ; renvoie ``(v (…, T, m), S (…, T, m, m))``."""
    obs = np.asarray(observed, dtype=bool)
    v = np.where(obs, innovation, 0.0)
    both = obs[..., :, None] & obs[..., None, :]
    eye = np.broadcast_to(np.eye(obs.shape[-1], dtype=bool), both.shape)
    S_full = np.where(both, S, np.where(eye, 1.0, 0.0))
    return v, S_full


def diffuse_information(model: LinearGaussianModel | ModelBatch, augmented: FilterResult):
    r""":math:`J_k` (T, n, n) et :math:`h_k` (T, n) cumulés, à partir du filtre augmenté (voir le module) ;
    pour un lot (``augmented`` d'axe des tirages en tête, ``model`` un
    :class:`~kalman_course.core.models.ModelBatch` ou un modèle commun), (N, T, n, n) et (N, T, n)."""
    obs = np.asarray(augmented.observed, dtype=bool)
    T = obs.shape[-2]
    n = augmented.x_pred.shape[-2]
    if isinstance(model, ModelBatch):
        C = model.C[:, None]                                 # (G, 1, m, n) : C_g à tous les pas
    else:
        C = np.asarray(model.sequence("C", T))              # (T, m, n) : C_k (constante ou variable)
    E = np.where(obs[..., :, :, None], C @ augmented.x_pred[..., 1:], 0.0)  # (…, T, m, n)
    v, S = masked_innovations(augmented.innovation, augmented.S, obs)
    lead = S.shape[:-2]
    SiE = psd_solve(S.reshape((-1,) + S.shape[-2:]), E.reshape((-1,) + E.shape[-2:])).reshape(E.shape)
    J = np.cumsum(np.swapaxes(E, -1, -2) @ SiE, axis=-3)
    h = np.cumsum((np.swapaxes(SiE, -1, -2) @ v[..., None])[..., 0], axis=-2)
    return symmetrize(J).reshape(lead + (n, n)), h


def _collapse(xa: np.ndarray, P: np.ndarray, J: np.ndarray, h: np.ndarray, ok: np.ndarray):
    r""":math:`a + XJ^{-1}h` et :math:`P + XJ^{-1}X^T` aux lignes ``ok``, NaN ailleurs."""
    T, n = P.shape[:2]
    x_out = np.full((T, n), np.nan)
    P_out = np.full((T, n, n), np.nan)
    if ok.any():
        X = xa[ok][:, :, 1:]
        rhs = np.concatenate([h[ok][:, :, None], np.swapaxes(X, 1, 2)], axis=2)  # [h | Xᵀ]
        sol = psd_solve(J[ok], rhs, message="L'information J sur l'état initial n'est pas définie positive.", name="J")
        x_out[ok] = xa[ok][:, :, 0] + (X @ sol[:, :, :1])[:, :, 0]
        P_out[ok] = symmetrize(P[ok] + X @ sol[:, :, 1:])
    return x_out, P_out


def diffuse_kalman_filter(model: LinearGaussianModel, y: Any, u: Any = None) -> DiffuseFilterResult:
    r"""Filtre de Kalman **sans a priori** (initialisation diffuse exacte de Durbin & Koopman), par le filtre augmenté.

    Paramètres
    ----------
    model : LinearGaussianModel
    y : (T, m), ou (T,) si m = 1 — ``NaN``/``None`` : composante manquante.
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (``u[k]`` sert à prédire vers ``y[k]`` ;
        ``u[0]`` est sans effet, l'état de la première mesure n'ayant pas d'a priori).

    Renvoie
    -------
    DiffuseFilterResult
        Les champs d'un :class:`~kalman_course.FilterResult` — ``x`` (T, n), ``P`` (T, n, n) : estimation
        exacte :math:`\hat x_{k\mid k} = a_k + X_kJ_k^{-1}h_k`, :math:`P_{k\mid k} = P^a_k + X_kJ_k^{-1}X_k^T`
        (NaN tant que :math:`J_k` n'est pas inversible) ; ``x_pred``, ``P_pred`` de même avec
        :math:`J_{k-1}` ; ``innovation`` :math:`\nu_k = y_k - C\hat x_{k\mid k-1}`, ``S``
        :math:`= CP_{k\mid k-1}C^T + R` et ``K`` :math:`= P_{k\mid k-1}C^TS_k^{-1}` aux pas
        :math:`k \ge d` (NaN avant) — et les pièces du filtre augmenté (``augmented``,
        ``information``, ``information_vector``, ``n_diffuse``).
    """
    augmented = run_filter(diffuse_family(), model, y, None, None, u)
    n, m = model.n_state, model.n_obs
    T = augmented.x.shape[0]
    J, h = diffuse_information(model, augmented)
    det = is_determined(J)
    x, P = _collapse(augmented.x, augmented.P, J, h, det)
    # prédiction de la ligne k : information des lignes < k
    J_prev = np.concatenate([np.zeros((1, n, n)), J[:-1]])
    h_prev = np.concatenate([np.zeros((1, n)), h[:-1]])
    det_prev = np.concatenate([[False], det[:-1]])
    x_pred, P_pred = _collapse(augmented.x_pred, augmented.P_pred, J_prev, h_prev, det_prev)
    obs = np.asarray(augmented.observed, dtype=bool)
    innovation = np.full((T, m), np.nan)
    S = np.full((T, m, m), np.nan)
    K = np.zeros((T, n, m))
    rows = det_prev & obs.any(axis=1)
    if rows.any():
        o = obs[rows]
        C_o = np.where(o[:, :, None], model.sequence("C", T)[rows], 0.0)  # lignes manquantes de C mises à 0
        # ν = y − C x̂⁻ = v − C(x̂⁻ − a⁻) : l'innovation du filtre conditionnel, corrigée de X⁻δ̂
        shift = x_pred[rows] - augmented.x_pred[rows][:, :, 0]
        nu = np.where(o, augmented.innovation[rows], 0.0) - (C_o @ shift[:, :, None])[:, :, 0]
        S_rows = C_o @ P_pred[rows] @ np.swapaxes(C_o, 1, 2) + model.sequence("R", T)[rows]
        _, S_solve = masked_innovations(nu, S_rows, o)
        K[rows] = np.swapaxes(psd_solve(S_solve, C_o @ P_pred[rows]), 1, 2)
        both = o[:, :, None] & o[:, None, :]
        innovation[rows] = np.where(o, nu, np.nan)
        S[rows] = np.where(both, symmetrize(S_rows), np.nan)
    # pas diffus observés : ni gain ni innovation de Kalman définis
    early = ~det_prev & obs.any(axis=1)
    K[early] = np.where(obs[early][:, None, :], np.nan, 0.0)
    n_diffuse = int(np.argmax(det_prev)) if det_prev.any() else T
    return DiffuseFilterResult(
        x=x, P=P, x_pred=x_pred, P_pred=P_pred, K=K, innovation=innovation, S=S, observed=obs,
        n_iter=augmented.n_iter, augmented=augmented, information=J, information_vector=h, n_diffuse=n_diffuse,
    )
