r"""Scénario « moteur d'avion » : l'exemple du cours (température, débit de carburant, thermomètre).

État :math:`x = (\theta_m, \theta_a)` : échauffement du moteur et de l'air autour de la sonde, en °C
au-dessus de l'air extérieur. Commande :math:`u` : débit de carburant (g/s). Mesure :math:`y` : tensions
(mV) de deux thermocouples, l'un sur le moteur, l'autre dans le flux d'air qui le refroidit.

.. math::

    x_{n+1} = A x_n + B u_n + \phi_n,\qquad y_{n+1} = C x_{n+1} + \psi_{n+1},

    A = \begin{pmatrix} 0{,}95 & 0{,}03\\ 0{,}02 & 0{,}96\end{pmatrix},\quad
    B = \begin{pmatrix} 0{,}5\\ 0\end{pmatrix},\quad
    C = s\begin{pmatrix} 1 & 0\\ 0{,}3 & 0{,}7\end{pmatrix},\quad s = 0{,}041\ \text{mV/°C}.

:math:`C` est l'**opérateur d'observation** du cours : il passe de l'espace d'état (°C) à l'espace des
mesures (mV). Il est inversible sans être l'identité, ce qui sert à illustrer les limites du gain
(:math:`K \to C^{-1}`) et l'initialisation (errata 001-4 à 001-6). Un pas de temps dure une seconde.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from ..core.models import LinearGaussianModel
from ..core.simulation import Simulation, simulate
from ..diagnostics.consistency import whitened_innovations
from ..diagnostics.monte_carlo import ConsistencyRuns, MonteCarlo, monte_carlo, monte_carlo_consistency
from ..filters.kalman import kalman_filter
from ..lecture.estimator import MeanError, linear_estimator_runs, mean_error_recursion
from ..core.results import FilterResult

__all__ = [
    "ENGINE_DT",
    "ENGINE_P0",
    "ENGINE_PHI",
    "ENGINE_PSI",
    "ENGINE_SEED",
    "ENGINE_SENSITIVITY",
    "ENGINE_STATE_NAMES",
    "ENGINE_X0_COV",
    "ENGINE_X0_HAT",
    "ENGINE_X0_MEAN",
    "engine_commands",
    "engine_model",
    "engine_model_without_command",
    "engine_simulation",
    "engine_filter",
    "engine_run",
    "overconfident_run",
    "ForgottenCommand",
    "forgotten_command",
    "OVERCONFIDENT_P0",
    "MEAN_ERROR_RUNS",
    "MEAN_ERROR_STEPS",
    "engine_kalman_gains",
    "mean_error_experiment",
    "LIMIT_SCALES",
    "gain_limit_run",
    "gain_limit_sweep",
    "CONSISTENCY_STEPS",
    "CONSISTENCY_MC_RUNS",
    "CONSISTENCY_MC_STEPS",
    "CONSISTENCY_MC_SEED",
    "incomplete_engine_model",
    "consistency_filters",
    "consistency_runs",
    "consistency_monte_carlo",
]

#: Durée d'un pas de temps (s).
ENGINE_DT = 1.0
#: Sensibilité des thermocouples (mV/°C), de l'ordre de celle d'un thermocouple de type K.
ENGINE_SENSITIVITY = 0.041
#: Graine des tirages du scénario.
ENGINE_SEED = 1960
#: Noms des composantes de l'état, pour les légendes.
ENGINE_STATE_NAMES = ("échauffement du moteur θ_m", "échauffement de l'air θ_a")

_A = np.array([[0.95, 0.03], [0.02, 0.96]])
_B = np.array([[0.5], [0.0]])
_C = ENGINE_SENSITIVITY * np.array([[1.0, 0.0], [0.3, 0.7]])
#: Covariance du bruit d'état par défaut (°C²) : écarts-types 0,3 °C et 0,2 °C par pas.
ENGINE_PHI = np.diag([0.3**2, 0.2**2])
#: Covariance du bruit de mesure par défaut (mV²) : écart-type de 0,5 °C ramené en mV.
ENGINE_PSI = (0.5 * ENGINE_SENSITIVITY) ** 2 * np.eye(2)
#: Loi de l'état initial vrai : moteur froid (échauffement nul), à 1 °C près.
ENGINE_X0_MEAN = np.zeros(2)
ENGINE_X0_COV = np.eye(2)
#: Estimation initiale volontairement fausse (°C) et covariance initiale du filtre (°C²).
ENGINE_X0_HAT = np.array([15.0, 5.0])
ENGINE_P0 = np.diag([15.0**2, 15.0**2])


def engine_model(Phi=None, Psi=None) -> LinearGaussianModel:
    r"""Le modèle du moteur ; ``Phi`` (2, 2) en °C² et ``Psi`` (2, 2) en mV² remplacent les valeurs par défaut.

    Renvoie un :class:`~kalman_course.models.LinearGaussianModel` avec ``A``, ``B`` (2, 1), ``C`` (2, 2),
    ``Q`` = :math:`\Phi`, ``R`` = :math:`\Psi`.
    """
    return LinearGaussianModel(
        A=_A,
        C=_C,
        Q=ENGINE_PHI if Phi is None else Phi,
        R=ENGINE_PSI if Psi is None else Psi,
        B=_B,
    )


def engine_commands(n_steps: int = 120) -> np.ndarray:
    """Profil de débit de carburant (g/s), forme (T, 1) : ralenti nul, plein régime à 5 g/s à partir de
    t = 10 s, réduit à 2 g/s à partir de t = 70 s."""
    t = np.arange(n_steps)
    u = np.where(t >= 10, 5.0, 0.0)
    u = np.where(t >= 70, 2.0, u)
    return u.reshape(-1, 1)


def engine_model_without_command() -> LinearGaussianModel:
    r"""Le modèle du moteur qui « oublie » la commande : mêmes :math:`A`, :math:`C`, :math:`\Phi`,
    :math:`\Psi`, sans matrice :math:`B` (l'hypothèse 1 du cours est violée)."""
    model = engine_model()
    return LinearGaussianModel(model.A, model.C, model.Q, model.R)


# --------------------------------------------------------------------------- l'expérience du moteur


def engine_simulation(n_steps: int = 120, *, true_model: LinearGaussianModel | None = None,
                      rng=ENGINE_SEED) -> Simulation:
    r"""Le moteur simulé pendant ``n_steps`` secondes : état initial vrai :data:`ENGINE_X0_MEAN` (moteur
    froid), débit :func:`engine_commands`, bruits de ``true_model`` (par défaut :func:`engine_model`),
    graine ``rng`` (par défaut celle du scénario)."""
    model = engine_model() if true_model is None else true_model
    return simulate(model, ENGINE_X0_MEAN, n_steps, engine_commands(n_steps), rng=rng)


def engine_filter(filter_model: LinearGaussianModel, y, *, P0=ENGINE_P0) -> FilterResult:
    r"""Les mesures ``y`` (T, 2) du moteur filtrées par ``filter_model`` depuis l'estimation initiale fausse
    :data:`ENGINE_X0_HAT` et ``P0`` (par défaut :data:`ENGINE_P0`), avec le débit :func:`engine_commands`
    (un modèle sans :math:`B`, :func:`engine_model_without_command`, n'en reçoit pas)."""
    u = None if filter_model.B is None else engine_commands(len(y))
    return kalman_filter(filter_model, y, ENGINE_X0_HAT, P0, u)


def engine_run(n_steps: int = 120, *, true_model: LinearGaussianModel | None = None,
               filter_model: LinearGaussianModel | None = None, P0=ENGINE_P0,
               rng=ENGINE_SEED) -> tuple[Simulation, FilterResult]:
    r"""L'expérience des chapitres linéaires : :func:`engine_simulation` puis :func:`engine_filter` (par
    défaut avec le vrai modèle). Renvoie ``(simulation, FilterResult)``."""
    sim = engine_simulation(n_steps, true_model=true_model, rng=rng)
    model = (engine_model() if true_model is None else true_model) if filter_model is None else filter_model
    return sim, engine_filter(model, sim.y, P0=P0)


# --------------------------------------------------------------------------- « Construction d'un estimateur »

#: Covariance initiale du filtre dans le chapitre de l'estimateur (°C²) : le filtre se croit précis à 1 °C
#: près alors que son estimation initiale ENGINE_X0_HAT est fausse de 15 °C ; l'erreur moyenne décroît donc
#: sur plusieurs pas.
OVERCONFIDENT_P0 = np.eye(2)
#: Taille des expériences de Monte-Carlo de l'erreur moyenne.
MEAN_ERROR_RUNS = 400
MEAN_ERROR_STEPS = 60


def overconfident_run(n_steps: int = MEAN_ERROR_STEPS) -> tuple[Simulation, FilterResult]:
    """Le moteur simulé (graine 0) et filtré depuis ENGINE_X0_HAT avec OVERCONFIDENT_P0 : le filtre de
    Kalman du chapitre de l'estimateur. Renvoie ``(simulation, FilterResult)``."""
    return engine_run(n_steps, P0=OVERCONFIDENT_P0, rng=0)


def engine_kalman_gains(n_steps: int = MEAN_ERROR_STEPS) -> np.ndarray:
    """Gains du filtre de Kalman du moteur (parti de ENGINE_X0_HAT, OVERCONFIDENT_P0), (T, 2, 2) : ils ne
    dépendent pas des mesures (une seule course suffit)."""
    return overconfident_run(n_steps)[1].K


def mean_error_experiment(forget_command: bool, n_steps: int = MEAN_ERROR_STEPS,
                          n_runs: int = MEAN_ERROR_RUNS) -> tuple[MonteCarlo, MeanError]:
    """Erreur moyenne de l'estimateur du moteur : Monte-Carlo et récurrence du cours.

    ``forget_command=False`` : le filtre de Kalman (conditions suffisantes respectées) ;
    ``True`` : mêmes gains mais :math:`B_f = 0` (condition 1 violée : l'estimateur oublie la commande).
    Renvoie ``(monte_carlo, recursion)``.
    """
    model = engine_model()
    u = engine_commands(n_steps)
    K = engine_kalman_gains(n_steps)
    B_f = np.zeros((2, 1)) if forget_command else None

    def estimator(Y):
        return linear_estimator_runs(model, Y, ENGINE_X0_HAT, K, u=u, B_f=B_f)

    mc = monte_carlo(
        model, estimator, n_steps, n_runs,
        x0_mean=ENGINE_X0_MEAN, x0_cov=ENGINE_X0_COV, x0_hat=ENGINE_X0_HAT, rng=ENGINE_SEED, u=u, batch=True,
    )
    rec = mean_error_recursion(model, K, x0_mean=ENGINE_X0_MEAN, x0_hat=ENGINE_X0_HAT, u=u, B_f=B_f)
    return mc, rec


# --------------------------------------------------------------------------- « Prédicteur–correcteur »


#: Facteurs appliqués à la covariance de mesure Ψ du filtre pour montrer les deux limites du gain.
LIMIT_SCALES = (1e6, 1e-6)


def gain_limit_run(scale: float, n_steps: int = 120):
    r"""Moteur simulé avec le vrai :math:`\Psi`, filtré en supposant :math:`s\,\Psi` (``scale`` = :math:`s`).

    Renvoie ``(simulation, FilterResult)``. :math:`s \to \infty` : :math:`K \to 0` ;
    :math:`s \to 0` : :math:`K \to C^{-1}` (ici :math:`C` est inversible sans être l'identité).
    """
    return engine_run(n_steps, filter_model=engine_model(Psi=scale * ENGINE_PSI))


def gain_limit_sweep(scales=None, n_steps: int = 120):
    r"""Gain final :math:`K_T` en fonction du facteur :math:`s` : renvoie ``(scales, ‖K‖/‖C⁻¹‖, ‖K − C⁻¹‖/‖C⁻¹‖)``
    (normes de Frobenius)."""
    scales = np.logspace(-8, 8, 33) if scales is None else np.asarray(scales, dtype=float)
    C_inv = scipy.linalg.inv(engine_model().C)
    norm = np.linalg.norm(C_inv)
    to_zero, to_inverse = [], []
    for s in scales:
        K = gain_limit_run(float(s), n_steps)[1].K[-1]
        to_zero.append(np.linalg.norm(K) / norm)
        to_inverse.append(np.linalg.norm(K - C_inv) / norm)
    return scales, np.array(to_zero), np.array(to_inverse)


# --------------------------------------------------------------------------- « Tests statistiques »

#: Durée des relevés du banc d'essai des tests statistiques (pas d'une seconde).
CONSISTENCY_STEPS = 500
#: Monte-Carlo de la NEES : nombre de tirages, durée, graine.
CONSISTENCY_MC_RUNS, CONSISTENCY_MC_STEPS, CONSISTENCY_MC_SEED = 100, 100, 2001


def incomplete_engine_model() -> LinearGaussianModel:
    r"""Le moteur sans couplage thermique : :math:`A = \operatorname{diag}(0{,}95 ; 0{,}96)` au lieu de
    la matrice pleine du système (les termes 0,03 et 0,02 sont oubliés) ; le reste est juste."""
    model = engine_model()
    return LinearGaussianModel(np.diag(np.diag(model.A)), model.C, model.Q, model.R, B=model.B)


def consistency_filters() -> dict[str, LinearGaussianModel]:
    """Les quatre filtres du banc d'essai, par nom affiché : le modèle juste, Ψ dix fois trop petit, Φ dix
    fois trop grand, le couplage oublié."""
    return {
        "modèle juste": engine_model(),
        "Ψ ÷ 10": engine_model(Psi=ENGINE_PSI / 10),
        "Φ × 10": engine_model(Phi=10 * ENGINE_PHI),
        "couplage oublié": incomplete_engine_model(),
    }


def consistency_runs(n_steps: int = CONSISTENCY_STEPS) -> tuple[Simulation, dict[str, FilterResult]]:
    """Le moteur simulé une fois (modèle vrai, graine du scénario), filtré par chacun des filtres de
    :func:`consistency_filters` ; renvoie ``(simulation, {nom: FilterResult})``."""
    sim = engine_simulation(n_steps)
    return sim, {name: engine_filter(m, sim.y) for name, m in consistency_filters().items()}


def consistency_monte_carlo(n_runs: int = CONSISTENCY_MC_RUNS, n_steps: int = CONSISTENCY_MC_STEPS) -> dict[str, ConsistencyRuns]:
    r"""NEES et NIS de ``n_runs`` tirages (``n_steps`` pas) pour le modèle juste et les deux réglages faux ;
    initialisation cohérente :math:`x_0 \sim \mathcal N(\hat x_0, P_0)`."""
    true = engine_model()
    u = engine_commands(n_steps)
    filters = consistency_filters()
    return {
        name: monte_carlo_consistency(true, n_steps, n_runs, x0_hat=ENGINE_X0_MEAN, P0=ENGINE_X0_COV,
                                      rng=CONSISTENCY_MC_SEED, filter_model=filters[name], u=u)
        for name in ("modèle juste", "Ψ ÷ 10", "Φ × 10")
    }


# --------------------------------------------------------------------------- « Implémentation pratique »


@dataclass(frozen=True, eq=False)
class ForgottenCommand:
    r"""Le moteur filtré avec le bon modèle (``good``) et avec un modèle qui oublie la commande (``bad``,
    :func:`engine_model_without_command`), sur la même ``simulation`` ; ``normalised_good`` et
    ``normalised_bad`` (T,) : innovations normalisées du premier capteur,
    :math:`\nu_{n,1}/\sqrt{S_{n,11}}` (première composante des innovations blanchies,
    :func:`~kalman_course.whitened_innovations`)."""

    simulation: Simulation
    good: FilterResult
    bad: FilterResult

    @property
    def normalised_good(self) -> np.ndarray:
        return whitened_innovations(self.good)[:, 0]

    @property
    def normalised_bad(self) -> np.ndarray:
        return whitened_innovations(self.bad)[:, 0]


def forgotten_command(n_steps: int = 120) -> ForgottenCommand:
    """Le moteur simulé une fois, filtré avec et sans la commande (chapitre « Implémentation pratique »)."""
    sim = engine_simulation(n_steps)
    return ForgottenCommand(sim, engine_filter(engine_model(), sim.y), engine_filter(engine_model_without_command(), sim.y))
