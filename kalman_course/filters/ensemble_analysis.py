r"""Analyses des filtres d'ensemble de l'assimilation de données : ETKF, DEnKF, LETKF et le « taper » de
Gaspari–Cohn — étapes pures, une analyse par appel.

Notations (celles de DAPPER et de Sakov & Oke 2008) : l'ensemble :math:`E` (N, n) a une ligne par membre ;
:math:`\bar x` sa moyenne, :math:`A = E - \bar x` ses anomalies (N, n) ; :math:`Y = h(E) - \bar y` les
anomalies de l'ensemble observé (N, m), :math:`\bar y` sa moyenne ; :math:`d = y - \bar y` l'innovation
moyenne ;

.. math::

    K = A^TY\,\big(Y^TY + (N-1)R\big)^{-1}
      = P_{xy}\,(P_{yy} + R)^{-1},\qquad P_{xy} = \tfrac{A^TY}{N-1},\ P_{yy} = \tfrac{Y^TY}{N-1},

le gain de l'EnKF ; :math:`\lambda \ge 1` l'**inflation**, qui multiplie les anomalies analysées.

* **ETKF** (Bishop, Etherton & Majumdar 2001 ; forme symétrique de Wang, Bishop & Julier 2004, Hunt et
  al. 2007 ; ``EnKF('Sqrt')`` de DAPPER) : :math:`E^a = \bar x + Kd + \lambda\,TA` avec la **transformée**
  :math:`T = \big[I_N + YR^{-1}Y^T/(N-1)\big]^{-1/2}`, racine symétrique définie positive. Les anomalies
  analysées :math:`TA` ont exactement la covariance de Kalman :math:`(I - KH)P` dans l'espace de
  l'ensemble, sans tirage ; :math:`T\mathbf 1 = \mathbf 1` (car :math:`Y^T\mathbf 1 = 0`), donc la
  moyenne est conservée.
* **DEnKF** (Sakov & Oke 2008) : :math:`E^a = \bar x + Kd + \lambda\,(A - \tfrac12 YK^T)`, la moitié du
  gain sur les anomalies : la covariance analysée vaut :math:`(I - KH)P + \tfrac14 KHPH^TK^T`, celle de
  Kalman à un terme du second ordre près (assez petit quand :math:`HPH^T \ll R`).
* **LETKF** (Hunt, Kostelich & Szunyogh 2007) : une analyse ETKF **par composante** :math:`j` de l'état,
  avec les observations pondérées par :math:`\rho_{ij}` = :func:`gaspari_cohn` (distance de
  l'observation :math:`i` à la composante :math:`j`) — localisation « R » : avec
  :math:`\tilde Y = YR^{-1/2}`, :math:`\tilde d = R^{-1/2}d` (racine symétrique), la colonne :math:`j` de
  :math:`E^a` est la colonne :math:`j` de l'ETKF calculé avec :math:`\tilde Y\operatorname{diag}(\sqrt{\rho_{\cdot j}})`,
  :math:`\operatorname{diag}(\sqrt{\rho_{\cdot j}})\,\tilde d` et :math:`R = I`. Les :math:`n` analyses
  locales sont faites **ensemble** : :math:`n` matrices :math:`N \times N` diagonalisées en un appel
  (``numpy.linalg.eigh`` en lot), aucune boucle Python sur les composantes.

Toutes les analyses passent par l'espace de l'ensemble (:math:`N \times N`) :
:math:`\tilde Y\tilde Y^T = V\operatorname{diag}(s)V^T`, :math:`Kd = A^Tw` avec
:math:`w = V\operatorname{diag}\big(1/(s + N - 1)\big)V^T\tilde Y\tilde d`, et
:math:`T = V\operatorname{diag}\big(\sqrt{(N-1)/(s + N - 1)}\big)V^T`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import scipy.linalg

from ..core.linalg import psd_solve
from ..core.validation import (
    KalmanInputError,
    as_float_array,
    as_matrix,
    as_square_matrix,
    as_vector,
    call_user_function,
    check_pd,
    shape_text,
)

__all__ = [
    "GASPARI_COHN_SCALE",
    "etkf_update",
    "denkf_update",
    "gaspari_cohn",
    "letkf_update",
    "etkf_transform",
    "check_inflation",
    "check_radius",
    "as_distances",
    "ensemble_gain",
    "symmetric_inverse_root",
    "etkf_analysis",
    "denkf_analysis",
    "letkf_analysis",
]

#: Rayon de Gaspari–Cohn :math:`c` = 1,82 × ``radius`` (:math:`\approx\sqrt{10/3}`, convention de DAPPER, qui
#: vise :math:`e^{-1/2} \approx 0{,}61` à la distance ``radius``, comme une gaussienne d'écart-type ``radius`` ; la
#: valeur exacte y est 0,634) ; le taper s'annule à :math:`2c` = 3,64 × ``radius``.
GASPARI_COHN_SCALE = 1.82


# --------------------------------------------------------------------------- vérifications


def check_inflation(inflation: Any) -> float:
    r"""L'inflation :math:`\lambda`, un réel fini :math:`\ge 1`, ou une :class:`KalmanInputError`."""
    if isinstance(inflation, bool) or not isinstance(inflation, (int, float, np.integer, np.floating)):
        raise KalmanInputError(f"« inflation » doit être un nombre réel ≥ 1 ; reçu {inflation!r}.")
    lam = float(inflation)
    if not (math.isfinite(lam) and lam >= 1.0):
        raise KalmanInputError(
            f"« inflation » doit être un nombre réel fini ≥ 1 (facteur appliqué aux anomalies analysées ; 1 : "
            f"aucune inflation) ; reçu {inflation!r}."
        )
    return lam


def check_radius(name: str, radius: Any) -> float:
    r"""Un rayon de localisation :math:`> 0` (``numpy.inf`` : aucune localisation), ou une
    :class:`KalmanInputError` qui nomme ``name``."""
    if isinstance(radius, bool) or not isinstance(radius, (int, float, np.integer, np.floating)):
        raise KalmanInputError(f"« {name} » doit être un rayon strictement positif (ou numpy.inf) ; reçu {radius!r}.")
    r = float(radius)
    if math.isnan(r) or r <= 0:
        raise KalmanInputError(
            f"« {name} » doit être un rayon strictement positif (ou numpy.inf : aucune localisation) ; reçu {radius!r}."
        )
    return r


def as_distances(name: str, distances: Any, m: int | None = None, n: int | None = None) -> np.ndarray:
    """Distances finies et positives ou nulles ; forme (m, n) si ``m`` et ``n`` sont donnés."""
    d = as_float_array(name, distances)
    if m is not None and d.shape != (m, n):
        raise KalmanInputError(
            f"« {name} » doit être de forme ({m}, {n}) (distance de chaque observation à chaque composante de "
            f"l'état) ; reçu {shape_text(d.shape)}."
        )
    if (d < 0).any():
        raise KalmanInputError(f"« {name} » doit contenir des distances positives ou nulles ; minimum {d.min()!r}.")
    return d


def _ensemble(E: Any) -> np.ndarray:
    E = as_float_array("E", E)
    if E.ndim != 2:
        raise KalmanInputError(f"« E » doit être un ensemble de forme (N, n), un membre par ligne ; reçu {shape_text(E.shape)}.")
    if E.shape[0] < 2:
        raise KalmanInputError(
            f"« E » doit avoir au moins 2 membres (lignes) : la covariance d'un ensemble de N membres a N − 1 "
            f"degrés de liberté ; reçu {E.shape[0]}."
        )
    return E


def _observed_ensemble(E: np.ndarray, C: Any, m: int) -> np.ndarray:
    """:math:`h(E)` (N, m) : ``C`` matrice (m, n) ou fonction de (N, n) dans (N, m)."""
    N, n = E.shape
    if callable(C):
        HE = np.asarray(call_user_function("C", C, E), dtype=float)
        if HE.shape != (N, m):
            raise KalmanInputError(
                f"La fonction « C » (opérateur d'observation h) doit envoyer l'ensemble ({N}, {n}) sur ({N}, {m}) "
                f"(m = {m}, taille de y) ; elle a renvoyé {shape_text(HE.shape)}."
            )
        if not np.isfinite(HE).all():
            raise KalmanInputError("La fonction « C » (opérateur d'observation h) a renvoyé des valeurs non finies.")
        return HE
    return E.dot(as_matrix("C", C, m, n).T)


def _analysis_inputs(E: Any, y: Any, C: Any, R: Any):
    r"""Vérifie les entrées d'une analyse et rend :math:`(\bar x, A, Y, d, R)`."""
    E = _ensemble(E)
    y = as_float_array("y", y)
    if y.ndim == 0:
        y = y.reshape(1)
    if y.ndim != 1:
        raise KalmanInputError(f"« y » doit être un vecteur (m,) ; reçu {shape_text(y.shape)}.")
    m = y.size
    R = check_pd("R", as_square_matrix("R", R, m))
    HE = _observed_ensemble(E, C, m)
    x_bar, y_bar = E.mean(axis=0), HE.mean(axis=0)
    return x_bar, E - x_bar, HE - y_bar, y - y_bar, R


# --------------------------------------------------------------------------- briques communes


def symmetric_inverse_root(R: np.ndarray) -> np.ndarray:
    r""":math:`R^{-1/2}` (m, m), racine symétrique définie positive de :math:`R^{-1}` (par ``eigh`` ; une
    matrice diagonale directement)."""
    d = np.diag(R)
    if np.count_nonzero(R - np.diag(d)) == 0:
        return np.diag(1.0 / np.sqrt(d))
    lam, V = scipy.linalg.eigh(R)
    return (V / np.sqrt(lam)).dot(V.T)


def ensemble_gain(A: np.ndarray, Y: np.ndarray, R: np.ndarray, where: str = "") -> tuple[np.ndarray, np.ndarray]:
    r"""Gain :math:`K = A^TY(Y^TY + (N-1)R)^{-1}` (n, m) et :math:`S = Y^TY/(N-1) + R` (m, m) de l'ensemble
    d'anomalies ``A`` (N, n), ``Y`` (N, m)."""
    N1 = A.shape[0] - 1
    S = Y.T.dot(Y) / N1 + R
    message = ("La covariance d'innovation P_yy + R de l'ensemble n'est pas définie positive"
               + (f" ({where})" if where else "") + " : vérifiez R.")
    K = psd_solve(S, Y.T.dot(A) / N1, message=message).T
    return K, S


def _ensemble_space(Yt: np.ndarray):
    r"""Diagonalisation :math:`\tilde Y\tilde Y^T = V\operatorname{diag}(s)V^T` (N, N) et les deux fonctions
    de ses valeurs propres : :math:`1/(s + N - 1)` (moyenne) et :math:`\sqrt{(N-1)/(s + N - 1)}` (transformée)."""
    N1 = Yt.shape[0] - 1
    s, V = np.linalg.eigh(Yt.dot(Yt.T))
    s = np.clip(s, 0.0, None)  # valeurs propres ≥ 0 (arrondis)
    return V, 1.0 / (s + N1), np.sqrt(N1 / (s + N1))


def _transform_minus_identity(s: np.ndarray, N1: int) -> np.ndarray:
    r""":math:`(f(s) - 1)/s` avec :math:`f(s) = \sqrt{(N-1)/(s + N - 1)}`, écrit sans soustraction :
    :math:`-1/\big(\sqrt{s + N - 1}\,(\sqrt{N - 1} + \sqrt{s + N - 1})\big)` (fini en :math:`s = 0`)."""
    root = np.sqrt(s + N1)
    return -1.0 / (root * (np.sqrt(N1) + root))


def etkf_transform(Y: Any, R: Any) -> np.ndarray:
    r"""La transformée de l'ETKF :math:`T = \big[I_N + YR^{-1}Y^T/(N-1)\big]^{-1/2}` (N, N), racine symétrique
    définie positive ; ``Y`` (N, m) anomalies de l'ensemble observé, ``R`` (m, m)."""
    Y = as_float_array("Y", Y)
    if Y.ndim != 2 or Y.shape[0] < 2:
        raise KalmanInputError(f"« Y » doit être de forme (N, m) avec N ≥ 2 ; reçu {shape_text(Y.shape)}.")
    R = check_pd("R", as_square_matrix("R", R, Y.shape[1]))
    V, _, f = _ensemble_space(Y.dot(symmetric_inverse_root(R)))
    return (V * f).dot(V.T)


def etkf_analysis(x_bar, A, Y, d, R, inflation: float = 1.0, W=None) -> np.ndarray:
    r"""L'ETKF sur des entrées déjà vérifiées : :math:`\bar x + Kd + \lambda TA` (N, n). ``W`` :
    :math:`R^{-1/2}` s'il est déjà calculé.

    :math:`N \le m` : diagonalisation de :math:`\tilde Y\tilde Y^T` (N, N). :math:`N > m` : celle de
    :math:`\tilde Y^T\tilde Y = Q\operatorname{diag}(s)Q^T` (m, m), qui a les mêmes valeurs propres non nulles
    (DAPPER passe de même à la SVD) : :math:`Kd = A^T\tilde YQ\operatorname{diag}(1/(s + N - 1))Q^T\tilde d` et
    :math:`TA = A + \tilde YQ\operatorname{diag}\big((f(s) - 1)/s\big)Q^T\tilde Y^TA`."""
    W = symmetric_inverse_root(R) if W is None else W
    Yt, dt = Y.dot(W), W.dot(d)
    N1, m = Yt.shape[0] - 1, Yt.shape[1]
    if N1 + 1 <= m:
        V, g, f = _ensemble_space(Yt)
        w = V.dot(g * V.T.dot(Yt.dot(dt)))                  # (N,) : Kd = Aᵀw
        TA = V.dot(f[:, None] * V.T.dot(A))                 # (N, n)
    else:
        s, Q = np.linalg.eigh(Yt.T.dot(Yt))
        s = np.clip(s, 0.0, None)
        w = Yt.dot(Q.dot(Q.T.dot(dt) / (s + N1)))
        TA = A + Yt.dot(Q.dot(_transform_minus_identity(s, N1)[:, None] * Q.T.dot(Yt.T.dot(A))))
    return x_bar + A.T.dot(w) + inflation * TA


def denkf_analysis(x_bar, A, Y, d, R, inflation: float = 1.0, K=None) -> np.ndarray:
    r"""Le DEnKF sur des entrées déjà vérifiées : :math:`\bar x + Kd + \lambda(A - \tfrac12 YK^T)` (N, n)."""
    K = ensemble_gain(A, Y, R)[0] if K is None else K
    return x_bar + K.dot(d) + inflation * (A - 0.5 * Y.dot(K.T))


def letkf_analysis(x_bar, A, Y, d, R, rho, inflation: float = 1.0, W=None) -> np.ndarray:
    r"""Le LETKF sur des entrées déjà vérifiées ; ``rho`` (m, n) les poids :math:`\rho_{ij}` de
    Gaspari–Cohn.

    Chaque analyse locale ne garde que les observations de poids non nul (:math:`\rho_{ij} = 0` n'y change
    rien : ce n'est pas une coupure), au plus :math:`k` par composante ; avec
    :math:`Z_j = \tilde Y_{\cdot,\mathcal L_j}\operatorname{diag}(\sqrt{\rho_{\mathcal L_j j}})` (N, k) et
    :math:`e_j = \sqrt{\rho_{\mathcal L_j j}} \circ \tilde d_{\mathcal L_j}`, les :math:`n` analyses sont faites
    en lot, par un seul ``eigh`` sur une pile de :math:`n` matrices : :math:`Z_jZ_j^T` (N, N) si
    :math:`N \le k`, sinon :math:`Z_j^TZ_j` (k, k) (mêmes valeurs propres non nulles, mêmes formules que
    :func:`etkf_analysis`). Quand tous les poids valent 1 (rayon infini), les :math:`n` analyses locales
    sont exactement l'analyse globale : :func:`etkf_analysis` la calcule une fois (même résultat, au bit près,
    que l'ETKF)."""
    W = symmetric_inverse_root(R) if W is None else W
    if np.all(rho == 1.0):  # tous les poids valent 1 (rayon infini) : les n analyses locales sont l'analyse globale
        return etkf_analysis(x_bar, A, Y, d, R, inflation, W=W)
    Yt, dt = Y.dot(W), W.dot(d)                         # (N, m), (m,)
    N1, n = Yt.shape[0] - 1, A.shape[1]
    reach = rho > 0.0
    k = max(int(reach.sum(axis=0).max()), 1)           # observations utiles d'une analyse locale, au plus
    if k < rho.shape[0]:
        local = np.argsort(~reach, axis=0, kind="stable")[:k]   # (k, n) : d'abord les poids non nuls
        weight = np.sqrt(np.take_along_axis(rho, local, axis=0)).T  # (n, k), nuls pour le remplissage
        Z = Yt[:, local.T] * weight[None]                # (N, n, k)
        e = dt[local.T] * weight                         # (n, k)
    else:
        weight = np.sqrt(rho).T
        Z = Yt[:, None, :] * weight[None]
        e = dt[None, :] * weight
    Z = np.swapaxes(Z, 0, 1)                             # (n, N, k) : Z_j
    Zt = np.swapaxes(Z, 1, 2)
    a = A.T[:, :, None]                                  # (n, N, 1) : A[:, j]
    if N1 + 1 <= k:
        s, V = np.linalg.eigh(np.matmul(Z, Zt))          # (n, N), (n, N, N)
        s = np.clip(s, 0.0, None)
        Vt = np.swapaxes(V, 1, 2)
        w = np.matmul(V, np.matmul(Vt, np.matmul(Z, e[:, :, None])) / (s + N1)[:, :, None])  # (n, N, 1)
        TA = np.matmul(V, np.matmul(Vt, a) * np.sqrt(N1 / (s + N1))[:, :, None])             # T_j A[:, j]
    else:
        s, Q = np.linalg.eigh(np.matmul(Zt, Z))          # (n, k), (n, k, k)
        s = np.clip(s, 0.0, None)
        Qt = np.swapaxes(Q, 1, 2)
        w = np.matmul(Z, np.matmul(Q, np.matmul(Qt, e[:, :, None]) / (s + N1)[:, :, None]))
        g = _transform_minus_identity(s, N1)[:, :, None]
        TA = a + np.matmul(Z, np.matmul(Q, g * np.matmul(Qt, np.matmul(Zt, a))))
    increment = np.einsum("ja,ja->j", A.T, w[:, :, 0])   # (n,) : colonne j de Kd = A[:, j]·w_j
    return x_bar + increment + inflation * TA[:, :, 0].T


# --------------------------------------------------------------------------- fonctions publiques


def gaspari_cohn(distances: Any, radius: Any) -> np.ndarray:
    r"""Le « taper » de Gaspari & Cohn (1999, éq. 4.10), fonction de corrélation à support compact,
    de :math:`z = d/c` avec :math:`c = 1{,}82\,\text{radius}` :

    .. math::

        \rho(z) = \begin{cases}
        -\tfrac14 z^5 + \tfrac12 z^4 + \tfrac58 z^3 - \tfrac53 z^2 + 1, & 0 \le z \le 1,\\
        \tfrac1{12} z^5 - \tfrac12 z^4 + \tfrac58 z^3 + \tfrac53 z^2 - 5z + 4 - \tfrac2{3z}, & 1 < z \le 2,\\
        0, & z > 2.
        \end{cases}

    ``distances`` : tableau de distances :math:`d \ge 0` (toute forme) ; ``radius`` :math:`> 0`, ou
    ``numpy.inf`` (aucune localisation : des 1). Renvoie un tableau de même forme, dans :math:`[0, 1]` ;
    :math:`\rho = 0{,}634` à :math:`d` = ``radius`` (convention de DAPPER), :math:`\rho = 0` dès :math:`d \ge 2c`.
    """
    r = check_radius("radius", radius)
    d = as_distances("distances", distances)
    if math.isinf(r):
        return np.ones_like(d)
    z = d / (GASPARI_COHN_SCALE * r)
    rho = np.zeros_like(z)
    near, far = z <= 1.0, (z > 1.0) & (z < 2.0)   # ρ = 0 dès z ≥ 2 : rien à calculer
    a = z[near]
    rho[near] = (((-0.25 * a + 0.5) * a + 0.625) * a - 5.0 / 3.0) * a * a + 1.0
    b = z[far]
    rho[far] = ((((b / 12.0 - 0.5) * b + 0.625) * b + 5.0 / 3.0) * b - 5.0) * b + 4.0 - 2.0 / (3.0 * b)
    # ρ ≥ 0 sur [0, 2] ; le maximum efface l'arrondi près de z = 2
    return np.maximum(rho, 0.0)


def etkf_update(E: Any, y: Any, C: Any, R: Any, *, inflation: float = 1.0) -> np.ndarray:
    r"""Analyse de l'ETKF (filtre de Kalman d'ensemble à transformée, racine symétrique ; ``EnKF('Sqrt')`` de
    DAPPER) :

    .. math::

        E^a = \bar x + Kd + \lambda\,TA,\qquad T = \big[I_N + YR^{-1}Y^T/(N-1)\big]^{-1/2}.

    Paramètres
    ----------
    E : (N, n) ensemble prévu, un membre par ligne (:math:`N \ge 2`).
    y : (m,) observation.
    C : (m, n) matrice d'observation, ou fonction :math:`h` de (N, n) dans (N, m).
    R : (m, m) covariance des erreurs d'observation, définie positive.
    inflation : :math:`\lambda \ge 1`, facteur des anomalies analysées.

    Renvoie l'ensemble analysé (N, n). Sans tirage : deux appels donnent le même ensemble.
    """
    lam = check_inflation(inflation)
    return etkf_analysis(*_analysis_inputs(E, y, C, R), inflation=lam)


def denkf_update(E: Any, y: Any, C: Any, R: Any, *, inflation: float = 1.0) -> np.ndarray:
    r"""Analyse du DEnKF (EnKF déterministe de Sakov & Oke 2008) :

    .. math::

        E^a = \bar x + Kd + \lambda\,\big(A - \tfrac12\,YK^T\big),\qquad K = A^TY\big(Y^TY + (N-1)R\big)^{-1}.

    Mêmes paramètres que :func:`etkf_update` ; renvoie l'ensemble analysé (N, n).
    """
    lam = check_inflation(inflation)
    return denkf_analysis(*_analysis_inputs(E, y, C, R), inflation=lam)


def letkf_update(E: Any, y: Any, C: Any, R: Any, distances: Any, *, radius: Any, inflation: float = 1.0) -> np.ndarray:
    r"""Analyse du LETKF (Hunt, Kostelich & Szunyogh 2007) : une analyse ETKF par composante :math:`j` de
    l'état, les observations pondérées par :math:`\rho_{ij}` = ``gaspari_cohn(distances[i, j], radius)``.

    Avec :math:`\tilde Y = YR^{-1/2}` et :math:`\tilde d = R^{-1/2}d` (racine symétrique), la colonne
    :math:`j` de :math:`E^a` est la colonne :math:`j` de l'ETKF (:func:`etkf_update`) calculé avec
    :math:`\tilde Y\operatorname{diag}(\sqrt{\rho_{\cdot j}})`, :math:`\operatorname{diag}(\sqrt{\rho_{\cdot j}})\tilde d`
    et :math:`R = I` ; aucune autre coupure. ``radius=numpy.inf`` redonne l'ETKF (au bit près).

    Paramètres
    ----------
    E, y, C, R, inflation : comme :func:`etkf_update`.
    distances : (m, n) distance de l'observation :math:`i` à la composante :math:`j` (≥ 0).
    radius : rayon de localisation :math:`> 0` (:math:`\rho = 0{,}634` à cette distance, nul au-delà de
        3,64 × ``radius``), ou ``numpy.inf``.

    Renvoie l'ensemble analysé (N, n) ; les :math:`n` analyses locales sont calculées en lot.
    """
    lam = check_inflation(inflation)
    r = check_radius("radius", radius)
    x_bar, A, Y, d, R = _analysis_inputs(E, y, C, R)
    rho = gaspari_cohn(as_distances("distances", distances, d.size, A.shape[1]), r)
    return letkf_analysis(x_bar, A, Y, d, R, rho, inflation=lam)


