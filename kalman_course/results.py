"""Le type de résultat unique de tous les filtres : des tableaux empilés dans le temps (temps en premier)."""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

__all__ = ["FilterResult", "FilterHistory", "freeze", "freeze_fields"]


def freeze(arr: np.ndarray) -> np.ndarray:
    """Copie en lecture seule (les résultats sont immuables)."""
    out = np.array(arr, dtype=float, copy=True)
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
    n_iter : (T,), entier, ou None
        Nombre d'itérations de la mise à jour (filtre itéré seulement).
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
        for f in fields(self):
            value = getattr(self, f.name)
            if value is None:
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
        return np.sqrt(np.diagonal(self.P, axis1=1, axis2=2))

    def __repr__(self) -> str:
        T, n = self.x.shape
        m = self.innovation.shape[1]
        return f"FilterResult(T={T}, n={n}, m={m})"


class FilterHistory:
    """Tableaux préalloués qu'une boucle de filtre remplit pas à pas, puis fige en :class:`FilterResult`.

    Usage interne des boucles (``kalman_filter``, filtres étendus) : elles écrivent ``x[k]``, ``P[k]``,
    ``x_pred[k]``, ``P_pred[k]`` directement et confient la correction à :meth:`correction`, qui range
    le gain, l'innovation et sa covariance aux composantes observées.
    """

    def __init__(self, T: int, n: int, m: int, observed: np.ndarray, iterated: bool = False) -> None:
        self.x = np.empty((T, n))
        self.P = np.empty((T, n, n))
        self.x_pred = np.empty((T, n))
        self.P_pred = np.empty((T, n, n))
        self.K = np.zeros((T, n, m))  # gain nul pour une composante manquante : aucune correction
        self.innovation = np.full((T, m), np.nan)
        self.S = np.full((T, m, m), np.nan)
        self.observed = observed
        self.n_iter = np.zeros(T, dtype=int) if iterated else None

    def store(self, k: int, x_pred: np.ndarray, P_pred: np.ndarray, x: np.ndarray, P: np.ndarray) -> None:
        """Range la prédiction et l'estimation a posteriori du pas ``k``."""
        self.x_pred[k] = x_pred
        self.P_pred[k] = P_pred
        self.x[k] = x
        self.P[k] = P

    def correction(self, k: int, K: np.ndarray, nu: np.ndarray, S: np.ndarray, idx: np.ndarray | None = None):
        """Range la correction du pas ``k`` ; ``idx`` : indices des composantes observées (``None`` : toutes)."""
        if idx is None:
            self.K[k] = K
            self.innovation[k] = nu
            self.S[k] = S
        else:
            self.K[k][:, idx] = K
            self.innovation[k, idx] = nu
            self.S[k][np.ix_(idx, idx)] = S

    def result(self) -> FilterResult:
        return FilterResult(
            x=self.x, P=self.P, x_pred=self.x_pred, P_pred=self.P_pred, K=self.K,
            innovation=self.innovation, S=self.S, observed=self.observed, n_iter=self.n_iter,
        )
