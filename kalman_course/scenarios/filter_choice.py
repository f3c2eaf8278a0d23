r"""Scénario du chapitre « Quel filtre choisir ? » : sept filtres sur le même problème, plusieurs niveaux
d'incertitude initiale.

Le problème est celui de la cible lointaine (:mod:`~kalman_course.scenarios.distant_target`) : un radar
mesure la distance (1 m) et l'azimut (0,2°) d'une cible à 1 km qui avance à 10 m/s. Ce qui varie est
l'incertitude de la position initiale, :math:`\sigma_0` (de 10 m à 1 km sur chaque coordonnée ; 3 m/s sur
la vitesse) : à 10 m, la mesure est presque linéaire à l'échelle de l'incertitude et tous les filtres se
valent ; à 1 km, la loi prédite est une « banane » de plusieurs dizaines de degrés.

:func:`choice_runs` fait passer les mêmes tirages (l'état initial vrai est tiré de l'a priori du filtre)
par l'EKF, l'EKF itéré, l'UKF (:math:`\alpha = 1, \beta = 2, \kappa = 0`), le CKF, le GHKF (ordre 3, 81
points), le filtre particulaire (:data:`CHOICE_PARTICLES` particules) et l'EnKF (:data:`CHOICE_MEMBERS`
membres), et rend pour chacun l'erreur de position et la NEES moyennes à chaque pas. Un filtre qui
échoue (covariance qui cesse d'être définie positive) est noté comme tel, sans arrêter les autres.
:func:`choice_table` en fait le tableau du chapitre, avec le coût par pas mesuré par
``benchmarks/filter_choice.py`` (:mod:`kalman_course.scenarios.filter_choice_timings`, daté).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Callable

import numpy as np

from ..core.results import FilterResult
from ..core.simulation import as_generator, check_positive_int
from ..core.validation import KalmanInputError
from ..diagnostics.consistency import chi2_band
from ..filters.cubature import CUBATURE, cubature_kalman_filter_runs
from ..filters.ensemble import ensemble_kalman_filter
from ..filters.extended import extended_kalman_filter_runs
from ..filters.gauss_hermite import GaussHermiteRule, gauss_hermite_kalman_filter_runs
from ..filters.iterated import iterated_extended_kalman_filter_runs
from ..filters.particle import particle_filter
from ..filters.unscented import UnscentedRule, unscented_kalman_filter_runs
from ..tables import Table
from ._motion import simulate_cv
from .distant_target import (
    TARGET_ACCEL_STD,
    TARGET_BEARING_STD,
    TARGET_DT,
    TARGET_RANGE_STD,
    TARGET_START,
    TARGET_STEPS,
    TARGET_UKF,
    distant_target_model,
)
from .radar import range_bearing

__all__ = [
    "CHOICE_FILTERS",
    "CHOICE_PRIOR_STDS",
    "CHOICE_PRIOR_STD",
    "CHOICE_RUNS",
    "CHOICE_SEED",
    "CHOICE_PARTICLES",
    "CHOICE_MEMBERS",
    "CHOICE_GH_ORDER",
    "CHOICE_SKIP",
    "ChoiceRuns",
    "choice_runs",
    "choice_sweep",
    "evaluations_per_step",
    "measured_costs",
    "choice_table",
]

#: Les filtres comparés, dans l'ordre du tableau.
CHOICE_FILTERS = ("EKF", "EKF itéré", "UKF", "CKF", "GHKF", "filtre particulaire", "EnKF")
#: Incertitudes initiales de position étudiées (m, sur chaque coordonnée).
CHOICE_PRIOR_STDS = (10.0, 100.0, 300.0, 1000.0)
#: Incertitude du tableau et de la position par défaut du curseur (m) : celle du chapitre de l'UKF.
CHOICE_PRIOR_STD = 300.0
#: Écart-type a priori de la vitesse (m/s).
CHOICE_VELOCITY_STD = 3.0
#: Nombre de tirages par niveau d'incertitude.
CHOICE_RUNS = 30
#: Graine des tirages.
CHOICE_SEED = 2023
#: Particules du filtre particulaire.
CHOICE_PARTICLES = 1000
#: Membres de l'EnKF.
CHOICE_MEMBERS = 200
#: Ordre de Gauss–Hermite (3⁴ = 81 points).
CHOICE_GH_ORDER = 3
#: Pas du régime transitoire, ignorés par l'erreur quadratique moyenne.
CHOICE_SKIP = 10


@dataclass(frozen=True, eq=False)
class ChoiceRuns:
    r"""Les sept filtres sur ``n_runs`` tirages à l'incertitude initiale ``prior_std`` (m) : ``t`` (T,)
    instants (s) ; pour chaque nom de :data:`CHOICE_FILTERS`, ``position_error[nom]`` (T,) erreur de
    position moyenne (m), ``squared_error[nom]`` (T,) erreur quadratique moyenne (m²), ``nees[nom]`` (T,)
    NEES moyenne (4 attendu), ``n_iter[nom]`` nombre moyen d'itérations de la correction par pas ;
    ``failed[nom]`` : message de l'erreur qui a arrêté le filtre sur au moins un tirage (sinon absent ; ses
    séries sont alors NaN)."""

    t: np.ndarray
    prior_std: float
    n_runs: int
    position_error: dict
    squared_error: dict
    nees: dict
    n_iter: dict
    failed: dict

    def rmse(self, name: str, skip: int = CHOICE_SKIP) -> float:
        r"""Erreur quadratique moyenne de position (m) après les ``skip`` premiers pas."""
        return float(np.sqrt(np.mean(self.squared_error[name][skip:])))

    def mean_nees(self, name: str, skip: int = CHOICE_SKIP) -> float:
        """NEES moyenne après les ``skip`` premiers pas."""
        return float(np.mean(self.nees[name][skip:]))

    def consistent_share(self, name: str) -> float:
        r"""Part des pas dont la NEES moyenne (sur les tirages) est dans l'intervalle à 95 % d'une NEES
        moyenne cohérente (:func:`~kalman_course.chi2_band`)."""
        lo, hi = chi2_band(4, self.n_runs)
        e = self.nees[name]
        return float(np.mean((e >= lo) & (e <= hi)))


def _choice_prior(prior_std: float) -> np.ndarray:
    return np.diag([prior_std**2, prior_std**2, CHOICE_VELOCITY_STD**2, CHOICE_VELOCITY_STD**2])


def _nees_runs(x_true: np.ndarray, x: np.ndarray, P: np.ndarray) -> np.ndarray:
    r"""NEES (N, T) de chaque tirage et de chaque pas ; :math:`+\infty` là où :math:`P` n'est pas définie
    positive (un nuage de particules réduit à quelques copies d'un même point)."""
    d = x - x_true
    out = np.full(d.shape[:-1], np.inf)
    eig_min = np.linalg.eigvalsh(P)[..., 0]
    ok = eig_min > 1e-12 * np.maximum(np.abs(P).max(axis=(-1, -2)), np.finfo(float).tiny)
    out[ok] = np.einsum("ni,ni->n", d[ok], np.linalg.solve(P[ok], d[ok][..., None])[..., 0])
    return out


def _loop(run_one: Callable[[np.ndarray, int], FilterResult], Y: np.ndarray):
    results = [run_one(Y[i], i) for i in range(Y.shape[0])]
    x = np.stack([r.x for r in results])
    P = np.stack([r.P for r in results])
    return x, P, np.stack([r.n_iter for r in results])


@lru_cache(maxsize=16)
def _cached(prior_std: float, n_runs: int, rng: int, n_steps: int) -> ChoiceRuns:
    gen = as_generator(rng)
    model = distant_target_model()
    P0 = _choice_prior(prior_std)
    x_true, Y = [], []
    for _ in range(n_runs):
        start = TARGET_START + np.sqrt(np.diag(P0)) * gen.standard_normal(4)
        xt = simulate_cv(start, n_steps, TARGET_DT, TARGET_ACCEL_STD, gen)
        noise = gen.standard_normal((n_steps, 2)) * np.array([TARGET_RANGE_STD, TARGET_BEARING_STD])
        x_true.append(xt)
        Y.append(range_bearing(xt) + noise)
    x_true, Y = np.stack(x_true), np.stack(Y)
    x0 = np.asarray(TARGET_START)
    seeds = gen.integers(0, 2**31, size=(2, n_runs))

    def batch(runner, **options):
        res = runner(model, Y, x0, P0, **options)
        return res.x, res.P, res.n_iter

    filters = {
        "EKF": lambda: batch(extended_kalman_filter_runs),
        "EKF itéré": lambda: batch(iterated_extended_kalman_filter_runs),
        "UKF": lambda: batch(unscented_kalman_filter_runs, **TARGET_UKF),
        "CKF": lambda: batch(cubature_kalman_filter_runs),
        "GHKF": lambda: batch(gauss_hermite_kalman_filter_runs, order=CHOICE_GH_ORDER),
        "filtre particulaire": lambda: _loop(lambda y, i: particle_filter(
            model, y, x0, P0, n_particles=CHOICE_PARTICLES, rng=int(seeds[0, i])), Y),
        "EnKF": lambda: _loop(lambda y, i: ensemble_kalman_filter(
            model, y, x0, P0, n_members=CHOICE_MEMBERS, rng=int(seeds[1, i])), Y),
    }
    err, sq, eps, iters, failed = {}, {}, {}, {}, {}
    nan = np.full(n_steps, np.nan)
    for name, run in filters.items():
        try:
            x, P, n_iter = run()
        except KalmanInputError as exc:
            failed[name] = str(exc)
            err[name], sq[name], eps[name], iters[name] = nan, nan, nan, float("nan")
            continue
        d = np.linalg.norm(x[..., :2] - x_true[..., :2], axis=-1)
        err[name] = d.mean(axis=0)
        sq[name] = (d**2).mean(axis=0)
        eps[name] = _nees_runs(x_true, x, P).mean(axis=0)
        iters[name] = float(np.mean(n_iter))
    return ChoiceRuns(t=TARGET_DT * np.arange(1, n_steps + 1), prior_std=float(prior_std), n_runs=n_runs,
                      position_error=err, squared_error=sq, nees=eps, n_iter=iters, failed=failed)


def choice_runs(prior_std: float = CHOICE_PRIOR_STD, n_runs: int = CHOICE_RUNS, rng: int = CHOICE_SEED,
                n_steps: int = TARGET_STEPS) -> ChoiceRuns:
    r"""Les sept filtres de :data:`CHOICE_FILTERS` sur ``n_runs`` tirages de la cible lointaine, incertitude
    initiale ``prior_std`` (m) sur chaque coordonnée de position (:class:`ChoiceRuns`). Même graine → mêmes
    tirages pour tous les filtres et tous les appels (résultat gardé en mémoire : le tableau, la figure et
    les curseurs du chapitre le partagent)."""
    if not isinstance(prior_std, (int, float, np.integer, np.floating)) or not prior_std > 0:
        raise KalmanInputError(f"« prior_std » doit être un écart-type strictement positif (m) ; reçu {prior_std!r}.")
    if isinstance(rng, bool) or not isinstance(rng, (int, np.integer)):
        raise KalmanInputError(f"« rng » doit être une graine entière ; reçu {rng!r}.")
    return _cached(float(prior_std), check_positive_int("n_runs", n_runs), int(rng),
                   check_positive_int("n_steps", n_steps))


def choice_sweep(prior_stds: Any = CHOICE_PRIOR_STDS, n_runs: int = CHOICE_RUNS) -> list[ChoiceRuns]:
    r""":func:`choice_runs` pour chaque incertitude initiale de ``prior_stds`` (m)."""
    return [choice_runs(float(s), n_runs) for s in np.atleast_1d(prior_stds)]


def evaluations_per_step(n: int = 4, n_iter: float = 1.0) -> dict:
    r"""Évaluations de :math:`f` et de :math:`h` par pas pour chaque filtre, en dimension ``n`` (``n_iter`` :
    itérations moyennes de l'EKF itéré, qui évalue :math:`h` et sa jacobienne à chaque itération)."""
    return {
        "EKF": (1, 1),
        "EKF itéré": (1, n_iter),
        "UKF": (UnscentedRule(**TARGET_UKF).n_points(n),) * 2,
        "CKF": (CUBATURE.n_points(n),) * 2,
        "GHKF": (GaussHermiteRule(CHOICE_GH_ORDER).n_points(n),) * 2,
        "filtre particulaire": (CHOICE_PARTICLES,) * 2,
        "EnKF": (CHOICE_MEMBERS,) * 2,
    }


def measured_costs() -> tuple[dict, str]:
    r"""Temps par pas (µs) de chaque filtre, mesuré par ``benchmarks/filter_choice.py --write``
    (:mod:`kalman_course.scenarios.filter_choice_timings`), et la description de la mesure (date, machine)."""
    from . import filter_choice_timings as m

    return dict(m.MICROSECONDS_PER_STEP), f"mesure du {m.DATE}, {m.MACHINE}, {m.SOFTWARE}"


def choice_table(runs: ChoiceRuns | None = None) -> Table:
    r"""Le tableau du chapitre : pour chaque filtre, erreur quadratique moyenne de position, NEES moyenne,
    part des pas cohérents, évaluations de :math:`f` et :math:`h` par pas et coût par pas mesuré (rapport à
    l'EKF)."""
    from ..numbers import format_spec

    runs = choice_runs() if runs is None else runs
    costs, _ = measured_costs()
    evals = evaluations_per_step(4, runs.n_iter.get("EKF itéré", 1.0))
    names, rmse, eps, share, n_eval, cost = [], [], [], [], [], []
    for name in CHOICE_FILTERS:
        names.append(name if name not in runs.failed else f"{name} (échec)")
        rmse.append(runs.rmse(name))
        eps.append(runs.mean_nees(name))
        share.append(runs.consistent_share(name))
        f_evals, h_evals = evals[name]
        n_eval.append(f"{format_spec(f_evals, 'g')} + {format_spec(h_evals, '.3g')}")
        cost.append(costs[name] / costs["EKF"])
    return Table(
        ["filtre", "erreur de position (m)", "NEES moyenne (4 attendu)", "pas cohérents",
         "évaluations de f + h par pas", "coût par pas (× EKF)"],
        [names, rmse, eps, share, n_eval, cost],
        [None, "{:.3g}", "{:.3g}", "{:.0%}", None, "{:.2g}"],
    )
