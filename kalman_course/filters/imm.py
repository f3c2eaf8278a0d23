r"""Filtre IMM (*interacting multiple models*, Blom & Bar-Shalom 1988) pour des régimes linéaires gaussiens.

Une cible qui vole droit puis vire n'obéit pas à un seul modèle. L'IMM en fait tourner :math:`r` à la fois
(des :class:`~kalman_course.LinearGaussianModel` de même état et de même mesure), reliés par une chaîne de
Markov sur le régime : ``transition[i, j]`` :math:`= \pi_{ij} = P(\text{régime } j \text{ au pas } k \mid
\text{régime } i \text{ au pas } k-1)`. Chaque pas, pour :math:`\mu_{k-1}` les probabilités des régimes :

1. **Mélange.** Probabilités prédites :math:`\bar c_j = \sum_i \pi_{ij}\mu_{k-1,i}`, poids de mélange
   :math:`\omega_{ij} = \pi_{ij}\mu_{k-1,i}/\bar c_j` ; chaque filtre repart du mélange des estimations
   :math:`x^0_j = \sum_i \omega_{ij}\hat x_i`,
   :math:`P^0_j = \sum_i \omega_{ij}\,[P_i + (\hat x_i - x^0_j)(\hat x_i - x^0_j)^T]`.
2. **Prédiction et correction par régime** : les étapes du filtre de Kalman
   (:func:`~kalman_course.filters.kalman.kalman_family`), modèle :math:`j` depuis :math:`(x^0_j, P^0_j)`,
   d'où :math:`\hat x_j`, :math:`P_j` et la vraisemblance
   :math:`\ell_j = \mathcal N(\nu_j; 0, S_j)` de la mesure.
3. **Probabilités des régimes** : :math:`\mu_{k,j} = \bar c_j\ell_j / \sum_i \bar c_i\ell_i` (calculées en
   logarithmes).
4. **Combinaison** (pour la sortie seulement) : :math:`\hat x = \sum_j \mu_{k,j}\hat x_j`,
   :math:`P = \sum_j \mu_{k,j}[P_j + (\hat x_j - \hat x)(\hat x_j - \hat x)^T]`.

Mêmes calculs et même ordre que ``IMMEstimator`` de filterpy (``predict()`` puis ``update(z)``). Le filtre
passe par le moteur commun (:func:`~kalman_course.filters.engine.run_filter`) : ses étapes pures
(mélange + prédiction, correction + probabilités) sont une famille comme les autres ; mesures manquantes
(prédiction seule, :math:`\mu_k = \bar c`), mesures partielles et modèles variables dans le temps viennent
du moteur.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple, Sequence

import numpy as np
import scipy.linalg

from ..core.linalg import S_NOT_PD, symmetrize
from ..core.models import LinearGaussianModel
from ..core.results import FilterResult
from ..core.validation import (
    KalmanInputError,
    as_float_array,
    as_square_matrix,
    as_vector,
    check_instance,
    check_psd,
    number_text,
    shape_text,
)
from .engine import Correction, FilterFamily, run_filter
from .kalman import kalman_family

__all__ = ["ModeSet", "IMMState", "IMMResult", "imm_family", "imm_filter", "mode_mixing"]

LOG_2PI = float(np.log(2.0 * np.pi))
_posv = scipy.linalg.get_lapack_funcs("posv", dtype=np.float64)


@dataclass(frozen=True, eq=False, init=False)
class ModeSet:
    r"""Les régimes d'un IMM : ``models`` (r modèles linéaires gaussiens de mêmes dimensions n, m, p),
    ``transition`` (r, r) stochastique (lignes de somme 1) et ``mu0`` (r,) probabilités initiales.
    Variable dans le temps si l'un des modèles l'est (:meth:`at`, :meth:`steps`, comme
    :class:`~kalman_course.LinearGaussianModel`)."""

    models: tuple[LinearGaussianModel, ...]
    transition: np.ndarray
    mu0: np.ndarray

    def __init__(self, models: Sequence[LinearGaussianModel], transition: Any, mu0: Any = None) -> None:
        if isinstance(models, LinearGaussianModel) or not isinstance(models, (list, tuple)) or not models:
            raise KalmanInputError(
                "« models » doit être une liste de LinearGaussianModel (un par régime, au moins un)."
            )
        models = tuple(models)
        for i, model in enumerate(models):
            check_instance(f"models[{i}]", model, LinearGaussianModel, "l'IMM combine des régimes linéaires gaussiens")
        n, m, p = models[0].n_state, models[0].n_obs, models[0].n_control
        for i, model in enumerate(models[1:], 1):
            if (model.n_state, model.n_obs, model.n_control) != (n, m, p):
                raise KalmanInputError(
                    f"« models[{i}] » a n = {model.n_state}, m = {model.n_obs}, p = {model.n_control} ; le premier "
                    f"régime a n = {n}, m = {m}, p = {p} : les régimes d'un IMM partagent état, mesure et commande."
                )
        lengths = {model.n_steps for model in models if model.time_varying}
        if len(lengths) > 1:
            raise KalmanInputError(
                f"Les régimes variables dans le temps doivent avoir le même nombre de pas ; reçu {sorted(lengths)}."
            )
        r = len(models)
        Pi = as_square_matrix("transition", transition, r)
        _check_probabilities("transition", Pi)
        mu = np.full(r, 1.0 / r) if mu0 is None else as_float_array("mu0", mu0)
        if mu.shape != (r,):
            raise KalmanInputError(f"« mu0 » doit être de forme ({r},) (une probabilité par régime) ; reçu "
                                   f"{shape_text(mu.shape)}.")
        _check_probabilities("mu0", mu[None, :])
        for name, value in (("models", models), ("transition", _frozen(Pi)), ("mu0", _frozen(mu)),
                            ("_n_steps", lengths.pop() if lengths else None), ("_steps", None)):
            object.__setattr__(self, name, value)

    @property
    def n_modes(self) -> int:
        """Nombre ``r`` de régimes."""
        return len(self.models)

    @property
    def n_state(self) -> int:
        return self.models[0].n_state

    @property
    def n_obs(self) -> int:
        return self.models[0].n_obs

    @property
    def n_control(self) -> int:
        return self.models[0].n_control

    @property
    def time_varying(self) -> bool:
        return self._n_steps is not None

    @property
    def n_steps(self) -> int | None:
        return self._n_steps

    def steps(self, T: int) -> list["ModeSet"]:
        """Les régimes de chacun des ``T`` pas (voir :meth:`LinearGaussianModel.steps`)."""
        if self._n_steps is None:
            return [self] * T
        if self._steps is None or len(self._steps) != T:
            per_model = [model.steps(T) for model in self.models]  # vérifie T
            steps = []
            for k in range(T):
                step = object.__new__(ModeSet)
                for name, value in (("models", tuple(pm[k] for pm in per_model)), ("transition", self.transition),
                                    ("mu0", self.mu0), ("_n_steps", None), ("_steps", None)):
                    object.__setattr__(step, name, value)
                steps.append(step)
            object.__setattr__(self, "_steps", steps)
        return self._steps

    def at(self, k: int) -> "ModeSet":
        """Les régimes constants du pas ``k``."""
        if self._n_steps is None:
            return self
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k < self._n_steps:
            raise KalmanInputError(f"« k » doit être un indice de pas entre 0 et {self._n_steps - 1} ; reçu {k!r}.")
        return self.steps(self._n_steps)[k]

    def __repr__(self) -> str:
        return f"ModeSet({self.n_modes} régimes, n={self.n_state}, m={self.n_obs})"


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float, copy=True)
    a.setflags(write=False)
    return a


def _check_probabilities(name: str, M: np.ndarray) -> None:
    if (M < 0).any():
        raise KalmanInputError(f"« {name} » doit contenir des probabilités (≥ 0) ; plus petite valeur "
                               f"{number_text(float(M.min()), '.3g')}.")
    sums = M.sum(axis=1)
    bad = np.abs(sums - 1.0) > 1e-9
    if bad.any():
        i = int(np.argmax(bad))
        where = f"la ligne {i}" if name == "transition" else "la somme"
        raise KalmanInputError(
            f"« {name} » : {where} doit valoir 1 (probabilités de tous les régimes) ; elle vaut "
            f"{number_text(float(sums[i]), '.12g')}."
            + (" transition[i, j] est la probabilité de passer du régime i au régime j." if name == "transition"
               else "")
        )


class IMMState(NamedTuple):
    r"""État interne de l'IMM : ``X`` (r, n) et ``P`` (r, n, n) les estimations des régimes, ``mu`` (r,)
    leurs probabilités, ``mu_pred`` (r,) les probabilités prédites :math:`\bar c` du dernier pas."""

    X: np.ndarray
    P: np.ndarray
    mu: np.ndarray
    mu_pred: np.ndarray


@dataclass(frozen=True, eq=False, repr=False)
class IMMResult(FilterResult):
    r"""Sortie de :func:`imm_filter` : les champs de :class:`~kalman_course.FilterResult` pour l'estimation
    **combinée** (``x`` (T, n), ``P`` (T, n, n) ; ``x_pred``, ``P_pred`` : la prédiction combinée
    :math:`\sum_j \bar c_j \hat x^-_j` ; ``innovation`` :math:`y_k - \sum_j\bar c_jC_j\hat x^-_j`, ``S`` la
    covariance du mélange des mesures prédites, ``K`` le gain de la loi gaussienne de mêmes moments), et :

    ``mu`` (T, r) : probabilités des régimes après la mesure ``y[k]`` ; ``mu_pred`` (T, r) : avant
    (:math:`\bar c`) ; ``x_modes`` (T, r, n), ``P_modes`` (T, r, n, n) : estimations de chaque régime."""

    mu: np.ndarray | None = None
    mu_pred: np.ndarray | None = None
    x_modes: np.ndarray | None = None
    P_modes: np.ndarray | None = None

    @property
    def n_modes(self) -> int:
        return self.mu.shape[-1]

    @property
    def mode(self) -> np.ndarray:
        """(T,) entier : le régime le plus probable à chaque pas."""
        return np.argmax(self.mu, axis=-1)


def mode_mixing(transition: np.ndarray, mu: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""Probabilités prédites :math:`\bar c_j = \sum_i\pi_{ij}\mu_i` (r,) et poids de mélange
    :math:`\omega_{ij} = \pi_{ij}\mu_i/\bar c_j` (r, r) (colonne :math:`j` : d'où vient le régime :math:`j` ;
    un régime de probabilité prédite nulle garde sa propre estimation)."""
    cbar = mu.dot(transition)
    W = transition * mu[:, None]
    zero = cbar <= 0.0
    if zero.any():
        W[:, zero] = np.eye(len(mu))[:, zero]
        return cbar, W / np.where(zero, 1.0, cbar)
    return cbar, W / cbar


def _weighted(w: np.ndarray, M: np.ndarray) -> np.ndarray:
    r""":math:`\sum_j w_jM_j` pour une pile ``M`` (r, a, b) (un produit matrice–vecteur, sans ``tensordot``)."""
    return w.dot(M.reshape(len(w), -1)).reshape(M.shape[1:])


def _combine(w: np.ndarray, X: np.ndarray, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r""":math:`\hat x = \sum_j w_jx_j` et :math:`\sum_j w_j[P_j + (x_j - \hat x)(x_j - \hat x)^T]`."""
    x = w.dot(X)
    D = X - x
    return x, symmetrize(_weighted(w, P) + (D.T * w).dot(D))


def imm_family() -> FilterFamily:
    r"""Les étapes de l'IMM pour le moteur (modèle : :class:`ModeSet`, état : :class:`IMMState`) ; chaque
    régime passe par les étapes du filtre de Kalman (:func:`~kalman_course.filters.kalman.kalman_family`), sous
    la forme du cours (état :math:`(\hat x, P)` : le mélange des régimes forme des covariances, pas des
    racines)."""
    kf = kalman_family("textbook")
    kf_predict, kf_update = kf.predict, kf.update

    def prior(model: ModeSet, x0, P0) -> IMMState:
        r, n = model.n_modes, model.n_state
        X = as_float_array("x0", x0)
        if X.ndim == 2 and X.shape == (r, n) and r > 1:  # un a priori par régime
            X = X.copy()
        else:  # commun : les vérifications (et messages) de tous les filtres
            X = np.tile(as_vector("x0", x0, n), (r, 1))
        P = as_float_array("P0", P0)
        if P.ndim == 3:
            if P.shape != (r, n, n):
                raise KalmanInputError(f"« P0 » doit être de forme ({n}, {n}) (commune) ou ({r}, {n}, {n}) "
                                       f"(une par régime) ; reçu {shape_text(P.shape)}.")
            P = np.array([check_psd(f"P0[{j}]", P[j]) for j in range(r)])
        else:
            P = np.tile(check_psd("P0", as_square_matrix("P0", P, n)), (r, 1, 1))
        mu = np.array(model.mu0)
        return IMMState(X, P, mu, mu)

    def predict(model: ModeSet, state: IMMState, u) -> IMMState:
        cbar, W = mode_mixing(model.transition, state.mu)
        X0 = W.T.dot(state.X)                                          # x⁰_j = Σ_i ω_ij x_i
        D = state.X[None, :, :] - X0[:, None, :]                       # (j, i, n)
        P0 = np.einsum("ij,ikl->jkl", W, state.P) + np.einsum("ij,jik,jil->jkl", W, D, D)
        X, P = np.empty_like(X0), np.empty_like(P0)
        for j, mj in enumerate(model.models):
            X[j], P[j] = kf_predict(mj, (X0[j], P0[j]), u)
        return IMMState(X, P, cbar, cbar)

    def update(model: ModeSet, state: IMMState, y, idx):
        r = model.n_modes
        X, P = np.empty_like(state.X), np.empty_like(state.P)
        nus, Ss, PCts = [], [], []
        for j, mj in enumerate(model.models):
            (X[j], P[j]), corr = kf_update(mj, (state.X[j], state.P[j]), y, idx)
            nus.append(corr.innovation)
            Ss.append(corr.S)
            PCts.append(corr.K.dot(corr.S))                           # P⁻_j C_jᵀ = K_j S_j
        nu, S = np.array(nus), np.array(Ss)                           # (r, m_k), (r, m_k, m_k)
        log_l = np.empty(r)
        for j in range(r):  # log N(ν_j ; 0, S_j) : un appel LAPACK (Cholesky et résolution) par régime
            factor, Sinv_nu, info = _posv(Ss[j], nus[j])
            if info != 0:
                raise KalmanInputError(f"{S_NOT_PD[:-1]} (régime {j}).")
            log_l[j] = -0.5 * (len(nus[j]) * LOG_2PI + nus[j].dot(Sinv_nu)) - np.log(np.diagonal(factor)).sum()
        cbar = state.mu
        with np.errstate(divide="ignore"):
            a = np.log(cbar) + log_l
        a = np.exp(a - a.max())
        mu = a / a.sum()
        # la correction vue du moteur : celle de la loi gaussienne de mêmes moments que le mélange prédit
        nu_mix = cbar.dot(nu)
        E = nu - nu_mix                                                # ŷ_j − ŷ = −(ν_j − ν)
        S_mix = symmetrize(_weighted(cbar, S) + (E.T * cbar).dot(E))
        x_pred = cbar.dot(state.X)
        Pxy = _weighted(cbar, np.array(PCts)) - ((state.X - x_pred).T * cbar).dot(E)
        K = np.linalg.solve(S_mix, Pxy.T).T
        return IMMState(X, P, mu, cbar), Correction(K, nu_mix, S_mix)

    def moments(state: IMMState):
        return _combine(state.mu, state.X, state.P)

    def outputs(state: IMMState) -> dict[str, np.ndarray]:
        return {"mu": state.mu, "mu_pred": state.mu_pred, "x_modes": state.X, "P_modes": state.P}

    return FilterFamily(
        name="filtre IMM",
        model_type=ModeSet,
        model_hint="donnez les régimes à imm_filter(models, y, x0, P0, transition=…)",
        prior=prior,
        predict=predict,
        update=update,
        moments=moments,
        result_type=IMMResult,
        step_outputs=outputs,
    )


def imm_filter(models: Sequence[LinearGaussianModel], y: Any, x0: Any, P0: Any, *, transition: Any,
               mu0: Any = None, u: Any = None) -> IMMResult:
    r"""Filtre IMM sur toutes les mesures (voir le module pour les équations).

    Paramètres
    ----------
    models : suite de r :class:`~kalman_course.LinearGaussianModel` — les régimes (mêmes n, m, p ;
        éventuellement variables dans le temps, avec le même nombre de pas).
    y : (T, m), ou (T,) si m = 1 — ``NaN`` : mesure manquante (prédiction seule).
    x0 : (n,) commun ou (r, n) un par régime ; P0 : (n, n) commune ou (r, n, n).
    transition : (r, r) — ``transition[i, j]`` = P(régime j au pas k | régime i au pas k−1), lignes de
        somme 1.
    mu0 : (r,), optionnel — probabilités des régimes avant la première mesure (uniformes par défaut).
    u : (T, p), optionnel — commandes, communes aux régimes (``u[k]``, qui contient :math:`u_{k-1}`, sert à prédire vers ``y[k]``).

    Renvoie un :class:`IMMResult` : ``x`` (T, n), ``P`` (T, n, n) combinés, ``mu`` (T, r), ``mu_pred``,
    ``x_modes`` (T, r, n), ``P_modes`` (T, r, n, n). Avec un seul régime, c'est
    :func:`~kalman_course.kalman_filter`.
    """
    return run_filter(imm_family(), ModeSet(models, transition, mu0), y, x0, P0, u)
