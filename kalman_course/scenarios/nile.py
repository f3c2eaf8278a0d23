r"""Le Nil à Assouan (1871–1970) et le modèle à niveau local : les expériences du chapitre
« Apprendre Q et R » (et des curseurs du chapitre « Lissage »), écrites une fois.

Modèle à niveau local (Durbin & Koopman 2012, ch. 2) : le niveau :math:`\mu_t` fait une marche
aléatoire, la mesure est le niveau plus un bruit,

.. math::

    \mu_{t+1} = \mu_t + \eta_t,\ \ \eta_t \sim \mathcal N(0, \sigma^2_\eta),\qquad
    y_t = \mu_t + \varepsilon_t,\ \ \varepsilon_t \sim \mathcal N(0, \sigma^2_\varepsilon),

soit :math:`A = C = 1`, :math:`Q = \sigma^2_\eta`, :math:`R = \sigma^2_\varepsilon`, sans a priori sur le
niveau de 1871 (initialisation diffuse exacte). Les paramètres sont :math:`\theta = (\log\sigma^2_\varepsilon,
\log\sigma^2_\eta)` : les variances restent positives sans contrainte.

Toutes les fonctions sont à résultat mis en cache : le chapitre, ses figures et ses tests partagent
les mêmes calculs.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..core.models import LinearGaussianModel
from ..core.results import FilterResult, freeze_fields
from ..datasets.nile import AnnualSeries, nile
from ..diagnostics.consistency import (
    CentringTest,
    ChiSquareTest,
    WhitenessTest,
    centring_test,
    nis_test,
    whitened_innovations,
    whiteness_test,
)
from ..filters.diffuse import diffuse_kalman_filter
from ..filters.kalman import kalman_filter
from ..filters.smoothers import SmootherResult, rts_smoother
from ..likelihood import (
    EMResult,
    MaximumLikelihood,
    expectation_maximization,
    filter_log_likelihood,
    log_likelihoods,
    maximum_likelihood,
)

__all__ = [
    "NILE_DK_VARIANCES",
    "NILE_THETA0",
    "NILE_EM_START",
    "local_level_model",
    "local_level_from_log",
    "local_linear_trend_model",
    "nile_fit",
    "NileSmoothing",
    "nile_smoothing",
    "nile_run",
    "LikelihoodSurface",
    "likelihood_surface",
    "nile_em",
    "NileDiagnostics",
    "nile_diagnostics",
    "diffuse_limit",
    "level_drop",
    "missing_years_coverage",
]

#: Estimations publiées par Durbin & Koopman (2012, § 2.10.3) : :math:`(\sigma^2_\varepsilon, \sigma^2_\eta)`.
NILE_DK_VARIANCES = (15099.0, 1469.1)
#: Point de départ du maximum de vraisemblance, :math:`\theta_0 = (\log 10^4, \log 10^3)`.
NILE_THETA0 = (float(np.log(1e4)), float(np.log(1e3)))
#: Point de départ d'EM, :math:`(\sigma^2_\varepsilon, \sigma^2_\eta)`, loin de l'optimum (pour voir le chemin).
NILE_EM_START = (3000.0, 20000.0)


def local_level_model(sigma2_eps: float, sigma2_eta: float) -> LinearGaussianModel:
    r"""Le modèle à niveau local : :math:`A = C = 1`, :math:`Q = \sigma^2_\eta`, :math:`R = \sigma^2_\varepsilon`."""
    return LinearGaussianModel(1.0, 1.0, sigma2_eta, sigma2_eps)


def local_level_from_log(theta) -> LinearGaussianModel:
    r"""``build`` du maximum de vraisemblance : :math:`\theta = (\log\sigma^2_\varepsilon, \log\sigma^2_\eta)`."""
    theta = np.asarray(theta, dtype=float)
    return local_level_model(float(np.exp(theta[0])), float(np.exp(theta[1])))


def local_linear_trend_model(sigma2_eps: float, sigma2_level: float, sigma2_slope: float) -> LinearGaussianModel:
    r"""Tendance locale : niveau et pente, :math:`A = \begin{bmatrix}1 & 1\\0 & 1\end{bmatrix}`, :math:`C = [1\ 0]`,
    :math:`Q = \operatorname{diag}(\sigma^2_{niveau}, \sigma^2_{pente})`, :math:`R = \sigma^2_\varepsilon`."""
    return LinearGaussianModel([[1.0, 1.0], [0.0, 1.0]], [[1.0, 0.0]], np.diag([sigma2_level, sigma2_slope]),
                               sigma2_eps)


@lru_cache(maxsize=2)
def nile_fit(missing: bool = False) -> MaximumLikelihood:
    r"""Maximum de vraisemblance (initialisation diffuse exacte) du niveau local sur le Nil (``missing`` : version à
    années manquantes), en partant de :data:`NILE_THETA0`."""
    return maximum_likelihood(local_level_from_log, nile(missing).flow, np.array(NILE_THETA0))


@dataclass(frozen=True, eq=False)
class NileSmoothing:
    """Le Nil filtré et lissé : ``data`` (:class:`~kalman_course.datasets.AnnualSeries`), ``model``,
    ``filtered`` (initialisation diffuse exacte), ``smoothed``."""

    data: AnnualSeries
    model: LinearGaussianModel
    filtered: FilterResult
    smoothed: SmootherResult


def _smooth(data: AnnualSeries, model: LinearGaussianModel) -> NileSmoothing:
    filtered = diffuse_kalman_filter(model, data.flow)
    return NileSmoothing(data, model, filtered, rts_smoother(model, filtered))


@lru_cache(maxsize=4)
def nile_smoothing(missing: bool = False) -> NileSmoothing:
    """Le Nil filtré et lissé avec les variances du maximum de vraisemblance de la même série."""
    return _smooth(nile(missing), nile_fit(missing).model)


def nile_run(sigma2_eps: float, sigma2_eta: float, missing: bool = True) -> NileSmoothing:
    """Le Nil filtré et lissé pour des variances données (curseurs)."""
    return _smooth(nile(missing), local_level_model(sigma2_eps, sigma2_eta))


@dataclass(frozen=True, eq=False)
class LikelihoodSurface:
    r""":math:`\log L` sur une grille : ``sigma2_eps`` (N,), ``sigma2_eta`` (M,) (échelles log),
    ``log_likelihood`` (M, N) (ligne : :math:`\sigma^2_\eta`, colonne : :math:`\sigma^2_\varepsilon`)."""

    sigma2_eps: np.ndarray
    sigma2_eta: np.ndarray
    log_likelihood: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "sigma2_eps", "sigma2_eta", "log_likelihood")


@lru_cache(maxsize=2)
def likelihood_surface(n: int = 25, missing: bool = False) -> LikelihoodSurface:
    r""":math:`\log L(\sigma^2_\varepsilon, \sigma^2_\eta)` (initialisation diffuse exacte) sur une grille log de
    ``n`` × ``n`` points : :math:`\sigma^2_\varepsilon \in [10^{3}, 10^{5}]`, :math:`\sigma^2_\eta \in [10^{1}, 10^{5}]`."""
    y = nile(missing).flow
    eps = np.logspace(3.0, 5.0, n)
    eta = np.logspace(1.0, 5.0, n)
    ll = log_likelihoods([local_level_model(e, q) for q in eta for e in eps], y).reshape(n, n)  # en lot
    return LikelihoodSurface(eps, eta, ll)


@lru_cache(maxsize=2)
def nile_em(missing: bool = False, max_iter: int = 2000, tol: float = 1e-12) -> EMResult:
    """EM sur le Nil (initialisation diffuse exacte) depuis :data:`NILE_EM_START`."""
    return expectation_maximization(local_level_model(*NILE_EM_START), nile(missing).flow, max_iter=max_iter, tol=tol)


@dataclass(frozen=True, eq=False)
class NileDiagnostics:
    r"""Tests des innovations du Nil au maximum de vraisemblance, après la période diffuse (:math:`k \ge d`) :
    ``years`` (T−d,), ``standardized`` (T−d,) innovations blanchies :math:`\nu_k/\sqrt{S_k}` (sans unité),
    ``nis`` (:class:`~kalman_course.ChiSquareTest`), ``whiteness``, ``centring``."""

    years: np.ndarray
    standardized: np.ndarray
    nis: ChiSquareTest
    whiteness: WhitenessTest
    centring: CentringTest

    def __post_init__(self) -> None:
        freeze_fields(self, "years", "standardized")


@lru_cache(maxsize=1)
def nile_diagnostics(max_lag: int = 10) -> NileDiagnostics:
    """NIS, blancheur (Ljung–Box, ``max_lag`` décalages) et centrage des innovations du Nil (série complète)."""
    run = nile_smoothing(False)
    proper = run.filtered.after_diffuse()
    e = whitened_innovations(proper)[:, 0]
    return NileDiagnostics(
        years=run.data.year[run.filtered.n_diffuse:], standardized=e, nis=nis_test(proper),
        whiteness=whiteness_test(proper, max_lag), centring=centring_test(e),
    )


def diffuse_limit(kappas, variances=NILE_DK_VARIANCES) -> np.ndarray:
    r""":math:`\log L_\kappa + \tfrac12\log\kappa` pour l'a priori :math:`\hat x_0 = 0`, :math:`P_0 = \kappa`
    du filtre de Kalman ordinaire (niveau local, Nil complet) : tend vers la vraisemblance diffuse exacte
    quand :math:`\kappa \to \infty`, tant que les arrondis le permettent. ``kappas`` (K,) ; renvoie (K,)."""
    model = local_level_model(*variances)
    y = nile().flow
    out = []
    for kappa in np.asarray(kappas, dtype=float):
        res = kalman_filter(model, y, 0.0, kappa)
        out.append(filter_log_likelihood(res) + 0.5 * np.log(kappa))
    return np.array(out)


def level_drop(smoothing: NileSmoothing | None = None) -> dict[str, float]:
    r"""La baisse du niveau lissé autour de 1899 : niveau lissé en 1894 et en 1903, et la plus forte baisse
    d'une année sur l'autre (``year`` : l'année d'arrivée, ``drop`` : la baisse, :math:`10^8` m³ par an)."""
    run = nile_smoothing(False) if smoothing is None else smoothing
    level = run.smoothed.x[:, 0]
    years = run.data.year
    steps = np.diff(level)
    i = int(np.argmin(steps))
    return {
        "level_1894": float(level[years == 1894][0]),
        "level_1903": float(level[years == 1903][0]),
        "year": float(years[i + 1]),
        "drop": float(-steps[i]),
    }


def missing_years_coverage() -> dict[str, float]:
    r"""Les 40 débits retirés (version à années manquantes) contre la prévision du lisseur : la mesure
    d'une année retirée suit :math:`\mathcal N(\hat\mu_{t\mid T}, P_{t\mid T} + \sigma^2_\varepsilon)`.
    Renvoie la part des débits retirés dans l'intervalle à ± 2 écarts-types (``inside``), l'erreur
    quadratique moyenne du niveau lissé sur ces années (``rmse``, :math:`10^8` m³ par an) et l'écart-type de
    prévision moyen (``sd``)."""
    run = nile_smoothing(True)
    full = nile(False).flow
    gone = run.data.missing
    mean = run.smoothed.x[gone, 0]
    sd = np.sqrt(run.smoothed.P[gone, 0, 0] + run.model.R[0, 0])
    err = full[gone] - mean
    return {"inside": float(np.mean(np.abs(err) <= 2 * sd)), "rmse": float(np.sqrt(np.mean(err**2))),
            "sd": float(np.mean(sd))}
