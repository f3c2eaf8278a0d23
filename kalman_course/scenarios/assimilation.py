r"""Expériences jumelles de l'assimilation de données, aux réglages publiés par DAPPER (nansencenter),
écrites une fois : le chapitre, ses figures, ses curseurs, ses tests et les bancs d'essai les appellent.

Une **expérience jumelle** (*twin experiment*) simule une vérité avec le modèle lui-même, l'observe avec
un bruit connu, puis assimile ces observations ; l'erreur se mesure contre la vérité, connue ici :
:math:`\mathrm{rmse}_k = \sqrt{\tfrac1n\sum_i (x_{k,i} - x^{\mathrm{vrai}}_{k,i})^2}`, et
``rmse_a`` (le « rmse.a » de DAPPER) est sa moyenne après la période de mise en route (``burn_in``).

* ``"lorenz96"`` (``mods/Lorenz96/sakov2008.py`` : Sakov & Oke 2008) : :math:`n = 40`, :math:`F = 8`,
  un pas RK4 de 0,05 par cycle, toutes les variables observées, :math:`R = I`, modèle parfait,
  :math:`x_0 = (1, 0, \dots, 0)`, :math:`P_0 = 0{,}001\,I` ; 400 cycles de mise en route (20 unités de temps).
* ``"lorenz63"`` (``mods/Lorenz63/sakov2012.py`` : Sakov et al. 2012) : 25 pas RK4 de 0,01 par cycle,
  :math:`R = 2I`, :math:`x_0 = (1{,}509, -1{,}531, 25{,}46)`, :math:`P_0 = 2I` ; 64 cycles de mise en
  route (16 unités de temps).

Tous les tirages viennent de ``rng`` : la vérité initiale :math:`\sim\mathcal N(x_0, P_0)`, les bruits
d'observation, puis ceux du filtre. Les méthodes : ``"stochastic"``, ``"etkf"``, ``"denkf"``
(:func:`~kalman_course.ensemble_kalman_filter`, ensemble parti de :math:`\mathcal N(x_0, P_0)` ;
``localization`` : Lorenz-96 seulement, distances sur l'anneau :math:`\min(|i - j|, 40 - |i - j|)`),
``"3dvar"`` (:func:`~kalman_course.three_dimensional_var` depuis :math:`x_0`, :math:`B` =
``background_scale`` · :math:`\Sigma`) et ``"oi"`` (:func:`~kalman_course.optimal_interpolation`,
ébauche la moyenne de la vérité, :math:`B = \Sigma`) ; :math:`\Sigma` est la covariance d'échantillon de
la vérité (la « climatologie », calculée sur la vérité comme dans DAPPER).

:data:`DAPPER_TABLE` : les rmse.a publiés à reproduire (commentaires des deux fichiers de DAPPER).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any, NamedTuple

import numpy as np

from ..core.lorenz import lorenz63, lorenz96
from ..core.models import NonlinearModel
from ..core.results import freeze_fields
from ..core.simulation import as_generator, check_positive_int, simulate
from ..core.validation import KalmanInputError
from ..filters.ensemble import METHODS as ENSEMBLE_METHODS
from ..filters.ensemble import ensemble_kalman_filter
from ..filters.variational import optimal_interpolation, three_dimensional_var

__all__ = [
    "SYSTEMS",
    "METHODS",
    "TwinSystem",
    "twin_system",
    "ring_distances",
    "attractor_start",
    "short_experiment",
    "SHORT_CYCLES",
    "SHORT_BURN_IN",
    "TwinExperiment",
    "twin_experiment",
    "DapperRow",
    "DAPPER_TABLE",
    "CONCLUSIVE_SHARE",
    "tolerance",
    "verdict",
]


class TwinSystem(NamedTuple):
    """Un système des expériences jumelles : modèle, loi initiale, mise en route par défaut."""

    model: Any
    x0: np.ndarray
    P0: np.ndarray
    burn_in: int


#: Systèmes disponibles.
SYSTEMS = ("lorenz96", "lorenz63")
#: Méthodes d'assimilation.
METHODS = ENSEMBLE_METHODS + ("3dvar", "oi")


def twin_system(system: str) -> TwinSystem:
    """Le modèle et les réglages de DAPPER du système ``"lorenz96"`` ou ``"lorenz63"``."""
    if system == "lorenz96":
        x0 = np.zeros(40)
        x0[0] = 1.0
        return TwinSystem(lorenz96(40, 8.0, 0.05, n_substeps=1, R=1.0), x0, 0.001 * np.eye(40), 400)
    if system == "lorenz63":
        return TwinSystem(lorenz63(10.0, 28.0, 8.0 / 3.0, 0.01, n_substeps=25, R=2.0),
                          np.array([1.509, -1.531, 25.46]), 2.0 * np.eye(3), 64)
    raise KalmanInputError(f"« system » doit valoir {', '.join(map(repr, SYSTEMS))} ; reçu {system!r}.")


def ring_distances(n: int = 40) -> np.ndarray:
    r"""Distances sur l'anneau de Lorenz-96 entre l'observation :math:`i` (de la variable :math:`i`) et la
    variable :math:`j` : :math:`\min(|i - j|, n - |i - j|)`, (n, n)."""
    gap = np.abs(np.subtract.outer(np.arange(n), np.arange(n)))
    return np.minimum(gap, n - gap).astype(float)


@dataclass(frozen=True, eq=False)
class TwinExperiment:
    r"""Une expérience jumelle : ``x_true``, ``y``, ``x`` (analyse, moyenne de l'ensemble) (K, n) ;
    ``rmse`` (K,) ; ``burn_in`` ; ``rmse_a`` = moyenne de ``rmse[burn_in:]`` (le rmse.a de DAPPER)."""

    x_true: np.ndarray
    y: np.ndarray
    x: np.ndarray
    rmse: np.ndarray
    burn_in: int
    rmse_a: float

    def __post_init__(self) -> None:
        freeze_fields(self, "x_true", "y", "x", "rmse")


def _check_scale(name: str, value: Any, minimum_text: str = "> 0") -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not np.isfinite(value) or value <= 0:
        raise KalmanInputError(f"« {name} » doit être un nombre réel {minimum_text} ; reçu {value!r}.")
    return float(value)


def twin_experiment(system: str, method: str, *, rng: Any, n_members: int | None = None, inflation: float = 1.0,
                    localization: Any = None, background_scale: float = 1.0, n_cycles: int = 1000,
                    burn_in: int | None = None) -> TwinExperiment:
    r"""Une expérience jumelle de DAPPER (voir le module) : vérité, observations, assimilation par
    ``method``, erreur.

    Paramètres
    ----------
    system : ``"lorenz96"`` ou ``"lorenz63"``.
    method : ``"stochastic"``, ``"etkf"``, ``"denkf"`` (filtres d'ensemble, ``n_members`` exigé),
        ``"3dvar"`` ou ``"oi"``.
    rng : graine entière ou ``numpy.random.Generator`` (obligatoire).
    n_members : taille :math:`N` de l'ensemble (méthodes d'ensemble seulement).
    inflation : :math:`\lambda \ge 1` (méthodes d'ensemble seulement).
    localization : rayon du LETKF (``"etkf"`` sur ``"lorenz96"`` seulement).
    background_scale : facteur de :math:`B = \text{background\_scale}\cdot\Sigma` du 3D-Var (le ``xB`` de DAPPER).
    n_cycles : nombre :math:`K` de cycles d'assimilation (1000 dans DAPPER).
    burn_in : cycles de mise en route exclus de ``rmse_a`` (défaut : 400 pour Lorenz-96, 64 pour
        Lorenz-63), :math:`< K`.

    Renvoie un :class:`TwinExperiment`.
    """
    twin = twin_system(system)
    return _experiment(system, twin, twin.x0, method, rng=rng, n_members=n_members, inflation=inflation,
                       localization=localization, background_scale=background_scale, n_cycles=n_cycles,
                       burn_in=twin.burn_in if burn_in is None else burn_in, default_burn_in=burn_in is None)


def _experiment(system: str, twin: TwinSystem, start_mean: np.ndarray, method: str, *, rng: Any,
                n_members: int | None, inflation: float, localization: Any, background_scale: float,
                n_cycles: int, burn_in: Any, default_burn_in: bool = False, observed_every: int = 1) -> TwinExperiment:
    """L'expérience jumelle : vérité partie de :math:`\\mathcal N(\\text{start\\_mean}, P_0)`, filtres partis de
    la même loi (3D-Var de sa moyenne) ; ``observed_every`` : une variable observée sur ``observed_every``."""
    if not isinstance(method, str) or method not in METHODS:
        raise KalmanInputError(f"« method » doit valoir {', '.join(map(repr, METHODS))} ; reçu {method!r}.")
    K = check_positive_int("n_cycles", n_cycles)
    if isinstance(burn_in, bool) or not isinstance(burn_in, (int, np.integer)) or not 0 <= burn_in < K:
        raise KalmanInputError(
            f"« burn_in » doit être un entier entre 0 et n_cycles − 1 = {K - 1} (cycles exclus de rmse_a) ; "
            f"reçu {burn_in!r}" + (" (défaut du système)." if default_burn_in else ".")
        )
    ensemble = method in ENSEMBLE_METHODS
    if ensemble and n_members is None:
        raise KalmanInputError(f"La méthode d'ensemble {method!r} exige « n_members » (taille de l'ensemble, ≥ 2).")
    if not ensemble:
        for name, value, default in (("n_members", n_members, None), ("inflation", inflation, 1.0),
                                     ("localization", localization, None)):
            if value is not default and value != default:
                raise KalmanInputError(
                    f"« {name} » ne s'applique qu'aux méthodes d'ensemble ({', '.join(map(repr, ENSEMBLE_METHODS))}) ; "
                    f"reçu method={method!r}."
                )
    scale = _check_scale("background_scale", background_scale)
    if method != "3dvar" and scale != 1.0:
        raise KalmanInputError(f"« background_scale » ne s'applique qu'à method='3dvar' ; reçu method={method!r}.")
    if localization is not None and system != "lorenz96":
        raise KalmanInputError("« localization » ne s'applique qu'au système 'lorenz96' (distances sur l'anneau).")
    gen = as_generator(rng)
    model, n = twin.model, twin.model.n_state
    observed = np.arange(0, n, observed_every)
    if observed_every != 1:
        model = _partially_observed(model, observed)
    start = start_mean + np.sqrt(np.diag(twin.P0)) * gen.standard_normal(n)  # P0 diagonale
    truth = simulate(model, start, K, rng=gen)
    x_true, y = truth.x, truth.y
    if ensemble:
        distances = ring_distances(n)[observed] if localization is not None else None
        result = ensemble_kalman_filter(model, y, start_mean, twin.P0, n_members=n_members, rng=gen, method=method,
                                        inflation=inflation, localization=localization, distances=distances)
    else:
        climate = np.cov(x_true.T, ddof=1)
        if method == "3dvar":
            result = three_dimensional_var(model, y, start_mean, scale * climate)
        else:
            result = optimal_interpolation(model, y, x_true.mean(axis=0), climate)
    rmse = np.sqrt(np.mean((result.x - x_true) ** 2, axis=1))
    return TwinExperiment(x_true=x_true, y=y, x=result.x, rmse=rmse, burn_in=int(burn_in),
                          rmse_a=float(rmse[burn_in:].mean()))


def _partially_observed(model: NonlinearModel, observed: np.ndarray) -> NonlinearModel:
    """Le même modèle, une variable observée sur quelques-unes : :math:`h(x) = x_{\\text{observed}}`,
    :math:`R = I` (m, m)."""
    m = observed.size
    H = np.eye(model.n_state)[observed]
    return NonlinearModel(model.f, lambda x: np.asarray(x, dtype=float)[..., observed], model.Q,
                          model.R[np.ix_(observed, observed)], h_jacobian=H, vectorized=True)


#: Expériences courtes des curseurs (Lorenz-96) : cycles, dont mise en route.
SHORT_CYCLES, SHORT_BURN_IN = 300, 100


@lru_cache(maxsize=None)
def attractor_start(system: str = "lorenz96") -> np.ndarray:
    r"""Un état sur l'attracteur : :math:`x_0` du système intégré pendant sa mise en route par défaut (400
    cycles pour Lorenz-96, 64 pour Lorenz-63), sans bruit ; lecture seule."""
    twin = twin_system(system)
    x = twin.x0
    for _ in range(twin.burn_in):
        x = twin.model.transition(x)
    x.setflags(write=False)
    return x


def short_experiment(method: str, *, rng: Any, n_members: int | None = None, inflation: float = 1.0,
                     localization: Any = None, background_scale: float = 1.0, observed_every: int = 1,
                     n_cycles: int = SHORT_CYCLES, burn_in: int = SHORT_BURN_IN) -> TwinExperiment:
    r"""L'expérience jumelle Lorenz-96 de :func:`twin_experiment`, **raccourcie** pour les figures à curseurs :
    vérité et filtres partent d'un état déjà sur l'attracteur (:func:`attractor_start` : les 400 cycles de
    la transition depuis :math:`(1, 0, \dots, 0)` sont sautés), ``n_cycles`` = 300 cycles dont 100 de mise
    en route (au lieu de 1000 dont 400) ; ``observed_every`` = :math:`k` : une variable observée sur
    :math:`k` (:math:`h(x) = (x_0, x_k, x_{2k}, \dots)`, :math:`R = I`). Mêmes paramètres que
    :func:`twin_experiment` sinon. Un rmse.a sur 200 cycles varie d'environ 0,01 d'une graine à l'autre,
    contre 0,005 sur 600."""
    if isinstance(observed_every, bool) or not isinstance(observed_every, (int, np.integer)) \
            or not 1 <= observed_every <= 40 or 40 % observed_every:
        raise KalmanInputError(f"« observed_every » doit être un diviseur de 40 (1, 2, 4, 5, 8…) ; reçu {observed_every!r}.")
    return _experiment("lorenz96", twin_system("lorenz96"), np.asarray(attractor_start("lorenz96")), method,
                       rng=rng, n_members=n_members, inflation=inflation, localization=localization,
                       background_scale=background_scale, n_cycles=n_cycles, burn_in=burn_in,
                       observed_every=int(observed_every))


class DapperRow(NamedTuple):
    """Une ligne du tableau publié : système, méthode et réglages (arguments de :func:`twin_experiment`),
    nom de la méthode dans DAPPER, rmse.a publié, et ``verdict`` annoncé par les chapitres (voir
    :func:`verdict`) — ce que les tests vérifient sur la mesure rangée."""

    system: str
    method: str
    settings: dict
    dapper: str
    published: float
    verdict: str = "reproduit"


#: Les rmse.a publiés par DAPPER (``mods/Lorenz96/sakov2008.py``, ``mods/Lorenz63/sakov2012.py``, 1000 cycles).
#: Les sept premières lignes sont celles de l'issue 33 ; les suivantes complètent le tableau des chapitres.
#: ``rot=True`` (rotation aléatoire des anomalies après chaque analyse, propre à DAPPER) n'existe pas dans le
#: paquet.
DAPPER_TABLE = (
    DapperRow("lorenz96", "stochastic", {"n_members": 40, "inflation": 1.06}, "EnKF('PertObs', N=40, infl=1.06)", 0.22),
    DapperRow("lorenz96", "denkf", {"n_members": 40, "inflation": 1.01}, "EnKF('DEnKF', N=40, infl=1.01)", 0.18),
    DapperRow("lorenz96", "etkf", {"n_members": 24, "inflation": 1.013}, "EnKF('Sqrt', N=24, infl=1.013, rot=True)", 0.18),
    DapperRow("lorenz96", "etkf", {"n_members": 20, "inflation": 1.04}, "EnKF('Sqrt', N=20, infl=1.04, rot=True)", 0.20),
    DapperRow("lorenz96", "etkf", {"n_members": 7, "inflation": 1.04, "localization": 4.0},
              "LETKF(N=7, infl=1.04, loc_rad=4, rot=True)", 0.22),
    DapperRow("lorenz63", "3dvar", {"background_scale": 0.1}, "Var3D(xB=0.1)", 1.04),
    DapperRow("lorenz63", "oi", {}, "OptInterp()", 1.25),
    DapperRow("lorenz96", "stochastic", {"n_members": 28, "inflation": 1.08}, "EnKF('PertObs', N=28, infl=1.08)", 0.24),
    DapperRow("lorenz96", "3dvar", {"background_scale": 0.02}, "Var3D(xB=0.02)", 0.41),
    DapperRow("lorenz96", "oi", {}, "OptInterp()", 0.95),
    DapperRow("lorenz63", "etkf", {"n_members": 10, "inflation": 1.02}, "EnKF('Sqrt', N=10, infl=1.02, rot=True)", 0.60,
              verdict="non concluant"),
)

#: Au-delà de cette part du chiffre publié, la tolérance ne départage plus rien : « non concluant ».
CONCLUSIVE_SHARE = 0.2


def tolerance(std: float, n_seeds: int) -> float:
    r"""Tolérance d'une moyenne de ``n_seeds`` graines d'écart-type ``std`` face au chiffre publié, lui-même
    **un** tirage arrondi à 0,01 : :math:`0{,}005 + 3\sigma\sqrt{1 + 1/k}` (deux tirages indépendants, trois
    écarts-types)."""
    return 0.005 + 3.0 * std * np.sqrt(1.0 + 1.0 / n_seeds)


def verdict(published: float, mean: float, std: float, n_seeds: int) -> str:
    """« reproduit » (écart dans la tolérance, tolérance ≤ 20 % du chiffre publié), « non concluant » (dans
    la tolérance, mais la dispersion entre graines la rend plus large que 20 %) ou « non reproduit »."""
    tol = tolerance(std, n_seeds)
    if abs(mean - published) > tol:
        return "non reproduit"
    return "reproduit" if tol <= CONCLUSIVE_SHARE * published else "non concluant"
