r"""Le moteur unique des filtres : une seule boucle dans le temps pour toutes les familles.

Une famille de filtres (Kalman, EKF, EKF itéré, SRIF, SE(3)…) ne fournit que ses étapes pures, réunies
dans un :class:`FilterFamily` :

* ``prior(model, x0, P0)`` → état interne initial (vérifie ``x0``, ``P0`` et les convertit : par exemple
  :math:`(\hat x_0, P_0)`, ou :math:`(\mathcal R_{xx}, z_x)` pour le SRIF) ;
* ``predict(model, state, u_k)`` → état prédit (:math:`k-1 \mid k-1 \to k \mid k-1`) ;
* ``update(model, state, y_k, idx)`` → ``(état corrigé, Correction)``, où ``y_k`` ne contient que les
  composantes observées et ``idx`` leurs indices (``None`` : toutes) ;
* ``moments(state)`` → :math:`(\hat x, P)` à ranger dans le résultat.

Deux crochets facultatifs servent les filtres de Monte-Carlo (filtre particulaire, EnKF) :

* ``stochastic=True`` : le moteur exige un générateur ``rng`` (graine entière ou
  ``numpy.random.Generator``) et le passe à chaque étape en argument nommé (``prior(..., rng=g)``,
  ``predict(..., rng=g)``, ``update(..., rng=g)``) : tous les tirages viennent de ce seul générateur, donc
  même graine → même résultat ;
* ``step_outputs(state)`` → dictionnaire ``nom → tableau`` lu après chaque pas (taille effective de
  l'échantillon, incrément de log-vraisemblance, particules…) ; le moteur les empile, temps en premier,
  et les passe au constructeur de ``result_type`` sous ces noms.

Le moteur (:func:`run_filter`) fait, une fois pour toutes les familles, ce que faisait chaque boucle :
vérifier le modèle, ``y``, ``u``, l'a priori ; traiter les mesures manquantes (ligne ``None``/``NaN`` :
prédiction seule ; ligne partielle : correction avec les seules composantes observées) ; assembler le
résultat immuable, temps en premier (:class:`~kalman_course.core.results.FilterResult`). Les erreurs
d'entrée sont donc les mêmes pour tous les filtres.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial
from typing import Any, Callable, NamedTuple

import numpy as np

from ..core.results import FilterHistory, FilterResult
from ..core.simulation import as_generator
from ..core.validation import KalmanInputError, as_controls, as_gaussian, as_measurements, check_instance

__all__ = ["Correction", "FilterFamily", "run_filter", "observed_rows", "gaussian_prior", "gaussian_moments"]


class Correction(NamedTuple):
    r"""Ce qu'une correction range dans le résultat, restreint aux composantes observées.

    ``K`` (n, m_k) : gain ; ``innovation`` (m_k,) : :math:`\nu_k` ; ``S`` (m_k, m_k) : sa covariance ;
    ``n_iter`` : nombre d'itérations de la correction (1 pour une correction non itérée)."""

    K: np.ndarray
    innovation: np.ndarray
    S: np.ndarray
    n_iter: int = 1


@dataclass(frozen=True)
class FilterFamily:
    """Les étapes pures d'une famille de filtres, que :func:`run_filter` enchaîne dans le temps.

    ``name`` : nom français du filtre (messages) ; ``model_type`` : classe(s) de modèle acceptée(s) ;
    ``model_hint`` : piste donnée quand le modèle n'est pas du bon type ; ``result_type`` : classe du
    résultat (une sous-classe de :class:`FilterResult`) ; ``state_shape(model)`` : forme de
    l'estimation rangée à chaque pas (``(n,)`` par défaut, ``(4, 4)`` pour une pose) ;
    ``tangent_dim(model)`` : dimension de la covariance (``n`` par défaut, 6 pour SE(3)) ;
    ``stochastic`` : les étapes tirent au hasard et reçoivent ``rng=`` (un ``numpy.random.Generator``) ;
    ``step_outputs(state)`` : sorties supplémentaires de chaque pas (dictionnaire de tableaux), empilées
    dans le temps et passées à ``result_type``.
    """

    name: str
    model_type: type | tuple[type, ...]
    prior: Callable[[Any, Any, Any], Any]
    predict: Callable[[Any, Any, np.ndarray | None], Any]
    update: Callable[[Any, Any, np.ndarray, np.ndarray | None], tuple[Any, Correction]]
    moments: Callable[[Any], tuple[np.ndarray, np.ndarray]]
    model_hint: str = ""
    result_type: type = FilterResult
    state_shape: Callable[[Any], tuple[int, ...]] = field(default=lambda model: (model.n_state,))
    tangent_dim: Callable[[Any], int] = field(default=lambda model: model.n_state)
    stochastic: bool = False
    step_outputs: Callable[[Any], dict[str, Any]] | None = None


def gaussian_prior(model: Any, x0: Any, P0: Any) -> tuple[np.ndarray, np.ndarray]:
    """A priori des filtres gaussiens : ``x0`` (n,), ``P0`` (n, n) symétrique semi-définie positive."""
    return as_gaussian(x0, P0, model.n_state, "x0", "P0")


def gaussian_moments(state: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    r"""L'état interne d'un filtre gaussien est déjà :math:`(\hat x, P)`."""
    return state


def observed_rows(Y: np.ndarray) -> np.ndarray:
    """Masque ``(T, m)`` des composantes observées (``False`` pour ``NaN``)."""
    return ~np.isnan(Y)


def run_filter(
    family: FilterFamily, model: Any, y: Any, x0: Any, P0: Any, u: Any = None, *, rng: Any = None
) -> FilterResult:
    r"""Applique la famille ``family`` à toutes les mesures : pour chaque ``y[k]``, prédiction avec
    ``u[k]`` puis correction.

    L'ordre est celui du cours (:math:`\hat x_n \to \hat x^-_{n+1} \to \hat x_{n+1}`) et de la boucle
    ``predict()``/``update()`` de filterpy : la ligne ``k`` du résultat est l'estimation après la
    mesure ``y[k]``.

    Paramètres
    ----------
    model : le modèle de la famille (vérifié).
    y : (T, m), ou (T,) si m = 1 — ``None`` ou ``NaN`` : mesure manquante (prédiction seule) ; une ligne
        partiellement manquante n'utilise que ses composantes observées.
    x0, P0 : a priori, vérifiés et convertis par ``family.prior``.
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (``u[k]`` sert à prédire vers ``y[k]``).
    rng : graine entière ou ``numpy.random.Generator`` — obligatoire pour une famille ``stochastic``,
        refusé pour les autres.

    Renvoie un ``family.result_type`` : ``x`` (T, …), ``P`` (T, d, d), ``x_pred``, ``P_pred``,
    ``K`` (T, d, m), ``innovation`` (T, m), ``S`` (T, m, m), ``observed`` (T, m), ``n_iter`` (T,), et
    les sorties de ``family.step_outputs`` empilées (T, …).
    """
    check_instance("model", model, family.model_type, family.model_hint)
    if family.stochastic:
        draws = {"rng": as_generator(rng)}
    elif rng is not None:
        raise KalmanInputError(f"« rng » est fourni, mais le {family.name} ne tire rien au hasard : retirez-le.")
    else:
        draws = {}
    m = model.n_obs
    Y = as_measurements("y", y, m)
    T = Y.shape[0]
    U = as_controls("u", u, T, model.n_control)
    prior, predict, update = family.prior, family.predict, family.update
    if draws:  # le générateur lié une fois pour toutes, pas à chaque appel
        prior, predict, update = (partial(f, **draws) for f in (prior, predict, update))
    state = prior(model, x0, P0)
    observed = observed_rows(Y)
    out = FilterHistory(T, family.state_shape(model), family.tangent_dim(model), m, observed)
    full = observed.all(axis=1)
    some = observed.any(axis=1)
    extras: dict[str, list] = {}
    # boucle chaude : références locales, pas d'appel superflu (moments identiques pour les filtres gaussiens)
    moments = None if family.moments is gaussian_moments else family.moments
    step_outputs = family.step_outputs
    xs, Ps, xps, Pps = out.x, out.P, out.x_pred, out.P_pred
    Ks, nus, Ss, n_iter = out.K, out.innovation, out.S, out.n_iter
    for k in range(T):
        predicted = predict(model, state, None if U is None else U[k])
        if full[k]:
            state, corr = update(model, predicted, Y[k], None)
            Ks[k], nus[k], Ss[k], n_iter[k] = corr
        elif some[k]:
            idx = np.flatnonzero(observed[k])
            state, corr = update(model, predicted, Y[k, idx], idx)
            out.correction(k, corr, idx)
        else:
            state = predicted
        if moments is None:
            xps[k], Pps[k] = predicted
            xs[k], Ps[k] = state
        else:
            xps[k], Pps[k] = moments(predicted)
            xs[k], Ps[k] = moments(state)
        if step_outputs is not None:
            for name, value in step_outputs(state).items():
                extras.setdefault(name, []).append(value)
    return out.result(family.result_type, **{name: np.stack(values) for name, values in extras.items()})

