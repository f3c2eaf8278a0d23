r"""Scénario « cible lointaine » : un radar mesure la distance et l'azimut d'une cible à 1 km, dont la
position initiale n'est connue qu'à 300 m près — la « banane » dans un filtre.

La cible avance à vitesse constante (:math:`\Delta t = 1` s, accélération blanche :math:`\sigma_a = 0{,}05`
m/s²) ; le radar est précis en distance (1 m) et en azimut (0,2°, soit 3,5 m à 1 km). Au premier pas,
l'incertitude transverse (300 m, soit 17° d'azimut) est énorme devant la courbure de la mesure : la
linéarisation de l'EKF place la correction sur la tangente au cercle de distance mesurée, pas sur le cercle,
et l'EKF se croit bien plus précis qu'il ne l'est ; l'UKF, qui fait passer ses points sigma par la vraie
fonction, reste cohérent.

:func:`distant_target_comparison` répète l'expérience sur ``n_runs`` tirages (même modèle, initialisation
tirée de la loi a priori du filtre) et renvoie, pour chaque filtre, l'erreur de position moyenne et la
NEES moyenne à chaque pas.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.models import NonlinearModel
from ..core.results import FilterResult, FilterRuns, freeze_fields
from ..core.simulation import as_generator, check_positive_int
from ..diagnostics.consistency import nees
from ..filters.extended import extended_kalman_filter_runs
from ..filters.iterated import iterated_extended_kalman_filter_runs
from ..filters.unscented import unscented_kalman_filter_runs
from ._motion import simulate_cv
from .radar import radar_tracking_model, range_bearing

__all__ = [
    "TARGET_DT",
    "TARGET_ACCEL_STD",
    "TARGET_RANGE_STD",
    "TARGET_BEARING_STD",
    "TARGET_START",
    "TARGET_P0",
    "TARGET_STEPS",
    "TARGET_RUNS",
    "TARGET_SEED",
    "TARGET_UKF",
    "distant_target_model",
    "DistantTargetRun",
    "distant_target_run",
    "FilterComparison",
    "distant_target_comparison",
]

#: Période du radar (s).
TARGET_DT = 1.0
#: Écart-type de l'accélération (m/s²).
TARGET_ACCEL_STD = 0.05
#: Écart-type de la distance mesurée (m).
TARGET_RANGE_STD = 1.0
#: Écart-type de l'azimut mesuré (rad) : 0,2°.
TARGET_BEARING_STD = float(np.deg2rad(0.2))
#: État vrai moyen au départ : 1 km à l'est, 10 m/s vers le nord.
TARGET_START = np.array([1000.0, 0.0, 0.0, 10.0])
TARGET_START.setflags(write=False)
#: Covariance a priori : 300 m sur chaque coordonnée de position, 3 m/s sur la vitesse.
TARGET_P0 = np.diag([300.0**2, 300.0**2, 3.0**2, 3.0**2])
TARGET_P0.setflags(write=False)
#: Nombre de pas (mesures) par tirage.
TARGET_STEPS = 40
#: Nombre de tirages de l'expérience.
TARGET_RUNS = 100
#: Graine de l'expérience.
TARGET_SEED = 2024
#: Points sigma de l'UKF : :math:`\alpha = 1`, :math:`\beta = 2`, :math:`\kappa = 0`.
TARGET_UKF = {"alpha": 1.0, "beta": 2.0, "kappa": 0.0}


def distant_target_model() -> NonlinearModel:
    r"""Le modèle du filtre : vitesse constante, mesure (distance, azimut) vue de l'origine (vectorisé)."""
    return radar_tracking_model(TARGET_DT, TARGET_ACCEL_STD, TARGET_RANGE_STD, TARGET_BEARING_STD)


@dataclass(frozen=True, eq=False)
class DistantTargetRun:
    r"""Un tirage : ``x_true`` (T, 4) états vrais, ``y`` (T, 2) mesures (m, rad), ``x0`` (4,) et ``P0``
    (4, 4) l'a priori du filtre (:math:`x_0 \sim \mathcal N(\hat x_0, P_0)` : l'a priori est juste)."""

    x_true: np.ndarray
    y: np.ndarray
    x0: np.ndarray
    P0: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "x_true", "y", "x0", "P0")


def distant_target_run(rng: Any = TARGET_SEED, n_steps: int = TARGET_STEPS) -> DistantTargetRun:
    r"""Tire l'état initial vrai autour de :data:`TARGET_START` (loi :data:`TARGET_P0`), la trajectoire et
    les mesures ; l'a priori du filtre est :math:`(\text{TARGET\_START}, P_0)`."""
    gen = as_generator(rng)
    n_steps = check_positive_int("n_steps", n_steps)
    start = TARGET_START + np.sqrt(np.diag(TARGET_P0)) * gen.standard_normal(4)
    x_true = simulate_cv(start, n_steps, TARGET_DT, TARGET_ACCEL_STD, gen)
    noise = gen.standard_normal((n_steps, 2)) * np.array([TARGET_RANGE_STD, TARGET_BEARING_STD])
    return DistantTargetRun(x_true=x_true, y=range_bearing(x_true) + noise, x0=TARGET_START, P0=TARGET_P0)


@dataclass(frozen=True, eq=False)
class FilterComparison:
    r"""Résultat de :func:`distant_target_comparison` : pour chaque filtre (clé ``"EKF"``, ``"UKF"``,
    ``"EKF itéré"``),
    ``position_error[nom]`` (T,) erreur de position moyenne sur les tirages (m) et ``nees[nom]`` (T,) NEES
    moyenne (attendue : 4 = dimension de l'état) ; ``n_runs`` tirages ; ``t`` (T,) instants (s)."""

    t: np.ndarray
    position_error: dict
    nees: dict
    n_runs: int

    def summary(self, skip: int = 10) -> dict:
        """Moyennes après les ``skip`` premiers pas : ``{nom: (erreur de position (m), NEES)}``."""
        return {name: (float(self.position_error[name][skip:].mean()), float(self.nees[name][skip:].mean()))
                for name in self.position_error}


def _runs_nees(x_true: np.ndarray, runs: FilterRuns) -> np.ndarray:
    r"""NEES (N, T) de chaque tirage et de chaque pas : la NEES ne dépend que du pas, on la calcule en un
    appel de :func:`~kalman_course.nees` sur les :math:`N T` pas mis bout à bout."""
    N, T, n = runs.x.shape
    flat = FilterResult(x=runs.x.reshape(N * T, n), P=runs.P.reshape(N * T, n, n), x_pred=runs.x_pred.reshape(N * T, n),
                        P_pred=runs.P_pred.reshape(N * T, n, n), K=runs.K.reshape(N * T, n, -1),
                        innovation=runs.innovation.reshape(N * T, -1), S=runs.S.reshape(N * T, *runs.S.shape[-2:]),
                        observed=runs.observed.reshape(N * T, -1), n_iter=runs.n_iter.reshape(N * T))
    return nees(x_true.reshape(N * T, n), flat).reshape(N, T)


def distant_target_comparison(n_runs: int = TARGET_RUNS, rng: Any = TARGET_SEED,
                              n_steps: int = TARGET_STEPS) -> FilterComparison:
    r"""EKF, UKF (:data:`TARGET_UKF`) et EKF itéré sur ``n_runs`` tirages de :func:`distant_target_run` : erreur de
    position et NEES moyennes à chaque pas.

    Les tirages sont tirés l'un après l'autre du même générateur (``rng``), puis chaque filtre les traite
    tous à la fois (filtres en lot : :func:`~kalman_course.filters.extended.extended_kalman_filter_runs`…),
    ce qui donne, aux arrondis près, les mêmes nombres qu'un filtre par tirage."""
    n_runs = check_positive_int("n_runs", n_runs)
    gen = as_generator(rng)
    model = distant_target_model()
    runs = [distant_target_run(gen, n_steps) for _ in range(n_runs)]
    x_true = np.stack([run.x_true for run in runs])  # (N, T, 4)
    Y = np.stack([run.y for run in runs])            # (N, T, 2)
    X0 = np.stack([run.x0 for run in runs])
    P0 = np.stack([run.P0 for run in runs])
    filters = {
        "EKF": lambda: extended_kalman_filter_runs(model, Y, X0, P0),
        "UKF": lambda: unscented_kalman_filter_runs(model, Y, X0, P0, **TARGET_UKF),
        "EKF itéré": lambda: iterated_extended_kalman_filter_runs(model, Y, X0, P0),
    }
    err, eps = {}, {}
    for name, run_filter in filters.items():
        result = run_filter()
        err[name] = np.mean(np.linalg.norm(result.x[..., :2] - x_true[..., :2], axis=-1), axis=0)
        eps[name] = np.mean(_runs_nees(x_true, result), axis=0)
    return FilterComparison(t=TARGET_DT * np.arange(1, n_steps + 1), position_error=err, nees=eps, n_runs=n_runs)
