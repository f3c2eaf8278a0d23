r"""Scénario « initialisation diffuse » (SRIF) : une cible plane à vitesse constante, des relevés de position au
millimètre, **aucun a priori** sur l'état initial.

État :math:`x = [p_x, p_y, v_x, v_y]` (m, m/s), mesure :math:`y = [p_x, p_y] + \psi`, :math:`\sigma = 1` mm,
pas :math:`\Delta t = 1` s, accélération blanche :math:`\sigma_a` (bruit d'état de rang 2 : :math:`Q = \sigma_a^2GG^T`).

Sans a priori, l'estimation exacte après :math:`k` relevés est la solution des moindres carrés pondérés
sur toutes les inconnues (:func:`batch_estimates`, indépendante de tout filtre). Le SRIF part de
:math:`\mathcal R_{xx} = 0` et la retrouve ; le filtre de Kalman sous la forme du cours
(``form="textbook"``, :math:`P = P^- - KCP^-`) doit simuler l'absence d'a priori par :math:`P_0 = 10^k I`, ce qui biaise l'estimation si :math:`P_0` est trop petite et la noie dans les
arrondis si elle est trop grande (:func:`diffuse_errors`). La référence de :func:`diffuse_errors` est
calculée en précision étendue (:func:`extended_precision_estimates`, 120 chiffres décimaux).
"""

from __future__ import annotations

from dataclasses import dataclass
from decimal import Decimal, localcontext

import numpy as np
import scipy.linalg

from ..filters.kalman import kalman_filter
from ..core.models import LinearGaussianModel
from ..core.results import freeze_fields
from ..filters.square_root_information import square_root_information_filter
from ..core.validation import KalmanInputError
from ..core.motion import acceleration_gain, constant_velocity
from ._motion import simulate_cv

__all__ = [
    "DIFFUSE_DT",
    "DIFFUSE_ACCEL_STD",
    "DIFFUSE_FIX_STD",
    "DIFFUSE_N_STEPS",
    "DIFFUSE_SEED",
    "DIFFUSE_X0",
    "DIFFUSE_P0_EXPONENTS",
    "diffuse_model",
    "diffuse_data",
    "batch_least_squares",
    "batch_estimates",
    "extended_precision_estimates",
    "DiffuseErrors",
    "diffuse_errors",
]

#: Pas de temps (s).
DIFFUSE_DT = 1.0
#: Écart-type de l'accélération blanche (m/s²).
DIFFUSE_ACCEL_STD = 0.005
#: Écart-type des relevés de position (m) : 1 mm.
DIFFUSE_FIX_STD = 1e-3
#: Nombre de relevés.
DIFFUSE_N_STEPS = 30
#: Graine des trajectoires et des relevés.
DIFFUSE_SEED = 20020
#: État vrai initial :math:`[p_x, p_y, v_x, v_y]` (m, m/s).
DIFFUSE_X0 = np.array([120.0, -40.0, 3.0, 1.5])
DIFFUSE_X0.setflags(write=False)
#: Exposants :math:`k` des a priori :math:`P_0 = 10^k I` essayés pour le filtre de Kalman.
DIFFUSE_P0_EXPONENTS = tuple(range(2, 17))


def diffuse_model(accel_std: float = DIFFUSE_ACCEL_STD, fix_std: float = DIFFUSE_FIX_STD,
                  dt: float = DIFFUSE_DT) -> LinearGaussianModel:
    r"""Modèle à vitesse constante, mesure de la position : :math:`C = [I_2\ 0]`, :math:`R = \sigma^2 I_2`."""
    C = np.hstack([np.eye(2), np.zeros((2, 2))])
    A, Q = constant_velocity(dt, accel_std=accel_std)
    return LinearGaussianModel(A, C, Q, fix_std**2 * np.eye(2))


def diffuse_data(n_steps: int = DIFFUSE_N_STEPS, rng=DIFFUSE_SEED):
    r"""États vrais ``x`` (T, 4) et relevés ``y`` (T, 2) (m), reproductibles."""
    gen = np.random.default_rng(rng) if not isinstance(rng, np.random.Generator) else rng
    x = simulate_cv(DIFFUSE_X0, n_steps, DIFFUSE_DT, DIFFUSE_ACCEL_STD, gen)
    y = x[:, :2] + DIFFUSE_FIX_STD * gen.standard_normal((n_steps, 2))
    return x, y


def batch_least_squares(A: np.ndarray, C: np.ndarray, LR: np.ndarray, G: np.ndarray, y: np.ndarray, *,
                        La: np.ndarray | None = None, B: np.ndarray | None = None,
                        u: np.ndarray | None = None) -> np.ndarray:
    r"""Estimations exactes **sans a priori**, par moindres carrés pondérés en bloc (``scipy.linalg.lstsq``) :
    la référence indépendante du SRIF parti de :math:`\mathcal R_{xx} = 0`.

    Modèle :math:`x_{j+1} = Ax_j + Bu_j + Ga_j`, :math:`a_j \sim \mathcal N(0, L_aL_a^T)` (``La`` triangulaire
    inférieure, identité par défaut), :math:`y_j = Cx_j + v_j`, :math:`v_j \sim \mathcal N(0, L_RL_R^T)`
    (``LR`` triangulaire inférieure). Pour chaque :math:`k` : inconnues
    :math:`\theta = [x_1, a_1, \dots, a_{k-1}]` (état au premier relevé, bruits),
    :math:`x_j = \Phi_j\theta + o_j` ; équations blanchies :math:`L_R^{-1}(Cx_j - y_j)` et
    :math:`L_a^{-1}a_i`. Renvoie
    :math:`\hat x_{k\mid k} = x_k(\hat\theta)`, forme (T, n) ; NaN tant que le système est de rang
    insuffisant (pas assez de relevés pour déterminer tout l'état).
    """
    n, q = A.shape[0], G.shape[1]
    T = y.shape[0]
    La = np.eye(q) if La is None else La
    out = np.full((T, n), np.nan)
    for k in range(1, T + 1):
        n_theta = n + q * (k - 1)
        # Phi[j], off[j] : x_j = Phi[j] θ + off[j] (j = 0 … k-1)
        Phi = np.zeros((k, n, n_theta))
        off = np.zeros((k, n))
        Phi[0, :, :n] = np.eye(n)
        for j in range(1, k):
            Phi[j] = A @ Phi[j - 1]
            Phi[j, :, n + q * (j - 1):n + q * j] += G
            if B is not None:
                off[j] = A @ off[j - 1] + B @ u[j]
        rows = [scipy.linalg.solve_triangular(LR, C @ Phi[j], lower=True) for j in range(k)]
        rhs = [scipy.linalg.solve_triangular(LR, y[j] - C @ off[j], lower=True) for j in range(k)]
        noise_rows = np.zeros((q * (k - 1), n_theta))
        for i in range(k - 1):
            noise_rows[q * i:q * (i + 1), n + q * i:n + q * (i + 1)] = scipy.linalg.solve_triangular(La, np.eye(q), lower=True)
        rows.append(noise_rows)
        rhs.append(np.zeros(q * (k - 1)))
        M = np.vstack(rows)
        if np.linalg.matrix_rank(M) < n_theta:
            continue
        theta = scipy.linalg.lstsq(M, np.concatenate(rhs))[0]
        out[k - 1] = Phi[k - 1] @ theta + off[k - 1]
    return out


def batch_estimates(y: np.ndarray, accel_std: float = DIFFUSE_ACCEL_STD, fix_std: float = DIFFUSE_FIX_STD,
                    dt: float = DIFFUSE_DT) -> np.ndarray:
    r""":func:`batch_least_squares` sur le scénario (accélérations :math:`a \sim \mathcal N(0, \sigma_a^2 I)`,
    positions mesurées à :math:`\sigma` près), forme (T, 4) (ligne 0 : NaN, un seul relevé ne donne pas
    la vitesse)."""
    C = np.hstack([np.eye(2), np.zeros((2, 2))])
    A = constant_velocity(dt, accel_std=accel_std).A
    return batch_least_squares(A, C, fix_std * np.eye(2), acceleration_gain(dt), y, La=accel_std * np.eye(2))


def extended_precision_estimates(model: LinearGaussianModel, y: np.ndarray, p0_exponent: int = 40,
                                 digits: int = 120) -> np.ndarray:
    r"""Référence en précision étendue : le filtre de Kalman du cours calculé en arithmétique décimale à
    ``digits`` chiffres (module ``decimal``), avec :math:`\hat x_0 = 0` et :math:`P_0 = 10^{40}I`.

    Un a priori aussi vague déplace l'estimation d'une fraction :math:`\sim 10^{-40}/\sigma^{-2}` de
    l'écart à zéro (négligeable devant la double précision) et la soustraction
    :math:`P^- - KCP^-` y perd une cinquantaine de chiffres sur 120 : il en reste bien assez. Les données
    (flottants) sont converties exactement. Pour une mesure de dimension 2 seulement (inverse 2 × 2
    explicite). Renvoie les estimations a posteriori arrondies en flottants, forme (T, n).
    """
    if model.n_obs != 2:
        raise KalmanInputError(f"La référence décimale est écrite pour m = 2 mesures ; reçu m = {model.n_obs}.")
    with localcontext() as ctx:
        ctx.prec = digits

        def dec(a):
            return [[Decimal(float(v)) for v in row] for row in np.atleast_2d(a)]

        def mul(X, Y):
            return [[sum(X[i][k] * Y[k][j] for k in range(len(Y))) for j in range(len(Y[0]))]
                    for i in range(len(X))]

        def tr(X):
            return [list(r) for r in zip(*X)]

        def add(X, Y, s=1):
            return [[a + s * b for a, b in zip(r, t)] for r, t in zip(X, Y)]

        A, C, Q, R = dec(model.A), dec(model.C), dec(model.Q), dec(model.R)
        n = len(A)
        x = [[Decimal(0)] for _ in range(n)]
        P = [[Decimal(10) ** p0_exponent if i == j else Decimal(0) for j in range(n)] for i in range(n)]
        out = np.empty((len(y), n))
        for k, y_k in enumerate(np.asarray(y, dtype=float)):
            x = mul(A, x)
            P = add(mul(mul(A, P), tr(A)), Q)
            S = add(mul(mul(C, P), tr(C)), R)
            det = S[0][0] * S[1][1] - S[0][1] * S[1][0]
            S_inv = [[S[1][1] / det, -S[0][1] / det], [-S[1][0] / det, S[0][0] / det]]
            K = mul(mul(P, tr(C)), S_inv)
            x = add(x, mul(K, add([[Decimal(float(v))] for v in y_k], mul(C, x), -1)))
            P = add(P, mul(K, mul(C, P)), -1)
            out[k] = [float(r[0]) for r in x]
    return out


@dataclass(frozen=True, eq=False)
class DiffuseErrors:
    r"""Écarts de position (m) à la référence en précision étendue, à partir du 2ᵉ relevé.

    ``exponents`` (E,) : :math:`k` de :math:`P_0 = 10^kI` ; ``kf`` (E, T) : écart de position du filtre de
    Kalman à chaque pas (norme, m ; colonne 0 : NaN ; ligne entière NaN si le filtre a échoué) ;
    ``kf_failed`` (E,) : le filtre de Kalman s'est arrêté (covariance d'innovation non définie positive) ;
    ``srif`` (T,) : écart du SRIF parti de :math:`\mathcal R_{xx} = 0` ; ``reference`` (T, 4).
    """

    exponents: np.ndarray
    kf: np.ndarray
    kf_failed: np.ndarray
    srif: np.ndarray
    reference: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "exponents", "kf", "srif", "reference")
        failed = np.array(self.kf_failed, dtype=bool)
        failed.setflags(write=False)
        object.__setattr__(self, "kf_failed", failed)

    @property
    def kf_max(self) -> np.ndarray:
        """Écart maximal sur les pas, par exposant (E,) (NaN si le filtre a échoué)."""
        out = np.full(len(self.exponents), np.nan)
        ok = ~self.kf_failed
        out[ok] = np.nanmax(self.kf[ok], axis=1)
        return out

    @property
    def srif_max(self) -> float:
        """Écart maximal du SRIF sur les pas (m)."""
        return float(np.nanmax(self.srif))

    def kf_max_at(self, exponent: int) -> float:
        """Écart maximal du filtre de Kalman pour :math:`P_0 = 10^{\\text{exponent}}I` (m)."""
        return float(self.kf_max[list(self.exponents).index(exponent)])


def _position_gap(x: np.ndarray, ref: np.ndarray) -> np.ndarray:
    gap = np.linalg.norm(x[:, :2] - ref[:, :2], axis=1)
    gap[0] = np.nan
    return gap


def diffuse_errors(exponents=DIFFUSE_P0_EXPONENTS) -> DiffuseErrors:
    r"""Filtre de Kalman (forme du cours) avec :math:`\hat x_0 = 0`, :math:`P_0 = 10^kI` pour chaque ``k``, et SRIF sans
    a priori, comparés à :func:`extended_precision_estimates` sur les relevés de :func:`diffuse_data`."""
    model = diffuse_model()
    _, y = diffuse_data()
    ref = extended_precision_estimates(model, y)
    srif = square_root_information_filter(model, y)
    kf = np.full((len(exponents), y.shape[0]), np.nan)
    failed = np.zeros(len(exponents), dtype=bool)
    for i, e in enumerate(exponents):
        try:
            kf[i] = _position_gap(kalman_filter(model, y, np.zeros(4), 10.0**e * np.eye(4), form="textbook").x, ref)
        except KalmanInputError:
            failed[i] = True
    return DiffuseErrors(np.array(exponents, dtype=float), kf, failed, _position_gap(srif.x, ref), ref)
