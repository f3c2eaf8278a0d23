r"""Cohérence statistique d'un filtre : NIS, NEES, blancheur et centrage des innovations.

Sous les hypothèses du cours — modèle juste (:math:`A, B, C, \Phi, \Psi` ceux du système), bruits
:math:`\phi` et :math:`\psi` gaussiens, centrés, blancs et indépendants entre eux et de :math:`x_0`,
et :math:`x_0 \sim \mathcal N(\hat x_0, P_0)` —, le filtre de Kalman donne la loi exacte de l'état
sachant les mesures, d'où (Bar-Shalom, Li et Kirubarajan, 2001, § 5.4) :

* l'innovation :math:`\nu_k = y_k - C\hat x_{k\mid k-1}` suit :math:`\mathcal N(0, S_k)` et les
  innovations successives sont **indépendantes** ; ainsi la NIS
  :math:`\epsilon_{\nu,k} = \nu_k^T S_k^{-1}\nu_k` suit une loi :math:`\chi^2_m` ;
* l'erreur :math:`x_k - \hat x_{k\mid k}` suit :math:`\mathcal N(0, P_k)` ; la NEES
  :math:`\epsilon_k = (x_k - \hat x_k)^T P_k^{-1} (x_k - \hat x_k)` suit une loi :math:`\chi^2_n`
  (mais les NEES successives d'un même tirage sont corrélées : on les moyenne sur des tirages de
  Monte-Carlo indépendants, pas dans le temps).

Les fonctions de ce module sont pures (tableaux ou :class:`~kalman_course.core.results.FilterResult` en
entrée, petits objets figés en sortie) ; les lois et les tests viennent de ``scipy.stats``. Les
covariances ne sont jamais inversées : on résout par Cholesky. Ce module n'importe pas matplotlib.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np
import scipy.linalg
import scipy.stats

from ..core.linalg import psd_solve
from ..filters.diffuse import DiffuseFilterResult
from ..core.results import FilterResult, FilterRuns, freeze_fields
from ..core.simulation import check_positive_int
from ..tables import Table
from ..core.validation import KalmanInputError, as_float_array, shape_text

__all__ = [
    "ChiSquareTest",
    "CentringTest",
    "WhitenessTest",
    "autocorrelation",
    "centring_test",
    "chi2_band",
    "chi2_mean_test",
    "consistency_table",
    "nees",
    "nis",
    "nis_test",
    "whitened_innovations",
    "whiteness_test",
]

#: Décalage maximal par défaut du test de blancheur : :math:`\min(20, \lfloor T/5 \rfloor)`.
DEFAULT_MAX_LAG = 20


# --------------------------------------------------------------------------- vérifications


def _check_result(result: Any, name: str = "result") -> FilterResult:
    if not isinstance(result, FilterResult):
        raise KalmanInputError(
            f"« {name} » doit être un FilterResult (sortie de kalman_filter, extended_kalman_filter…) ; "
            f"reçu {type(result).__name__}."
        )
    if isinstance(result, FilterRuns):
        raise KalmanInputError(
            f"« {name} » doit être le résultat d'un seul tirage ; reçu un FilterRuns de {result.n_runs} tirages "
            f"(prendre « {name}.run(i) », ou voir monte_carlo_consistency)."
        )
    if isinstance(result, DiffuseFilterResult):
        raise KalmanInputError(
            f"« {name} » vient de diffuse_kalman_filter : au début ({result.n_diffuse} pas ici), l'état n'est pas "
            "encore déterminé par les mesures et ni l'innovation ni sa covariance n'y sont définies. Testez les "
            f"pas suivants : passez {name}.after_diffuse(), par exemple nis({name}.after_diffuse())."
        )
    return result


def _check_level(level: Any) -> float:
    if isinstance(level, (bool, np.bool_)) or not isinstance(level, (int, float, np.integer, np.floating)):
        raise KalmanInputError(
            f"« level » doit être un niveau de confiance réel strictement entre 0 et 1 (par exemple 0.95) ; "
            f"reçu {level!r}."
        )
    value = float(level)
    if not (0.0 < value < 1.0):
        raise KalmanInputError(
            f"« level » doit être strictement entre 0 et 1 (par exemple 0.95 pour 95 %) ; reçu {value!r}."
        )
    return value


def _cholesky_or_error(M: np.ndarray, name: str, k: int) -> np.ndarray:
    try:
        return scipy.linalg.cholesky(M, lower=True, check_finite=True)
    except (np.linalg.LinAlgError, ValueError):
        raise KalmanInputError(
            f"« {name} » n'est pas définie positive (ou n'est pas finie) au pas k = {k} : "
            "impossible de normaliser par cette covariance."
        ) from None


def _forward_substitution(L: np.ndarray, v: np.ndarray) -> np.ndarray:
    r""":math:`L_k^{-1}v_k` pour tous les pas à la fois, par descente :
    :math:`w_i = (v_i - \sum_{j<i} L_{ij}w_j)/L_{ii}`. ``L`` (T, d, d) triangulaires inférieures, ``v`` (T, d)."""
    w = np.empty_like(v)
    for i in range(v.shape[1]):
        w[:, i] = (v[:, i] - np.sum(L[:, i, :i] * w[:, :i], axis=1)) / L[:, i, i]
    return w


def _whiten(vectors: np.ndarray, covs: np.ndarray, mask: np.ndarray, cov_name: str) -> np.ndarray:
    r"""Pour chaque pas :math:`k`, :math:`L_k^{-1} v_k` sur les composantes ``mask[k]`` (Cholesky
    :math:`L_kL_k^T` du bloc correspondant de ``covs[k]``), NaN ailleurs. Formes (T, d), (T, d, d), (T, d)."""
    T, d = vectors.shape
    out = np.full((T, d), np.nan)
    full = mask.all(axis=1)
    if full.any():
        idx = np.flatnonzero(full)
        block = covs[idx]
        try:
            if not np.isfinite(block).all():
                raise ValueError
            L = np.linalg.cholesky(block)  # tout le lot en un appel (LAPACK en boucle C)
        except (np.linalg.LinAlgError, ValueError):
            # le lot a échoué : on cherche le pas fautif pour le nommer
            for k in idx:
                _cholesky_or_error(covs[k], cov_name, int(k))
            raise  # pragma: no cover  (toujours levée ci-dessus)
        out[idx] = _forward_substitution(L, vectors[idx])
    for k in np.flatnonzero(~full & mask.any(axis=1)):
        sel = np.flatnonzero(mask[k])
        L = _cholesky_or_error(covs[k][np.ix_(sel, sel)], cov_name, int(k))
        out[k, sel] = scipy.linalg.solve_triangular(L, vectors[k, sel], lower=True)
    return out


def _innovation_arrays(result: FilterResult) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    nu, S, observed = result.innovation, result.S, np.asarray(result.observed, dtype=bool)
    if nu.ndim != 2 or S.shape != nu.shape + (nu.shape[1],) or observed.shape != nu.shape:
        raise KalmanInputError(
            "« result » est incohérent : innovation (T, m), S (T, m, m) et observed (T, m) attendus ; "
            f"reçu {nu.shape}, {S.shape} et {observed.shape}."
        )
    bad = observed & ~np.isfinite(nu)
    if bad.any():
        k = int(np.argwhere(bad)[0, 0])
        raise KalmanInputError(
            f"« result.innovation » n'est pas finie au pas k = {k} alors que la mesure y est marquée observée."
        )
    return nu, S, observed


# --------------------------------------------------------------------------- NIS et NEES


def whitened_innovations(result: FilterResult) -> np.ndarray:
    r"""Innovations blanchies :math:`e_k = L_k^{-1}\nu_k`, où :math:`S_k = L_kL_k^T` (Cholesky).

    Sous les hypothèses du filtre, :math:`e_k \sim \mathcal N(0, I_m)` et les :math:`e_k` sont
    indépendants : c'est la série sur laquelle portent les tests de blancheur et de centrage, et
    :math:`\lVert e_k\rVert^2` est la NIS. Une composante non observée donne NaN (les autres sont
    blanchies avec le bloc observé de :math:`S_k`).

    Paramètres : ``result`` — :class:`FilterResult` (``innovation`` (T, m), ``S`` (T, m, m)).
    Renvoie : (T, m).
    """
    nu, S, observed = _innovation_arrays(_check_result(result))
    return _whiten(nu, S, observed, "result.S")


def nis(result: FilterResult) -> np.ndarray:
    r"""NIS (*normalised innovation squared*) à chaque pas :

    .. math:: \epsilon_{\nu,k} = \nu_k^T S_k^{-1} \nu_k = \lVert L_k^{-1}\nu_k \rVert^2,
        \qquad S_k = L_kL_k^T,

    calculée par résolution triangulaire (jamais d'inverse). Sous les hypothèses du filtre,
    :math:`\epsilon_{\nu,k} \sim \chi^2_{m_k}`, :math:`m_k` nombre de composantes observées au pas
    :math:`k`. Mesure partielle : seules les composantes observées comptent ; aucune : NaN.

    Paramètres : ``result`` — :class:`FilterResult`. Renvoie : (T,).
    """
    e = whitened_innovations(result)
    out = np.nansum(e * e, axis=1)
    out[np.isnan(e).all(axis=1)] = np.nan
    return out


def nees(x_true: Any, result: FilterResult, *, prior: bool = False) -> np.ndarray:
    r"""NEES (*normalised estimation error squared*) à chaque pas :

    .. math:: \epsilon_k = (x_k - \hat x_k)^T P_k^{-1} (x_k - \hat x_k),

    avec :math:`\hat x_k = \hat x_{k\mid k}`, :math:`P_k = P_{k\mid k}` (``prior=False``) ou la
    prédiction :math:`\hat x_{k\mid k-1}`, :math:`P_{k\mid k-1}` (``prior=True``). Calculée par Cholesky
    et résolution triangulaire. Sous les hypothèses du filtre, :math:`\epsilon_k \sim \chi^2_n` ; elle
    exige l'état vrai, donc une simulation.

    Paramètres : ``x_true`` — (T, n), ou (T,) si n = 1 : états vrais alignés sur ``result``
    (``Simulation.x``) ; ``result`` — :class:`FilterResult` (``x`` (T, n), ``P`` (T, n, n)).
    Renvoie : (T,).
    """
    result = _check_result(result)
    x_hat, P = (result.x_pred, result.P_pred) if prior else (result.x, result.P)
    T, n = x_hat.shape
    x = as_float_array("x_true", x_true)
    if x.ndim == 1 and n == 1:
        x = x.reshape(-1, 1)
    if x.shape != (T, n):
        raise KalmanInputError(
            f"« x_true » doit être de forme ({T}, {n}) (un état vrai par pas de « result ») ; "
            f"reçu {shape_text(x.shape)}."
        )
    e = _whiten(x - x_hat, P, np.ones((T, n), dtype=bool), "result.P_pred" if prior else "result.P")
    return np.sum(e * e, axis=1)


# --------------------------------------------------------------------------- test du χ²


def chi2_band(dof: int, n_values: int = 1, level: float = 0.95) -> tuple[float, float]:
    r"""Intervalle bilatéral de niveau ``level`` pour la **moyenne** de ``n_values`` variables
    indépendantes de loi :math:`\chi^2_{d}` (``d = dof``) :

    .. math:: \left[\frac{\chi^2_{Nd}\big(\tfrac{1-\beta}{2}\big)}{N},\;
              \frac{\chi^2_{Nd}\big(\tfrac{1+\beta}{2}\big)}{N}\right],

    où :math:`\chi^2_{Nd}(q)` est le quantile d'ordre :math:`q` de la loi à :math:`Nd` degrés de liberté
    (la somme de :math:`N` lois :math:`\chi^2_d` indépendantes) et :math:`\beta` = ``level``.
    Renvoie ``(borne basse, borne haute)``.
    """
    d = check_positive_int("dof", dof)
    N = check_positive_int("n_values", n_values)
    beta = _check_level(level)
    lo, hi = scipy.stats.chi2.ppf([(1 - beta) / 2, (1 + beta) / 2], N * d) / N
    return float(lo), float(hi)


@dataclass(frozen=True)
class ChiSquareTest:
    r"""Résultat de :func:`chi2_mean_test`.

    ``statistic`` : moyenne :math:`\bar\epsilon` des valeurs ; ``dof`` : degrés de liberté de leur
    somme :math:`\sum_i d_i` ; ``n_values`` : nombre :math:`N` de valeurs ; ``expected`` : espérance
    :math:`\sum_i d_i / N` de la moyenne ; ``lower``, ``upper`` : bande bilatérale de niveau ``level``
    pour :math:`\bar\epsilon` ; ``p_value`` : probabilité critique bilatérale ; ``consistent`` :
    :math:`\bar\epsilon` dans la bande ; ``quantity`` : « NIS » ou « NEES ».
    """

    quantity: str
    statistic: float
    dof: int
    n_values: int
    expected: float
    lower: float
    upper: float
    level: float
    p_value: float
    consistent: bool

    def __str__(self) -> str:
        from ..numbers import format_spec as fr  # Babel, chargé à l'affichage seulement

        verdict = "cohérent" if self.consistent else "incohérent : hypothèse rejetée"
        return (
            f"Test du χ² sur la {self.quantity} moyenne ({self.n_values} valeur(s))\n"
            f"  moyenne {fr(self.statistic, '.4g')} ; attendu {fr(self.expected, '.4g')} "
            f"(somme à {self.dof} degrés de liberté)\n"
            f"  bande à {fr(100 * self.level, 'g')} % : [{fr(self.lower, '.4g')} ; {fr(self.upper, '.4g')}] ; p = {fr(self.p_value, '.3g')}\n"
            f"  → {verdict}"
        )


def chi2_mean_test(values: Any, dof: Any, *, level: float = 0.95, quantity: str = "NIS") -> ChiSquareTest:
    r"""Test du :math:`\chi^2` sur la moyenne de NIS ou de NEES **indépendantes**.

    Hypothèse nulle : les :math:`N` valeurs :math:`\epsilon_i` sont indépendantes, de lois
    :math:`\chi^2_{d_i}`. Alors :math:`N\bar\epsilon = \sum_i \epsilon_i \sim \chi^2_{D}`,
    :math:`D = \sum_i d_i`, et l'on rejette si :math:`\bar\epsilon` sort de
    :math:`[\chi^2_D(\tfrac{1-\beta}{2}),\ \chi^2_D(\tfrac{1+\beta}{2})]/N` ; la probabilité critique
    bilatérale est :math:`p = 2\min(F_D(N\bar\epsilon),\ 1 - F_D(N\bar\epsilon))`.

    Valeurs indépendantes : les NIS d'un même tirage (innovations blanches) ou les NEES de tirages
    de Monte-Carlo différents **au même instant** ; pas les NEES successives d'un tirage.

    Paramètres
    ----------
    values : tableau de forme quelconque (N valeurs), positives ; NaN = valeur absente (ignorée).
    dof : entier :math:`d \ge 1` commun à toutes les valeurs, ou tableau d'entiers de la forme de
        ``values`` (par exemple le nombre de composantes observées à chaque pas).
    level : niveau de confiance :math:`\beta \in (0, 1)`.
    quantity : nom affiché (« NIS », « NEES »).
    """
    beta = _check_level(level)
    v = as_float_array("values", values, allow_nan=True)
    if isinstance(dof, (int, np.integer)) and not isinstance(dof, (bool, np.bool_)):
        d = np.full(v.shape, check_positive_int("dof", dof), dtype=float)
    else:
        d = as_float_array("dof", dof)
        if d.shape != v.shape:
            raise KalmanInputError(
                f"« dof » doit être un entier ou un tableau de la forme de « values » {v.shape} ; "
                f"reçu {shape_text(d.shape)}."
            )
    present = ~np.isnan(v)
    if not present.any():
        raise KalmanInputError("« values » ne contient aucune valeur (vide ou uniquement des NaN).")
    if (v[present] < 0).any():
        raise KalmanInputError("« values » contient des valeurs négatives : une NIS ou une NEES est ≥ 0.")
    dp = d[present]
    if (dp < 1).any() or (dp != np.round(dp)).any():
        raise KalmanInputError("« dof » doit ne contenir que des entiers ≥ 1 là où « values » est présent.")
    N = int(present.sum())
    D = int(dp.sum())
    total = float(v[present].sum())
    lo, hi = scipy.stats.chi2.ppf([(1 - beta) / 2, (1 + beta) / 2], D) / N
    p = float(min(1.0, 2 * min(scipy.stats.chi2.cdf(total, D), scipy.stats.chi2.sf(total, D))))
    mean = total / N
    return ChiSquareTest(
        quantity=str(quantity),
        statistic=mean,
        dof=D,
        n_values=N,
        expected=D / N,
        lower=float(lo),
        upper=float(hi),
        level=beta,
        p_value=p,
        consistent=bool(lo <= mean <= hi),
    )


def nis_test(result: FilterResult, *, level: float = 0.95) -> ChiSquareTest:
    r"""Test du :math:`\chi^2` sur la NIS moyenne d'un tirage : :func:`chi2_mean_test` appliqué à
    :func:`nis` avec :math:`d_k` = nombre de composantes observées au pas :math:`k`
    (:math:`\sum_k \epsilon_{\nu,k} \sim \chi^2_{\sum_k m_k}` sous les hypothèses du filtre)."""
    values = nis(result)
    return chi2_mean_test(values, np.asarray(result.observed).sum(axis=1), level=level, quantity="NIS")


# --------------------------------------------------------------------------- blancheur


def _as_series(name: str, value: Any) -> np.ndarray:
    """Série (T,) ou (T, m) → (T, m), finie ; un ``FilterResult`` donne ses innovations blanchies."""
    if isinstance(value, FilterResult):
        arr = whitened_innovations(value)
        if np.isnan(arr).any():
            k = int(np.argwhere(np.isnan(arr))[0, 0])
            raise KalmanInputError(
                f"« {name} » a une mesure manquante au pas k = {k} : ce test exige des innovations complètes "
                "(retirez les pas incomplets de la série blanchie, whitened_innovations(result))."
            )
        return arr
    arr = as_float_array(name, value)
    if arr.ndim == 1:
        arr = arr.reshape(-1, 1)
    if arr.ndim != 2 or arr.shape[0] == 0 or arr.shape[1] == 0:
        raise KalmanInputError(
            f"« {name} » doit être une série de forme (T,) ou (T, m), ou un FilterResult ; "
            f"reçu {shape_text(arr.shape)}."
        )
    return arr


def _check_max_lag(max_lag: Any, T: int) -> int:
    if max_lag is None:
        max_lag = max(1, min(DEFAULT_MAX_LAG, T // 5))
    L = check_positive_int("max_lag", max_lag)
    if L > T // 2:
        raise KalmanInputError(
            f"« max_lag » = {L} est trop grand pour une série de T = {T} valeurs : au plus T/2 = {T // 2} "
            "(au-delà, trop peu de paires par décalage pour estimer l'autocorrélation)."
        )
    return L


def autocorrelation(series: Any, max_lag: int) -> np.ndarray:
    r"""Autocorrélation empirique normalisée aux décalages :math:`\ell = 1 \dots L` :

    .. math:: r_\ell = \frac{\sum_{t=1}^{T-\ell} (e_t - \bar e)(e_{t+\ell} - \bar e)}
                            {\sum_{t=1}^{T} (e_t - \bar e)^2}.

    Pour une suite indépendante de même loi, :math:`r_\ell` suit approximativement
    :math:`\mathcal N(0, 1/T)`, d'où la bande :math:`\pm 1{,}96/\sqrt T` à 95 %.

    Paramètres : ``series`` (T,) ou (T, m) (une colonne par composante) ; ``max_lag`` entier
    :math:`1 \le L \le T/2`. Renvoie : (L,) pour une série (T,), (m, L) pour (T, m).
    """
    arr = _as_series("series", series)
    T, m = arr.shape
    L = _check_max_lag(max_lag, T)
    centred = arr - arr.mean(axis=0)
    denom = np.sum(centred * centred, axis=0)
    if (denom == 0).any():
        raise KalmanInputError("« series » est constante (variance nulle) : autocorrélation indéfinie.")
    r = np.array([np.sum(centred[:-lag] * centred[lag:], axis=0) / denom for lag in range(1, L + 1)]).T
    return r[0] if np.ndim(series) == 1 and not isinstance(series, FilterResult) else r


@dataclass(frozen=True, eq=False)
class WhitenessTest:
    r"""Résultat de :func:`whiteness_test`.

    ``lags`` (L,) : décalages :math:`1 \dots L` ; ``autocorrelation`` (m, L) : :math:`r_\ell` par
    composante ; ``band`` : demi-largeur :math:`z_{(1+\beta)/2}/\sqrt T` (1,96/√T à 95 %) ;
    ``fraction_outside`` : part des :math:`r_\ell` hors de la bande ; ``ljung_box`` (m,) : statistique
    de Ljung–Box par composante ; ``component_p_values`` (m,) ; ``statistic`` : leur somme ; ``dof`` :
    :math:`mL` ; ``p_value`` : :math:`P(\chi^2_{mL} > Q)` ; ``white`` : ``p_value`` ≥ 1 − ``level``.
    """

    lags: np.ndarray
    autocorrelation: np.ndarray
    band: float
    fraction_outside: float
    ljung_box: np.ndarray
    component_p_values: np.ndarray
    statistic: float
    dof: int
    p_value: float
    n_values: int
    level: float
    white: bool

    def __post_init__(self) -> None:
        lags = np.array(self.lags, dtype=int, copy=True)
        lags.setflags(write=False)
        object.__setattr__(self, "lags", lags)
        freeze_fields(self, "autocorrelation", "ljung_box", "component_p_values")

    def __str__(self) -> str:
        from ..numbers import format_spec as fr  # Babel, chargé à l'affichage seulement

        verdict = "blanches" if self.white else "non blanches : hypothèse rejetée"
        return (
            f"Test de blancheur ({self.n_values} innovations, décalages 1 à {self.lags[-1]})\n"
            f"  {fr(100 * self.fraction_outside, '.1f')} % des autocorrélations hors de ± {fr(self.band, '.3g')}\n"
            f"  Ljung–Box Q = {fr(self.statistic, '.4g')} ({self.dof} degrés de liberté) ; p = {fr(self.p_value, '.3g')}\n"
            f"  → {verdict} (niveau {fr(100 * self.level, 'g')} %)"
        )


def whiteness_test(innovations: Any, max_lag: int | None = None, *, level: float = 0.95) -> WhitenessTest:
    r"""Test de blancheur des innovations : autocorrélations et statistique de Ljung–Box.

    Pour chaque composante :math:`i` de la série :math:`e` (innovations blanchies, ou toute série
    normalisée), les autocorrélations :math:`r_{i,\ell}` (:func:`autocorrelation`) donnent la
    statistique portemanteau de Ljung et Box (1978)

    .. math:: Q_i = T(T+2)\sum_{\ell=1}^{L} \frac{r_{i,\ell}^2}{T-\ell}
              \;\underset{H_0}{\sim}\; \chi^2_L \text{ (approximativement)},

    et, les composantes blanchies étant indépendantes sous :math:`H_0`,
    :math:`Q = \sum_i Q_i \sim \chi^2_{mL}`. La blancheur est rejetée si
    :math:`P(\chi^2_{mL} > Q) < 1 - \beta`.

    Paramètres
    ----------
    innovations : :class:`FilterResult` (ses innovations blanchies :func:`whitened_innovations`, sans
        mesure manquante), ou série (T,) / (T, m) déjà normalisée.
    max_lag : :math:`L`, entier entre 1 et T/2 ; par défaut :math:`\min(20, \lfloor T/5\rfloor)`.
    level : niveau :math:`\beta \in (0, 1)`.
    """
    beta = _check_level(level)
    e = _as_series("innovations", innovations)
    T, m = e.shape
    L = _check_max_lag(max_lag, T)
    r = autocorrelation(e, L)  # (m, L)
    lags = np.arange(1, L + 1)
    q = T * (T + 2) * np.sum(r**2 / (T - lags), axis=1)
    Q = float(q.sum())
    band = float(scipy.stats.norm.ppf((1 + beta) / 2) / np.sqrt(T))
    p = float(scipy.stats.chi2.sf(Q, m * L))
    return WhitenessTest(
        lags=lags,
        autocorrelation=r,
        band=band,
        fraction_outside=float(np.mean(np.abs(r) > band)),
        ljung_box=q,
        component_p_values=scipy.stats.chi2.sf(q, L),
        statistic=Q,
        dof=m * L,
        p_value=p,
        n_values=T,
        level=beta,
        white=bool(p >= 1 - beta),
    )


# --------------------------------------------------------------------------- centrage


@dataclass(frozen=True, eq=False)
class CentringTest:
    r"""Résultat de :func:`centring_test`.

    ``mean`` (m,) : moyenne :math:`\bar e` ; ``t_statistic`` (m,), ``t_p_values`` (m,) : tests de
    Student composante par composante ; ``hotelling`` : :math:`T^2` de Hotelling ; ``f_statistic`` et
    ``dof`` = :math:`(m, N-m)` : sa forme :math:`F` ; ``p_value`` : probabilité critique de
    Hotelling ; ``centred`` : ``p_value`` ≥ 1 − ``level``.
    """

    mean: np.ndarray
    t_statistic: np.ndarray
    t_p_values: np.ndarray
    hotelling: float
    f_statistic: float
    dof: tuple[int, int]
    p_value: float
    n_values: int
    level: float
    centred: bool

    def __post_init__(self) -> None:
        freeze_fields(self, "mean", "t_statistic", "t_p_values")

    def __str__(self) -> str:
        from ..numbers import format_spec as fr  # Babel, chargé à l'affichage seulement

        verdict = "centrées" if self.centred else "non centrées : hypothèse rejetée"
        means = " ; ".join(fr(v, ".3g") for v in self.mean)  # « ; » : la virgule est décimale
        return (
            f"Test de centrage ({self.n_values} innovations)\n"
            f"  moyenne ({means})\n"
            f"  T² de Hotelling = {fr(self.hotelling, '.4g')}, F({self.dof[0]}, {self.dof[1]}) = {fr(self.f_statistic, '.4g')} ; "
            f"p = {fr(self.p_value, '.3g')}\n"
            f"  → {verdict} (niveau {fr(100 * self.level, 'g')} %)"
        )


def centring_test(innovations: Any, *, level: float = 0.95) -> CentringTest:
    r"""Test de centrage des innovations : :math:`H_0 : \mathbb E[e_k] = 0`.

    Sur :math:`N` vecteurs :math:`e_k` de dimension :math:`m`, de moyenne :math:`\bar e` et de
    covariance empirique :math:`W` (dénominateur :math:`N - 1`), le :math:`T^2` de Hotelling

    .. math:: T^2 = N\,\bar e^T W^{-1} \bar e,\qquad
              F = \frac{N - m}{m(N-1)}\,T^2 \;\underset{H_0}{\sim}\; F(m, N - m)

    (loi exacte pour des :math:`e_k` gaussiens indépendants ; :math:`W` est résolue, pas inversée). Pour
    :math:`m = 1`, c'est le carré du :math:`t` de Student :math:`t = \bar e / (s/\sqrt N)`. La variance
    est estimée : le test porte sur le centrage seul, pas sur le réglage de :math:`\Psi`. Les tests de
    Student par composante (``scipy.stats.ttest_1samp``) sont donnés en plus.

    Paramètres : ``innovations`` — :class:`FilterResult` (innovations blanchies ; les pas incomplets
    sont écartés) ou série (T,) / (T, m) ; ``level`` — niveau :math:`\beta \in (0, 1)`.
    """
    beta = _check_level(level)
    if isinstance(innovations, FilterResult):
        e = whitened_innovations(innovations)
        e = e[~np.isnan(e).any(axis=1)]
    else:
        e = _as_series("innovations", innovations)
    N, m = e.shape
    if N < m + 1:
        raise KalmanInputError(
            f"« innovations » : {N} vecteur(s) complet(s) de dimension {m}, il en faut au moins {m + 1}."
        )
    mean = e.mean(axis=0)
    W = np.atleast_2d(np.cov(e, rowvar=False, ddof=1))
    t2 = float(N * mean @ psd_solve(W, mean, message="« innovations » : covariance empirique singulière "
                                                   "(composantes constantes ou liées)."))
    f_stat = (N - m) / (m * (N - 1)) * t2
    p = float(scipy.stats.f.sf(f_stat, m, N - m))
    t = scipy.stats.ttest_1samp(e, 0.0, axis=0)
    return CentringTest(
        mean=mean,
        t_statistic=np.asarray(t.statistic, dtype=float),
        t_p_values=np.asarray(t.pvalue, dtype=float),
        hotelling=t2,
        f_statistic=float(f_stat),
        dof=(m, N - m),
        p_value=p,
        n_values=N,
        level=beta,
        centred=bool(p >= 1 - beta),
    )


# --------------------------------------------------------------------------- synthèse


def consistency_table(results: Mapping[str, FilterResult], *, max_lag: int | None = None,
                      level: float = 0.95) -> Table:
    r"""Tableau de synthèse des trois tests (NIS, blancheur, centrage) pour plusieurs filtres appliqués
    aux mêmes mesures : une ligne par filtre (clé du dictionnaire = nom affiché), avec la NIS moyenne,
    les probabilités critiques de Ljung–Box et de Hotelling et les trois verdicts (« oui »/« non »)."""
    if not isinstance(results, Mapping) or not results:
        raise KalmanInputError("« results » doit être un dictionnaire non vide {nom : FilterResult}.")
    rows = []
    for name, res in results.items():
        _check_result(res, f"results[{name!r}]")
        chi = nis_test(res, level=level)
        white = whiteness_test(res, max_lag, level=level)
        centre = centring_test(res, level=level)
        rows.append((str(name), chi.statistic, _yes(chi.consistent), white.p_value, _yes(white.white),
                     centre.p_value, _yes(centre.centred)))
    headers = ["filtre", "NIS moyenne", "NIS cohérente", "p (Ljung–Box)", "blanches", "p (Hotelling)", "centrées"]
    formats = [None, "{:.2f}", None, "{:.2g}", None, "{:.2g}", None]
    return Table(headers, [list(col) for col in zip(*rows)], formats)


def _yes(flag: bool) -> str:
    return "oui" if flag else "non"
