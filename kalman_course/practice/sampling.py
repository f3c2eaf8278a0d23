r"""Exercices des filtres à points : points sigma, transformée unscented, rééchantillonnage systématique,
poids des particules en logarithme.

Références : les poids de :func:`kalman_course.sigma_weights` et la transformée
:func:`kalman_course.unscented_transform` du paquet, :func:`kalman_course.systematic_resample`, et pour
les poids des particules la densité de :mod:`scipy.stats` et ``logsumexp`` de :mod:`scipy.special`.
Les points sigma sont jugés par leurs propriétés (toute racine carrée de :math:`(n+\lambda)P` convient) :
premier point à la moyenne, paires symétriques, poids, covariance restituée.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
import scipy.special
import scipy.stats

from ..filters.particle import systematic_resample as package_systematic
from ..filters.unscented import sigma_points as package_sigma_points
from ..filters.unscented import unscented_transform as package_ut
from .grading import Case, Exercise, Mistake, Output, close
from .matrices import generator, spd
from .nonlinear import point_function

__all__ = ["SIGMA_POINTS", "UNSCENTED_TRANSFORM", "SYSTEMATIC_RESAMPLE", "PARTICLE_WEIGHTS"]


# --------------------------------------------------------------------------- points sigma


def _lam(n, alpha, kappa):
    return alpha**2 * (n + kappa) - n


def _sigma_case(label, x, P, alpha, beta, kappa) -> Case:
    ref = package_sigma_points(x, P, alpha=alpha, beta=beta, kappa=kappa)
    n = x.shape[0]
    return Case(label, (x, P, alpha, beta, kappa), (ref.points, ref.Wm, ref.Wc),
                ((2 * n + 1, n), (2 * n + 1,), (2 * n + 1,)), {"lam": ref.lam})


def _sigma_cases() -> list[Case]:
    rng = generator(808)
    P2 = np.array([[2.0, 0.6], [0.6, 1.0]])
    return [
        _sigma_case("n = 1, N(0, 1), α = 1, β = 0, κ = 2 (le TD : points 0 et ±√3)", np.array([0.0]),
                    np.array([[1.0]]), 1.0, 0.0, 2.0),
        _sigma_case("n = 2, P pleine, α = 1, β = 2, κ = 0", np.array([1.0, -2.0]), P2, 1.0, 2.0, 0.0),
        _sigma_case("n = 3, α = 0,5, β = 2, κ = 0 (poids central négatif)", rng.standard_normal(3), spd(rng, 3),
                    0.5, 2.0, 0.0),
        _sigma_case("n = 4, α = 10⁻³, β = 2, κ = 3 − n (réglage de van der Merwe)", rng.standard_normal(4),
                    spd(rng, 4), 1e-3, 2.0, -1.0),
        _sigma_case("n = 2, P diagonale, α = 1, β = 2, κ = 1", np.array([0.5, 0.5]), np.diag([4.0, 0.25]),
                    1.0, 2.0, 1.0),
    ]


def _deviations(chi, x):
    n = x.shape[0]
    return chi[1:n + 1] - x


def _sigma_judge(outs, case) -> str | None:
    chi, wm, wc = outs
    x, P, alpha, beta, kappa = case.args
    n = x.shape[0]
    if chi.shape != (2 * n + 1, n) or wm.shape != (2 * n + 1,) or wc.shape != (2 * n + 1,):
        return "Formes fausses."
    ref_wm, ref_wc = case.expected[1], case.expected[2]
    if not close(chi[0], x):
        return "Le premier point sigma doit être la moyenne : χ₀ = x."
    if not close(wm, ref_wm):
        lam = case.info["lam"]
        return (f"Poids de la moyenne faux : wm₀ = λ/(n + λ) et wmᵢ = 1/(2(n + λ)), avec "
                f"λ = α²(n + κ) − n (ici λ = {_fr(lam)}).")
    if not close(wc, ref_wc):
        return "Poids de la covariance faux : wc₀ = wm₀ + (1 − α² + β), les autres égaux à ceux de la moyenne."
    plus, minus = chi[1:n + 1] - x, chi[n + 1:] - x
    if not close(plus, -minus):
        return ("Les points doivent aller par paires symétriques : χᵢ = x + sᵢ et χₙ₊ᵢ = x − sᵢ (même ordre "
                "dans les deux moitiés).")
    cov = (wc[:, None, None] * np.einsum("ki,kj->kij", chi - x, chi - x)).sum(axis=0)
    if not close(cov, P):
        return ("Les points ne restituent pas la covariance : Σ wcᵢ (χᵢ − x)(χᵢ − x)ᵀ doit valoir P. Les écarts "
                "sᵢ sont les colonnes d'une racine carrée S de (n + λ) P (S Sᵀ = (n + λ) P).")
    return None


def _fr(x):
    from ..numbers import format_number

    return format_number(float(x), significant=4)


def sigma_points_solution(x, P, alpha, beta, kappa):
    """Solution de référence (appelle le paquet)."""
    ref = package_sigma_points(x, P, alpha=alpha, beta=beta, kappa=kappa)
    return ref.points, ref.Wm, ref.Wc


def _student_weights(n, lam, alpha, beta):
    wm = np.full(2 * n + 1, 1.0 / (2 * (n + lam)))
    wc = wm.copy()
    wm[0] = lam / (n + lam)
    wc[0] = wm[0] + 1 - alpha**2 + beta
    return wm, wc


def _sigma_wc_equals_wm(x, P, alpha, beta, kappa):
    n = len(x)
    lam = alpha**2 * (n + kappa) - n
    L = np.linalg.cholesky((n + lam) * P)
    chi = np.vstack([x, x + L.T, x - L.T])
    wm, _ = _student_weights(n, lam, alpha, beta)
    return chi, wm, wm.copy()


def _sigma_no_scale(x, P, alpha, beta, kappa):
    n = len(x)
    lam = alpha**2 * (n + kappa) - n
    L = np.linalg.cholesky(P)
    chi = np.vstack([x, x + L.T, x - L.T])
    return (chi, *_student_weights(n, lam, alpha, beta))


def _sigma_elementwise_sqrt(x, P, alpha, beta, kappa):
    n = len(x)
    lam = alpha**2 * (n + kappa) - n
    S = np.sqrt((n + lam) * P)
    chi = np.vstack([x, x + S, x - S])
    return (chi, *_student_weights(n, lam, alpha, beta))


def _sigma_cholesky_rows(x, P, alpha, beta, kappa):
    n = len(x)
    lam = alpha**2 * (n + kappa) - n
    L = np.linalg.cholesky((n + lam) * P)
    chi = np.vstack([x, x + L, x - L])  # lignes de L : faux (colonnes de L = lignes de Lᵀ)
    return (chi, *_student_weights(n, lam, alpha, beta))


def _sigma_lambda_without_n(x, P, alpha, beta, kappa):
    n = len(x)
    lam = alpha**2 * (n + kappa)
    L = np.linalg.cholesky((n + lam) * P)
    chi = np.vstack([x, x + L.T, x - L.T])
    return (chi, *_student_weights(n, lam, alpha, beta))


def _point_cov(outs, x):
    chi = outs[0]
    s = _deviations(chi, x)
    return s.T @ s


def _detect_no_scale(outs, case):
    x, P = case.args[0], case.args[1]
    n = x.shape[0]
    scale = n + case.info["lam"]
    return abs(scale - 1.0) > 1e-6 and close(_point_cov(outs, x), P) and close(outs[1], case.expected[1])


def _detect_elementwise(outs, case):
    x, P = case.args[0], case.args[1]
    n = x.shape[0]
    S = np.sqrt((n + case.info["lam"]) * P)
    s = _deviations(outs[0], x)
    return not np.allclose(S, np.linalg.cholesky((n + case.info["lam"]) * P).T) and (close(s, S) or close(s, S.T))


def _detect_cholesky_rows(outs, case):
    x, P = case.args[0], case.args[1]
    n = x.shape[0]
    L = np.linalg.cholesky((n + case.info["lam"]) * P)
    return not close(L.T @ L, L @ L.T) and close(_point_cov(outs, x), L.T @ L)


def _detect_wc_equals_wm(outs, case):
    ref_wm, ref_wc = case.expected[1], case.expected[2]
    return not close(ref_wm, ref_wc) and close(outs[2], outs[1]) and close(outs[1], ref_wm)


def _detect_lambda_without_n(outs, case):
    x, P, alpha, beta, kappa = case.args
    n = x.shape[0]
    wm, _ = _student_weights(n, alpha**2 * (n + kappa), alpha, beta)
    return close(outs[1], wm)


SIGMA_POINTS = Exercise(
    id="sigma-points",
    title="Points sigma et poids de la transformée unscented",
    chapter="ukf",
    signature="sigma_points(x, P, alpha, beta, kappa) -> (chi, wm, wc)",
    parameters=("x", "P", "alpha", "beta", "kappa"),
    outputs=(Output("chi", "matrice"), Output("wm"), Output("wc")),
    make_cases=_sigma_cases,
    solution=sigma_points_solution,
    judge=_sigma_judge,
    shapes_hint="x (n,), P (n, n) ; chi (2n + 1, n), une ligne par point ; wm, wc (2n + 1,)",
    mistakes=(
        Mistake("wc-equals-wm", "poids de covariance sans le terme (1 − α² + β)",
                "Le poids central de la covariance est wc₀ = λ/(n + λ) + (1 − α² + β) : ce terme (β = 2 est "
                "optimal pour une loi gaussienne) corrige le quatrième moment. Les autres poids sont communs.",
                _sigma_wc_equals_wm, detect=_detect_wc_equals_wm, culprit=(r"\bwc\w*\s*(\[\s*0\s*\])?\s*=",)),
        Mistake("no-scale", "racine de P au lieu de racine de (n + λ) P",
                "Les écarts sont les colonnes d'une racine de (n + λ) P, pas de P : sans le facteur, les points "
                "sont trop serrés et restituent P/(n + λ) au lieu de P.",
                _sigma_no_scale, detect=_detect_no_scale,
                culprit=(r"cholesky|sqrtm",), refute=(r"lam|\bn\s*\+|\+\s*n\b|kappa|alpha",)),
        Mistake("elementwise-sqrt", "racine carrée élément par élément (`np.sqrt`) au lieu d'une racine matricielle",
                "`np.sqrt(P)` prend la racine de chaque coefficient : ce n'est pas une matrice S telle que "
                "S Sᵀ = (n + λ) P dès que P n'est pas diagonale. Utilisez `np.linalg.cholesky` (ou `scipy.linalg.sqrtm`).",
                _sigma_elementwise_sqrt, detect=_detect_elementwise, culprit=(r"np\.sqrt\(",), confirm=(r"\bP\b",)),
        Mistake("cholesky-rows", "lignes de L au lieu de ses colonnes",
                "Avec L = cholesky((n + λ) P), triangulaire inférieure et L Lᵀ = (n + λ) P, les écarts sont les "
                "colonnes de L (`L[:, i]`, ou les lignes de `L.T`), pas ses lignes `L[i]`. (Les lignes de la "
                "triangulaire supérieure U = Lᵀ conviennent : c'est le choix de filterpy.)",
                _sigma_cholesky_rows, detect=_detect_cholesky_rows, culprit=(r"x\w*\s*[+-]\s*L\b(?!\.T)",)),
        Mistake("lambda-without-n", "λ = α²(n + κ) sans le « − n »",
                "λ = α²(n + κ) − n : avec α = 1 et κ = 0, λ = 0 et les points sont à ±√n écarts-types. "
                "Sans le « − n », tous les poids sont faux.",
                _sigma_lambda_without_n, detect=_detect_lambda_without_n, culprit=(r"\blam\w*\s*=", r"\bl\s*="),
                refute=(r"-\s*n\b",)),
    ),
)


# --------------------------------------------------------------------------- transformée unscented


def _ut_case(label, x, P, func, alpha, beta, kappa) -> Case:
    n = x.shape[0]
    sp = package_sigma_points(x, P, alpha=alpha, beta=beta, kappa=kappa)
    ref = package_ut(x, P, func, alpha=alpha, beta=beta, kappa=kappa)
    f = point_function("f", func, n, "chi[i]")
    return Case(label, (sp.points, sp.Wm, sp.Wc, f), (ref.mean, ref.cov), (ref.mean.shape, ref.cov.shape),
                {"func": func})


def _polar(z):
    return np.array([z[0] * np.cos(z[1]), z[0] * np.sin(z[1])])


def _ut_cases() -> list[Case]:
    rng = generator(909)
    M = rng.standard_normal((2, 3))
    return [
        _ut_case("f(x) = x², N(0, 1), α = 1, β = 0, κ = 2 (le TD)", np.array([0.0]), np.array([[1.0]]),
                 lambda z: z**2, 1.0, 0.0, 2.0),
        _ut_case("polaire → cartésien, n = 2, m = 2", np.array([1.0, np.pi / 4]), np.diag([0.02, 0.3]), _polar,
                 1.0, 2.0, 0.0),
        _ut_case("f linéaire (transformée exacte), n = 3, m = 2", rng.standard_normal(3), spd(rng, 3),
                 lambda z: M @ z + 1.0, 1.0, 2.0, 0.0),
        _ut_case("n = 3 → m = 1, α = 0,5 (poids central négatif)", rng.standard_normal(3), spd(rng, 3, 0.5),
                 lambda z: np.array([np.sin(z[0]) * z[1] + z[2] ** 2]), 0.5, 2.0, 0.0),
        _ut_case("n = 2 → m = 3", np.array([0.3, -0.4]), spd(rng, 2, 0.2),
                 lambda z: np.array([np.exp(z[0]), z[0] * z[1], np.cos(z[1])]), 1.0, 2.0, 1.0),
    ]


def unscented_transform_solution(chi, wm, wc, f):
    """Solution de référence : mêmes formules que le paquet, sur les points donnés."""
    Y = np.array([np.atleast_1d(f(c)) for c in chi])
    mean = wm @ Y
    d = Y - mean
    return mean, (wc[:, None] * d).T @ d


def _ut_cov_with_wm(chi, wm, wc, f):
    Y = np.array([f(c) for c in chi])
    mean = wm @ Y
    d = Y - mean
    return mean, (wm[:, None] * d).T @ d


def _ut_f_of_mean(chi, wm, wc, f):
    Y = np.array([f(c) for c in chi])
    mean = f(wm @ chi)
    d = Y - mean
    return mean, (wc[:, None] * d).T @ d


def _ut_not_centred(chi, wm, wc, f):
    Y = np.array([f(c) for c in chi])
    return wm @ Y, (wc[:, None] * Y).T @ Y


def _ut_uniform(chi, wm, wc, f):
    Y = np.array([f(c) for c in chi])
    mean = Y.mean(axis=0)
    d = Y - mean
    return mean, d.T @ d / len(chi)


def _ut_all_points(chi, wm, wc, f):
    Y = f(chi)
    mean = wm @ Y
    d = Y - mean
    return mean, (wc[:, None] * d).T @ d


def _f_on_all_points(exc: BaseException, line: str) -> bool:
    from ..core.validation import KalmanInputError

    return isinstance(exc, KalmanInputError) and "« f » s'applique à un seul point" in str(exc)


UNSCENTED_TRANSFORM = Exercise(
    id="unscented-transform",
    title="Transformée unscented : moyenne et covariance des images",
    chapter="ukf",
    signature="unscented_transform(chi, wm, wc, f) -> (mean, cov)",
    parameters=("chi", "wm", "wc", "f"),
    outputs=(Output("mean"), Output("cov", "covariance")),
    make_cases=_ut_cases,
    solution=unscented_transform_solution,
    shapes_hint="chi (2n + 1, n), wm, wc (2n + 1,), f(chi[i]) (m,) ; mean (m,), cov (m, m)",
    mistakes=(
        Mistake("cov-with-wm", "covariance pondérée par wm au lieu de wc",
                "La moyenne utilise les poids wm, la covariance les poids wc : ils diffèrent au point central "
                "de (1 − α² + β). Avec wm partout, la covariance est fausse (trop petite pour β = 2).",
                _ut_cov_with_wm, outputs=(1,), output=1),
        Mistake("f-of-mean", "f de la moyenne au lieu de la moyenne des images",
                "La transformée unscented moyenne les images : ȳ = Σ wmᵢ f(χᵢ). f(x̄) est la prédiction "
                "linéarisée (celle de l'EKF), que la transformée cherche justement à corriger.",
                _ut_f_of_mean, outputs=(0,), output=0),
        Mistake("not-centred", "covariance sans retrancher la moyenne",
                "P_y = Σ wcᵢ (f(χᵢ) − ȳ)(f(χᵢ) − ȳ)ᵀ : il faut centrer les images ; Σ wcᵢ f(χᵢ) f(χᵢ)ᵀ est un "
                "moment d'ordre deux, pas une covariance.",
                _ut_not_centred, outputs=(1,), output=1),
        Mistake("uniform-weights", "poids égaux 1/(2n + 1)",
                "Les points sigma ne sont pas équiprobables : utilisez les poids wm et wc donnés (le poids central "
                "peut même être négatif).",
                _ut_uniform),
        Mistake("f-on-all-points", "f appliquée à tous les points d'un coup",
                "Ici f transforme un point (n,) en un vecteur (m,) : appliquez-la à chaque point, "
                "`Y = np.array([f(c) for c in chi])`, forme (2n + 1, m).",
                _ut_all_points, exception=_f_on_all_points),
    ),
)


# --------------------------------------------------------------------------- rééchantillonnage systématique


def _resample_case(label, w, u) -> Case:
    idx = package_systematic(w, u)
    return Case(label, (w, u), (idx,), (idx.shape,), {"bound": w.size})


def _resample_cases() -> list[Case]:
    rng = generator(1010)
    w10 = rng.uniform(0.1, 1.0, 10)
    w6 = np.array([0.3, 0.0, 0.2, 0.0, 0.4, 0.1])
    w1000 = np.full(1000, 0.2 / 999)
    w1000[417] = 0.8
    return [
        _resample_case("quatre particules, poids 0,1 / 0,2 / 0,3 / 0,4, u = 0,5 (le TD)",
                       np.array([0.1, 0.2, 0.3, 0.4]), 0.5),
        _resample_case("N = 10, poids au hasard, u = 0,77", w10 / w10.sum(), 0.77),
        _resample_case("poids égaux, u = 0 (positions exactement sur les bornes)", np.full(4, 0.25), 0.0),
        _resample_case("N = 6 dont deux poids nuls, u = 0,31", w6, 0.31),
        _resample_case("N = 1", np.array([1.0]), 0.42),
        _resample_case("N = 1000, une particule porte 80 % du poids, u = 0,95", w1000 / w1000.sum(), 0.95),
        _resample_case("N = 27 poids égaux, u = 1 − 10⁻¹⁴ : la somme cumulée des poids s'arrête à 1 − 8 × 10⁻¹⁶, "
                       "sous la dernière position (arrondi)", np.full(27, 1 / 27), 0.99999999999999),
    ]


def systematic_resample_solution(weights, u):
    """Solution de référence (appelle le paquet)."""
    return package_systematic(weights, u)


def _sys_u_plus_i(weights, u):
    N = len(weights)
    positions = u + np.arange(N) / N
    return np.searchsorted(np.cumsum(weights), positions, side="right")


def _sys_u_ignored(weights, u):
    N = len(weights)
    positions = np.arange(N) / N
    return np.searchsorted(np.cumsum(weights), positions, side="right")


def _sys_left(weights, u):
    N = len(weights)
    positions = (u + np.arange(N)) / N
    return np.searchsorted(np.cumsum(weights), positions, side="left")


def _sys_one_based(weights, u):
    N = len(weights)
    positions = (u + np.arange(1, N + 1)) / N
    return np.searchsorted(np.cumsum(weights), positions, side="right")


def _sys_last_cumsum(weights, u):
    N = len(weights)
    positions = (u + np.arange(N)) / N
    return np.searchsorted(np.cumsum(weights), positions, side="right")


def _detect_last_cumsum(outs, case):
    w, u = case.args
    raw = _sys_last_cumsum(w, u)
    return bool((raw >= w.size).any()) and close(outs[0], raw)


def _detect_u_plus_i(outs, case):
    w, u = case.args
    N = w.size
    raw = np.searchsorted(np.cumsum(w), u + np.arange(N) / N, side="right")
    return u > 0 and (close(outs[0], raw) or close(outs[0], np.minimum(raw, N - 1)))


def _detect_one_based(outs, case):
    w, u = case.args
    N = w.size
    raw = np.searchsorted(np.cumsum(w), (u + np.arange(1, N + 1)) / N, side="right")
    return close(outs[0], raw) or close(outs[0], np.minimum(raw, N - 1))


SYSTEMATIC_RESAMPLE = Exercise(
    id="systematic-resample",
    title="Rééchantillonnage systématique",
    chapter="filtre-particulaire",
    signature="systematic_resample(weights, u) -> indices",
    parameters=("weights", "u"),
    outputs=(Output("indices", "indices"),),
    make_cases=_resample_cases,
    solution=systematic_resample_solution,
    shapes_hint="weights (N,) de somme 1, u dans [0, 1) ; indices (N,) entiers dans 0…N − 1",
    mistakes=(
        Mistake("u-plus-i-over-n", "positions u + i/N au lieu de (u + i)/N",
                "Les N positions sont (u + i)/N pour i = 0…N − 1 : une seule translation u/N, dans la première "
                "strate. Avec u + i/N, les positions dépassent 1 et les dernières tombent hors des particules.",
                _sys_u_plus_i, detect=_detect_u_plus_i,
                culprit=(r"u\s*\+\s*[\w.()]+\s*/\s*N", r"u\s*\+\s*np\.arange\([^)]*\)\s*/")),
        Mistake("u-ignored", "u ignoré (positions i/N)",
                "Le tirage u décale toutes les positions : (u + i)/N. Sans u, le rééchantillonnage n'est plus "
                "aléatoire et la particule 0 est toujours choisie.",
                _sys_u_ignored, culprit=(r"arange\(\s*N\s*\)\s*/\s*N", r"i\s*/\s*N")),
        Mistake("left-side", "bornes mal attribuées (`side=\"left\"` ou `>=`)",
                "Une position p égale à une somme cumulée cⱼ appartient à la particule suivante : on cherche j "
                "tel que cⱼ₋₁ ≤ p < cⱼ, soit `np.searchsorted(c, p, side=\"right\")` (ou, dans une boucle, "
                "`while c[j] <= p: j += 1`).",
                _sys_left, culprit=(r"searchsorted", r"while.*(>=|<)"), refute=(r"side\s*=\s*[\"']right",)),
        Mistake("one-based", "positions (u + i)/N avec i = 1…N au lieu de 0…N − 1",
                "Les positions commencent à u/N (i = 0) : avec i = 1…N, la dernière dépasse 1 et il n'y a plus "
                "de particule où la placer.",
                _sys_one_based, detect=_detect_one_based, culprit=(r"arange\(\s*1", r"range\(\s*1")),
        Mistake("last-cumsum", "dernière somme cumulée laissée sous 1 (arrondi)",
                "En flottants, la somme cumulée des poids peut s'arrêter un peu sous 1 (1 − 8 × 10⁻¹⁶ pour 27 "
                "poids égaux) : une position (u + N − 1)/N juste au-dessus ne tombe alors dans aucune bande et "
                "reçoit l'indice N, hors des particules. Forcez la dernière somme cumulée à 1 (`c[-1] = 1.0`) "
                "avant de chercher les bandes.",
                _sys_last_cumsum, detect=_detect_last_cumsum, culprit=(r"cumsum\(",), refute=(r"\[\s*-1\s*\]",)),
    ),
)


# --------------------------------------------------------------------------- poids des particules


def particle_weights_reference(log_weights, predicted, y, R):
    r"""Forme close : :math:`\log\tilde w^i = \log w^i + \log\mathcal N(y; \hat y^i, R)`, normalisés par
    ``logsumexp`` (scipy)."""
    log_lik = scipy.stats.multivariate_normal(mean=np.zeros(len(y)), cov=R).logpdf(y - predicted)
    total = np.atleast_1d(log_weights + log_lik)
    return np.exp(total - scipy.special.logsumexp(total))


def _weights_case(label, log_w, predicted, y, R) -> Case:
    ref = particle_weights_reference(log_w, predicted, y, R)
    return Case(label, (log_w, predicted, y, R), (ref,), (ref.shape,))


def _weights_cases() -> list[Case]:
    rng = generator(1111)
    cases = [_weights_case("N = 5, m = 1, poids précédents égaux", np.full(5, -np.log(5)),
                           rng.standard_normal((5, 1)), np.array([0.3]), np.array([[0.5]]))]
    log_w = np.log(rng.dirichlet(np.ones(20)))
    cases.append(_weights_case("N = 20, m = 2, R pleine, poids précédents inégaux", log_w,
                               rng.standard_normal((20, 2)), np.array([0.2, -0.1]), np.array([[0.3, 0.1], [0.1, 0.2]])))
    cases.append(_weights_case("mesure très loin des particules (vraisemblances < 10⁻³⁰⁰)", np.full(8, -np.log(8)),
                               rng.standard_normal((8, 1)), np.array([60.0]), np.array([[0.5]])))
    cases.append(_weights_case("N = 1", np.array([0.0]), np.array([[1.0, 2.0]]), np.array([1.1, 1.9]), np.eye(2)))
    cases.append(_weights_case("log-poids précédents très négatifs (−1000)", -1000.0 + rng.standard_normal(6),
                               rng.standard_normal((6, 1)), np.array([0.0]), np.array([[1.0]])))
    return cases


def particle_weights_solution(log_weights, predicted, y, R):
    """Solution de référence (forme close, scipy)."""
    return particle_weights_reference(np.asarray(log_weights, float), np.asarray(predicted, float),
                                      np.asarray(y, float), np.asarray(R, float))


def _log_lik(predicted, y, R):
    d = y - predicted
    Rinv = np.linalg.inv(R)
    quad = np.einsum("ni,ij,nj->n", d, Rinv, d)
    return -0.5 * quad - 0.5 * np.log(np.linalg.det(2 * np.pi * R))


def _pw_no_max(log_weights, predicted, y, R):
    w = np.exp(log_weights + _log_lik(predicted, y, R))
    return w / w.sum()


def _pw_prior_ignored(log_weights, predicted, y, R):
    lw = _log_lik(predicted, y, R)
    lw = lw - lw.max()
    w = np.exp(lw)
    return w / w.sum()


def _pw_r_not_inverted(log_weights, predicted, y, R):
    d = y - predicted
    lw = log_weights - 0.5 * np.einsum("ni,ij,nj->n", d, R, d)
    w = np.exp(lw - lw.max())
    return w / w.sum()


def _pw_no_half(log_weights, predicted, y, R):
    d = y - predicted
    lw = log_weights - np.einsum("ni,ij,nj->n", d, np.linalg.inv(R), d)
    w = np.exp(lw - lw.max())
    return w / w.sum()


def _pw_not_normalised(log_weights, predicted, y, R):
    lw = log_weights + _log_lik(predicted, y, R)
    return np.exp(lw - lw.max())


def _pw_log_returned(log_weights, predicted, y, R):
    lw = log_weights + _log_lik(predicted, y, R)
    return lw - scipy.special.logsumexp(lw)


def _detect_not_normalised(outs, case):
    w = outs[0]
    s = float(w.sum())
    return np.isfinite(s) and s > 0 and not np.isclose(s, 1.0) and close(w / s, case.expected[0])


def _detect_log_returned(outs, case):
    w = outs[0]
    return bool(np.isfinite(w).all()) and close(np.exp(w - scipy.special.logsumexp(w)), case.expected[0]) \
        and not close(w, case.expected[0])


PARTICLE_WEIGHTS = Exercise(
    id="particle-weights",
    title="Poids des particules, calculés en logarithme",
    chapter="filtre-particulaire",
    signature="particle_weights(log_weights, predicted, y, R) -> weights",
    parameters=("log_weights", "predicted", "y", "R"),
    outputs=(Output("weights", "poids"),),
    make_cases=_weights_cases,
    solution=particle_weights_solution,
    shapes_hint="log_weights (N,), predicted (N, m) = h(xⁱ), y (m,), R (m, m) ; weights (N,), de somme 1",
    mistakes=(
        Mistake("no-max-shift", "exponentielle sans soustraire le maximum",
                "Les vraisemblances sont minuscules quand la mesure est loin des particules : exp(−1800) vaut 0 en "
                "flottant, la somme aussi, et 0/0 donne NaN. Travaillez en logarithme et retranchez le plus grand "
                "log-poids avant l'exponentielle (log-sum-exp) : les poids normalisés ne changent pas.",
                _pw_no_max, culprit=(r"np\.exp\(",), refute=(r"max|logsumexp",)),
        Mistake("prior-ignored", "poids précédents oubliés",
                "Le nouveau poids est l'ancien multiplié par la vraisemblance : log w̃ⁱ = log wⁱ + log N(y ; ŷⁱ, R). "
                "Sans l'ancien poids, on perd ce que disaient les mesures précédentes (sans rééchantillonnage).",
                _pw_prior_ignored),
        Mistake("r-not-inverted", "R au lieu de R⁻¹ dans la forme quadratique",
                "log N(y ; ŷ, R) = −½ (y − ŷ)ᵀ R⁻¹ (y − ŷ) + constante : la distance de Mahalanobis utilise "
                "l'inverse de R (`np.linalg.solve(R, d)`).",
                _pw_r_not_inverted),
        Mistake("no-half", "facteur ½ oublié",
                "La densité gaussienne est exp(−½ dᵀ R⁻¹ d) : sans le ½, les poids sont trop contrastés (c'est la "
                "vraisemblance pour une covariance R/2).",
                _pw_no_half),
        Mistake("not-normalised", "poids non normalisés",
                "Les poids doivent sommer à 1 : divisez par leur somme (après l'exponentielle).",
                _pw_not_normalised, detect=_detect_not_normalised),
        Mistake("log-returned", "log-poids renvoyés au lieu des poids",
                "La fonction renvoie les poids eux-mêmes (positifs, de somme 1) : prenez l'exponentielle des "
                "log-poids normalisés.",
                _pw_log_returned, detect=_detect_log_returned),
    ),
)
