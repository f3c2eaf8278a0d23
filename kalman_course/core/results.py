"""Le type de résultat unique de tous les filtres : des tableaux empilés dans le temps (temps en premier)."""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from .linalg import gram
from .validation import KalmanInputError

__all__ = ["FilterResult", "AdaptiveResult", "FilterRuns", "FilterHistory", "PoseAliases", "freeze", "freeze_fields"]


def freeze(arr: np.ndarray, dtype: type = float) -> np.ndarray:
    """Copie en lecture seule (les résultats sont immuables), de type ``dtype`` (``float`` par défaut ;
    ``bool`` ou ``np.intp`` pour des masques et des indices). Un tableau déjà figé par cette fonction
    (``float64``, en lecture seule, propriétaire de ses données) est rendu tel quel : reconstruire un
    résultat à partir d'un autre ne recopie pas ses tableaux."""
    if (dtype is float and isinstance(arr, np.ndarray) and arr.dtype == np.float64 and not arr.flags.writeable
            and arr.flags.owndata):
        return arr
    out = np.array(arr, dtype=dtype, copy=True)
    out.setflags(write=False)
    return out


def freeze_fields(obj, *names: str) -> None:
    """Dans le ``__post_init__`` d'une dataclass figée : remplace les champs ``names`` par des copies
    ``float`` en lecture seule."""
    for name in names:
        object.__setattr__(obj, name, freeze(getattr(obj, name)))


@dataclass(frozen=True, eq=False)
class FilterResult:
    r"""Sortie d'un filtre sur ``T`` pas de temps (``n`` états, ``m`` mesures).

    La ligne ``k`` (0 ≤ k < T) correspond à la mesure ``y[k]``, c'est-à-dire au pas
    :math:`k+1` de la récurrence du cours :math:`n \to n+1`.

    Attributs
    ---------
    x : (T, n)
        Estimation *a posteriori* :math:`\hat x_{k\mid k}` (le :math:`\hat x_{n+1}` du cours).
    P : (T, n, n)
        Covariance *a posteriori* :math:`P_{k\mid k}`.
    x_pred : (T, n)
        Prédiction *a priori* :math:`\hat x_{k\mid k-1}` (le :math:`\hat x^-_{n+1}` du cours).
    P_pred : (T, n, n)
        Covariance *a priori* :math:`P_{k\mid k-1}`.
    K : (T, n, m)
        Gain :math:`K_k` (colonnes nulles pour une mesure manquante : aucune correction).
    innovation : (T, m)
        Innovation :math:`\nu_k = y_k - C\hat x_{k\mid k-1}` (NaN pour une composante manquante).
    S : (T, m, m)
        Covariance d'innovation :math:`S_k = C P_{k\mid k-1} C^T + R` (NaN sur les lignes/colonnes manquantes).
    observed : (T, m), booléen
        ``True`` où la composante de la mesure était disponible.
    n_iter : (T,), entier
        Nombre d'itérations de la correction à chaque pas : 0 sans mesure (prédiction seule), 1 pour une
        correction non itérée, :math:`N \ge 1` pour un filtre itéré.

    Un lot de tirages (:class:`FilterRuns`) ajoute un axe en tête : ``x`` (N, T, n)…
    """

    x: np.ndarray
    P: np.ndarray
    x_pred: np.ndarray
    P_pred: np.ndarray
    K: np.ndarray
    innovation: np.ndarray
    S: np.ndarray
    observed: np.ndarray
    n_iter: np.ndarray | None = None

    def __post_init__(self) -> None:
        for f in fields(self):  # ceux des sous-classes compris
            value = getattr(self, f.name)
            if value is None or isinstance(value, FilterResult):  # un résultat emboîté est déjà figé
                continue
            if f.name in ("observed", "n_iter"):
                arr = np.array(value, copy=True)
                arr.setflags(write=False)
            else:
                arr = freeze(value)
            object.__setattr__(self, f.name, arr)

    @property
    def n_steps(self) -> int:
        """Nombre de pas de temps ``T``."""
        return self.x.shape[0]

    def std(self) -> np.ndarray:
        r"""Écarts-types a posteriori :math:`\sqrt{\operatorname{diag} P_{k\mid k}}`, forme (T, n)."""
        return np.sqrt(np.diagonal(self.P, axis1=-2, axis2=-1))

    @property
    def rejected(self) -> np.ndarray:
        """(T,) booléen : pas dont la mesure, présente, a été **rejetée** par la porte du filtre
        (``kalman_filter(..., gate=p)``) — prédiction seule, ``n_iter`` nul. Toujours ``False`` sans porte."""
        if self.n_iter is None:
            return np.zeros(self.observed.shape[:-1], dtype=bool)
        return np.asarray(self.observed).any(axis=-1) & (np.asarray(self.n_iter) == 0)

    def __repr__(self) -> str:
        T = self.n_steps
        n, m = self.P.shape[-1], self.innovation.shape[-1]
        seen = int(np.count_nonzero(self.observed.any(axis=-1))) if self.observed.size else 0
        return (f"<{type(self).__name__} : {T} pas, état de dimension {n}, mesure de dimension {m}, "
                f"{seen} pas avec mesure>")


@dataclass(frozen=True, eq=False, repr=False)
class AdaptiveResult(FilterResult):
    r"""Sortie d'un filtre à :math:`Q` adaptative (option ``adapt`` du moteur,
    :func:`~kalman_course.adaptive_kalman_filter`) : les champs de :class:`FilterResult` et ``q_scale`` (T,),
    l'échelle :math:`s_k` de :math:`Q` retenue après la mesure ``y[k]`` (elle sert à prédire le pas suivant)."""

    q_scale: np.ndarray | None = None


@dataclass(frozen=True, eq=False, repr=False)
class FilterRuns(FilterResult):
    r"""Les résultats de ``N`` tirages filtrés ensemble (:func:`~kalman_course.kalman_filter_runs`, et les
    filtres non linéaires en lot de :func:`~kalman_course.filters.engine.run_filter_runs`) : les
    champs de :class:`FilterResult` avec un axe des tirages en tête — ``x`` (N, T, n),
    ``innovation`` (N, T, m), ``observed`` (N, T, m), ``n_iter`` (N, T) — sauf, pour le filtre de
    Kalman linéaire sans mesure manquante, les covariances et le gain, qui ne dépendent alors pas des
    mesures : ``P``, ``P_pred`` (T, n, n), ``K`` (T, n, m), ``S`` (T, m, m) sont communs à tous les
    tirages (``shared_covariance``) ; sinon (mesures manquantes, filtres non linéaires, dont la
    linéarisation dépend de chaque tirage) ils sont de forme (N, T, …)."""

    @property
    def n_runs(self) -> int:
        """Nombre de tirages ``N``."""
        return self.x.shape[0]

    @property
    def n_steps(self) -> int:
        return self.x.shape[1]

    @property
    def shared_covariance(self) -> bool:
        """``True`` si ``P``, ``P_pred``, ``K`` et ``S`` sont communs à tous les tirages (forme (T, …))."""
        return self.P.ndim == 3

    def run(self, i: int) -> FilterResult:
        """Le résultat du tirage ``i`` seul, comme l'aurait rendu ``kalman_filter``."""
        if isinstance(i, bool) or not isinstance(i, (int, np.integer)) or not -self.n_runs <= i < self.n_runs:
            raise KalmanInputError(
                f"« i » doit être un indice de tirage entier entre {-self.n_runs} et {self.n_runs - 1} ; reçu {i!r}."
            )

        def pick(a):
            return a if self.shared_covariance else a[i]

        return FilterResult(x=self.x[i], P=pick(self.P), x_pred=self.x_pred[i], P_pred=pick(self.P_pred),
                            K=pick(self.K), innovation=self.innovation[i], S=pick(self.S),
                            observed=self.observed[i], n_iter=self.n_iter[i])


class PoseAliases:
    """Noms de pose des résultats dont l'estimation est une pose (filtres sur SE(3) et SE(2)) : ``T`` pour
    ``x``, ``T_pred`` pour ``x_pred``."""

    @property
    def T(self) -> np.ndarray:
        """Poses a posteriori (…, T, d, d) : ``x``."""
        return self.x

    @property
    def T_pred(self) -> np.ndarray:
        """Poses prédites (…, T, d, d) : ``x_pred``."""
        return self.x_pred


class FilterHistory:
    """Tableaux préalloués que le moteur (:func:`~kalman_course.filters.engine.run_filter`) remplit pas à
    pas, puis fige en un résultat.

    ``state_shape`` : forme d'une estimation (``(n,)``, ou ``(4, 4)`` pour une pose) ; ``d`` : dimension
    de la covariance ; ``m`` : dimension de la mesure. :meth:`correction` range le gain, l'innovation et
    sa covariance aux composantes observées (gain nul, innovation et ``S`` NaN ailleurs).

    ``root_rows`` : le filtre porte des **racines** au lieu des covariances (:math:`M^TM = P`, au plus
    ``root_rows`` lignes) ; ``P`` et ``P_pred`` rangent alors des racines (T, root_rows, d), complétées de
    lignes nulles (qui ne changent pas :math:`M^TM`), ``S`` des racines (T, m, m) de :math:`S` (zéros hors
    des composantes observées), et :meth:`result` forme toutes les covariances à la fin, en un produit
    en lot (:func:`~kalman_course.core.linalg.gram`).
    """

    def __init__(self, T: int, state_shape: tuple[int, ...], d: int, m: int, observed: np.ndarray,
                 root_rows: int | None = None) -> None:
        self.x = np.empty((T, *state_shape))
        self.x_pred = np.empty((T, *state_shape))
        self.root_rows = root_rows
        if root_rows is None:
            self.P = np.empty((T, d, d))
            self.P_pred = np.empty((T, d, d))
            self.S = np.full((T, m, m), np.nan)
        else:
            self.P = np.zeros((T, root_rows, d))
            self.P_pred = np.zeros((T, root_rows, d))
            self.S = np.zeros((T, m, m))
        self.K = np.zeros((T, d, m))  # gain nul pour une composante manquante : aucune correction
        self.innovation = np.full((T, m), np.nan)
        self.observed = observed
        self.n_iter = np.zeros(T, dtype=int)

    def store(self, k: int, x_pred: np.ndarray, P_pred: np.ndarray, x: np.ndarray, P: np.ndarray) -> None:
        """Range la prédiction et l'estimation a posteriori du pas ``k``."""
        self.x_pred[k] = x_pred
        self.P_pred[k] = P_pred
        self.x[k] = x
        self.P[k] = P

    def correction(self, k: int, corr, idx: np.ndarray | None = None) -> None:
        """Range la correction ``corr`` (:class:`~kalman_course.filters.engine.Correction`) du pas ``k`` ;
        ``idx`` : indices des composantes observées (``None`` : toutes)."""
        self.n_iter[k] = corr.n_iter
        if idx is None:
            self.K[k] = corr.K
            self.innovation[k] = corr.innovation
            self.S[k] = corr.S
        else:
            self.K[k][:, idx] = corr.K
            self.innovation[k, idx] = corr.innovation
            self.S[k][np.ix_(idx, idx)] = corr.S

    def result(self, result_type: type | None = None, **extra) -> "FilterResult":
        """Le résultat figé ; ``extra`` : champs propres à ``result_type`` (sorties empilées de chaque pas)."""
        cls = FilterResult if result_type is None else result_type
        P, P_pred, S = self.P, self.P_pred, self.S
        if self.root_rows is not None:  # des racines : les covariances, toutes à la fois
            P, P_pred, S = gram(P), gram(P_pred), gram(S)
            S[~(self.observed[:, :, None] & self.observed[:, None, :])] = np.nan
        return cls(
            x=self.x, P=P, x_pred=self.x_pred, P_pred=P_pred, K=self.K,
            innovation=self.innovation, S=S, observed=self.observed, n_iter=self.n_iter, **extra,
        )
