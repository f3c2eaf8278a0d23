r"""La loi jointe de toute une trajectoire et de ses mesures, calculée d'un bloc, sans filtre.

Pour le modèle linéaire gaussien :math:`x_k = Ax_{k-1} + \phi_{k-1}`, :math:`y_k = Cx_k + \psi_k`,
:math:`x_0 \sim \mathcal N(\hat x_0, P_0)`, le vecteur :math:`(x_1, \dots, x_T, y_1, \dots, y_T)` est gaussien :
chaque état est une fonction affine de :math:`x_0` et des bruits,
:math:`x_k = A^kx_0 + \sum_{j<k}A^{k-1-j}\phi_j`. :func:`joint_gaussian` en donne la moyenne et la covariance
par des matrices pleines (taille :math:`T(n + m)`) ; le conditionnement gaussien et la densité jointe des
mesures (:mod:`scipy.stats`) s'en déduisent. Aucune récurrence : c'est la référence contre laquelle les
démonstrations du livre vérifient le lisseur, la blancheur des innovations et la décomposition de la
vraisemblance (petits :math:`T` seulement).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg

from ..core.models import LinearGaussianModel
from ..core.validation import KalmanInputError, as_gaussian, check_instance

__all__ = ["JointGaussian", "joint_gaussian"]


@dataclass(frozen=True)
class JointGaussian:
    r"""Loi de :math:`(x_{1:T}, y_{1:T})` : ``mean_x`` (T, n), ``mean_y`` (T, m), ``cov_xx`` (Tn, Tn),
    ``cov_xy`` (Tn, Tm), ``cov_yy`` (Tm, Tm) (états et mesures empilés dans l'ordre du temps)."""

    mean_x: np.ndarray
    mean_y: np.ndarray
    cov_xx: np.ndarray
    cov_xy: np.ndarray
    cov_yy: np.ndarray

    def states_given(self, y: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r"""Loi des états sachant toutes les mesures ``y`` (T, m), par le conditionnement gaussien
        :math:`m_x + \Sigma_{xy}\Sigma_{yy}^{-1}(y - m_y)`, :math:`\Sigma_{xx} - \Sigma_{xy}\Sigma_{yy}^{-1}\Sigma_{yx}` :
        moyennes (T, n), covariances (T, n, n) et covariances de décalage un
        :math:`\operatorname{Cov}(x_k, x_{k-1} \mid y)` (T, n, n), la première à NaN."""
        T, n = self.mean_x.shape
        Y = np.asarray(y, dtype=float).reshape(self.mean_y.shape)
        gain = scipy.linalg.solve(self.cov_yy, self.cov_xy.T, assume_a="pos").T
        mean = self.mean_x.ravel() + gain @ (Y - self.mean_y).ravel()
        cov = self.cov_xx - gain @ self.cov_xy.T
        blocks = cov.reshape(T, n, T, n)
        lag = np.full((T, n, n), np.nan)
        lag[1:] = np.array([blocks[k, :, k - 1, :] for k in range(1, T)])
        return mean.reshape(T, n), np.array([blocks[k, :, k, :] for k in range(T)]), lag

    def log_likelihood(self, y: Any) -> float:
        r"""Log-densité jointe des mesures, :math:`\log\mathcal N(y_{1:T} ; m_y, \Sigma_{yy})` (scipy)."""
        import scipy.stats

        Y = np.asarray(y, dtype=float).reshape(self.mean_y.shape)
        return float(scipy.stats.multivariate_normal(self.mean_y.ravel(), self.cov_yy).logpdf(Y.ravel()))


def joint_gaussian(model: LinearGaussianModel, x0: Any, P0: Any, T: int) -> JointGaussian:
    r"""La loi jointe de :math:`(x_{1:T}, y_{1:T})` pour un modèle constant sans commande, a priori
    :math:`x_0 \sim \mathcal N(` ``x0`` :math:`,` ``P0`` :math:`)` à l'instant 0 (voir le module)."""
    check_instance("model", model, LinearGaussianModel, "la loi jointe d'un modèle linéaire gaussien")
    if model.time_varying or model.B is not None:
        raise KalmanInputError("« model » : la loi jointe est écrite pour un modèle constant, sans commande.")
    if isinstance(T, bool) or not isinstance(T, (int, np.integer)) or not 1 <= T <= 200:
        raise KalmanInputError(f"« T » doit être un entier entre 1 et 200 (matrices pleines) ; reçu {T!r}.")
    x0, P0 = as_gaussian(x0, P0, model.n_state, "x0", "P0")
    A, C, Q, R = (np.asarray(M) for M in (model.A, model.C, model.Q, model.R))
    n, m = model.n_state, model.n_obs
    # x_k = Φ_k θ avec θ = (x_0, φ_0, …, φ_{T-1}) de covariance diag(P0, Q, …, Q)
    d = n * (T + 1)
    Phi = np.zeros((T, n, d))
    power = np.eye(n)
    for k in range(T):
        power = A @ power
        Phi[k, :, :n] = power
        for j in range(k + 1):
            Phi[k, :, n * (j + 1):n * (j + 2)] = np.linalg.matrix_power(A, k - j)
    theta = scipy.linalg.block_diag(P0, *([Q] * T))
    X = Phi.reshape(T * n, d)
    cov_xx = X @ theta @ X.T
    Cbig = np.kron(np.eye(T), C)
    cov_xy = cov_xx @ Cbig.T
    cov_yy = Cbig @ cov_xx @ Cbig.T + np.kron(np.eye(T), R)
    mean_x = np.array([np.linalg.matrix_power(A, k + 1) @ x0 for k in range(T)])
    return JointGaussian(mean_x, mean_x @ C.T, cov_xx, cov_xy, 0.5 * (cov_yy + cov_yy.T))
