r"""Le moteur unique des filtres : une seule boucle dans le temps pour toutes les familles.

Une famille de filtres (Kalman, EKF, EKF itéré, SRIF, SE(3)…) ne fournit que ses étapes pures, réunies
dans un :class:`FilterFamily` :

* ``prior(model, x0, P0)`` → état interne initial (vérifie ``x0``, ``P0`` et les convertit : par exemple
  :math:`(\hat x_0, P_0)`, ou :math:`(\mathcal R_{xx}, z_x)` pour le SRIF) ;
* ``predict(model, state, u_k)`` → état prédit (:math:`k-1 \mid k-1 \to k \mid k-1`), avec la ligne ``u[k]``
  des commandes, qui contient :math:`u_{k-1}` (convention du livre : :math:`x_k = f(x_{k-1}, u_{k-1})`) ;
* ``update(model, state, y_k, idx)`` → ``(état corrigé, Correction)``, où ``y_k`` ne contient que les
  composantes observées et ``idx`` leurs indices (``None`` : toutes) ;
* ``moments(state)`` → :math:`(\hat x, P)` à ranger dans le résultat.

Deux crochets facultatifs servent les filtres de Monte-Carlo (filtre particulaire, EnKF) :

* ``stochastic=True`` : le moteur exige un générateur ``rng`` (graine entière ou
  ``numpy.random.Generator``) et le passe à chaque étape en argument nommé (``prior(..., rng=g)``,
  ``predict(..., rng=g)``, ``update(..., rng=g)``) : tous les tirages viennent de ce seul générateur, donc
  même graine → même résultat ;
* ``step_outputs(state)`` → dictionnaire ``nom → tableau`` lu après chaque pas (taille effective de
  l'échantillon, incrément de log-vraisemblance, particules…) ; le moteur les empile, temps en premier,
  et les passe au constructeur de ``result_type`` sous ces noms.

Un troisième crochet sert les filtres en racine carrée : ``root_rows(model)`` → nombre maximal de lignes
d'une racine. L'état interne porte alors, en ``state[1]``, une racine :math:`M` de la covariance
(:math:`M^TM = P`) et ``Correction.S`` une racine de :math:`S` ; le moteur range ces racines à chaque pas
et forme toutes les covariances du résultat à la fin, en un produit en lot, au lieu d'un produit
:math:`M^TM` par pas qui ne servirait qu'au résultat.

**Options du moteur** (:mod:`~kalman_course.filters.gating`) : la porte (``gate=p``), la mémoire évanescente
(``fading=α``) et l'adaptation de :math:`Q` (``adapt=Adaptation(...)``) sont appliquées ici, une fois pour
toutes les familles, à partir de ce que rendent leurs étapes : l'innovation et :math:`S` de la
:class:`Correction` (ou la racine de :math:`S` d'une famille en racine carrée), l'état prédit. Une famille les
déclare par trois crochets : ``inflate(state, α)`` → état dont la covariance est multipliée par
:math:`\alpha^2` (mémoire évanescente) ; ``gating=True`` (la :class:`Correction` porte l'innovation et
:math:`S` de la mesure prédite : la porte s'applique ; ``gate_nis(state, corr)`` donne, s'il le faut, les NIS
de plusieurs hypothèses, une par régime d'un IMM, et la mesure est gardée si l'une passe) ;
``noise_image(model, predicted, idx)`` → :math:`G = HQH^T` (adaptation). Une option demandée à une famille
qui ne la déclare pas est refusée en français.

Le moteur (:func:`run_filter`) fait, une fois pour toutes les familles, ce que faisait chaque boucle :
vérifier le modèle, ``y``, ``u``, l'a priori ; traiter les mesures manquantes (ligne ``None``/``NaN`` :
prédiction seule ; ligne partielle : correction avec les seules composantes observées) ; assembler le
résultat immuable, temps en premier (:class:`~kalman_course.core.results.FilterResult`). Les erreurs
d'entrée sont donc les mêmes pour tous les filtres.

**Tirages en lot.** Une famille peut aussi fournir ses étapes sur ``N`` tirages indépendants du même
modèle (``prior_many``, ``predict_many``, ``update_many``, axe des tirages en tête) ; :func:`run_filter_runs`
les enchaîne dans le temps — la même boucle, les mêmes vérifications, les mêmes mesures manquantes — et
rend un :class:`~kalman_course.core.results.FilterRuns` (``x`` (N, T, n), ``P`` (N, T, n, n)…). Chaque
tirage y est égal, aux arrondis près, à :func:`run_filter` sur ses seules mesures. Quand la récurrence
des covariances ne dépend pas des mesures (famille ``shared_covariance``, filtre de Kalman linéaire) et
qu'aucune mesure ne manque, le même moteur la calcule **une fois** pour tous les tirages (« Riccati
commune ») : seules les moyennes sont propagées en lot.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial
from typing import Any, Callable, NamedTuple

import numpy as np

from ..core.models import model_steps, scale_process_noise
from ..core.results import AdaptiveResult, FilterHistory, FilterResult, FilterRuns
from ..core.simulation import as_generator
from ..core.validation import (
    KalmanInputError,
    as_batch_controls,
    as_batch_measurements,
    as_batch_vector,
    as_controls,
    as_float_array,
    as_gaussian,
    as_measurements,
    as_square_matrix,
    check_instance,
    check_pd,
    check_psd,
    shape_text,
)
from .gating import Adaptation, fading_factor, gate_probability, gate_threshold, nis_value, root_nis

__all__ = [
    "Correction",
    "FilterFamily",
    "run_filter",
    "run_filter_runs",
    "observed_rows",
    "gaussian_prior",
    "gaussian_prior_many",
    "gaussian_moments",
]


class Correction(NamedTuple):
    r"""Ce qu'une correction range dans le résultat, restreint aux composantes observées.

    ``K`` (n, m_k) : gain ; ``innovation`` (m_k,) : :math:`\nu_k` ; ``S`` (m_k, m_k) : sa covariance ;
    ``n_iter`` : nombre d'itérations de la correction (1 pour une correction non itérée)."""

    K: np.ndarray
    innovation: np.ndarray
    S: np.ndarray
    n_iter: int = 1


@dataclass(frozen=True)
class FilterFamily:
    r"""Les étapes pures d'une famille de filtres, que :func:`run_filter` enchaîne dans le temps.

    ``name`` : nom français du filtre (messages) ; ``model_type`` : classe(s) de modèle acceptée(s) ;
    ``model_hint`` : piste donnée quand le modèle n'est pas du bon type ; ``result_type`` : classe du
    résultat (une sous-classe de :class:`FilterResult`) ; ``state_shape(model)`` : forme de
    l'estimation rangée à chaque pas (``(n,)`` par défaut, ``(4, 4)`` pour une pose) ;
    ``tangent_dim(model)`` : dimension de la covariance (``n`` par défaut, 6 pour SE(3)) ;
    ``stochastic`` : les étapes tirent au hasard et reçoivent ``rng=`` (un ``numpy.random.Generator``) ;
    ``step_outputs(state)`` : sorties supplémentaires de chaque pas (dictionnaire de tableaux), empilées
    dans le temps et passées à ``result_type``.
    ``root_rows(model)`` : l'état porte une racine de la covariance au lieu de la covariance —
    ``state[1]`` est une racine :math:`M` (r × d, r ≤ ``root_rows(model)``), :math:`M^TM = P`, et
    ``Correction.S`` une racine (m_k × m_k) de :math:`S` ; :func:`run_filter` ne lit pas ``moments`` mais
    ``state[0]`` et la racine ``state[1]``, et forme les covariances à la fin
    (:class:`~kalman_course.core.results.FilterHistory`).

    Mode en lot (facultatif, pour :func:`run_filter_runs`) : ``prior_many(model, x0, P0, N)`` → état
    interne des ``N`` tirages, un **tuple de tableaux dont le premier axe est celui des tirages** ;
    ``moments(state)`` doit alors rendre :math:`(\hat X, P)` de formes (N, n) et (N, n, n) ;
    ``predict_many(model, state, u_k, k)`` → état prédit (``k`` : indice de la mesure visée, pour nommer
    le pas dans un message ; ``u_k`` : (p,) commune, ou (N, p) si ``batch_controls``) ;
    ``update_many(model, state, Y_k, idx, k)`` → ``(état corrigé, Correction)``, où ``state`` et ``Y_k``
    (g, m_k) ne contiennent que les ``g`` tirages qui observent les composantes ``idx`` (``None`` :
    toutes) et où les champs de la :class:`Correction` ont un axe des tirages en tête (``n_iter`` (g,)).

    Options du moteur (voir l'en-tête du module) : ``inflate(state, alpha)`` (mémoire évanescente),
    ``gating`` et ``gate_nis(state, corr)`` (porte), ``noise_image(model, predicted, idx)`` (adaptation de
    :math:`Q`, :math:`G = HQH^T` sur les composantes observées ``idx``).

    ``batch_controls`` : ``predict_many`` accepte des commandes propres à chaque tirage, ``u_k`` (N, p)
    (sinon le moteur prédit ces tirages un par un). ``shared_covariance`` : la récurrence des
    covariances ne dépend pas des mesures (filtre de Kalman linéaire) ; sans mesure manquante et avec un
    ``P0`` commun, le moteur appelle ``prior_many(model, x0, P0, N, shared=True)``, qui rend un état dont
    seule la moyenne a l'axe des tirages (covariance, ou sa racine, sans cet axe), et les étapes en lot
    calculent alors la covariance une fois pour tous (``K``, ``S`` sans axe des tirages).
    """

    name: str
    model_type: type | tuple[type, ...]
    prior: Callable[[Any, Any, Any], Any]
    predict: Callable[[Any, Any, np.ndarray | None], Any]
    update: Callable[[Any, Any, np.ndarray, np.ndarray | None], tuple[Any, Correction]]
    moments: Callable[[Any], tuple[np.ndarray, np.ndarray]]
    model_hint: str = ""
    result_type: type = FilterResult
    state_shape: Callable[[Any], tuple[int, ...]] = field(default=lambda model: (model.n_state,))
    tangent_dim: Callable[[Any], int] = field(default=lambda model: model.n_state)
    stochastic: bool = False
    step_outputs: Callable[[Any], dict[str, Any]] | None = None
    root_rows: Callable[[Any], int] | None = None
    prior_many: Callable[[Any, Any, Any, int], Any] | None = None
    predict_many: Callable[[Any, Any, np.ndarray | None, int], Any] | None = None
    update_many: Callable[[Any, Any, np.ndarray, np.ndarray | None, int], tuple[Any, Correction]] | None = None
    batch_controls: bool = False
    shared_covariance: bool = False
    inflate: Callable[[Any, float], Any] | None = None
    gating: bool = False
    gate_nis: Callable[[Any, Correction], Any] | None = None
    noise_image: Callable[[Any, Any, np.ndarray | None], np.ndarray] | None = None


def gaussian_prior(model: Any, x0: Any, P0: Any) -> tuple[np.ndarray, np.ndarray]:
    """A priori des filtres gaussiens : ``x0`` (n,), ``P0`` (n, n) symétrique semi-définie positive."""
    return as_gaussian(x0, P0, model.n_state, "x0", "P0")


def gaussian_prior_many(model: Any, x0: Any, P0: Any, N: int, definite: bool = False, shared: bool = False):
    """A priori de ``N`` tirages : ``x0`` (n,) commun ou (N, n) un par tirage ; ``P0`` (n, n) commune ou
    (N, n, n) une par tirage, symétrique semi-définie positive (``definite=True`` : définie positive).
    Renvoie ``(X0 (N, n), P0 (N, n, n))`` (copies) ; ``shared=True`` : ``P0`` commune rendue (n, n)."""
    n = model.n_state
    X0 = as_batch_vector("x0", x0, n, N)
    check = check_pd if definite else check_psd
    P = as_float_array("P0", P0)
    if P.ndim == 3:
        if P.shape != (N, n, n):
            raise KalmanInputError(
                f"« P0 » doit être de forme ({n}, {n}) (commune) ou ({N}, {n}, {n}) (une par tirage) ; "
                f"reçu {shape_text(P.shape)}."
            )
        for i in range(N):
            check(f"P0[{i}]", P[i])
    else:
        P = check("P0", as_square_matrix("P0", P, n))
        if not shared:
            P = np.broadcast_to(P, (N, n, n))
    return X0, np.array(P, dtype=float)


def gaussian_moments(state: tuple[np.ndarray, ...]) -> tuple[np.ndarray, np.ndarray]:
    r"""L'état interne d'un filtre gaussien commence par :math:`(\hat x, P)` (il peut porter d'autres
    tableaux ensuite, par exemple une racine de :math:`P`) : le moteur les lit sans appel de fonction."""
    return state[0], state[1]


def observed_rows(Y: np.ndarray) -> np.ndarray:
    """Masque ``(T, m)`` des composantes observées (``False`` pour ``NaN``)."""
    return ~np.isnan(Y)


def run_filter(
    family: FilterFamily, model: Any, y: Any, x0: Any, P0: Any, u: Any = None, *, rng: Any = None,
    gate: Any = None, fading: Any = None, adapt: Adaptation | None = None,
) -> FilterResult:
    r"""Applique la famille ``family`` à toutes les mesures : pour chaque ``y[k]``, prédiction avec
    ``u[k]`` puis correction.

    L'ordre est celui du cours (:math:`\hat x_n \to \hat x^-_{n+1} \to \hat x_{n+1}`) et de la boucle
    ``predict()``/``update()`` de filterpy : la ligne ``k`` du résultat est l'estimation après la
    mesure ``y[k]``.

    Paramètres
    ----------
    model : le modèle de la famille (vérifié). Un modèle variable dans le temps (``model.time_varying``,
        par exemple un :class:`~kalman_course.LinearGaussianModel` à matrices (T, …)) : les étapes du pas
        ``k`` reçoivent son modèle constant ``model.at(k)``.
    y : (T, m), ou (T,) si m = 1 — ``None`` ou ``NaN`` : mesure manquante (prédiction seule) ; une ligne
        partiellement manquante n'utilise que ses composantes observées.
    x0, P0 : a priori, vérifiés et convertis par ``family.prior``.
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (``u[k]`` sert à prédire vers ``y[k]``).
    rng : graine entière ou ``numpy.random.Generator`` — obligatoire pour une famille ``stochastic``,
        refusé pour les autres.
    gate : probabilité :math:`0 < p < 1`, optionnelle — porte (:mod:`~kalman_course.filters.gating`) : une
        mesure dont la NIS dépasse :math:`\chi^2_{m_k}(p)` est rejetée (prédiction seule,
        ``result.rejected``), son innovation et sa covariance gardées.
    fading : facteur :math:`\alpha \ge 1`, optionnel — mémoire évanescente (covariance a posteriori
        multipliée par :math:`\alpha^2` avant la prédiction).
    adapt : :class:`~kalman_course.filters.gating.Adaptation`, optionnelle — :math:`Q` remise à l'échelle
        par ajustement de covariance ; le résultat est alors un
        :class:`~kalman_course.core.results.AdaptiveResult` (``q_scale`` (T,)).

    Renvoie un ``family.result_type`` : ``x`` (T, …), ``P`` (T, d, d), ``x_pred``, ``P_pred``,
    ``K`` (T, d, m), ``innovation`` (T, m), ``S`` (T, m, m), ``observed`` (T, m), ``n_iter`` (T,), et
    les sorties de ``family.step_outputs`` empilées (T, …).
    """
    check_instance("model", model, family.model_type, family.model_hint)
    if family.stochastic:
        draws = {"rng": as_generator(rng)}
    elif rng is not None:
        raise KalmanInputError(f"« rng » est fourni, mais le {family.name} ne tire rien au hasard : retirez-le.")
    else:
        draws = {}
    p_gate = gate_probability(gate, "gate")
    alpha = fading_factor(fading)
    _check_options(family, p_gate, fading, alpha, adapt)
    m = model.n_obs
    Y = as_measurements("y", y, m)
    T = Y.shape[0]
    U = as_controls("u", u, T, model.n_control)
    prior, predict, update = family.prior, family.predict, family.update
    if draws:  # le générateur lié une fois pour toutes, pas à chaque appel
        prior, predict, update = (partial(f, **draws) for f in (prior, predict, update))
    state = prior(model, x0, P0)
    observed = observed_rows(Y)
    roots = family.root_rows is not None  # l'état porte une racine de la covariance (famille en racine carrée)
    out = FilterHistory(T, family.state_shape(model), family.tangent_dim(model), m, observed,
                        family.root_rows(model) if roots else None)
    full = observed.all(axis=1).tolist()  # booléens Python : la boucle n'indexe pas de tableau numpy à chaque pas
    some = observed.any(axis=1).tolist()
    extras: dict[str, list] = {}
    # boucle chaude : références locales, pas d'appel superflu (moments lus sans appel pour les filtres gaussiens)
    moments = None if family.moments is gaussian_moments else family.moments
    step_outputs = family.step_outputs
    xs, Ps, xps, Pps = out.x, out.P, out.x_pred, out.P_pred
    Ks, nus, Ss, n_iter = out.K, out.innovation, out.S, out.n_iter
    steps = model_steps(model, T)  # modèle variable dans le temps : celui du pas k (model.at(k))
    inflate = family.inflate if alpha is not None else None
    options = p_gate is not None or adapt is not None
    run = adapt.start() if adapt is not None else None
    scales = np.empty(T) if run is not None else None
    for k in range(T):
        mk = model if steps is None else steps[k]
        if inflate is not None:
            state = inflate(state, alpha)
        predicted = predict(mk if run is None else scale_process_noise(mk, run.scale), state,
                            None if U is None else U[k])
        if full[k] and not options:
            state, corr = update(mk, predicted, Y[k], None)
            Ks[k], nus[k], Ss[k], n_iter[k] = corr
        elif some[k]:
            idx = None if full[k] else np.flatnonzero(observed[k])
            state, corr = update(mk, predicted, Y[k] if idx is None else Y[k, idx], idx)
            if p_gate is not None and _outside_gate(family, state, corr, p_gate, roots):
                state, corr = predicted, Correction(np.zeros_like(corr.K), corr.innovation, corr.S, 0)
            elif run is not None:
                S = corr.S.T.dot(corr.S) if roots else corr.S
                run.observe(corr.innovation, S, family.noise_image(mk, predicted, idx))
            out.correction(k, corr, idx)
        else:
            state = predicted
        if roots:  # racines complétées de lignes nulles ; covariances formées à la fin
            M_pred, M = predicted[1], state[1]
            xps[k], Pps[k, :len(M_pred)] = predicted[0], M_pred
            xs[k], Ps[k, :len(M)] = state[0], M
        elif moments is None:
            xps[k], Pps[k] = predicted[0], predicted[1]
            xs[k], Ps[k] = state[0], state[1]
        else:
            xps[k], Pps[k] = moments(predicted)
            xs[k], Ps[k] = moments(state)
        if step_outputs is not None:
            for name, value in step_outputs(state).items():
                extras.setdefault(name, []).append(value)
        if scales is not None:
            scales[k] = run.scale
    stacked = {name: np.stack(values) for name, values in extras.items()}
    if scales is not None:
        return out.result(AdaptiveResult, q_scale=scales, **stacked)
    return out.result(family.result_type, **stacked)


def _check_options(family: FilterFamily, p_gate: float | None, fading: Any, alpha: float | None,
                   adapt: Any) -> None:
    """Une option du moteur demandée à une famille qui ne la déclare pas : une erreur française."""
    if p_gate is not None and not family.gating:
        raise KalmanInputError(
            f"« gate » : le {family.name} n'a pas de porte (sa correction ne rend pas l'innovation et la covariance "
            "S de la mesure prédite) ; retirez « gate » ou prenez un filtre gaussien (kalman_filter, "
            "extended_kalman_filter, unscented_kalman_filter, cubature_kalman_filter, gauss_hermite_kalman_filter, "
            "imm_filter)."
        )
    if alpha is not None and family.inflate is None:
        raise KalmanInputError(
            f"« fading » : le {family.name} n'a pas de mémoire évanescente ; retirez « fading » ou prenez un filtre "
            "gaussien (kalman_filter, extended_kalman_filter, unscented_kalman_filter, cubature_kalman_filter, "
            "gauss_hermite_kalman_filter, imm_filter)."
        )
    if adapt is not None:
        if not isinstance(adapt, Adaptation):
            raise KalmanInputError(
                f"« adapt » doit être un réglage Adaptation(window=…, min_scale=…, detect=…) ; reçu {type(adapt).__name__}."
            )
        if family.noise_image is None or family.result_type is not FilterResult:
            raise KalmanInputError(
                f"« adapt » : le {family.name} n'a pas d'adaptation de Q ; prenez adaptive_kalman_filter (modèle "
                "linéaire) ou un filtre gaussien d'un seul modèle."
            )


def _outside_gate(family: FilterFamily, state: Any, corr: Correction, p_gate: float, roots: bool) -> bool:
    r"""Vrai si la mesure est hors de la porte :math:`\chi^2_{m_k}(p)` : sa NIS (celle de chaque hypothèse
    si la famille en a plusieurs, ``gate_nis`` ; la mesure est gardée si l'une passe) dépasse le seuil."""
    threshold = gate_threshold(p_gate, len(corr.innovation))
    if family.gate_nis is not None:
        return bool(np.min(family.gate_nis(state, corr)) > threshold)
    nis = root_nis(corr.innovation, corr.S) if roots else nis_value(corr.innovation, corr.S)
    return nis > threshold


def run_filter_runs(family: FilterFamily, model: Any, Y: Any, x0: Any, P0: Any, u: Any = None) -> FilterRuns:
    r"""Applique la famille ``family`` à ``N`` tirages indépendants du même modèle, tous à la fois : à
    chaque pas, une prédiction puis une correction sur la pile des tirages (axe des tirages en tête).

    C'est la boucle de :func:`run_filter`, dans le même ordre, avec les étapes en lot de la famille
    (``prior_many``, ``predict_many``, ``update_many``) ; chaque tirage est égal, aux arrondis près, à
    :func:`run_filter` sur ses mesures ``Y[i]``.

    Mesures manquantes : comme :func:`run_filter`, tirage par tirage. Au pas ``k``, les tirages sont
    regroupés par motif de composantes observées ; chaque groupe est corrigé ensemble avec ses seules
    composantes observées, et les tirages sans aucune mesure au pas ``k`` ne font que la prédiction
    (gain nul, innovation et ``S`` NaN, ``n_iter`` = 0).

    **Riccati commune.** Pour une famille ``shared_covariance`` (filtre de Kalman linéaire), sans mesure
    manquante et avec un ``P0`` commun, les covariances, gains et :math:`S` ne dépendent pas des mesures :
    ils sont calculés une fois, dans cette même boucle, et rangés sans axe des tirages (forme (T, …)).

    Paramètres
    ----------
    model : le modèle de la famille (vérifié).
    Y : (N, T, m) — mesures des ``N`` tirages (un tableau 2-D est refusé) ; ``NaN`` : composante manquante.
    x0 : (n,) commun ou (N, n) ; P0 : (n, n) commune ou (N, n, n) — vérifiés par ``family.prior_many``.
    u : (T, p) commune à tous les tirages, ou (N, T, p) une suite par tirage (``(T,)`` accepté si p = 1).

    Renvoie un :class:`~kalman_course.core.results.FilterRuns` : ``x``, ``x_pred`` (N, T, n) (ou (N, T, …)
    pour une famille dont l'estimation est une pose, ``state_shape``), ``P``,
    ``P_pred`` (N, T, n, n), ``K`` (N, T, n, m), ``innovation`` (N, T, m), ``S`` (N, T, m, m),
    ``observed`` (N, T, m), ``n_iter`` (N, T) — ``P``, ``P_pred``, ``K``, ``S`` de forme (T, …) avec la
    Riccati commune ; ``result.run(i)`` est le :class:`FilterResult` du tirage ``i``.
    """
    check_instance("model", model, family.model_type, family.model_hint)
    if family.predict_many is None or family.update_many is None or family.prior_many is None:
        raise KalmanInputError(
            f"Le {family.name} n'a pas de mode en lot : filtrez les tirages un par un (boucle sur run_filter)."
        )
    m = model.n_obs
    Yarr = as_batch_measurements("Y", Y, m)
    N, T, _ = Yarr.shape
    U = as_batch_controls("u", u, N, T, model.n_control)
    observed = ~np.isnan(Yarr)
    full = observed.all(axis=2)  # (N, T)
    seen = observed.any(axis=(0, 2)).tolist()  # (T,) : au moins une composante observée par un tirage
    shared = family.shared_covariance and bool(full.all()) and np.ndim(P0) < 3
    state = family.prior_many(model, x0, P0, N, shared=True) if shared else family.prior_many(model, x0, P0, N)
    moments = family.moments
    shape, n = family.state_shape(model), family.tangent_dim(model)  # estimation (n,) ou matrice (filtre augmenté)
    lead = () if shared else (N,)  # axe des tirages des covariances, gains et S
    xs, xps = np.empty((N, T) + shape), np.empty((N, T) + shape)
    Ps, Pps = np.empty(lead + (T, n, n)), np.empty(lead + (T, n, n))
    Ks = np.zeros(lead + (T, n, m))  # gain nul pour une composante manquante : aucune correction
    nus = np.full((N, T, m), np.nan)
    Ss = np.full(lead + (T, m, m), np.nan)
    n_iter = np.zeros((N, T), dtype=int)
    run_by_run = U is not None and U.ndim == 3 and not family.batch_controls
    steps = model_steps(model, T)  # modèle variable dans le temps : celui du pas k (model.at(k))
    for k in range(T):
        mk = model if steps is None else steps[k]
        if run_by_run:
            predicted = _predict_run_by_run(family, mk, state, U[:, k], k)
        else:
            predicted = family.predict_many(mk, state, None if U is None else U[..., k, :], k)
        if not seen[k]:  # aucun tirage n'a de mesure à ce pas : prédiction seule, sans regroupement
            state = predicted
        elif full[:, k].all():
            state, corr = family.update_many(mk, predicted, Yarr[:, k], None, k)
            if shared:
                Ks[k], nus[:, k], Ss[k], n_iter[:, k] = corr
            else:
                Ks[:, k], nus[:, k], Ss[:, k], n_iter[:, k] = corr
        else:
            state = tuple(np.array(a) for a in predicted)
            patterns, group = np.unique(observed[:, k], axis=0, return_inverse=True)
            for g, pattern in enumerate(patterns):
                if not pattern.any():
                    continue  # tirages sans mesure à ce pas : prédiction seule
                runs = np.flatnonzero(group.ravel() == g)
                idx = None if pattern.all() else np.flatnonzero(pattern)
                y_g = Yarr[runs, k] if idx is None else Yarr[runs, k][:, idx]
                new, corr = family.update_many(mk, tuple(a[runs] for a in predicted), y_g, idx, k)
                for a, b in zip(state, new):
                    a[runs] = b
                _store_correction(Ks, nus, Ss, n_iter, runs, k, idx, corr)
        xps[:, k], P_pred = moments(predicted)
        xs[:, k], P = moments(state)
        if shared:
            Pps[k], Ps[k] = P_pred, P
        else:
            Pps[:, k], Ps[:, k] = P_pred, P
    for a in (xs, Ps, xps, Pps, Ks, nus, Ss):  # figés sur place : le résultat les garde sans les recopier
        a.setflags(write=False)
    return FilterRuns(x=xs, P=Ps, x_pred=xps, P_pred=Pps, K=Ks, innovation=nus, S=Ss,
                      observed=observed, n_iter=n_iter)


def _predict_run_by_run(family: FilterFamily, model: Any, state: tuple, U_k: np.ndarray, k: int) -> tuple:
    """Prédiction de chaque tirage avec sa propre commande ``U_k[i]`` (famille sans ``batch_controls``)."""
    parts = [family.predict_many(model, tuple(a[i:i + 1] for a in state), U_k[i], k) for i in range(U_k.shape[0])]
    return tuple(np.concatenate(arrays) for arrays in zip(*parts))


def _store_correction(Ks, nus, Ss, n_iter, runs, k, idx, corr) -> None:
    """Range la correction d'un groupe de tirages ``runs`` au pas ``k`` (composantes ``idx``)."""
    n_iter[runs, k] = corr.n_iter
    if idx is None:
        Ks[runs, k], nus[runs, k], Ss[runs, k] = corr.K, corr.innovation, corr.S
        return
    g, (n, m) = len(runs), Ks.shape[2:]
    K = np.zeros((g, n, m))
    K[:, :, idx] = corr.K
    nu = np.full((g, m), np.nan)
    nu[:, idx] = corr.innovation
    S = np.full((g, m, m), np.nan)
    S[:, idx[:, None], idx] = corr.S
    Ks[runs, k], nus[runs, k], Ss[runs, k] = K, nu, S
