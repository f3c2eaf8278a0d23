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
from typing import Any, Callable, NamedTuple

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
    "STUDY_SEED",
    "MAP_MEMBERS",
    "MAP_INFLATIONS",
    "LOCALIZATION_RADII",
    "LOCALIZATION_MEMBERS",
    "LOCALIZATION_INFLATION",
    "DENSITY_SPACINGS",
    "DENSITY_METHODS",
    "DENSITY_SETTINGS",
    "inflation_run",
    "inflation_map",
    "localization_run",
    "density_run",
    "density_table",
    "SampleCorrelations",
    "sample_correlations",
    "Lorenz63Picture",
    "lorenz63_picture",
    "Lorenz96Picture",
    "lorenz96_picture",
    "variational_lorenz63",
    "CostCase",
    "var3d_cost_case",
    "LAB_MEMBERS",
    "LAB_INFLATION",
    "LAB_CYCLES",
    "LAB_RADIUS",
    "LAB_SEED",
    "etkf_lab",
    "DapperRow",
    "DAPPER_TABLE",
    "CONCLUSIVE_SHARE",
    "dapper_table",
    "cost_table",
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


# --------------------------------------------------------------------------- études des chapitres (expériences courtes)

#: Graine des expériences courtes des chapitres et de leurs curseurs.
STUDY_SEED = 0
#: Carte taille × inflation de l'EnKF stochastique (chapitre « Le filtre d'ensemble en grande dimension »).
MAP_MEMBERS = (10, 15, 20, 30, 40)
MAP_INFLATIONS = (1.0, 1.02, 1.06, 1.1, 1.2)
#: Rayons de localisation du LETKF (7 membres, inflation 1,04, comme la ligne de DAPPER).
LOCALIZATION_RADII = (1.0, 2.0, 4.0, 8.0, 16.0, np.inf)
LOCALIZATION_MEMBERS, LOCALIZATION_INFLATION = 7, 1.04
#: Densité d'observation (chapitre « Méthodes variationnelles ») : une variable observée sur k, et les
#: réglages des trois méthodes comparées.
DENSITY_SPACINGS = (1, 2, 4, 8)
DENSITY_METHODS = ("letkf", "3dvar", "oi")
DENSITY_SETTINGS = {
    "letkf": ("etkf", {"n_members": 10, "inflation": 1.04, "localization": 4.0}),
    "3dvar": ("3dvar", {"background_scale": 0.02}),
    "oi": ("oi", {}),
}


@lru_cache(maxsize=None)
def inflation_run(n_members: int, inflation: float) -> TwinExperiment:
    """L'EnKF stochastique (expérience courte, :func:`short_experiment`) pour la carte taille × inflation."""
    return short_experiment("stochastic", rng=STUDY_SEED, n_members=int(n_members), inflation=float(inflation))


def inflation_map() -> np.ndarray:
    """rmse.a (len(MAP_MEMBERS), len(MAP_INFLATIONS)) de l'EnKF stochastique : taille × inflation."""
    return np.array([[inflation_run(N, lam).rmse_a for lam in MAP_INFLATIONS] for N in MAP_MEMBERS])


@lru_cache(maxsize=None)
def localization_run(radius: float) -> TwinExperiment:
    """Le LETKF à 7 membres (expérience courte) de rayon ``radius`` (``numpy.inf`` : l'ETKF global)."""
    return short_experiment("etkf", rng=STUDY_SEED, n_members=LOCALIZATION_MEMBERS,
                            inflation=LOCALIZATION_INFLATION, localization=float(radius))


@lru_cache(maxsize=None)
def density_run(spacing: int, method: str) -> TwinExperiment:
    """``method`` (``"letkf"``, ``"3dvar"`` ou ``"oi"``) avec une variable observée sur ``spacing``
    (expérience courte)."""
    name, settings = DENSITY_SETTINGS[method]
    return short_experiment(name, rng=STUDY_SEED, observed_every=int(spacing), **settings)


def density_table() -> np.ndarray:
    """rmse.a (len(DENSITY_METHODS), len(DENSITY_SPACINGS))."""
    return np.array([[density_run(k, m).rmse_a for k in DENSITY_SPACINGS] for m in DENSITY_METHODS])


class SampleCorrelations(NamedTuple):
    """Corrélations de la variable ``centre`` avec les 40 variables d'un ensemble prévu de Lorenz-96 :
    ``reference`` (grand ensemble), ``small`` (les ``n_small`` premiers membres), ``tapered`` (``small``
    multipliée par Gaspari–Cohn de rayon ``radius``), ``distance`` (distance sur l'anneau) ; ``rank`` :
    rang de la covariance du petit ensemble."""

    distance: np.ndarray
    reference: np.ndarray
    small: np.ndarray
    tapered: np.ndarray
    rank: int
    n_small: int
    n_large: int
    radius: float
    centre: int


@lru_cache(maxsize=None)
def sample_correlations(n_small: int = 10, n_large: int = 2000, radius: float = 4.0, centre: int = 20,
                        cycles: int = 4) -> SampleCorrelations:
    r"""Corrélations d'échantillon d'un ensemble prévu : ``n_large`` membres tirés autour d'un état de
    l'attracteur (écart-type 0,5), prévus ``cycles`` cycles (les corrélations deviennent celles de
    l'écoulement), puis corrélation de la variable ``centre`` avec chacune des 40 ; le petit ensemble en
    est un sous-ensemble de ``n_small`` membres. Graine :data:`STUDY_SEED`."""
    from ..filters.ensemble_analysis import gaspari_cohn

    gen = np.random.default_rng(STUDY_SEED)
    model = twin_system("lorenz96").model
    E = np.asarray(attractor_start()) + 0.5 * gen.standard_normal((n_large, 40))
    for _ in range(cycles):
        E = model.f(E, None)

    def row(X):
        return np.corrcoef(X.T)[centre]

    small = row(E[:n_small])
    distance = ring_distances(40)[centre]
    rank = int(np.linalg.matrix_rank(np.cov(E[:n_small].T)))
    return SampleCorrelations(distance, row(E), small, small * gaspari_cohn(distance, radius), rank,
                              n_small, n_large, radius, centre)


class Lorenz63Picture(NamedTuple):
    """L'attracteur de Lorenz-63 et une assimilation : ``path`` (M, 3) la vérité pas à pas (pas RK4 de 0,01),
    ``experiment`` l'expérience jumelle (ETKF), ``free`` (K, 3) une prévision sans assimilation partie
    à 10⁻³ près de la même vérité."""

    path: np.ndarray
    experiment: TwinExperiment
    free: np.ndarray


@lru_cache(maxsize=1)
def lorenz63_picture(n_cycles: int = 120, n_members: int = 10, inflation: float = 1.02) -> Lorenz63Picture:
    """ETKF à 10 membres sur Lorenz-63 (expérience courte : ``n_cycles`` cycles, 64 de mise en route), la
    vérité entre deux cycles (25 pas RK4 de 0,01 chacun), et une prévision libre partie de la vérité
    initiale décalée de 10⁻³."""
    exp = twin_experiment("lorenz63", "etkf", rng=STUDY_SEED, n_members=n_members, inflation=inflation,
                          n_cycles=n_cycles, burn_in=64)
    fine = lorenz63(n_substeps=1)
    path = [exp.x_true[0]]
    for _ in range((n_cycles - 1) * 25):
        path.append(fine.f(path[-1], None))
    coarse = twin_system("lorenz63").model
    free = [exp.x_true[0] + np.array([1e-3, 0.0, 0.0])]
    for _ in range(n_cycles - 1):
        free.append(coarse.f(free[-1], None))
    return Lorenz63Picture(np.array(path), exp, np.array(free))


class Lorenz96Picture(NamedTuple):
    """Lorenz-96 en diagramme de Hovmöller : ``experiment`` (ETKF, expérience courte), ``free`` (K, 40) une
    prévision libre partie de la vérité initiale décalée de 10⁻³ sur une variable."""

    experiment: TwinExperiment
    free: np.ndarray


@lru_cache(maxsize=1)
def lorenz96_picture() -> Lorenz96Picture:
    """ETKF à 20 membres, inflation 1,04 (la ligne de DAPPER), expérience courte (:func:`short_experiment`),
    et une prévision libre partie de la vérité du premier cycle décalée de 10⁻³ sur la variable 0."""
    exp = short_experiment("etkf", rng=STUDY_SEED, n_members=20, inflation=1.04)
    model = twin_system("lorenz96").model
    free = [exp.x_true[0] + 1e-3 * np.eye(40)[0]]
    for _ in range(exp.x_true.shape[0] - 1):
        free.append(model.f(free[-1], None))
    return Lorenz96Picture(exp, np.array(free))


@lru_cache(maxsize=1)
def variational_lorenz63() -> dict:
    """Les deux lignes de Lorenz-63 du tableau (3D-Var, :math:`B = 0{,}1\\,\\Sigma`, et interpolation
    optimale), 1000 cycles, graine :data:`STUDY_SEED` : nom → :class:`TwinExperiment`."""
    return {"3dvar": twin_experiment("lorenz63", "3dvar", rng=STUDY_SEED, background_scale=0.1),
            "oi": twin_experiment("lorenz63", "oi", rng=STUDY_SEED)}


class CostCase(NamedTuple):
    r"""Le 3D-Var en deux dimensions : ébauche ``x_b``, covariance ``B`` (corrélation 0,8 entre les deux
    composantes), observation ``y`` (1,) de la première composante (``C`` (1, 2), ``R`` (1, 1)), analyse
    ``x_a`` (:func:`~kalman_course.var3d_update`) et minimiseur ``x_numeric`` de :math:`J` trouvé par
    ``scipy.optimize.minimize`` (BFGS, gradient donné)."""

    x_b: np.ndarray
    B: np.ndarray
    C: np.ndarray
    R: np.ndarray
    y: np.ndarray
    x_a: np.ndarray
    x_numeric: np.ndarray


@lru_cache(maxsize=1)
def var3d_cost_case() -> CostCase:
    """Le cas de la figure « 3dvar-cout » du chapitre « Méthodes variationnelles »."""
    import scipy.optimize

    from ..filters.variational import var3d_update

    x_b = np.array([0.0, 0.0])
    B = np.array([[1.0, 0.8], [0.8, 1.0]])
    C, R, y = np.array([[1.0, 0.0]]), np.array([[0.25]]), np.array([2.0])
    Bi, Ri = np.linalg.inv(B), np.linalg.inv(R)

    def cost(x):
        return 0.5 * (x - x_b) @ Bi @ (x - x_b) + 0.5 * (y - C @ x) @ Ri @ (y - C @ x)

    def grad(x):
        return Bi @ (x - x_b) - C.T @ Ri @ (y - C @ x)

    best = scipy.optimize.minimize(cost, x_b, jac=grad, method="BFGS", options={"gtol": 1e-12})
    return CostCase(x_b, B, C, R, y, var3d_update(x_b, y, C, B, R), best.x)


# --------------------------------------------------------------------------- TP : l'ETKF de l'étudiant

#: Le TP de l'ETKF : membres, inflation, cycles, rayon du taper, graine.
LAB_MEMBERS, LAB_INFLATION, LAB_CYCLES, LAB_RADIUS, LAB_SEED = 20, 1.04, 100, 4.0, 5


def etkf_lab(etkf_update: Callable | None = None, gaspari_cohn: Callable | None = None):
    r"""TP « L'ETKF sur Lorenz-96 » : un cycle d'assimilation écrit en boucle (prévision RK4 de l'ensemble,
    analyse ``etkf_update(E, y, H, R, inflation)`` de l'étudiant, :math:`H = R = I`, 20 membres, inflation
    1,04, 100 cycles, départ sur l'attracteur, ensemble initial :math:`\mathcal N(x_0, I)`), contre la même
    boucle avec :func:`~kalman_course.etkf_update` ; et le taper ``gaspari_cohn(d, 4)`` de l'étudiant contre
    :func:`~kalman_course.gaspari_cohn`. Sans argument, les solutions du correcteur. Renvoie un
    :class:`~kalman_course.scenarios.labs.LabRun` : ``data`` (``distance``, ``reference_taper``,
    ``reference_rmse``), ``reference`` et ``student`` (``rmse``, ``taper``), ``message``."""
    from .. import practice
    from ..filters.ensemble_analysis import etkf_update as package_update
    from ..filters.ensemble_analysis import gaspari_cohn as package_taper
    from .labs import LabRun

    update = practice.exercise("etkf-update").solution if etkf_update is None else etkf_update
    taper = practice.exercise("gaspari-cohn").solution if gaspari_cohn is None else gaspari_cohn
    gen = np.random.default_rng(LAB_SEED)
    model = twin_system("lorenz96").model
    start = np.asarray(attractor_start())
    truth = simulate(model, start, LAB_CYCLES, rng=gen)
    E0 = start + gen.standard_normal((LAB_MEMBERS, 40))
    I = np.eye(40)
    distance = np.linspace(0.0, 16.0, 161)

    def cycle(analysis):
        E, rmse = E0.copy(), []
        for k in range(LAB_CYCLES):
            E = model.f(E, None)
            E = np.asarray(analysis(E.copy(), truth.y[k].copy(), I.copy(), I.copy(), LAB_INFLATION), dtype=float)
            if E.shape != (LAB_MEMBERS, 40):
                raise ValueError(f"etkf_update doit renvoyer l'ensemble analysé ({LAB_MEMBERS}, 40) ; "
                                 f"elle renvoie la forme {E.shape}")
            rmse.append(np.sqrt(np.mean((E.mean(axis=0) - truth.x[k]) ** 2)))
        return np.array(rmse)

    reference = {"rmse": cycle(lambda *a: package_update(*a[:4], inflation=a[4])),
                 "taper": package_taper(distance, LAB_RADIUS)}
    outcome = practice.attempt(lambda: {"rmse": cycle(update),
                                        "taper": np.asarray(taper(distance.copy(), LAB_RADIUS), dtype=float)})
    data = {"distance": distance, "reference_taper": reference["taper"], "reference_rmse": reference["rmse"]}
    return LabRun(data, reference, outcome.value, outcome.message)


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


# --------------------------------------------------------------------------- tableaux des chapitres


def dapper_table(systems: tuple[str, ...] = SYSTEMS, methods: tuple[str, ...] = METHODS):
    """Le tableau de DAPPER reproduit (mesure rangée par ``benchmarks/assimilation_table.py --write``, 1000
    cycles, plusieurs graines), restreint aux ``systems`` et ``methods`` : méthode de DAPPER, système, rmse.a
    publié, moyenne ± écart-type entre graines, verdict (:class:`~kalman_course.Table`)."""
    from ..numbers import format_number
    from ..tables import Table
    from . import assimilation_table as stored

    names = {"lorenz96": "Lorenz-96", "lorenz63": "Lorenz-63"}
    rows = [(row, m, s) for row, m, s in zip(DAPPER_TABLE, stored.MEAN, stored.STD)
            if row.system in systems and row.method in methods]
    return Table(
        ["méthode (DAPPER)", "réglages", "système", "rmse.a publié", f"rmse.a reproduit ({stored.N_SEEDS} graines)",
         "verdict"],
        [[r.dapper.split("(")[0] + ("('" + r.dapper.split("'")[1] + "')" if "'" in r.dapper else "")
          for r, _, _ in rows],
         [_settings_text(r) for r, _, _ in rows], [names[r.system] for r, _, _ in rows],
         [r.published for r, _, _ in rows],
         [f"{format_number(m, decimals=3)} ± {format_number(s, decimals=3)}" for _, m, s in rows],
         [r.verdict for r, _, _ in rows]],
        [None, None, None, "{:.2f}", None, None],
    )


def _settings_text(row: DapperRow) -> str:
    """Les réglages d'une ligne du tableau, écrits en français : « N = 40, λ = 1,06 », « B = 0,1 Σ »…"""
    from ..numbers import format_number

    parts = []
    if "n_members" in row.settings:
        parts.append(f"N = {row.settings['n_members']}")
    if "inflation" in row.settings:
        parts.append(f"λ = {format_number(row.settings['inflation'], significant=4, trim=True)}")
    if "localization" in row.settings:
        parts.append(f"rayon {format_number(row.settings['localization'], significant=3, trim=True)}")
    if "background_scale" in row.settings:
        parts.append(f"B = {format_number(row.settings['background_scale'], significant=3, trim=True)} Σ")
    if "rot=True" in row.dapper:
        parts.append("rotation aléatoire (DAPPER seul)")
    return ", ".join(parts) or "B = Σ, ébauche climatologique"


def cost_table():
    """Le coût par cycle des filtres d'ensemble sur Lorenz-96 (mesure rangée par
    ``benchmarks/assimilation_costs.py --write``) : paquet, par membre, boucle numpy, rapport."""
    from ..tables import Table
    from . import assimilation_costs as stored

    keys = list(stored.CYCLE)
    members = [int(k.rsplit("N = ", 1)[1]) for k in keys]
    package = [stored.CYCLE[k][0] for k in keys]
    loop = [stored.CYCLE[k][1] for k in keys]
    return Table(
        ["méthode, taille de l'état n, membres N", "paquet (µs par cycle)", "par membre (µs)",
         "boucle numpy (µs par cycle)", "boucle / paquet"],
        [keys, package, [p / N for p, N in zip(package, members)], loop, [b / p for b, p in zip(loop, package)]],
        [None, "{:.0f}", "{:.1f}", "{:.0f}", "{:.1f}"],
    )

