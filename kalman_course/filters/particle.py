r"""Filtre particulaire « bootstrap » (SIR, Gordon, Salmond & Smith 1993) : rééchantillonnages, étapes
pures et famille pour le moteur.

La loi a posteriori est représentée par :math:`N` particules :math:`x^i` de poids normalisés :math:`w^i`,
gardés en **logarithme** (aucun poids ne s'annule par soupassement, même avec un :math:`R` minuscule) :

* a priori : :math:`x^i_0 \sim \mathcal N(\hat x_0, P_0)`, :math:`w^i_0 = 1/N` ;
* prédiction (la loi de transition sert de loi de proposition) : si
  :math:`\mathrm{ESS} = 1/\sum_i (w^i)^2 < \tau N`, rééchantillonnage (indices tirés selon les poids,
  poids remis à :math:`1/N`), puis :math:`x^i_k = f(x^i_{k-1}, u_{k-1}) + w^i` (:math:`u_{k-1}` : ligne ``u[k]``), :math:`w^i \sim \mathcal N(0, Q)` ;
* correction : :math:`\log\tilde w^i = \log w^i + \log\mathcal N(y_k;\,h(x^i_k),\,R)`, puis
  normalisation par log-somme-exp ; l'incrément de log-vraisemblance est
  :math:`\log\hat p(y_k\mid y_{1:k-1}) = \log\sum_i w^i\,\mathcal N(y_k;\,h(x^i_k),\,R)`.

:math:`\hat p(y_{1:T}) = \prod_k \hat p(y_k\mid y_{1:k-1})` est un estimateur **sans biais** de la
vraisemblance :math:`p(y_{1:T})` (son logarithme, lui, est biaisé vers le bas : inégalité de Jensen).

Les estimations rangées dans le résultat sont la moyenne et la covariance pondérées des particules :
:math:`\hat x = \sum_i w^i x^i`, :math:`P = \sum_i w^i (x^i - \hat x)(x^i - \hat x)^T` (prédiction : poids
d'avant la mesure ; correction : poids mis à jour, avant tout rééchantillonnage).

Les quatre rééchantillonnages reçoivent leurs tirages uniformes explicitement (ils sont donc
déterministes et vérifiables) : multinomial (:math:`N` uniformes), stratifié (:math:`N`), systématique
(un seul) et résiduel (:math:`\lfloor Nw^i\rfloor` copies puis un tirage multinomial sur les restes).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, NamedTuple

import numpy as np
import scipy.linalg

from ..core.angles import wrap_angle
from ..core.linalg import centred_rows, covariance_factor, psd_solve, symmetrize, weighted_rows
from ..core.models import NonlinearModel
from ..core.results import FilterResult
from ..core.simulation import as_generator, check_positive_int
from ..core.validation import KalmanInputError, array_text, as_float_array, as_gaussian, shape_text
from .engine import Correction, FilterFamily, run_filter
from .extended import NONLINEAR_HINT
from .gaussian import weighted_mean

__all__ = [
    "RESAMPLING_SCHEMES",
    "ParticleFilterResult",
    "ParticleState",
    "effective_sample_size",
    "multinomial_resample",
    "stratified_resample",
    "systematic_resample",
    "residual_resample",
    "resample",
    "particle_family",
    "particle_filter",
]

_LOG_2PI = float(np.log(2.0 * np.pi))


# --------------------------------------------------------------------------- rééchantillonnages


def _check_weights(weights: Any) -> np.ndarray:
    w = as_float_array("weights", weights)
    if w.ndim != 1 or w.size == 0:
        raise KalmanInputError(f"« weights » doit être un vecteur non vide (N,) ; reçu {shape_text(w.shape)}.")
    if (w < 0).any():
        raise KalmanInputError("« weights » doit être positif ou nul (des poids de particules).")
    total = float(w.sum())
    if abs(total - 1.0) > 1e-9 * w.size:
        raise KalmanInputError(f"« weights » doit sommer à 1 (poids normalisés) ; somme reçue {total!r}.")
    return w


def _check_uniforms(u: Any, size: int | None) -> np.ndarray:
    arr = as_float_array("u", u)
    expected = "un scalaire" if size is None else f"un vecteur ({size},)"
    if (size is None and arr.ndim != 0) or (size is not None and arr.shape != (size,)):
        raise KalmanInputError(f"« u » doit être {expected} de tirages uniformes ; reçu {shape_text(arr.shape)}.")
    if ((arr < 0) | (arr >= 1)).any():
        raise KalmanInputError("« u » doit contenir des tirages uniformes dans [0, 1).")
    return arr


def _inverse_cdf(w: np.ndarray, positions: np.ndarray) -> np.ndarray:
    r"""Indice :math:`j` tel que :math:`\sum_{l<j} w^l \le p < \sum_{l\le j} w^l` pour chaque position ``p``
    (une particule de poids nul n'est jamais choisie)."""
    c = np.cumsum(w)
    c[-1] = 1.0  # les arrondis ne doivent pas laisser une position au-delà de la dernière particule
    # une position arrondie à 1 exactement ((u + N − 1)/N avec u à un ulp de 1) : la dernière particule de
    # poids non nul
    return np.minimum(np.searchsorted(c, positions, side="right"), np.flatnonzero(w > 0)[-1])


def _multinomial(w: np.ndarray, u: np.ndarray) -> np.ndarray:
    return _inverse_cdf(w, u)


def _stratified(w: np.ndarray, u: np.ndarray) -> np.ndarray:
    return _inverse_cdf(w, (u + np.arange(w.size)) / w.size)


def _systematic(w: np.ndarray, u: float) -> np.ndarray:
    return _inverse_cdf(w, (u + np.arange(w.size)) / w.size)


def _residual(w: np.ndarray, u: np.ndarray) -> np.ndarray:
    N = w.size
    counts = np.floor(N * w).astype(int)
    deterministic = np.repeat(np.arange(N), counts)
    if deterministic.size == N:
        return deterministic
    rest = N * w - counts
    return np.concatenate([deterministic, _inverse_cdf(rest / rest.sum(), u)])


def multinomial_resample(weights: Any, u: Any) -> np.ndarray:
    r"""Rééchantillonnage multinomial : :math:`N` tirages indépendants selon les poids, la copie
    :math:`k` est la particule :math:`F^{-1}(u_k)` (:math:`F` : fonction de répartition des poids).

    ``weights`` (N,) normalisés ; ``u`` (N,) uniformes dans [0, 1). Renvoie les indices (N,) (entiers)."""
    w = _check_weights(weights)
    return _multinomial(w, _check_uniforms(u, w.size))


def stratified_resample(weights: Any, u: Any) -> np.ndarray:
    r"""Rééchantillonnage stratifié : une position par strate, :math:`p_k = (k + u_k)/N`,
    :math:`u_k \sim U[0, 1)` indépendants. ``u`` (N,). Renvoie les indices (N,), croissants."""
    w = _check_weights(weights)
    return _stratified(w, _check_uniforms(u, w.size))


def systematic_resample(weights: Any, u: Any) -> np.ndarray:
    r"""Rééchantillonnage systématique : positions :math:`p_k = (k + u)/N` avec **un seul** tirage
    :math:`u \sim U[0, 1)` (scalaire). Renvoie les indices (N,), croissants."""
    w = _check_weights(weights)
    return _systematic(w, float(_check_uniforms(u, None)))


def residual_resample(weights: Any, u: Any) -> np.ndarray:
    r"""Rééchantillonnage résiduel (Liu & Chen 1998) : :math:`\lfloor Nw^i\rfloor` copies de chaque
    particule, puis :math:`R = N - \sum_i\lfloor Nw^i\rfloor` tirages multinomiaux selon les restes
    normalisés :math:`(Nw^i - \lfloor Nw^i\rfloor)/R`.

    ``u`` (R,) : les uniformes du tirage multinomial. Renvoie les indices (N,) : les copies
    déterministes (croissantes), puis les :math:`R` tirées.

    (``filterpy.monte_carlo.residual_resample`` 2.0.0 calcule les restes comme :math:`w^i - \lfloor Nw^i\rfloor`
    au lieu de :math:`Nw^i - \lfloor Nw^i\rfloor` : ses restes peuvent être négatifs et leur somme nulle.)
    """
    w = _check_weights(weights)
    n_rest = w.size - int(np.floor(w.size * w).sum())
    return _residual(w, _check_uniforms(u, n_rest))


class _Scheme(NamedTuple):
    function: Callable[[np.ndarray, Any], np.ndarray]
    draws: Callable[[np.ndarray, np.random.Generator], Any]


#: Rééchantillonnages disponibles : nom → (fonction sans vérification, tirage de ses uniformes avec un
#: ``Generator``). Les fonctions publiques (``systematic_resample``…) vérifient leurs entrées.
RESAMPLING_SCHEMES: dict[str, _Scheme] = {
    "multinomial": _Scheme(_multinomial, lambda w, g: g.random(w.size)),
    "stratified": _Scheme(_stratified, lambda w, g: g.random(w.size)),
    "systematic": _Scheme(_systematic, lambda w, g: g.random()),
    "residual": _Scheme(_residual, lambda w, g: g.random(w.size - int(np.floor(w.size * w).sum()))),
}


def _check_scheme(name: Any) -> _Scheme:
    if not isinstance(name, str) or name not in RESAMPLING_SCHEMES:
        raise KalmanInputError(
            f"« resampling » doit valoir {', '.join(repr(k) for k in RESAMPLING_SCHEMES)} ; reçu {name!r}."
        )
    return RESAMPLING_SCHEMES[name]


def resample(weights: Any, method: str = "systematic", *, rng: Any) -> np.ndarray:
    r"""Indices (N,) des particules retenues par le rééchantillonnage ``method`` (``"multinomial"``,
    ``"stratified"``, ``"systematic"`` ou ``"residual"``), uniformes tirées avec ``rng`` (graine ou
    ``Generator``). Chaque particule :math:`i` est copiée :math:`N w^i` fois **en moyenne**."""
    scheme = _check_scheme(method)
    w = _check_weights(weights)
    return scheme.function(w, scheme.draws(w, as_generator(rng)))


def effective_sample_size(weights: Any) -> float:
    r"""Taille effective de l'échantillon :math:`\mathrm{ESS} = 1/\sum_i (w^i)^2` (entre 1 et :math:`N`)."""
    w = _check_weights(weights)
    return float(1.0 / np.dot(w, w))


# --------------------------------------------------------------------------- résultat


@dataclass(frozen=True, eq=False, repr=False)
class ParticleFilterResult(FilterResult):
    r"""Résultat du filtre particulaire : les champs de :class:`~kalman_course.FilterResult` (moyenne et
    covariance pondérées des particules) et

    ``ess`` (T,) : taille effective de l'échantillon après chaque correction (avant rééchantillonnage) ;
    ``log_likelihood_increments`` (T,) : :math:`\log\hat p(y_k\mid y_{1:k-1})` (0 sans mesure) ;
    ``particles`` (T, N, n) et ``weights`` (T, N) : le nuage pondéré après chaque pas, si
    ``keep_particles=True`` (sinon ``None``) ; ``resampled`` (T,) : le nuage a été rééchantillonné avant
    la prédiction du pas.
    """

    ess: np.ndarray | None = None
    log_likelihood_increments: np.ndarray | None = None
    resampled: np.ndarray | None = None
    particles: np.ndarray | None = None
    weights: np.ndarray | None = None

    @property
    def log_likelihood(self) -> float:
        r"""Estimation :math:`\log\hat p(y_{1:T}) = \sum_k \log\hat p(y_k\mid y_{1:k-1})` (nats)."""
        return float(np.sum(self.log_likelihood_increments))

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.resampled is not None:
            flags = np.array(self.resampled, dtype=bool)
            flags.setflags(write=False)
            object.__setattr__(self, "resampled", flags)


class Whitening(NamedTuple):
    r"""Ce qu'il faut de :math:`R = LL^T` pour :math:`\log\mathcal N(y;\,h(x^i),\,R)` : ``Linv_t``
    :math:`= (L^{-1})^T` (m, m), ``half_m_log_2pi`` :math:`= \tfrac m2\log 2\pi` et ``log_diag``
    :math:`= \sum_j\log L_{jj} = \tfrac12\log|R|`."""

    Linv_t: np.ndarray
    half_m_log_2pi: float
    log_diag: float


class ParticleState(NamedTuple):
    r"""État interne du filtre : ``X`` (N, n) particules, ``logw`` (N,) log-poids normalisés et ``w`` (N,)
    les poids, ``ess``, ``increment`` :math:`\log\hat p(y_k\mid y_{1:k-1})` du dernier pas (0 sans mesure),
    ``resampled`` (le nuage a été rééchantillonné avant la dernière prédiction), ``k`` : indice de la mesure
    visée (pour nommer le pas dans un message d'erreur), ``LQ`` : facteur :math:`L_QL_Q^T = Q` (calculé une
    fois) ; ``white`` : :class:`Whitening` de la covariance de mesure complète (calculé une fois, ``None``
    si elle n'est pas constante) ; ``moments`` : :math:`(\hat x, P, X - \hat x)` du nuage pondéré, calculés
    une seule fois par nuage (le moteur les range, la correction réutilise les écarts du nuage prédit)."""

    X: np.ndarray
    logw: np.ndarray
    w: np.ndarray
    ess: float
    increment: float
    resampled: bool
    k: int
    LQ: np.ndarray
    white: Whitening | None = None
    moments: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None


# --------------------------------------------------------------------------- famille


def _check_threshold(value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not 0.0 <= float(value) <= 1.0:
        raise KalmanInputError(
            f"« ess_threshold » doit être un nombre entre 0 (jamais de rééchantillonnage) et 1 (à chaque pas) ; "
            f"reçu {value!r}."
        )
    return float(value)


def _check_model(model: NonlinearModel) -> None:
    if model.h_noise_jacobian is not None and callable(model.h_noise_jacobian):
        raise KalmanInputError(
            "Le filtre particulaire demande une covariance de mesure constante : h_noise_jacobian (V) doit être "
            "une matrice, pas une fonction."
        )


def _noise(model: NonlinearModel, X: np.ndarray, u, gen: np.random.Generator, LQ: np.ndarray) -> np.ndarray:
    """Bruits d'état :math:`W\\phi^i` (N, n), :math:`\\phi^i \\sim \\mathcal N(0, Q)`."""
    phi = gen.standard_normal((X.shape[0], LQ.shape[0])).dot(LQ.T)
    W = model.f_noise_jacobian
    if W is None:
        return phi
    if not callable(W):
        return phi.dot(np.asarray(W).T)
    return np.array([model.process_noise_gain(x, u).dot(p) for x, p in zip(X, phi)])


def _whitening(R: np.ndarray) -> Whitening:
    r""":class:`Whitening` de ``R`` (m, m) définie positive (Cholesky :math:`R = LL^T`, puis :math:`L^{-1}`)."""
    L = scipy.linalg.cholesky(R, lower=True, check_finite=False)
    Linv = scipy.linalg.solve_triangular(L, np.eye(R.shape[0]), lower=True, check_finite=False)
    return Whitening(Linv.T, 0.5 * R.shape[0] * _LOG_2PI, np.log(np.diag(L)).sum())


def _log_likelihoods(model: NonlinearModel, HX: np.ndarray, y: np.ndarray, white: Whitening, idx) -> np.ndarray:
    r""":math:`\log\mathcal N(y;\,h(x^i),\,R) = -\tfrac12\lVert L^{-1}(y - h(x^i))\rVert^2 - \tfrac m2\log 2\pi
    - \tfrac12\log|R|` pour chaque particule, (N,) ; ``white`` : :class:`Whitening` de :math:`R`."""
    D = model.residual(y, HX, idx)
    Z = D.dot(white.Linv_t)  # lignes : L⁻¹(y − h(xⁱ)), blanchies
    with np.errstate(over="ignore", invalid="ignore"):
        maha = np.einsum("ij,ij->i", Z, Z)
    return -0.5 * maha - white.half_m_log_2pi - white.log_diag


def _weighted_moments(X: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Moyenne et covariance pondérées :math:`\hat x = \sum_i w^ix^i`,
    :math:`P = \sum_i w^i(x^i - \hat x)(x^i - \hat x)^T`, et les poids fois les écarts
    :math:`w^i(x^i - \hat x)` (N, n), qui resservent à la covariance croisée."""
    x = w.dot(X)
    D = centred_rows(X, x)
    WD = weighted_rows(w, D)
    return x, symmetrize(D.T.dot(WD)), WD


def _measurement_moments(HX: np.ndarray, w: np.ndarray, angles: list[int]):
    r"""Moments pondérés des mesures prédites ``HX`` (N, m) : :math:`\hat y`, :math:`P_{yy}` et
    :math:`w^i(h(x^i) - \hat y)` (N, m), comme :func:`_weighted_moments`, mais les composantes angulaires
    ``angles`` (un azimut près de :math:`\pm\pi`) ont une **moyenne circulaire**
    :math:`\operatorname{atan2}(\sum_i w^i\sin, \sum_i w^i\cos)` et des écarts ramenés dans
    :math:`(-\pi, \pi]` : sans cela, un nuage à cheval sur :math:`\pm\pi` aurait une moyenne proche de 0 et
    un écart-type de l'ordre de :math:`\pi`."""
    if not angles:
        return _weighted_moments(HX, w)
    y_hat = weighted_mean(HX, w, angles)
    D = HX - y_hat
    D[:, angles] = wrap_angle(D[:, angles])
    WD = weighted_rows(w, D)
    return y_hat, symmetrize(D.T.dot(WD)), WD


def _cloud_moments(X: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r""":math:`(\hat x, P, X - \hat x)` du nuage ``X`` (N, n) de poids ``w`` (N,)."""
    x = w.dot(X)
    D = centred_rows(X, x)
    return x, symmetrize(D.T.dot(weighted_rows(w, D))), D


def particle_family(
    n_particles: int,
    resampling: str = "systematic",
    ess_threshold: float = 0.5,
    keep_particles: bool = False,
) -> FilterFamily:
    r"""Les étapes du filtre particulaire bootstrap pour le moteur (famille ``stochastic`` : chaque étape
    reçoit le générateur ``rng``). État interne : :class:`ParticleState`."""
    N = check_positive_int("n_particles", n_particles)
    scheme = _check_scheme(resampling)
    tau = _check_threshold(ess_threshold)
    log_uniform = np.full(N, -np.log(N))
    uniform = np.full(N, 1.0 / N)

    def prior(model, x0, P0, rng):
        _check_model(model)
        x, P = as_gaussian(x0, P0, model.n_state, "x0", "P0")
        X = x + rng.standard_normal((N, model.n_state)).dot(covariance_factor(P).T)
        # R ramenée à la mesure est constante (V constante, vérifié ci-dessus) : factorisée une fois
        white = _whitening(model.measurement_noise(X[0]))
        return ParticleState(X, log_uniform, uniform, float(N), 0.0, False, -1, covariance_factor(model.Q), white)

    def predict_step(model, state, u, rng):
        X, logw, w, ess = state.X, state.logw, state.w, state.ess
        resampled = ess < tau * N
        if resampled:
            X = X.take(scheme.function(w, scheme.draws(w, rng)), axis=0)  # X[indices], sans l'indexation lente
            logw, w, ess = log_uniform, uniform, float(N)
        X = model.transition_many(X, u) + _noise(model, X, u, rng, state.LQ)
        return ParticleState(X, logw, w, ess, 0.0, resampled, state.k + 1, state.LQ, state.white,
                             _cloud_moments(X, w))

    def update_step(model, state, y, idx, rng):
        X, logw, w_prev = state.X, state.logw, state.w
        HX = model.observe_many(X)
        R = model.measurement_noise(X[0])
        white = state.white
        if idx is not None:
            HX, R = HX[:, idx], R[np.ix_(idx, idx)]
            white = _whitening(R)
        joint = logw + _log_likelihoods(model, HX, y, white, idx)
        top = joint.max()
        if not np.isfinite(top):
            raise KalmanInputError(
                f"Filtre particulaire, correction par y[{state.k}] = {array_text(y, significant=4)} : toutes "
                "les particules ont un poids nul (la mesure est infiniment improbable pour chacune). Vérifiez la "
                "mesure et R, augmentez Q, P0 ou le nombre de particules."
            )
        # log-somme-exp : log Σ exp(jointⁱ) = max + log Σ exp(jointⁱ − max), sans soupassement
        increment = float(top + np.log(np.exp(joint - top).sum()))
        new_logw = joint - increment
        w = np.exp(new_logw)
        w /= w.sum()  # efface les arrondis (Σw = 1 à 1e-16 près)
        ess = float(1.0 / np.dot(w, w))
        # correction « linéaire équivalente » du nuage prédit : ŷ, S, P_xy, K = P_xy S⁻¹ (pour la NIS) ;
        # P_xy = Σ wⁱ(xⁱ − x̂⁻)(h(xⁱ) − ŷ)ᵀ avec les écarts xⁱ − x̂⁻ du nuage prédit (déjà calculés) ;
        # composantes angulaires de la mesure : moyenne circulaire et écarts ramenés dans (−π, π]
        D = (state.moments or _cloud_moments(X, w_prev))[2]
        y_hat, Pyy, WDy = _measurement_moments(HX, w_prev, model.observed_angles(idx))
        S = Pyy + R
        Pxy = D.T.dot(WDy)
        K = psd_solve(S, Pxy.T, message=f"Filtre particulaire, correction par y[{state.k}] : la covariance "
                                         "d'innovation équivalente P_yy + R n'est pas définie positive.").T
        nu = model.residual(y, y_hat, idx)
        state = ParticleState(X, new_logw, w, ess, increment, state.resampled, state.k, state.LQ, state.white,
                              _cloud_moments(X, w))
        return state, Correction(K, nu, S)

    def moments(state):
        return (state.moments or _cloud_moments(state.X, state.w))[:2]

    def outputs(state):
        out = {"ess": state.ess, "log_likelihood_increments": state.increment, "resampled": state.resampled}
        if keep_particles:
            out["particles"] = state.X
            out["weights"] = state.w
        return out

    return FilterFamily(
        name="filtre particulaire",
        model_type=NonlinearModel,
        model_hint=NONLINEAR_HINT,
        prior=prior,
        predict=predict_step,
        update=update_step,
        moments=moments,
        result_type=ParticleFilterResult,
        stochastic=True,
        step_outputs=outputs,
    )


def particle_filter(
    model: NonlinearModel,
    y: Any,
    x0: Any,
    P0: Any,
    u: Any = None,
    *,
    n_particles: int,
    rng: Any,
    resampling: str = "systematic",
    ess_threshold: float = 0.5,
    keep_particles: bool = False,
) -> ParticleFilterResult:
    r"""Filtre particulaire bootstrap (SIR) sur toutes les mesures, dans l'ordre des autres filtres.

    Paramètres
    ----------
    model : NonlinearModel (``vectorized=True`` fortement conseillé : les :math:`N` particules passent par
        ``f`` et ``h`` en un appel au lieu de :math:`N`).
    y : (T, m), ou (T,) si m = 1 — ``NaN`` : composante manquante (ligne entière : prédiction seule, poids
        inchangés ; ligne partielle : vraisemblance des seules composantes observées).
    x0 : (n,), P0 : (n, n) semi-définie positive — loi des particules initiales.
    u : (T, p), ou (T,) si p = 1, optionnel — commandes (``u[k]``, qui contient :math:`u_{k-1}`, sert à prédire vers ``y[k]``).
    n_particles : nombre de particules :math:`N` (entier ≥ 1).
    rng : graine entière ou ``numpy.random.Generator`` (obligatoire : même graine → même résultat).
    resampling : ``"systematic"`` (défaut), ``"stratified"``, ``"residual"`` ou ``"multinomial"``.
    ess_threshold : :math:`\tau \in [0, 1]` — rééchantillonner quand :math:`\mathrm{ESS} < \tau N`
        (0 : jamais, 1 : à chaque pas).
    keep_particles : garder le nuage pondéré de chaque pas (``particles`` (T, N, n), ``weights`` (T, N)).

    Renvoie un :class:`ParticleFilterResult` : ``x`` (T, n), ``P`` (T, n, n), ``ess`` (T,),
    ``log_likelihood`` (float), ``K``, ``innovation``, ``S`` de la correction linéaire équivalente du
    nuage prédit (:math:`S = \operatorname{cov}_w h(x^i) + R`, :math:`K = P_{xy}S^{-1}`).
    """
    family = particle_family(n_particles, resampling, ess_threshold, keep_particles)
    return run_filter(family, model, y, x0, P0, u, rng=rng)
