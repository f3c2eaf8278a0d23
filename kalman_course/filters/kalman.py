r"""Filtre de Kalman linéaire : étapes pures ``predict`` / ``update``, leur famille pour le moteur, les
boucles ``kalman_filter`` et ``kalman_filter_runs``.

Notations (cours → paquet) : :math:`A, B, C` identiques, :math:`\Phi \to Q`, :math:`\Psi \to R`,
:math:`\hat x^-_{n+1} \to` ``x_pred``, :math:`\hat x_{n+1} \to` ``x``.

**Trois formes de la covariance a posteriori** (option ``form``, mêmes valeurs en arithmétique exacte) :

* ``"square_root"`` (par défaut) : le filtre propage une racine triangulaire :math:`U` de :math:`P`
  (:math:`U^TU = P`) ; la prédiction empile les racines :math:`[UA^T; U_Q]` de :math:`P^-`, la correction
  triangularise par une seule QR le pré-tableau qui les contient
  (:func:`~kalman_course.core.linalg.correct_square_root`). Aucune soustraction de covariances : :math:`P`
  reste semi-définie positive et garde ses petites valeurs propres quand :math:`P_0` est vague. Mesuré
  (``tests/test_family.py``) : avec :math:`P_0 = 10^{10}I` puis :math:`10^{14}I`, l'écart au départ
  diffus exact reste de l'ordre de :math:`10^{-11}` à :math:`10^{-8}`, quand la forme de Joseph (celle
  de filterpy) s'écarte de :math:`10^{-5}` à :math:`10^{-3}` et que la forme du cours échoue
  (:math:`S` n'est plus définie positive). C'est pourquoi elle est la forme par défaut : la justesse
  d'abord. Son prix : une QR et une résolution triangulaire par pas (les covariances :math:`P, P^-, S`
  du résultat ne sont formées qu'à la fin, en un produit en lot sur les racines rangées) ; en temps CPU
  (``benchmarks/kf_vs_filterpy.py``), de 0,6 × (un état) à 0,7 × (quatre états) le temps par pas de
  filterpy, contre 0,5 à 0,7 × pour la forme du cours ; en lot (``kalman_filter_runs``), la Riccati
  commune est calculée une fois et le coût par tirage ne dépend plus de la forme.
* ``"textbook"`` : la formule du cours :math:`P = (I - KC)P^-`, calculée :math:`P^- - K(P^-C^T)^T` ; la
  moins coûteuse, exacte pour le gain optimal, mais elle soustrait deux nombres de l'ordre de :math:`P^-`
  et perd tous ses chiffres quand :math:`P^-` est très grande devant :math:`R` (chapitre SRIF).
* ``"joseph"`` : :math:`P = (I - KC)P^-(I - KC)^T + KRK^T`, valable pour un gain quelconque, somme de
  termes semi-définis positifs.

Les étapes publiques vérifient leurs entrées ; les boucles les vérifient une fois (le moteur) puis
appellent les noyaux internes (mêmes formules, sans vérification répétée).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import scipy.linalg

from ..core.linalg import (
    correct, correct_many, correct_square_root, covariance_root, gram, kalman_gain, symmetrize, triangular_root,
)
from ..core.models import LinearGaussianModel
from ..core.results import FilterResult, FilterRuns
from ..core.validation import KalmanInputError, as_gaussian, as_vector, check_control_allowed
from .gating import fading_factor
from .engine import (
    Correction, FilterFamily, gaussian_moments, gaussian_prior, gaussian_prior_many, run_filter, run_filter_runs,
)

__all__ = [
    "FORMS", "Prediction", "Update", "predict", "update", "kalman_filter", "kalman_family", "kalman_filter_runs",
    "recipe_step",
]

#: Formes de la covariance a posteriori (voir l'en-tête du module) ; la première est celle par défaut.
FORMS = ("square_root", "textbook", "joseph")


class Prediction(NamedTuple):
    r"""Résultat de :func:`predict` : :math:`\hat x_{k\mid k-1}` (n,) et :math:`P_{k\mid k-1}` (n, n)."""

    x: np.ndarray
    P: np.ndarray


class Update(NamedTuple):
    r"""Résultat de :func:`update`.

    ``x`` (n,), ``P`` (n, n) : estimation a posteriori ; ``K`` (n, m) : gain ;
    ``innovation`` (m,) : :math:`\nu = y - C\hat x^-` ; ``S`` (m, m) : covariance d'innovation.
    """

    x: np.ndarray
    P: np.ndarray
    K: np.ndarray
    innovation: np.ndarray
    S: np.ndarray


def _check_form(form: Any) -> str:
    if form not in FORMS:
        raise KalmanInputError(
            f"« form » doit être l'une des formes {', '.join(repr(f) for f in FORMS)} ; reçu {form!r}."
        )
    return form


# --------------------------------------------------------------------------- noyaux internes


def _predict(x: np.ndarray, P: np.ndarray, A: np.ndarray, Q: np.ndarray, Bu: np.ndarray | None):
    # ``A.dot(P)`` plutôt que ``A @ P`` : même calcul, trois fois moins de surcoût par appel sur de
    # petites matrices (voir benchmarks/).
    x_pred = A.dot(x)
    if Bu is not None:
        x_pred += Bu
    return x_pred, symmetrize(A.dot(P).dot(A.T) + Q)


def _check_state(x: Any, P: Any, n: int, x_name: str, P_name: str):
    return as_gaussian(x, P, n, x_name, P_name)


def _control_term(model: LinearGaussianModel, u: Any) -> np.ndarray | None:
    if u is None:
        return None
    check_control_allowed("u", model.n_control)
    return model.B @ as_vector("u", u, model.n_control)


# --------------------------------------------------------------------------- étapes publiques


def predict(model: LinearGaussianModel, x: Any, P: Any, u: Any = None, *, fading: Any = None) -> Prediction:
    r"""Étape de prédiction (*time update*).

    .. math::

        \hat x_{k\mid k-1} = A\,\hat x_{k-1\mid k-1} + B\,u_{k-1},\qquad
        P_{k\mid k-1} = A\,P_{k-1\mid k-1}A^T + Q

    Paramètres : ``x`` (n,), ``P`` (n, n) symétrique semi-définie positive, ``u`` (p,) ou ``None`` ;
    ``fading`` : facteur :math:`\alpha \ge 1` de mémoire évanescente, :math:`P_{k\mid k-1} = \alpha^2AP
    A^T + Q` (:mod:`~kalman_course.filters.gating`). Modèle variable dans le temps : passez ``model.at(k)``.
    """
    alpha = fading_factor(fading)
    x_arr, P_arr = _check_state(x, P, model.n_state, "x", "P")
    if alpha is not None:
        P_arr = alpha**2 * P_arr
    x_pred, P_pred = _predict(x_arr, P_arr, model.A, model.Q, _control_term(model, u))
    return Prediction(x_pred, P_pred)


def update(model: LinearGaussianModel, x_pred: Any, P_pred: Any, y: Any, *, form: str = FORMS[0]) -> Update:
    r"""Étape de correction (*measurement update*).

    .. math::

        \nu_k = y_k - C\hat x_{k\mid k-1},\quad S_k = C P_{k\mid k-1} C^T + R,\quad
        K_k = P_{k\mid k-1} C^T S_k^{-1},

        \hat x_{k\mid k} = \hat x_{k\mid k-1} + K_k\nu_k,\qquad
        P_{k\mid k} = (I - K_kC)\,P_{k\mid k-1}

    ``S`` n'est jamais inversée. ``form`` choisit le calcul de :math:`P_{k\mid k}` (voir l'en-tête du
    module) : ``"square_root"`` (par défaut) part d'une racine de :math:`P_{k\mid k-1}` et fait une QR ;
    ``"textbook"`` calcule :math:`P^- - K(P^-C^T)^T`, :math:`K` résolvant :math:`SK^T = CP^-` par
    Cholesky (LAPACK ``posv``) ; ``"joseph"`` calcule
    :math:`(I - K_kC)P_{k\mid k-1}(I-K_kC)^T + K_kRK_k^T`.

    Paramètres : ``x_pred`` (n,), ``P_pred`` (n, n), ``y`` (m,) (scalaire accepté si m = 1).
    """
    form = _check_form(form)
    x_arr, P_arr = _check_state(x_pred, P_pred, model.n_state, "x_pred", "P_pred")
    y_arr = as_vector("y", y, model.n_obs)
    nu = y_arr - model.C @ x_arr
    if form == "square_root":
        x, U, K, U_S = correct_square_root(x_arr, covariance_root(P_arr), nu, model.C, model.noise_roots[1],
                                           blocks=model.square_root_blocks)
        return Update(x, gram(U), K, nu, gram(U_S))
    x, P, K, S = correct(x_arr, P_arr, nu, model.C, model.R, form == "joseph")
    return Update(x, P, K, nu, S)


def recipe_step(model: LinearGaussianModel, x: Any, P: Any, y: Any, u: Any = None):
    r"""La « recette de cuisine » du cours en une ligne, **corrigée** (erratum 001-7).

    .. math::

        K_{n+1} = (AP_nA^T+\Phi)C^T\,\big[C(AP_nA^T+\Phi)C^T+\Psi\big]^{-1}

        \hat x_{n+1} = A\hat x_n + Bu_n + K_{n+1}\big[y_{n+1} - C(A\hat x_n + Bu_n)\big]

        P_{n+1} = (I - K_{n+1}C)(AP_nA^T + \Phi)

    Écrite indépendamment de :func:`predict`/:func:`update` (résolution par ``scipy.linalg.solve``)
    pour les vérifier l'une par l'autre. Renvoie ``(x, P, K)``.
    """
    x_arr, P_arr = _check_state(x, P, model.n_state, "x", "P")
    y_arr = as_vector("y", y, model.n_obs)
    A, C, Phi, Psi = model.A, model.C, model.Q, model.R
    Bu = _control_term(model, u)
    x_model = A @ x_arr + (0.0 if Bu is None else Bu)
    M = A @ P_arr @ A.T + Phi
    K = scipy.linalg.solve(C @ M @ C.T + Psi, C @ M.T, assume_a="pos").T
    x_new = x_model + K @ (y_arr - C @ x_model)
    P_new = (np.eye(model.n_state) - K @ C) @ M
    return x_new, P_new, K


# --------------------------------------------------------------------------- boucles


def kalman_filter(
    model: LinearGaussianModel,
    y: Any,
    x0: Any,
    P0: Any,
    u: Any = None,
    *,
    form: str = FORMS[0],
    gate: Any = None,
    fading: Any = None,
) -> FilterResult:
    r"""Filtre de Kalman sur toutes les mesures : pour chaque ``y[k]``, prédiction puis correction.

    L'ordre est celui du cours (:math:`\hat x_n \to \hat x^-_{n+1} \to \hat x_{n+1}`) et de la boucle
    ``predict()``/``update()`` de filterpy : la ligne ``k`` du résultat est l'estimation après la
    mesure ``y[k]``, la prédiction utilisant la commande ``u[k]``.

    Paramètres
    ----------
    model : LinearGaussianModel
    y : (T, m), ou (T,) si m = 1
        Mesures. ``None`` ou ``NaN`` : mesure manquante, le pas se réduit à la prédiction
        (gain nul). Une ligne partiellement manquante n'utilise que ses composantes présentes.
    x0 : (n,) — :math:`\hat x_0` (scalaire accepté si n = 1).
    P0 : (n, n) — :math:`P_0`, symétrique semi-définie positive (scalaire accepté si n = 1).
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (exige un modèle avec ``B`` ;
        ``u[k]``, qui contient :math:`u_{k-1}`, sert à prédire vers ``y[k]``).
    form : ``"square_root"`` (par défaut : racine carrée de :math:`P`, sûre pour un :math:`P_0` vague),
        ``"textbook"`` (:math:`P = (I - KC)P^-`, la formule du cours) ou ``"joseph"`` — voir l'en-tête
        du module.
    gate : probabilité :math:`0 < p < 1`, optionnelle — **porte** (option du moteur,
        :mod:`~kalman_course.filters.gating`) : une mesure dont la NIS :math:`\nu_k^TS_k^{-1}\nu_k` dépasse
        le quantile :math:`\chi^2_{m_k}(p)` (:math:`m_k` composantes observées) est rejetée et le pas se
        réduit à la prédiction, comme si la mesure manquait. Un pas rejeté garde son innovation et sa
        covariance ``S`` (son NIS se lit par :func:`~kalman_course.nis`), avec un gain nul ;
        ``result.rejected`` (T,) marque ces pas, que la log-vraisemblance ne compte pas.
    fading : facteur :math:`\alpha \ge 1`, optionnel — **mémoire évanescente** (option du moteur) :
        :math:`P_{k\mid k-1} = \alpha^2 A P_{k-1\mid k-1}A^T + Q` (``KalmanFilter.alpha`` de filterpy).

    ``model`` peut varier dans le temps (matrices (T, …), voir
    :class:`~kalman_course.LinearGaussianModel`) : le pas ``k`` prédit avec :math:`A_k, Q_k` et corrige
    avec :math:`C_k, R_k`.

    Renvoie
    -------
    FilterResult
        ``x`` (T, n), ``P`` (T, n, n), ``x_pred``, ``P_pred``, ``K`` (T, n, m), ``innovation`` (T, m),
        ``S`` (T, m, m), ``observed`` (T, m), ``rejected`` (T,).
    """
    return run_filter(kalman_family(form), model, y, x0, P0, u, gate=gate, fading=fading)


def kalman_filter_runs(
    model: LinearGaussianModel,
    Y: Any,
    x0: Any,
    P0: Any,
    u: Any = None,
    *,
    form: str = FORMS[0],
) -> FilterRuns:
    r"""Filtre de Kalman sur ``N`` tirages à la fois (mêmes équations que :func:`kalman_filter`), par le
    mode en lot du moteur (:func:`~kalman_course.filters.engine.run_filter_runs`).

    Sans mesure manquante et avec un :math:`P_0` commun, la récurrence des covariances
    :math:`P_{k\mid k-1}, S_k, K_k, P_{k\mid k}` ne dépend pas des mesures : le moteur la calcule **une
    fois** pour tous les tirages, et seule la moyenne est propagée en lot,
    :math:`\hat X_{k\mid k-1} = \hat X_{k-1\mid k-1}A^T + (Bu_{k-1})^T`,
    :math:`\hat X_{k\mid k} = \hat X_{k\mid k-1} + (Y_k - \hat X_{k\mid k-1}C^T)K_k^T` (une ligne par
    tirage). Avec des mesures manquantes (``NaN``, tirage par tirage) ou un :math:`P_0` par tirage, chaque
    tirage garde sa covariance ; à chaque pas, les tirages qui ont le même motif de composantes observées
    sont corrigés ensemble.

    Paramètres
    ----------
    model : LinearGaussianModel
    Y : (N, T, m) — mesures des ``N`` tirages ; ``NaN`` : composante manquante. Un tableau 2-D est refusé.
    x0 : (n,) commun (scalaire si n = 1), ou (N, n) un par tirage.
    P0 : (n, n) commune, ou (N, n, n) une par tirage.
    u : (T, p) commune, ou (N, T, p) une par tirage, optionnel.
    form : comme :func:`kalman_filter`.

    Renvoie un :class:`~kalman_course.core.results.FilterRuns` : ``x`` (N, T, n), ``innovation``
    (N, T, m)… et ``P``, ``P_pred``, ``K``, ``S`` de forme (T, …) s'ils sont communs (aucune mesure
    manquante, :math:`P_0` commune), (N, T, …) sinon. Chaque tirage est égal à :func:`kalman_filter` sur
    ses mesures.
    """
    return run_filter_runs(kalman_family(form), model, Y, x0, P0, u)


def _predicted_root(U: np.ndarray, A: np.ndarray, U_Q: np.ndarray) -> np.ndarray:
    r"""Racine de :math:`P^- = AP A^T + Q` à partir d'une racine ``U`` (…, r, n) de :math:`P` : les racines
    empilées :math:`[UA^T; U_Q]` ((r + n) × n), que la QR de la correction triangularisera (une QR par pas au
    lieu de deux). Une racine de plus de ``n`` lignes (le pas précédent était sans mesure) est d'abord
    triangularisée ; les racines d'une pile de tirages (N, r, n) le sont aussitôt (une seule forme pour
    toute la pile, quel que soit le motif des mesures manquantes)."""
    n = A.shape[0]
    if U.shape[-2] > n:
        U = triangular_root(U)
    if U.ndim == 2:
        return np.concatenate((U.dot(A.T), U_Q))
    return triangular_root(np.concatenate([U @ A.T, np.broadcast_to(U_Q, U.shape)], axis=-2))


def _observed_part(model: LinearGaussianModel, idx: np.ndarray | None, square_root: bool):
    r""":math:`C` et :math:`R` (ou la racine :math:`U_R`) restreintes aux composantes observées ``idx``
    (``None`` : toutes)."""
    if idx is None:
        return model.C, (model.noise_roots[1] if square_root else model.R)
    R = model.R[np.ix_(idx, idx)]
    return model.C[idx], (covariance_root(R) if square_root else R)


def kalman_family(form: str = FORMS[0]) -> FilterFamily:
    r"""Les étapes du filtre de Kalman linéaire pour le moteur, un tirage
    (:func:`~kalman_course.filters.engine.run_filter`) ou ``N`` à la fois
    (:func:`~kalman_course.filters.engine.run_filter_runs`).

    État interne d'un tirage : :math:`(\hat x, M)` pour ``form="square_root"`` — la racine :math:`M`
    (:math:`M^TM = P`) porte tout le calcul, et la famille le déclare au moteur (``root_rows``) : il range
    les racines et forme les covariances :math:`P, P^-, S` du résultat à la fin, en un produit en lot — et
    :math:`(\hat x, P)` pour les deux autres formes. Étapes en lot : :math:`(\hat X, P, M)` en racine
    carrée, :math:`(\hat X, P)` sinon ; la moyenne a une ligne par tirage (N, n), la covariance et sa
    racine sont communes à tous les tirages (n, n) (Riccati commune) ou une par tirage (N, n, n) ; la
    commande est (p,) ou (N, p).

    Options du moteur (:mod:`~kalman_course.filters.gating`) : mémoire évanescente (``inflate`` : la
    covariance multipliée par :math:`\alpha^2`, sa racine par :math:`\alpha`), porte (la correction rend
    :math:`\nu` et :math:`S`, ou sa racine), adaptation de :math:`Q` (``noise_image`` :
    :math:`G = CQC^T`)."""
    form = _check_form(form)
    square_root, joseph = form == "square_root", form == "joseph"

    def predict_mean(model, x, u):  # x̂⁻ = A x̂ + B u ; x (n,) ou une ligne par tirage (N, n)
        x_pred = x.dot(model.A.T)
        if u is not None:
            x_pred += u.dot(model.B.T)
        return x_pred

    if square_root:
        def prior(model, x0, P0):
            x, P = gaussian_prior(model, x0, P0)
            return x, covariance_root(P)

        def prior_many(model, x0, P0, N, shared=False):
            X, P = gaussian_prior_many(model, x0, P0, N, shared=shared)
            return X, P, covariance_root(P)

        def predict(model, state, u):  # un tirage : x̂⁻ = A x̂ + B u, racine M = [U Aᵀ; U_Q] de P⁻ (2n × n)
            x, U = state
            A = model.A
            if U.shape[0] > A.shape[0]:  # le pas précédent était sans mesure : racine rectangulaire
                U = triangular_root(U)
            M = np.concatenate((U.dot(A.T), model.noise_roots[0]))
            return (A.dot(x) if u is None else A.dot(x) + model.B.dot(u)), M

        def update(model, state, y, idx):  # une QR ; rend la racine U de P et celle de S (Correction.S)
            x_pred, M = state
            if idx is None:  # toutes les composantes : blocs constants du pré-tableau, calculés une fois
                C, U_R, blocks = model.C, model.noise_roots[1], model.square_root_blocks
            else:
                (C, U_R), blocks = _observed_part(model, idx, True), None
            nu = y - C.dot(x_pred)
            x, U, K, U_S = correct_square_root(x_pred, M, nu, C, U_R, blocks=blocks)
            return (x, U), Correction(K, nu, U_S)

        def predict_many(model, state, u, k):
            X, _, U = state
            M = _predicted_root(U, model.A, model.noise_roots[0])
            return predict_mean(model, X, u), gram(M), M

        def update_many(model, state, Y, idx, k):
            X_pred, _, M = state
            C, U_R = _observed_part(model, idx, True)
            nu = Y - X_pred.dot(C.T)
            blocks = model.square_root_blocks if idx is None else None
            X, U, K, U_S = correct_square_root(X_pred, M, nu, C, U_R, f"correction par y[{k}]", blocks)
            return (X, gram(U), U), Correction(K, nu, gram(U_S))
    else:
        prior = gaussian_prior

        def prior_many(model, x0, P0, N, shared=False):
            return gaussian_prior_many(model, x0, P0, N, shared=shared)

        def predict(model, state, u):  # un tirage : le noyau montré dans le chapitre « prédicteur-correcteur »
            x, P = state
            return _predict(x, P, model.A, model.Q, None if u is None else model.B.dot(u))

        def update(model, state, y, idx):
            x_pred, P_pred = state
            C, R = _observed_part(model, idx, False)
            nu = y - C.dot(x_pred)
            x, P, K, S = correct(x_pred, P_pred, nu, C, R, joseph)
            return (x, P), Correction(K, nu, S)

        def predict_many(model, state, u, k):
            X, P = state
            A = model.A
            return predict_mean(model, X, u), symmetrize((A.dot(P).dot(A.T) if P.ndim == 2 else A @ P @ A.T) + model.Q)

        def update_many(model, state, Y, idx, k):
            X_pred, P_pred = state
            C, R = _observed_part(model, idx, False)
            nu = Y - X_pred.dot(C.T)
            where = f"correction par y[{k}]"
            if P_pred.ndim == 2:  # covariance commune : un gain pour tous les tirages
                K, S, PCt = kalman_gain(P_pred, C, R, where)
                IKC = np.eye(P_pred.shape[0]) - K.dot(C)
                P = IKC.dot(P_pred).dot(IKC.T) + K.dot(R).dot(K.T) if joseph else P_pred - K.dot(PCt.T)
                return (X_pred + nu.dot(K.T), symmetrize(P)), Correction(K, nu, S)
            X, P, K, S = correct_many(X_pred, P_pred, nu, C, R, joseph, where)
            return (X, P), Correction(K, nu, S)

    def inflate(state, alpha):  # mémoire évanescente : P ← α² P (en racine carrée, M ← α M)
        return (state[0], (alpha if square_root else alpha * alpha) * state[1])

    def noise_image(model, predicted, idx):  # G = C Q Cᵀ sur les composantes observées
        C = model.C if idx is None else model.C[idx]
        return C.dot(model.Q).dot(C.T)

    return FilterFamily(
        name="filtre de Kalman",
        model_type=LinearGaussianModel,
        model_hint="pour un modèle non linéaire, utilisez extended_kalman_filter",
        prior=prior,
        predict=predict,
        update=update,
        moments=gaussian_moments,
        root_rows=(lambda model: 2 * model.n_state) if square_root else None,  # M = [U Aᵀ; U_Q]
        prior_many=prior_many,
        predict_many=predict_many,
        update_many=update_many,
        batch_controls=True,
        shared_covariance=True,
        inflate=inflate,
        gating=True,
        noise_image=noise_image,
    )
