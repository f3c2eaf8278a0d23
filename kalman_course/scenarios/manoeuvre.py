r"""Cibles qui manœuvrent : les expériences du chapitre « Cibles qui manœuvrent : filtres adaptatifs et
IMM », écrites une fois.

**En simulation** (la vérité est connue) : une cible à 50 m/s vole droit, vire à gauche (0,12 rad/s de 40 à
60 s), revole droit, vire à droite (−0,08 rad/s de 90 à 115 s), suivie par un radar qui donne sa position
toutes les secondes à 10 m près (virage coordonné exact, :func:`~kalman_course.core.motion.turn_transition`).
Cinq filtres à vitesse presque constante la suivent :

* ``calme`` — densité d'accélération :math:`q = 0{,}05` m²/s³, réglée pour la ligne droite ;
* ``agité`` — :math:`q = 20` m²/s³, réglée pour les virages ;
* ``oubli`` — le calme avec une mémoire évanescente :math:`\alpha = 1{,}2` ;
* ``adaptatif`` — le calme avec :math:`Q` ajustée aux innovations (:func:`~kalman_course.filters.adaptive.adaptive_kalman_filter`) ;
* ``IMM`` — les régimes calme et agité, probabilité de changer de régime 0,05 par pas.

**Sur l'hélicoptère SAMU 31** (la vérité est inconnue) : l'IMM à deux régimes sur les deux capteurs de
:mod:`~kalman_course.scenarios.helicopter`, et la probabilité du régime agité comparée à la vitesse de
virage mesurée.

**Vitesse constante / virage coordonné** : l'IMM dont le second régime est le virage coordonné
(:func:`~kalman_course.core.motion.coordinated_turn`, non linéaire en :math:`\omega` : un EKF dans l'IMM)
et le premier la ligne droite sur le même état (:func:`~kalman_course.core.motion.straight_flight`), contre
l'IMM calme/agité, sur la cible simulée (:func:`turn_mode_study`) et sur l'hélicoptère
(:func:`helicopter_turn_imm`, pas variable lu dans la commande :math:`u_k = [\Delta t_k]`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..core.models import LinearGaussianModel, NonlinearModel
from ..core.motion import constant_velocity, coordinated_turn, straight_flight
from ..core.results import FilterResult, freeze_fields
from ..diagnostics.consistency import nees
from ..filters.adaptive import adaptive_kalman_filter
from ..filters.imm import IMMResult, imm_filter
from ..filters.kalman import kalman_filter
from ._motion import simulate_turning
from .helicopter import helicopter_model, helicopter_track, prediction_rms

__all__ = [
    "SPEED", "DT", "N_STEPS", "TURNS", "POSITION_STD", "Q_QUIET", "Q_MANOEUVRE", "FADING", "SWITCH", "WINDOW",
    "FILTERS", "turn_rate_profile", "simulate_target", "cv_model", "imm_transition", "run_filters",
    "ManoeuvreStudy", "manoeuvre_study", "HelicopterIMM", "helicopter_imm", "measured_turn_rate",
    "TURN_ACCEL_PSD", "TURN_RATE_PSD", "TURN_RATE_STD0", "HELI_TURN_ACCEL_PSD", "N_RUNS_TURN", "IMM_PAIR",
    "turn_state_prior", "cv_ct_modes", "run_cv_ct", "TurnModeStudy", "turn_mode_study", "HelicopterTurnIMM",
    "helicopter_turn_imm", "helicopter_cv_ct_filter", "STRAIGHT_RATE",
]

#: Vitesse (m/s), pas (s), nombre de pas de la cible simulée.
SPEED, DT, N_STEPS = 50.0, 1.0, 150
#: Virages : (début, fin, vitesse de rotation en rad/s).
TURNS = ((40.0, 60.0, 0.12), (90.0, 115.0, -0.08))
#: Écart-type du radar (m).
POSITION_STD = 10.0
#: Densités d'accélération (m²/s³) des régimes calme et agité.
Q_QUIET, Q_MANOEUVRE = 0.05, 20.0
#: Facteur de mémoire évanescente, probabilité de changement de régime de l'IMM, fenêtre du filtre adaptatif.
FADING, SWITCH, WINDOW = 1.2, 0.05, 5
#: Les filtres comparés, dans l'ordre des figures.
FILTERS = ("calme", "agité", "oubli", "adaptatif", "IMM")
#: Nombre de trajectoires de la comparaison de Monte-Carlo et graine.
N_RUNS, SEED = 50, 2021


def turn_rate_profile(t: np.ndarray) -> np.ndarray:
    """Vitesse de rotation vraie (rad/s) aux instants ``t`` (s)."""
    w = np.zeros_like(np.asarray(t, dtype=float))
    for start, end, rate in TURNS:
        w[(t >= start) & (t < end)] = rate
    return w


def simulate_target(rng) -> tuple[np.ndarray, np.ndarray]:
    r"""Une trajectoire vraie :math:`[e, n, v_e, v_n]` (T, 4) et ses relevés radar (T, 2), tirés avec ``rng``
    (virage coordonné exact, pas de bruit d'état : la manœuvre est la seule surprise ;
    :func:`~kalman_course.scenarios._motion.simulate_turning`)."""
    gen = np.random.default_rng(rng) if not isinstance(rng, np.random.Generator) else rng
    t = DT * np.arange(1, N_STEPS + 1)
    truth, y = simulate_turning(turn_rate_profile(t - DT), [0.0, 0.0, SPEED, 0.0], DT, POSITION_STD, gen)
    return truth[:, :4], y


def cv_model(q: float) -> LinearGaussianModel:
    """Le modèle à vitesse presque constante de densité ``q`` (m²/s³), relevés de position à 10 m près."""
    A, Q = constant_velocity(DT, q, dim=2)
    return LinearGaussianModel(A, np.eye(4)[:2], Q, POSITION_STD**2 * np.eye(2))


def imm_transition(switch: float) -> np.ndarray:
    """Matrice de transition de l'IMM à deux régimes : quitter son régime avec la probabilité ``switch``."""
    return np.array([[1.0 - switch, switch], [switch, 1.0 - switch]])


X0 = np.array([0.0, 0.0, SPEED, 0.0])
P0 = np.diag([POSITION_STD**2] * 2 + [25.0] * 2)


def run_filters(y: np.ndarray, *, q_quiet: float = Q_QUIET, q_manoeuvre: float = Q_MANOEUVRE,
                fading: float = FADING, switch: float = SWITCH) -> dict[str, FilterResult]:
    """Les cinq filtres de :data:`FILTERS` sur les relevés ``y`` (T, 2)."""
    quiet = cv_model(q_quiet)
    return {
        "calme": kalman_filter(quiet, y, X0, P0),
        "agité": kalman_filter(cv_model(q_manoeuvre), y, X0, P0),
        "oubli": kalman_filter(quiet, y, X0, P0, fading=fading),
        "adaptatif": adaptive_kalman_filter(quiet, y, X0, P0, window=WINDOW),
        "IMM": imm_filter([quiet, cv_model(q_manoeuvre)], y, X0, P0, transition=imm_transition(switch),
                          mu0=[1.0 - switch, switch]),
    }


@dataclass(frozen=True, eq=False)
class ManoeuvreStudy:
    r"""La comparaison de Monte-Carlo (:data:`N_RUNS` trajectoires, graine :data:`SEED`).

    ``t`` (T,) s ; ``turning`` (T,) booléen : pas pendant un virage ; ``rmse`` (F, T) : erreur quadratique
    moyenne de position de chaque filtre à chaque pas (m) ; ``nees`` (F, T) : NEES moyen (4 états) ;
    ``rmse_straight``, ``rmse_turn`` (F,) : erreur quadratique moyenne de position en ligne droite et en
    virage ; ``nees_mean`` (F,) : NEES moyen sur tout le vol ; ``band`` : intervalle à 95 % du NEES moyen
    de :data:`N_RUNS` tirages d'un filtre cohérent, à un instant (à comparer pas à pas :
    :meth:`band_shares`) ; ``example`` : les filtres de la première trajectoire ;
    ``truth``, ``y`` : cette trajectoire ; ``names`` : :data:`FILTERS`."""

    t: np.ndarray
    turning: np.ndarray
    rmse: np.ndarray
    nees: np.ndarray
    rmse_straight: np.ndarray
    rmse_turn: np.ndarray
    nees_mean: np.ndarray
    band: tuple[float, float]
    truth: np.ndarray
    y: np.ndarray
    example: dict
    names: tuple[str, ...] = FILTERS

    def __post_init__(self) -> None:
        freeze_fields(self, "t", "rmse", "nees", "rmse_straight", "rmse_turn", "nees_mean", "truth", "y")

    def index(self, name: str) -> int:
        return self.names.index(name)

    def band_shares(self, name: str) -> tuple[float, float, float]:
        r"""Parts des pas (après les 10 premières secondes) où le NEES moyen du filtre ``name`` sur les
        :data:`N_RUNS` trajectoires est **sous** l'intervalle à 95 % d'un filtre cohérent (filtre prudent :
        sa covariance surestime son erreur), **dedans**, et **au-dessus** (filtre trop sûr de lui).
        C'est pas à pas qu'il faut comparer à :attr:`band` : l'intervalle est celui d'une moyenne sur
        :data:`N_RUNS` tirages à un instant, pas d'une moyenne sur le temps."""
        settled = self.t > 10.0
        e = self.nees[self.index(name), settled]
        lo, hi = self.band
        return float(np.mean(e < lo)), float(np.mean((e >= lo) & (e <= hi))), float(np.mean(e > hi))


@dataclass(frozen=True, eq=False)
class ManoeuvreExample:
    r"""La trajectoire d'exemple : la première des :data:`N_RUNS` trajectoires de :func:`manoeuvre_study`
    (mêmes tirages). ``t`` (T,) s ; ``turning`` (T,) booléen : un virage et les 10 s qui le suivent ;
    ``truth`` (T, 4) : :math:`[e, n, v_e, v_n]` vrai (m, m/s) ; ``y`` (T, 2) : relevés radar (m)."""

    t: np.ndarray
    turning: np.ndarray
    truth: np.ndarray
    y: np.ndarray

    def __post_init__(self) -> None:
        freeze_fields(self, "t", "truth", "y")
        self.turning.flags.writeable = False


def _turning(t: np.ndarray) -> np.ndarray:
    """Pas « en virage » : un virage et les 10 s qui le suivent (le temps de s'en remettre)."""
    turning = np.zeros(t.shape, dtype=bool)
    for start, end, _ in TURNS:
        turning |= (t > start) & (t <= end + 10.0)
    return turning


@lru_cache(maxsize=1)
def manoeuvre_example() -> ManoeuvreExample:
    """La trajectoire d'exemple seule (les curseurs du chapitre n'ont pas besoin des :data:`N_RUNS`
    trajectoires) : le premier tirage de la graine :data:`SEED`, comme dans :func:`manoeuvre_study`."""
    t = DT * np.arange(1, N_STEPS + 1)
    truth, y = simulate_target(np.random.default_rng(SEED))
    return ManoeuvreExample(t=t, turning=_turning(t), truth=truth, y=y)


@lru_cache(maxsize=1)
def manoeuvre_study() -> ManoeuvreStudy:
    """La comparaison des cinq filtres sur :data:`N_RUNS` trajectoires simulées (calculée une fois)."""
    import scipy.stats

    rng = np.random.default_rng(SEED)
    ex = manoeuvre_example()  # la première trajectoire, ses instants et ses virages
    t, turning = ex.t, ex.turning
    sq = np.zeros((len(FILTERS), N_STEPS))
    ne = np.zeros((len(FILTERS), N_STEPS))
    example = truth0 = y0 = None
    for i in range(N_RUNS):
        truth, y = simulate_target(rng)
        results = run_filters(y)
        if i == 0:
            example, truth0, y0 = results, truth, y
        for f, name in enumerate(FILTERS):
            res = results[name]
            sq[f] += np.sum((res.x[:, :2] - truth[:, :2]) ** 2, axis=1)
            ne[f] += nees(truth, res)
    rmse = np.sqrt(sq / N_RUNS)
    nees_mean_t = ne / N_RUNS
    settled = t > 10.0
    straight = settled & ~turning
    rms = lambda mask: np.sqrt(np.mean(rmse[:, mask] ** 2, axis=1))  # noqa: E731
    lo, hi = scipy.stats.chi2.ppf([0.025, 0.975], 4 * N_RUNS) / N_RUNS
    return ManoeuvreStudy(t=t, turning=turning, rmse=rmse, nees=nees_mean_t, rmse_straight=rms(straight),
                          rmse_turn=rms(turning), nees_mean=nees_mean_t[:, settled].mean(axis=1),
                          band=(float(lo), float(hi)), truth=truth0, y=y0, example=example)


# --------------------------------------------------------------------------- l'hélicoptère


@dataclass(frozen=True, eq=False)
class HelicopterIMM:
    r"""L'IMM sur l'hélicoptère (deux capteurs) : ``result`` (:class:`~kalman_course.filters.imm.IMMResult`),
    ``t`` (K,) s ; ``rate_t``, ``rate`` : vitesse de virage mesurée (°/s) aux messages de vitesse ;
    ``mu_at_rate`` : probabilité du régime agité à ces instants ; ``correlation`` : leur corrélation
    (avec :math:`|\text{vitesse de virage}|`) ; ``prediction_rms`` et ``prediction_rms_single`` (m) : erreur
    de prédiction des positions de l'IMM et du filtre unique appris (:mod:`.helicopter`)."""

    result: IMMResult
    t: np.ndarray
    rate_t: np.ndarray
    rate: np.ndarray
    mu_at_rate: np.ndarray
    correlation: float
    prediction_rms: float
    prediction_rms_single: float


def measured_turn_rate(flight) -> tuple[np.ndarray, np.ndarray]:
    """Vitesse de virage (°/s) déduite des messages de vitesse successifs : instants (V,) et valeurs (V,)."""
    heading = np.unwrap(np.arctan2(flight.velocity_east, flight.velocity_north))
    return np.asarray(flight.velocity_t), np.rad2deg(np.gradient(heading, flight.velocity_t))


@lru_cache(maxsize=None)
def helicopter_imm(q_quiet: float = 0.1, q_manoeuvre: float = 30.0, switch: float = 0.05) -> HelicopterIMM:
    """L'IMM calme/agité sur les deux capteurs du vol SAMU 31 (écarts-types de mesure appris)."""
    from .helicopter import fitted_parameters, helicopter_filter

    track = helicopter_track("both")
    _, sp, sv = fitted_parameters("both")
    modes = [helicopter_model(track, q, sp, sv) for q in (q_quiet, q_manoeuvre)]
    res = imm_filter(modes, track.y, track.x0, track.P0, transition=imm_transition(switch),
                     mu0=[1.0 - switch, switch])
    rate_t, rate = measured_turn_rate(track.flight)
    rows = np.searchsorted(np.asarray(track.t), np.round(rate_t, 3))
    mu = res.mu[rows, 1]
    return HelicopterIMM(
        result=res, t=np.asarray(track.t), rate_t=rate_t, rate=rate, mu_at_rate=mu,
        correlation=float(np.corrcoef(mu, np.abs(rate))[0, 1]),
        prediction_rms=prediction_rms(res, track),
        prediction_rms_single=prediction_rms(helicopter_filter("both"), track),
    )


# --------------------------------------------------------------------------- vitesse constante / virage coordonné

#: Régime virage de l'IMM vitesse constante / virage coordonné : densité d'accélération (m²/s³) sur la cible
#: simulée, densité de la vitesse de rotation :math:`q_\omega` (rad²/s³) et écart-type a priori de
#: :math:`\omega` (rad/s).
TURN_ACCEL_PSD, TURN_RATE_PSD, TURN_RATE_STD0 = 0.5, 1e-3, 0.02
#: Densité d'accélération du régime virage sur l'hélicoptère (m²/s³).
HELI_TURN_ACCEL_PSD = 1.0
#: Trajectoires de la comparaison des deux IMM : les premières de :func:`manoeuvre_study` (même graine).
N_RUNS_TURN = 12
#: Les deux IMM comparés : calme/agité (vitesse constante, deux densités) et vitesse constante / virage.
IMM_PAIR = ("IMM CV/CV", "IMM CV/CT")
#: En dessous de cette vitesse de rotation mesurée (°/s), l'hélicoptère vole presque droit.
STRAIGHT_RATE = 1.0


def turn_state_prior(x0, P0, turn_rate_std: float = TURN_RATE_STD0) -> tuple[np.ndarray, np.ndarray]:
    r"""L'a priori sur l'état du virage :math:`[p_x, p_y, v_x, v_y, \omega]` : ``x0`` (4,) complété de
    :math:`\omega_0 = 0`, ``P0`` (4, 4) de la variance :math:`\sigma_\omega^2` (``turn_rate_std`` en rad/s),
    sans corrélation. Renvoie (5,) et (5, 5)."""
    x = np.append(np.asarray(x0, dtype=float), 0.0)
    P = np.zeros((5, 5))
    P[:4, :4] = P0
    P[4, 4] = turn_rate_std**2
    return x, P


def cv_ct_modes(dt, q_straight: float, q_turn: float, turn_psd: float, R, C=None) -> list[NonlinearModel]:
    r"""Les deux régimes de l'IMM vitesse constante / virage coordonné, sur le même état
    :math:`[p_x, p_y, v_x, v_y, \omega]` :

    * **ligne droite** (:func:`~kalman_course.core.motion.straight_flight`) : :math:`p^+ = p + \Delta t\,v`,
      :math:`v^+ = v`, :math:`\omega^+ = 0`, accélération blanche de densité ``q_straight`` ;
    * **virage coordonné** (:func:`~kalman_course.core.motion.coordinated_turn`) : la vitesse tourne de
      :math:`\omega\Delta t`, transition **non linéaire** en :math:`\omega` (des :math:`\sin\omega\Delta t`,
      :math:`\cos\omega\Delta t`) : l'IMM filtre ce régime par un EKF ; densités ``q_turn`` (m²/s³) et
      ``turn_psd`` (rad²/s³).

    ``dt`` : pas fixe (s), ou ``None`` (pas lu dans la commande :math:`u_k = [\Delta t_k]`) ; ``R`` et ``C``
    comme :func:`~kalman_course.core.motion.coordinated_turn`."""
    return [straight_flight(dt, q_straight, R, C=C), coordinated_turn(dt, q_turn, turn_psd, R, C=C)]


def run_cv_ct(y: np.ndarray, *, q_straight: float = Q_QUIET, q_turn: float = TURN_ACCEL_PSD,
              turn_psd: float = TURN_RATE_PSD, switch: float = SWITCH) -> IMMResult:
    r"""L'IMM vitesse constante / virage coordonné (:func:`cv_ct_modes`, régimes EKF) sur les relevés ``y``
    (T, 2) de la cible simulée : a priori :data:`X0`, :data:`P0` complétés de :math:`\omega_0 = 0` à
    :data:`TURN_RATE_STD0` près, probabilité de changer de régime ``switch``."""
    x5, P5 = turn_state_prior(X0, P0)
    modes = cv_ct_modes(DT, q_straight, q_turn, turn_psd, POSITION_STD**2 * np.eye(2))
    return imm_filter(modes, y, x5, P5, transition=imm_transition(switch), mu0=[1.0 - switch, switch])


def _position_velocity_nees(truth: np.ndarray, x: np.ndarray, P: np.ndarray) -> np.ndarray:
    r"""NEES (T,) de :math:`[p, v]` seuls (les 4 premiers états ; ``truth`` (T, 4)) : la marginale d'un
    état plus grand, pour comparer des filtres d'états différents sur les mêmes 4 composantes."""
    e = x[:, :4] - truth
    L = np.linalg.cholesky(P[:, :4, :4])
    z = np.linalg.solve(L, e[..., None])[..., 0]
    return np.sum(z**2, axis=1)


@dataclass(frozen=True, eq=False)
class TurnModeStudy:
    r"""Les deux IMM (:data:`IMM_PAIR` : calme/agité de :func:`run_filters`, vitesse constante / virage de
    :func:`run_cv_ct`) sur les :data:`N_RUNS_TURN` premières trajectoires de :func:`manoeuvre_study`.

    ``rmse_straight``, ``rmse_turn`` (2,) : REQM de position (m) hors virages (après 10 s) et en virage ;
    ``nees_straight``, ``nees_turn`` (2,) : NEES moyennes de :math:`[p, v]` correspondantes (4 attendu) ;
    ``turn_rate_rmse`` : REQM (rad/s) de :math:`\hat\omega` (l'estimation combinée) de l'IMM CV/CT ;
    ``t`` (T,) s ; ``turning`` (T,) booléen : un virage et les 10 s qui le suivent ; ``rmse`` (2, T) : REQM
    de position à chaque pas ; ``nees`` (2, T) : NEES moyenne à chaque pas ; ``example`` : le résultat de
    l'IMM CV/CT sur la première trajectoire (``truth`` (T, 5), avec :math:`\omega` vraie, et ``y``)."""

    rmse_straight: np.ndarray
    rmse_turn: np.ndarray
    nees_straight: np.ndarray
    nees_turn: np.ndarray
    turn_rate_rmse: float
    t: np.ndarray
    turning: np.ndarray
    rmse: np.ndarray
    nees: np.ndarray
    truth: np.ndarray
    y: np.ndarray
    example: IMMResult
    names: tuple[str, ...] = IMM_PAIR
    n_runs: int = N_RUNS_TURN

    def __post_init__(self) -> None:
        freeze_fields(self, "t", "rmse", "nees", "rmse_straight", "rmse_turn", "nees_straight", "nees_turn",
                      "truth", "y")

    def index(self, name: str) -> int:
        return self.names.index(name)


@lru_cache(maxsize=1)
def turn_mode_study() -> TurnModeStudy:
    """Les deux IMM sur :data:`N_RUNS_TURN` trajectoires simulées (calculé une fois)."""
    rng = np.random.default_rng(SEED)  # les mêmes tirages que manoeuvre_study, dans le même ordre
    ex = manoeuvre_example()
    t, turning = ex.t, ex.turning
    sq, ne = np.zeros((2, N_STEPS)), np.zeros((2, N_STEPS))
    sq_w = 0.0
    quiet, agitated = cv_model(Q_QUIET), cv_model(Q_MANOEUVRE)
    example = truth0 = y0 = None
    for i in range(N_RUNS_TURN):
        truth, y = simulate_target(rng)
        results = (imm_filter([quiet, agitated], y, X0, P0, transition=imm_transition(SWITCH),
                              mu0=[1.0 - SWITCH, SWITCH]), run_cv_ct(y))
        for f, res in enumerate(results):
            sq[f] += np.sum((res.x[:, :2] - truth[:, :2]) ** 2, axis=1)
            ne[f] += _position_velocity_nees(truth, res.x, res.P)
        w_true = turn_rate_profile(t - DT)
        sq_w += float(np.sum((results[1].x[:, 4] - w_true) ** 2))
        if i == 0:
            example, truth0, y0 = results[1], np.column_stack([truth, w_true]), y
    rmse = np.sqrt(sq / N_RUNS_TURN)
    nees_t = ne / N_RUNS_TURN
    straight = (t > 10.0) & ~turning
    rms = lambda mask: np.sqrt(np.mean(rmse[:, mask] ** 2, axis=1))  # noqa: E731
    return TurnModeStudy(t=t, turning=turning, rmse=rmse, nees=nees_t, rmse_straight=rms(straight),
                         rmse_turn=rms(turning), nees_straight=nees_t[:, straight].mean(axis=1),
                         nees_turn=nees_t[:, turning].mean(axis=1),
                         turn_rate_rmse=float(np.sqrt(sq_w / (N_RUNS_TURN * N_STEPS))),
                         truth=truth0, y=y0, example=example)


@dataclass(frozen=True, eq=False)
class HelicopterTurnIMM:
    r"""L'IMM vitesse constante / virage coordonné sur l'hélicoptère (deux capteurs, instants irréguliers) :
    ``result`` (:class:`~kalman_course.filters.imm.IMMResult`, état :math:`[e, n, v_e, v_n, \omega]`) ;
    ``t`` (K,) s ; ``rate_t`` (V,) s, ``rate`` (V,) : vitesse de rotation mesurée (°/s), comptée positive
    vers la gauche comme :math:`\omega` (l'opposé de la dérivée de la route, qui se compte vers la droite) ;
    ``turn_prob`` (V,) : probabilité du régime virage à ces instants ; ``turn_rate`` (V,) : :math:`\hat\omega`
    combinée (°/s) ; ``correlation`` : corrélation de ``turn_prob`` avec :math:`|` ``rate`` :math:`|` ;
    ``correlation_cvcv`` : la même pour la probabilité du régime agité de l'IMM calme/agité
    (:func:`helicopter_imm`) ; ``straight_turn_prob``, ``straight_agitated_prob`` : probabilités moyennes du
    régime virage et du régime agité quand l'hélicoptère vole presque droit (:math:`|` ``rate`` :math:`|` <
    :data:`STRAIGHT_RATE`) ; ``rate_correlation`` : corrélation de :math:`\hat\omega` avec ``rate`` ;
    ``prediction_rms``, ``prediction_rms_cvcv``, ``prediction_rms_single`` (m) : erreur de prédiction des
    positions de cet IMM, de l'IMM calme/agité et du filtre unique appris ; ``log_likelihood``,
    ``log_likelihood_cvcv`` : log-vraisemblances des deux IMM (mêmes mesures)."""

    result: IMMResult
    t: np.ndarray
    rate_t: np.ndarray
    rate: np.ndarray
    turn_prob: np.ndarray
    turn_rate: np.ndarray
    correlation: float
    correlation_cvcv: float
    straight_turn_prob: float
    straight_agitated_prob: float
    rate_correlation: float
    prediction_rms: float
    prediction_rms_cvcv: float
    prediction_rms_single: float
    log_likelihood: float
    log_likelihood_cvcv: float

    def __post_init__(self) -> None:
        freeze_fields(self, "t", "rate_t", "rate", "turn_prob", "turn_rate")


def helicopter_cv_ct_filter(q_straight: float = 0.1,
                            q_turn: float = HELI_TURN_ACCEL_PSD,
                            turn_psd: float = TURN_RATE_PSD,
                            switch: float = 0.05) -> IMMResult:
    r"""L'IMM vitesse constante / virage coordonné (:func:`cv_ct_modes`, EKF dans l'IMM) sur les deux capteurs
    du vol SAMU 31 : :math:`C = [I_4\ 0]` (positions et vitesses mesurées, pas :math:`\omega`), écarts-types
    de mesure appris, pas variable :math:`\Delta t_k` passé en commande (``u = track.dt[:, None]``), a priori
    de :func:`~kalman_course.scenarios.helicopter.helicopter_track` complété de :math:`\omega_0 = 0` à
    :data:`TURN_RATE_STD0` près. Le régime ligne droite a par défaut la densité du régime calme de
    :func:`helicopter_imm` (0,1 m²/s³)."""
    from .helicopter import fitted_parameters

    track = helicopter_track("both")
    _, sp, sv = fitted_parameters("both")
    # mesures : positions (m) et vitesses (m/s) ; état [e, n, v_e, v_n, ω]
    R = np.diag([sp**2] * 2 + [sv**2] * 2)
    modes = cv_ct_modes(None, q_straight, q_turn, turn_psd, R,
                        C=np.eye(5)[:4])
    x0, P0 = turn_state_prior(track.x0, track.P0)      # ω₀ = 0
    u = np.asarray(track.dt)[:, None]                  # u_k = [Δt_k]
    return imm_filter(modes, track.y, x0, P0, u,
                      transition=imm_transition(switch),
                      mu0=[1.0 - switch, switch])


@lru_cache(maxsize=None)
def helicopter_turn_imm(q_straight: float = 0.1, q_turn: float = HELI_TURN_ACCEL_PSD,
                        turn_psd: float = TURN_RATE_PSD, switch: float = 0.05) -> HelicopterTurnIMM:
    r"""L'IMM vitesse constante / virage coordonné sur l'hélicoptère (:func:`helicopter_cv_ct_filter`), comparé
    à l'IMM calme/agité de mêmes ``q_straight`` et ``switch`` (:func:`helicopter_imm`, régime agité
    30 m²/s³) et au filtre unique appris, et la vitesse de rotation mesurée (:func:`measured_turn_rate`,
    changée de signe)."""
    track = helicopter_track("both")
    res = helicopter_cv_ct_filter(q_straight, q_turn, turn_psd, switch)
    cvcv = helicopter_imm(q_straight, 30.0, switch)
    rate_t, heading_rate = measured_turn_rate(track.flight)
    rate = -heading_rate
    rows = np.searchsorted(np.asarray(track.t), np.round(rate_t, 3))
    prob, w = res.mu[rows, 1], np.rad2deg(res.x[rows, 4])
    straight = np.abs(rate) < STRAIGHT_RATE
    return HelicopterTurnIMM(
        result=res, t=np.asarray(track.t), rate_t=rate_t, rate=rate, turn_prob=prob, turn_rate=w,
        correlation=float(np.corrcoef(prob, np.abs(rate))[0, 1]), correlation_cvcv=cvcv.correlation,
        straight_turn_prob=float(prob[straight].mean()),
        straight_agitated_prob=float(cvcv.mu_at_rate[straight].mean()),
        rate_correlation=float(np.corrcoef(w, rate)[0, 1]),
        prediction_rms=prediction_rms(res, track), prediction_rms_cvcv=cvcv.prediction_rms,
        prediction_rms_single=cvcv.prediction_rms_single, log_likelihood=res.log_likelihood,
        log_likelihood_cvcv=cvcv.result.log_likelihood,
    )
