"""Oracle indépendant des filtres : la loi a posteriori de **toute** la trajectoire, calculée d'un bloc.

Les inconnues sont l'état de départ et tous les bruits d'état, θ = (z, w_…) ; chaque état est une fonction
affine de θ, x_k = Φ_k θ + c_k, et chaque mesure observée y_k = C_o x_k + v_k. La loi de θ sachant les
mesures est gaussienne, calculée sous forme d'information par des matrices pleines (taille n·T) : aucune
récurrence, aucun filtre. Départ connu : z = x_init ~ N(x0, P0) (instant 0) ; départ diffus : z = x_0 (état
de la première mesure) sans a priori (précision nulle). Un modèle variable dans le temps donne ses matrices
de chaque pas (``model.sequence``) : la ligne ``k`` est prédite par :math:`A_k, B_k, Q_k` et mesurée par
:math:`C_k, R_k`.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
import scipy.stats


def _steps(model, name, T):
    """La matrice ``name`` de chaque pas (T, …)."""
    return np.asarray(model.sequence(name, T))


def _design(model, T, u, diffuse):
    """Φ (T, n, d) et c (T, n) tels que x_k = Φ_k θ + c_k."""
    A, n = _steps(model, "A", T), model.n_state
    B = None if model.B is None else _steps(model, "B", T)
    n_w = T - 1 if diffuse else T  # bruits d'état inconnus
    d = n + n * n_w
    Phi = np.zeros((T, n, d))
    c = np.zeros((T, n))
    if diffuse:
        Phi[0, :, :n] = np.eye(n)
    else:
        Phi[0, :, :n] = A[0]
        Phi[0, :, n:2 * n] = np.eye(n)
        if B is not None:
            c[0] = B[0] @ u[0]
    for k in range(1, T):
        Phi[k] = A[k] @ Phi[k - 1]
        j = (k if not diffuse else k - 1)
        Phi[k, :, n + n * j:n + n * (j + 1)] += np.eye(n)
        c[k] = A[k] @ c[k - 1] + (0.0 if B is None else B[k] @ u[k])
    return Phi, c


def _observations(model, y, Phi, c):
    """Matrices empilées des composantes observées : H (N, d), offset (N,), y_o (N,), R (N, N)."""
    T = y.shape[0]
    C, R = _steps(model, "C", T), _steps(model, "R", T)
    rows, offs, ys, blocks = [], [], [], []
    for k in range(T):
        o = ~np.isnan(y[k])
        if not o.any():
            continue
        rows.append(C[k][o] @ Phi[k])
        offs.append(C[k][o] @ c[k])
        ys.append(y[k, o])
        blocks.append(R[k][np.ix_(o, o)])
    return np.vstack(rows), np.concatenate(offs), np.concatenate(ys), scipy.linalg.block_diag(*blocks)


def batch_posterior(model, y, u=None, x0=None, P0=None):
    """Moyennes (T, n), covariances (T, n, n), covariances de décalage un Cov(x_k, x_{k-1}) (T, n, n) ;
    au départ connu, aussi l'état initial lissé (moyenne, covariance) et Cov(x_0, x_init)."""
    y = np.asarray(y, dtype=float).reshape(len(y), model.n_obs)
    T, n = y.shape[0], model.n_state
    diffuse = x0 is None
    Phi, c = _design(model, T, u, diffuse)
    d = Phi.shape[2]
    Qs = _steps(model, "Q", T)
    prec = np.zeros((d, d))
    mean_prior = np.zeros(d)
    if not diffuse:
        prec[:n, :n] = np.linalg.inv(np.asarray(P0))
        mean_prior[:n] = x0
    for j in range((d - n) // n):  # bruit w_j : celui du pas j (départ connu) ou j + 1 (départ diffus)
        prec[n + n * j:n + n * (j + 1), n + n * j:n + n * (j + 1)] = np.linalg.inv(Qs[j if not diffuse else j + 1])
    H, off, yo, Rb = _observations(model, y, Phi, c)
    Ri = np.linalg.inv(Rb)
    Lam = prec + H.T @ Ri @ H
    b = prec @ mean_prior + H.T @ Ri @ (yo - off)
    cov = np.linalg.inv(Lam)
    theta = cov @ b
    xs = np.einsum("tnd,d->tn", Phi, theta) + c
    Ps = np.einsum("tnd,de,tme->tnm", Phi, cov, Phi)
    lag = np.full((T, n, n), np.nan)
    lag[1:] = np.einsum("tnd,de,tme->tnm", Phi[1:], cov, Phi[:-1])
    out = {"x": xs, "P": Ps, "P_lag": lag}
    if not diffuse:
        E = np.zeros((n, d))
        E[:, :n] = np.eye(n)  # x_init = z
        out["x_initial"] = E @ theta
        out["P_initial"] = E @ cov @ E.T
        out["lag0"] = Phi[0] @ cov @ E.T
    return out


def batch_log_likelihood(model, y, u=None, x0=None, P0=None):
    """log p(y) par la loi jointe des mesures observées ; départ diffus : la limite exacte
    −½[N log 2π + log|Σ| + log|ZᵀΣ⁻¹Z| + rᵀ(Σ⁻¹ − Σ⁻¹Z(ZᵀΣ⁻¹Z)⁻¹ZᵀΣ⁻¹)r] (y = Zδ + e, e ~ N(0, Σ))."""
    y = np.asarray(y, dtype=float).reshape(len(y), model.n_obs)
    T, n = y.shape[0], model.n_state
    diffuse = x0 is None
    Phi, c = _design(model, T, u, diffuse)
    H, off, yo, Rb = _observations(model, y, Phi, c)
    d = Phi.shape[2]
    cov_prior = np.zeros((d, d))
    mean_prior = np.zeros(d)
    if not diffuse:
        cov_prior[:n, :n] = P0
        mean_prior[:n] = x0
    Qs = _steps(model, "Q", T)
    for j in range((d - n) // n):
        cov_prior[n + n * j:n + n * (j + 1), n + n * j:n + n * (j + 1)] = Qs[j if not diffuse else j + 1]
    Sigma = H @ cov_prior @ H.T + Rb
    r = yo - off - H @ mean_prior
    if not diffuse:
        return float(scipy.stats.multivariate_normal(np.zeros(r.size), Sigma).logpdf(r))
    Z = H[:, :n]
    Si = np.linalg.inv(Sigma)
    M = Z.T @ Si @ Z
    proj = Si - Si @ Z @ np.linalg.inv(M) @ Z.T @ Si
    N = r.size
    return float(-0.5 * (N * np.log(2 * np.pi) + np.linalg.slogdet(Sigma)[1] + np.linalg.slogdet(M)[1] + r @ proj @ r))
