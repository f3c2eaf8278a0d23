r"""Scénario du chapitre « Filtrer en parallèle dans le temps » : une longue série à filtrer d'un coup.

Le modèle est celui des bancs d'essai : une cible à vitesse constante dans le plan (4 états,
:math:`\Delta t = 0{,}1` s, accélération blanche de variance 0,25 m²/s⁴) dont on mesure la position à 10 cm
près. :func:`parallel_agreement` filtre et lisse la même série séquentiellement et par balayage associatif
et rend les écarts ; :func:`operation_counts` compte les pas dépendants (la profondeur) et les combinaisons
(le travail) des deux méthodes ; :func:`measured_timings` lit les temps mesurés par
``benchmarks/parallel.py`` (:mod:`kalman_course.scenarios.parallel_timings`, avec la date et la machine) :
les temps varient d'une machine et d'une exécution à l'autre, le chapitre cite donc une mesure datée et
calcule à la construction ce qui est exact (écarts, comptes).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.models import LinearGaussianModel
from ..core.motion import constant_velocity
from ..core.results import freeze_fields
from ..core.simulation import as_generator, check_positive_int, simulate
from ..filters.kalman import kalman_filter
from ..filters.parallel import parallel_kalman_filter, parallel_rts_smoother, scan_passes
from ..filters.smoothers import rts_smoother
from ..likelihood import filter_log_likelihood

__all__ = [
    "PARALLEL_DT",
    "PARALLEL_SEED",
    "PARALLEL_X0",
    "PARALLEL_P0",
    "parallel_model",
    "parallel_data",
    "Agreement",
    "parallel_agreement",
    "OperationCounts",
    "operation_counts",
    "MeasuredTimings",
    "measured_timings",
]

#: Pas de temps (s).
PARALLEL_DT = 0.1
#: Graine des séries.
PARALLEL_SEED = 2021
#: A priori du filtre : loin de zéro (le cas de dynamax #423), 1 m et 1 m/s d'incertitude.
PARALLEL_X0 = np.array([100.0, -50.0, 1.0, 0.5])
PARALLEL_X0.setflags(write=False)
PARALLEL_P0 = np.eye(4)
PARALLEL_P0.setflags(write=False)


def parallel_model(dt: float = PARALLEL_DT) -> LinearGaussianModel:
    r"""Vitesse constante dans le plan : état :math:`(p_x, p_y, v_x, v_y)`, mesure de la position
    (:math:`R = 0{,}01` m²), :math:`Q = 0{,}25\,GG^T` (accélération blanche)."""
    A, Q = constant_velocity(dt, accel_std=0.5)
    return LinearGaussianModel(A, np.eye(2, 4), Q, 0.01 * np.eye(2))


def parallel_data(n_steps: int, rng: Any = PARALLEL_SEED) -> np.ndarray:
    r"""Mesures (T, 2) d'une trajectoire simulée par :func:`~kalman_course.simulate` depuis
    :data:`PARALLEL_X0` (graine ``rng``)."""
    n_steps = check_positive_int("n_steps", n_steps)
    return np.array(simulate(parallel_model(), PARALLEL_X0, n_steps, rng=as_generator(rng)).y)


@dataclass(frozen=True, eq=False)
class Agreement:
    r"""Écarts entre calcul séquentiel et parallèle sur une série de ``n_steps`` pas : ``filter_gap``
    (écart relatif maximal sur ``x``, ``P``, ``x_pred``, ``P_pred``, ``K``, ``innovation``, ``S``),
    ``smoother_gap`` (sur ``x``, ``P``, ``G``), ``loglik`` (log-vraisemblance séquentielle),
    ``loglik_gap`` (écart absolu des log-vraisemblances), ``passes`` (appels de l'opérateur)."""

    n_steps: int
    filter_gap: float
    smoother_gap: float
    loglik: float
    loglik_gap: float
    passes: int


def _gap(a: Any, b: Any, fields: tuple[str, ...]) -> float:
    out = 0.0
    for f in fields:
        x, y = np.asarray(getattr(a, f)), np.asarray(getattr(b, f))
        scale = float(np.nanmax(np.abs(y)))
        out = max(out, float(np.nanmax(np.abs(x - y))) / scale)
    return out


def parallel_agreement(n_steps: int = 2000, rng: Any = PARALLEL_SEED) -> Agreement:
    r"""Filtre et lisse :func:`parallel_data` par :func:`~kalman_course.kalman_filter` et
    :func:`~kalman_course.rts_smoother`, puis par :func:`~kalman_course.parallel_kalman_filter` et
    :func:`~kalman_course.parallel_rts_smoother` ; rend les écarts (:class:`Agreement`)."""
    model, y = parallel_model(), parallel_data(n_steps, rng)
    seq = kalman_filter(model, y, PARALLEL_X0, PARALLEL_P0)
    par = parallel_kalman_filter(model, y, PARALLEL_X0, PARALLEL_P0)
    fields = ("x", "P", "x_pred", "P_pred", "K", "innovation", "S")
    smooth_seq = rts_smoother(model, seq, PARALLEL_X0, PARALLEL_P0)
    smooth_par = parallel_rts_smoother(model, par, PARALLEL_X0, PARALLEL_P0)
    ll = filter_log_likelihood(seq)
    return Agreement(n_steps=n_steps, filter_gap=_gap(par, seq, fields),
                     smoother_gap=_gap(smooth_par, smooth_seq, ("x", "P", "G")), loglik=ll,
                     loglik_gap=abs(filter_log_likelihood(par) - ll), passes=scan_passes(n_steps))


@dataclass(frozen=True, eq=False)
class OperationCounts:
    r"""Pour chaque longueur ``T`` (L,) : ``sequential_depth`` (L,) pas dépendants du filtre séquentiel
    (:math:`T`), ``parallel_depth`` (L,) passes du balayage (:func:`~kalman_course.filters.parallel.scan_passes`),
    ``parallel_work`` (L,) combinaisons calculées en tout (environ :math:`2T`)."""

    T: np.ndarray
    sequential_depth: np.ndarray
    parallel_depth: np.ndarray
    parallel_work: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "T", "sequential_depth", "parallel_depth", "parallel_work")


def _work(T: int) -> int:
    """Combinaisons du balayage de Blelloch (la récurrence de :func:`~kalman_course.filters.parallel.associative_scan`)."""
    if T < 2:
        return 0
    return T // 2 + _work(T // 2) + (T - 1) // 2


def operation_counts(T: Any = (10, 100, 1_000, 10_000, 100_000, 1_000_000)) -> OperationCounts:
    r"""Profondeur et travail du filtre séquentiel et du balayage associatif pour chaque longueur de ``T``."""
    Ts = np.array([check_positive_int("T", int(t)) for t in np.atleast_1d(T)])
    return OperationCounts(T=Ts, sequential_depth=Ts.copy(), parallel_depth=np.array([scan_passes(int(t)) for t in Ts]),
                           parallel_work=np.array([_work(int(t)) for t in Ts]))


@dataclass(frozen=True, eq=False)
class MeasuredTimings:
    r"""Temps mesurés par ``benchmarks/parallel.py`` (meilleur de plusieurs essais, en secondes) : ``T`` (L,),
    ``sequential`` (L,) :func:`~kalman_course.kalman_filter`, ``parallel`` (L,)
    :func:`~kalman_course.parallel_kalman_filter`, ``sequential_smoother`` et ``parallel_smoother`` (L,)
    (filtre puis lisseur RTS, contre :func:`~kalman_course.parallel_rts_smoother`) ; ``date``, ``machine``,
    ``software`` : quand, où et avec quoi."""

    T: np.ndarray
    sequential: np.ndarray
    parallel: np.ndarray
    sequential_smoother: np.ndarray
    parallel_smoother: np.ndarray
    date: str
    machine: str
    software: str

    def __post_init__(self) -> None:
        freeze_fields(self, "T", "sequential", "parallel", "sequential_smoother", "parallel_smoother")

    @property
    def speedup(self) -> np.ndarray:
        """Rapport des temps du filtre (séquentiel / parallèle), (L,)."""
        return self.sequential / self.parallel

    @property
    def smoother_speedup(self) -> np.ndarray:
        """Rapport des temps du lissage (séquentiel / parallèle), (L,)."""
        return self.sequential_smoother / self.parallel_smoother


def measured_timings() -> MeasuredTimings:
    r"""La dernière mesure de ``benchmarks/parallel.py --write`` (module
    :mod:`kalman_course.scenarios.parallel_timings`)."""
    from . import parallel_timings as m

    return MeasuredTimings(T=np.array(m.T), sequential=np.array(m.SEQUENTIAL), parallel=np.array(m.PARALLEL),
                           sequential_smoother=np.array(m.SEQUENTIAL_SMOOTHER),
                           parallel_smoother=np.array(m.PARALLEL_SMOOTHER), date=m.DATE, machine=m.MACHINE,
                           software=m.SOFTWARE)
