r"""Filtre IMM (*interacting multiple models*, Blom & Bar-Shalom 1988) : des régimes linéaires gaussiens, ou
non linéaires filtrés par un membre du filtre gaussien (EKF, UKF, CKF, GHKF).

Une cible qui vole droit puis vire n'obéit pas à un seul modèle. L'IMM en fait tourner :math:`r` à la fois
(des :class:`~kalman_course.LinearGaussianModel` — ou des :class:`~kalman_course.NonlinearModel`, par exemple
vitesse constante et virage coordonné — de même état et de même mesure), reliés par une chaîne de
Markov sur le régime : ``transition[i, j]`` :math:`= \pi_{ij} = P(\text{régime } j \text{ au pas } k \mid
\text{régime } i \text{ au pas } k-1)`. Chaque pas, pour :math:`\mu_{k-1}` les probabilités des régimes :

1. **Mélange.** Probabilités prédites :math:`\bar c_j = \sum_i \pi_{ij}\mu_{k-1,i}`, poids de mélange
   :math:`\omega_{ij} = \pi_{ij}\mu_{k-1,i}/\bar c_j` ; chaque filtre repart du mélange des estimations
   :math:`x^0_j = \sum_i \omega_{ij}\hat x_i`,
   :math:`P^0_j = \sum_i \omega_{ij}\,[P_i + (\hat x_i - x^0_j)(\hat x_i - x^0_j)^T]`.
2. **Prédiction et correction par régime** : les étapes du filtre de Kalman
   (:func:`~kalman_course.filters.kalman.kalman_family`) — ou, pour des régimes non linéaires, celles du
   filtre gaussien de la règle choisie (:func:`~kalman_course.filters.gaussian.gaussian_family` :
   linéarisation pour l'EKF par défaut, ``rule=kc.UnscentedRule(…)``, ``kc.CubatureRule()``,
   ``kc.GaussHermiteRule(…)``) —, modèle :math:`j` depuis :math:`(x^0_j, P^0_j)`, d'où :math:`\hat x_j`,
   :math:`P_j` et la vraisemblance :math:`\ell_j = \mathcal N(\nu_j; 0, S_j)` de la mesure.
3. **Probabilités des régimes** : :math:`\mu_{k,j} = \bar c_j\ell_j / \sum_i \bar c_i\ell_i` (calculées en
   logarithmes). Le dénominateur est la vraisemblance de la mesure sous le mélange,
   :math:`p(y_k\mid y_{1:k-1}) = \sum_j \bar c_j\,\mathcal N(\nu_j; 0, S_j)` : la log-vraisemblance de l'IMM est
   :math:`\sum_k \log\sum_j \bar c_j\,\mathcal N(\nu_j; 0, S_j)` (``result.log_likelihood``, que rend
   :func:`~kalman_course.filter_log_likelihood`), et non celle de la loi gaussienne de mêmes moments.
4. **Combinaison** (pour la sortie seulement) : :math:`\hat x = \sum_j \mu_{k,j}\hat x_j`,
   :math:`P = \sum_j \mu_{k,j}[P_j + (\hat x_j - \hat x)(\hat x_j - \hat x)^T]`.

Mêmes calculs et même ordre que ``IMMEstimator`` de filterpy (``predict()`` puis ``update(z)``). Le filtre
passe par le moteur commun (:func:`~kalman_course.filters.engine.run_filter`) : ses étapes pures
(mélange + prédiction, correction + probabilités) sont une famille comme les autres ; mesures manquantes
(prédiction seule, :math:`\mu_k = \bar c`), mesures partielles, modèles variables dans le temps et les
options du moteur viennent de lui : porte (``gate=p`` : chaque régime a la sienne, :math:`\chi^2_{m_k}(p)`
sur :math:`\nu_j^TS_j^{-1}\nu_j`, et la mesure est gardée si elle tombe dans l'une ; sinon le pas est une
prédiction seule, :math:`\mu_k = \bar c`, et ne compte pas dans la vraisemblance), mémoire évanescente
(``fading=α`` : la covariance de chaque régime multipliée par :math:`\alpha^2` avant le mélange).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple, Sequence

import numpy as np
import scipy.linalg

from ..core.linalg import S_NOT_PD, symmetrize
from ..core.models import LinearGaussianModel, NonlinearModel, TimeVarying
from ..core.results import FilterResult
from ..core.validation import (
    KalmanInputError,
    as_float_array,
    as_square_matrix,
    as_vector,
    check_pd,
    check_psd,
    number_text,
    shape_text,
)
from .engine import Correction, FilterFamily, run_filter
from .gaussian import GaussianRule, gaussian_family
from .kalman import kalman_family

__all__ = ["ModeSet", "IMMState", "IMMResult", "imm_family", "imm_filter", "mode_mixing"]

LOG_2PI = float(np.log(2.0 * np.pi))
_posv = scipy.linalg.get_lapack_funcs("posv", dtype=np.float64)


@dataclass(frozen=True, eq=False, init=False)
class ModeSet(TimeVarying):
    r"""Les régimes d'un IMM : ``models`` (r modèles de mêmes dimensions n, m, p : tous
    :class:`~kalman_course.LinearGaussianModel`, ou au moins un :class:`~kalman_course.NonlinearModel`, les
    régimes linéaires constants étant alors vus comme non linéaires par
    :meth:`~kalman_course.NonlinearModel.from_linear`), ``transition`` (r, r) stochastique (lignes de somme
    1) et ``mu0`` (r,) probabilités initiales. ``linear`` : tous les régimes sont linéaires (filtre de
    Kalman par régime). Variable dans le temps si l'un des modèles l'est : le protocole des modèles
    (:class:`~kalman_course.core.models.TimeVarying` : :meth:`at`, :meth:`steps`)."""

    models: tuple
    transition: np.ndarray
    mu0: np.ndarray
    linear: bool

    def __init__(self, models: Sequence[Any], transition: Any, mu0: Any = None) -> None:
        if isinstance(models, (LinearGaussianModel, NonlinearModel)) or not isinstance(models, (list, tuple)) \
                or not models:
            raise KalmanInputError(
                "« models » doit être une liste de modèles (LinearGaussianModel ou NonlinearModel, un par régime, "
                "au moins un)."
            )
        models = tuple(models)
        for i, model in enumerate(models):
            if not isinstance(model, (LinearGaussianModel, NonlinearModel)):
                raise KalmanInputError(
                    f"« models[{i}] » doit être un LinearGaussianModel ou un NonlinearModel ; reçu "
                    f"{type(model).__name__} (l'IMM combine des régimes : un modèle par régime)."
                )
        linear = all(isinstance(model, LinearGaussianModel) for model in models)
        if not linear:
            for i, model in enumerate(models):
                if isinstance(model, LinearGaussianModel) and model.time_varying:
                    raise KalmanInputError(
                        f"« models[{i}] » varie dans le temps : avec des régimes non linéaires, chaque régime doit "
                        "être constant (un NonlinearModel n'a pas d'axe des temps)."
                    )
            models = tuple(NonlinearModel.from_linear(mdl) if isinstance(mdl, LinearGaussianModel) else mdl
                           for mdl in models)
        n, m, p = models[0].n_state, models[0].n_obs, models[0].n_control
        for i, model in enumerate(models[1:], 1):
            if (model.n_state, model.n_obs, model.n_control) != (n, m, p):
                raise KalmanInputError(
                    f"« models[{i}] » a n = {model.n_state}, m = {model.n_obs}, p = {model.n_control} ; le premier "
                    f"régime a n = {n}, m = {m}, p = {p} : les régimes d'un IMM partagent état, mesure et commande."
                )
        lengths = {model.n_steps for model in models if linear and model.time_varying}
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
                            ("linear", linear), ("_n_steps", lengths.pop() if lengths else None), ("_steps", None)):
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

    def _build_steps(self, T: int) -> list["ModeSet"]:
        per_model = [model.steps(T) for model in self.models]
        steps = []
        for k in range(T):
            step = object.__new__(ModeSet)
            for name, value in (("models", tuple(pm[k] for pm in per_model)), ("transition", self.transition),
                                ("mu0", self.mu0), ("linear", self.linear), ("_n_steps", None), ("_steps", None)):
                object.__setattr__(step, name, value)
            steps.append(step)
        return steps

    def __repr__(self) -> str:
        kind = "linéaires" if self.linear else "non linéaires"
        return f"ModeSet({self.n_modes} régimes {kind}, n={self.n_state}, m={self.n_obs})"


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
    leurs probabilités, ``mu_pred`` (r,) les probabilités prédites :math:`\bar c` du dernier pas, ``k``
    l'indice de la mesure visée (messages), ``increment`` :math:`\log\sum_j\bar c_j\mathcal N(\nu_j; 0, S_j)`
    (0 après une prédiction seule) et ``nis`` (r,) les NIS :math:`\nu_j^TS_j^{-1}\nu_j` des régimes (porte)."""

    X: np.ndarray
    P: np.ndarray
    mu: np.ndarray
    mu_pred: np.ndarray
    k: int = -1
    increment: float = 0.0
    nis: np.ndarray | None = None


@dataclass(frozen=True, eq=False, repr=False)
class IMMResult(FilterResult):
    r"""Sortie de :func:`imm_filter` : les champs de :class:`~kalman_course.FilterResult` pour l'estimation
    **combinée** (``x`` (T, n), ``P`` (T, n, n) ; ``x_pred``, ``P_pred`` : la prédiction combinée
    :math:`\sum_j \bar c_j \hat x^-_j` ; ``innovation`` :math:`y_k - \sum_j\bar c_j\hat y_j`, ``S`` la
    covariance du mélange des mesures prédites, ``K`` le gain de la loi gaussienne de mêmes moments), et :

    ``mu`` (T, r) : probabilités des régimes après la mesure ``y[k]`` ; ``mu_pred`` (T, r) : avant
    (:math:`\bar c`) ; ``x_modes`` (T, r, n), ``P_modes`` (T, r, n, n) : estimations de chaque régime ;
    ``log_likelihood_increments`` (T,) : :math:`\log p(y_k\mid y_{1:k-1}) = \log\sum_j \bar c_j\,
    \mathcal N(\nu_j; 0, S_j)` (0 pour un pas sans mesure ou rejeté par la porte) — la vraisemblance du
    mélange, que rend :func:`~kalman_course.filter_log_likelihood` (pas celle de la gaussienne de mêmes
    moments, ``innovation`` et ``S``, qui n'est pas la loi de l'IMM)."""

    mu: np.ndarray | None = None
    mu_pred: np.ndarray | None = None
    x_modes: np.ndarray | None = None
    P_modes: np.ndarray | None = None
    log_likelihood_increments: np.ndarray | None = None

    @property
    def n_modes(self) -> int:
        return self.mu.shape[-1]

    @property
    def mode(self) -> np.ndarray:
        """(T,) entier : le régime le plus probable à chaque pas."""
        return np.argmax(self.mu, axis=-1)

    @property
    def log_likelihood(self) -> float:
        r""":math:`\sum_k \log\sum_j \bar c_j\,\mathcal N(\nu_j; 0, S_j)` : la log-vraisemblance du mélange."""
        return float(np.sum(self.log_likelihood_increments))


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


def _mode_steps(linear: bool, rule: GaussianRule | None):
    r"""Les étapes d'un régime, ``(predict(model, x, P, u, k) → (x⁻, P⁻), update(model, x⁻, P⁻, y, idx, k) →
    (x, P, Correction), check(model, P0))`` : celles du filtre de Kalman (forme du cours, état
    :math:`(\hat x, P)` : le mélange forme des covariances) pour des régimes linéaires, celles du filtre
    gaussien de la règle ``rule`` (état :math:`(\hat x, P, k, \cdot)`) sinon."""
    if linear:
        kf = kalman_family("textbook")

        def predict(model, x, P, u, k):
            return kf.predict(model, (x, P), u)

        def update(model, x, P, y, idx, k):
            (x_new, P_new), corr = kf.update(model, (x, P), y, idx)
            return x_new, P_new, corr

        def check(model, P0, name):
            return check_psd(name, P0)

        return predict, update, check
    from .extended import LINEARIZATION

    rule = LINEARIZATION if rule is None else rule
    gf = gaussian_family(rule)

    def predict(model, x, P, u, k):
        x_pred, P_pred, *_ = gf.predict(model, (x, P, k, None), u)
        return x_pred, P_pred

    def update(model, x, P, y, idx, k):
        (x_new, P_new, *_), corr = gf.update(model, (x, P, k, None), y, idx)
        return x_new, P_new, corr

    def check(model, P0, name):
        rule.check(model)
        return check_pd(name, P0) if rule.definite else check_psd(name, P0)

    return predict, update, check


def imm_family(linear: bool = True, rule: GaussianRule | None = None) -> FilterFamily:
    r"""Les étapes de l'IMM pour le moteur (modèle : :class:`ModeSet`, état : :class:`IMMState`) ; chaque
    régime passe par les étapes d'un membre de la famille gaussienne (:func:`_mode_steps`) : le filtre de
    Kalman (``linear=True``) ou le filtre gaussien de la règle ``rule`` (linéarisation par défaut : l'EKF).
    Options du moteur : mémoire évanescente (``inflate`` : :math:`P_j \leftarrow \alpha^2P_j` avant le
    mélange) et porte (``gate_nis`` : les NIS des régimes, la mesure est gardée si l'une passe)."""
    mode_predict, mode_update, check_mode = _mode_steps(linear, rule)

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
            P = np.array([check_mode(model.models[j], P[j], f"P0[{j}]") for j in range(r)])
        else:
            P0_checked = as_square_matrix("P0", P, n)
            P = np.array([check_mode(mdl, P0_checked, "P0") for mdl in model.models])
        mu = np.array(model.mu0)
        return IMMState(X, P, mu, mu)

    def predict(model: ModeSet, state: IMMState, u) -> IMMState:
        cbar, W = mode_mixing(model.transition, state.mu)
        X0 = W.T.dot(state.X)                                          # x⁰_j = Σ_i ω_ij x_i
        D = state.X[None, :, :] - X0[:, None, :]                       # (j, i, n)
        P0 = np.einsum("ij,ikl->jkl", W, state.P) + np.einsum("ij,jik,jil->jkl", W, D, D)
        X, P = np.empty_like(X0), np.empty_like(P0)
        k = state.k + 1
        for j, mj in enumerate(model.models):
            X[j], P[j] = mode_predict(mj, X0[j], P0[j], u, k)
        return IMMState(X, P, cbar, cbar, k)

    def update(model: ModeSet, state: IMMState, y, idx):
        r = model.n_modes
        X, P = np.empty_like(state.X), np.empty_like(state.P)
        nus, Ss, PCts = [], [], []
        for j, mj in enumerate(model.models):
            X[j], P[j], corr = mode_update(mj, state.X[j], state.P[j], y, idx, state.k)
            nus.append(corr.innovation)
            Ss.append(corr.S)
            PCts.append(corr.K.dot(corr.S))                           # P⁻_j H_jᵀ = K_j S_j (covariance croisée)
        nu, S = np.array(nus), np.array(Ss)                           # (r, m_k), (r, m_k, m_k)
        log_l, nis = np.empty(r), np.empty(r)
        for j in range(r):  # log N(ν_j ; 0, S_j) : un appel LAPACK (Cholesky et résolution) par régime
            factor, Sinv_nu, info = _posv(Ss[j], nus[j])
            if info != 0:
                raise KalmanInputError(f"{S_NOT_PD[:-1]} (régime {j}, correction par y[{state.k}]).")
            nis[j] = nus[j].dot(Sinv_nu)
            log_l[j] = -0.5 * (len(nus[j]) * LOG_2PI + nis[j]) - np.log(np.abs(np.diagonal(factor))).sum()
        cbar = state.mu
        with np.errstate(divide="ignore"):
            a = np.log(cbar) + log_l
        top = a.max()
        w = np.exp(a - top)
        total = w.sum()
        mu = w / total
        increment = float(top + np.log(total))                         # log Σ_j c̄_j N(ν_j ; 0, S_j)
        # la correction vue du moteur : celle de la loi gaussienne de mêmes moments que le mélange prédit
        nu_mix = cbar.dot(nu)
        E = nu - nu_mix                                                # ŷ_j − ŷ = −(ν_j − ν)
        S_mix = symmetrize(_weighted(cbar, S) + (E.T * cbar).dot(E))
        x_pred = cbar.dot(state.X)
        Pxy = _weighted(cbar, np.array(PCts)) - ((state.X - x_pred).T * cbar).dot(E)
        K = np.linalg.solve(S_mix, Pxy.T).T
        return IMMState(X, P, mu, cbar, state.k, increment, nis), Correction(K, nu_mix, S_mix)

    def moments(state: IMMState):
        return _combine(state.mu, state.X, state.P)

    def outputs(state: IMMState) -> dict[str, np.ndarray]:
        return {"mu": state.mu, "mu_pred": state.mu_pred, "x_modes": state.X, "P_modes": state.P,
                "log_likelihood_increments": state.increment}

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
        inflate=lambda state, alpha: state._replace(P=alpha * alpha * state.P),
        gating=True,
        gate_nis=lambda state, corr: state.nis,
    )


def _looks_like_transition(u: Any, r: int) -> bool:
    """``u`` ressemble-t-il à une matrice de transition (r, r) stochastique, donnée en cinquième position ?"""
    try:
        arr = np.asarray(u, dtype=float)
    except (TypeError, ValueError):
        return False
    return arr.shape == (r, r) and bool(np.all(arr >= 0)) and bool(np.allclose(arr.sum(axis=1), 1.0))


def imm_filter(models: Sequence[Any], y: Any, x0: Any, P0: Any, u: Any = None, *, transition: Any = None,
               mu0: Any = None, rule: GaussianRule | None = None, gate: Any = None, fading: Any = None) -> IMMResult:
    r"""Filtre IMM sur toutes les mesures (voir le module pour les équations).

    Paramètres
    ----------
    models : suite de r modèles — les régimes (mêmes n, m, p) : des :class:`~kalman_course.LinearGaussianModel`
        (filtre de Kalman par régime ; éventuellement variables dans le temps, avec le même nombre de pas),
        ou des :class:`~kalman_course.NonlinearModel` (par exemple vitesse constante et virage coordonné ;
        les régimes linéaires constants s'y joignent par :meth:`~kalman_course.NonlinearModel.from_linear`).
    y : (T, m), ou (T,) si m = 1 — ``NaN`` : mesure manquante (prédiction seule).
    x0 : (n,) commun ou (r, n) un par régime ; P0 : (n, n) commune ou (r, n, n).
    u : (T, p), optionnel — commandes, communes aux régimes (``u[k]``, qui contient :math:`u_{k-1}`, sert à
        prédire vers ``y[k]``).
    transition : (r, r), obligatoire — ``transition[i, j]`` = P(régime j au pas k | régime i au pas k−1),
        lignes de somme 1.
    mu0 : (r,), optionnel — probabilités des régimes avant la première mesure (uniformes par défaut).
    rule : règle du filtre gaussien des régimes non linéaires (:class:`~kalman_course.GaussianRule` :
        ``kc.Linearization()`` — l'EKF, par défaut —, ``kc.UnscentedRule(α, β, κ)``, ``kc.CubatureRule()``,
        ``kc.GaussHermiteRule(order=…)``) ; avec des régimes tous linéaires, elle les fait filtrer par ce
        membre au lieu du filtre de Kalman.
    gate, fading : porte (une par régime, la mesure gardée si elle tombe dans l'une) et mémoire évanescente
        (chaque régime), options du moteur (:mod:`~kalman_course.filters.gating`).

    Renvoie un :class:`IMMResult` : ``x`` (T, n), ``P`` (T, n, n) combinés, ``mu`` (T, r), ``mu_pred``,
    ``x_modes`` (T, r, n), ``P_modes`` (T, r, n, n), ``log_likelihood_increments`` (T,). Avec un seul
    régime, c'est :func:`~kalman_course.kalman_filter` (ou le filtre gaussien de ``rule``).
    """
    if transition is None:
        r = len(models) if isinstance(models, (list, tuple)) else 1
        hint = (" La matrice donnée en cinquième position, qui est la place des commandes « u », ressemble à une "
                "matrice de transition : nommez-la, transition=Pi." if u is not None and _looks_like_transition(u, r)
                else "")
        raise KalmanInputError(
            "« transition » manque : la matrice (r, r) des probabilités de changement de régime se donne par son "
            f"nom, imm_filter(models, y, x0, P0, transition=Pi, mu0=…).{hint}"
        )
    if rule is not None and not isinstance(rule, GaussianRule):
        raise KalmanInputError(
            "« rule » doit être une règle du filtre gaussien (kc.Linearization(), kc.UnscentedRule(...), "
            f"kc.CubatureRule(), kc.GaussHermiteRule(order=...)) ; reçu {type(rule).__name__}."
        )
    if rule is not None and isinstance(models, (list, tuple)):
        models = [NonlinearModel.from_linear(mdl) if isinstance(mdl, LinearGaussianModel) and not mdl.time_varying
                  else mdl for mdl in models]
    modes = ModeSet(models, transition, mu0)
    return run_filter(imm_family(modes.linear, rule), modes, y, x0, P0, u, gate=gate, fading=fading)
