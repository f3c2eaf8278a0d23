r"""Exercices de l'assimilation de données : l'analyse de l'ETKF (sa transformée symétrique) et le taper de
Gaspari–Cohn.

Références : :func:`kalman_course.etkf_update` et :func:`kalman_course.gaspari_cohn` (le paquet, vérifiés
dans ``tests/test_assimilation.py`` contre ``scipy.linalg.sqrtm``, la correction de Kalman dense et le
polynôme de 1999), indépendants de ce qu'écrit l'étudiant.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from ..core.lorenz import lorenz96
from ..filters.ensemble_analysis import etkf_update, gaspari_cohn
from .grading import Case, Exercise, Mistake, Output
from .matrices import generator, spd

__all__ = ["ETKF_UPDATE", "GASPARI_COHN"]


# --------------------------------------------------------------------------- analyse de l'ETKF


def _etkf_case(label, E, y, H, R, inflation) -> Case:
    E, y, H, R = (np.asarray(a, dtype=float) for a in (E, y, H, R))
    ref = etkf_update(E, y, H, R, inflation=inflation)
    return Case(label, (E, y, H, R, float(inflation)), (ref,), (E.shape,))


def _lorenz_forecast(N: int, rng: np.random.Generator) -> np.ndarray:
    """Un ensemble prévu de Lorenz-96 (40 variables) : N membres autour d'un état proche de l'attracteur,
    prévus 15 cycles."""
    model = lorenz96()
    x = 8.0 + rng.standard_normal(40)
    for _ in range(60):
        x = model.f(x, None)
    E = x + 0.5 * rng.standard_normal((N, 40))
    for _ in range(15):
        E = model.f(E, None)
    return E


def _etkf_cases() -> list[Case]:
    rng = generator(3301)
    cases = [_etkf_case("N = 2 membres, n = 2, une observation (le calcul du TD), sans inflation",
                        [[1.0, 0.0], [3.0, 2.0]], [3.5], [[1.0, 0.0]], [[2.0]], 1.0)]
    E = rng.standard_normal((5, 4)) * 2.0 + 1.0
    H = rng.standard_normal((2, 4))
    cases.append(_etkf_case("N = 5, n = 4, m = 2, R pleine, inflation 1,1", E, H @ E.mean(axis=0) + rng.standard_normal(2),
                            H, spd(rng, 2, 0.5), 1.1))
    E = rng.standard_normal((12, 3)) + np.array([0.0, 5.0, -2.0])
    H = np.eye(3)[[0, 2]]
    cases.append(_etkf_case("N = 12 membres pour n = 3 variables (plus de membres que de variables), inflation 1,05",
                            E, np.array([0.4, -1.5]), H, np.diag([0.3, 0.8]), 1.05))
    E = rng.standard_normal((4, 6))
    H = rng.standard_normal((6, 6))
    cases.append(_etkf_case("N = 4 membres pour m = 6 observations (plus d'observations que de membres)",
                            E, rng.standard_normal(6), H, spd(rng, 6), 1.0))
    E = _lorenz_forecast(20, rng)
    y = E.mean(axis=0) + rng.standard_normal(40)
    cases.append(_etkf_case("Lorenz-96 : N = 20, n = m = 40, toutes les variables observées, inflation 1,04",
                            E, y, np.eye(40), np.eye(40), 1.04))
    return cases


def etkf_update_solution(E, y, H, R, inflation):
    """Solution de référence (appelle le paquet)."""
    return etkf_update(E, y, H, R, inflation=inflation)


def _anomalies(E, y, H):
    N = E.shape[0]
    x = E.mean(axis=0)
    A = E - x
    HE = E @ H.T
    Y = HE - HE.mean(axis=0)
    return N, x, A, Y, y - HE.mean(axis=0)


def _mean_update(x, A, Y, d, R, N):
    K = A.T @ Y @ np.linalg.inv(Y.T @ Y + (N - 1) * R)
    return x + K @ d


def _etkf_cholesky(E, y, H, R, inflation):
    N, x, A, Y, d = _anomalies(E, y, H)
    M = np.eye(N) + Y @ np.linalg.inv(R) @ Y.T / (N - 1)
    T = np.linalg.cholesky(np.linalg.inv(M))    # une racine, mais pas la racine symétrique
    return _mean_update(x, A, Y, d, R, N) + inflation * T @ A


def _etkf_inflate_forecast(E, y, H, R, inflation):
    x = E.mean(axis=0)
    E = x + inflation * (E - x)                 # inflation de l'ensemble prévu, avant l'analyse
    N, x, A, Y, d = _anomalies(E, y, H)
    M = np.eye(N) + Y @ np.linalg.inv(R) @ Y.T / (N - 1)
    T = np.real(scipy.linalg.sqrtm(np.linalg.inv(M)))
    return _mean_update(x, A, Y, d, R, N) + T @ A


def _etkf_no_n_minus_one(E, y, H, R, inflation):
    N, x, A, Y, d = _anomalies(E, y, H)         # anomalies non divisées par √(N − 1) : P = AᵀA
    M = np.eye(N) + Y @ np.linalg.inv(R) @ Y.T
    T = np.real(scipy.linalg.sqrtm(np.linalg.inv(M)))
    K = A.T @ Y @ np.linalg.inv(Y.T @ Y + R)
    return x + K @ d + inflation * T @ A


def _etkf_r_not_inverted(E, y, H, R, inflation):
    N, x, A, Y, d = _anomalies(E, y, H)
    M = np.eye(N) + Y @ R @ Y.T / (N - 1)       # R au lieu de R⁻¹
    T = np.real(scipy.linalg.sqrtm(np.linalg.inv(M)))
    return _mean_update(x, A, Y, d, R, N) + inflation * T @ A


def _etkf_mean_not_updated(E, y, H, R, inflation):
    N, x, A, Y, d = _anomalies(E, y, H)
    M = np.eye(N) + Y @ np.linalg.inv(R) @ Y.T / (N - 1)
    T = np.real(scipy.linalg.sqrtm(np.linalg.inv(M)))
    return x + inflation * T @ A                # la moyenne n'est pas corrigée


ETKF_UPDATE = Exercise(
    id="etkf-update",
    title="Analyse de l'ETKF : la transformée symétrique",
    chapter="assimilation-ensemble",
    signature="etkf_update(E, y, H, R, inflation) -> E_a",
    parameters=("E", "y", "H", "R", "inflation"),
    outputs=(Output("E_a", "matrice"),),
    make_cases=_etkf_cases,
    solution=etkf_update_solution,
    shapes_hint="E (N, n) un membre par ligne, y (m,), H (m, n), R (m, m), inflation un nombre ; E_a (N, n)",
    mistakes=(
        Mistake("cholesky", "racine de Cholesky au lieu de la racine symétrique",
                "La transformée est la racine **symétrique** T = [I + Y R⁻¹ Yᵀ/(N − 1)]^(−1/2) (par exemple "
                "V diag(s^(−1/2)) Vᵀ avec `np.linalg.eigh`). Une racine de Cholesky donne la même covariance, "
                "mais elle n'est pas symétrique : T 1 ≠ 1, elle déplace la moyenne de l'ensemble et mélange les "
                "membres au hasard de leur ordre.",
                _etkf_cholesky, culprit=(r"cholesky",)),
        Mistake("inflation-forecast", "inflation appliquée à l'ensemble prévu",
                "L'inflation multiplie les anomalies **analysées** : E_a = x̄_a + λ T A. Gonfler l'ensemble prévu "
                "avant l'analyse change aussi le gain (les observations pèsent plus) : ce n'est pas le même filtre.",
                _etkf_inflate_forecast, culprit=(r"inflation\s*\*\s*\(?\s*E\b", r"E\s*-\s*\w+\s*\)\s*\*\s*inflation")),
        Mistake("no-n-minus-one", "anomalies non divisées par √(N − 1)",
                "La covariance d'échantillon est P = AᵀA/(N − 1) : la transformée est "
                "[I + Y R⁻¹ Yᵀ/(N − 1)]^(−1/2) et le gain A ᵀY (YᵀY + (N − 1) R)⁻¹. Sans le facteur N − 1, "
                "l'ensemble se croit N − 1 fois plus dispersé et les observations le resserrent trop.",
                _etkf_no_n_minus_one, culprit=(r"np\.eye\(\s*N\s*\)\s*\+",)),
        Mistake("r-not-inverted", "R au lieu de R⁻¹ dans la transformée",
                "La transformée pondère les anomalies observées par la précision des observations : "
                "Y R⁻¹ Yᵀ, pas Y R Yᵀ (les deux ne coïncident que pour R = I).",
                _etkf_r_not_inverted, culprit=(r"@\s*R\s*@",)),
        Mistake("mean-not-updated", "la moyenne n'est pas corrigée",
                "L'ETKF corrige la moyenne par le gain de Kalman de l'ensemble, x̄_a = x̄ + K (y − ȳ), puis "
                "ajoute les anomalies transformées : E_a = x̄_a + λ T A. Votre ensemble garde la moyenne prévue.",
                _etkf_mean_not_updated),
    ),
)


# --------------------------------------------------------------------------- taper de Gaspari–Cohn


def _gc_case(label, distances, radius) -> Case:
    d = np.asarray(distances, dtype=float)
    return Case(label, (d, float(radius)), (gaspari_cohn(d, radius),), (d.shape,))


def _gc_cases() -> list[Case]:
    rng = generator(3302)
    ring = np.abs(np.subtract.outer(np.arange(8), np.arange(8)))
    return [
        _gc_case("distances 0 à 10 par pas de 0,5, rayon 2 (les trois branches : z ≤ 1, 1 < z < 2, z ≥ 2)",
                 np.arange(0.0, 10.5, 0.5), 2.0),
        _gc_case("matrice (8, 8) des distances sur un anneau, rayon 1", np.minimum(ring, 8 - ring), 1.0),
        _gc_case("distances exactement c = 1,82 × rayon et 2c, rayon 4", np.array([0.0, 1.82 * 4, 2 * 1.82 * 4, 20.0]),
                 4.0),
        _gc_case("distances au hasard, rayon 0,5", rng.uniform(0.0, 2.0, 15), 0.5),
        _gc_case("rayon infini (aucune localisation)", np.array([0.0, 3.0, 1e6]), np.inf),
        _gc_case("une seule distance, égale au rayon 3 (ρ ≈ 0,63)", np.array([3.0]), 3.0),
    ]


def gaspari_cohn_solution(distances, radius):
    """Solution de référence (appelle le paquet)."""
    return gaspari_cohn(np.asarray(distances, dtype=float), radius)


def _gc_formula(z):
    z = np.asarray(z, dtype=float)
    near = -0.25 * z**5 + 0.5 * z**4 + 0.625 * z**3 - 5 / 3 * z**2 + 1
    with np.errstate(divide="ignore", invalid="ignore"):
        far = z**5 / 12 - 0.5 * z**4 + 0.625 * z**3 + 5 / 3 * z**2 - 5 * z + 4 - 2 / (3 * z)
    return near, far


def _gc_no_scale(distances, radius):
    z = np.asarray(distances, dtype=float) / radius   # c = rayon, sans le facteur 1,82
    near, far = _gc_formula(z)
    return np.where(z <= 1, near, np.where(z < 2, far, 0.0))


def _gc_no_cutoff(distances, radius):
    z = np.asarray(distances, dtype=float) / (1.82 * radius)
    near, far = _gc_formula(z)
    return np.where(z <= 1, near, far)                 # la seconde branche au-delà de z = 2


def _gc_missing_term(distances, radius):
    z = np.asarray(distances, dtype=float) / (1.82 * radius)
    near, _ = _gc_formula(z)
    far = z**5 / 12 - 0.5 * z**4 + 0.625 * z**3 + 5 / 3 * z**2 - 5 * z + 4   # sans − 2/(3z)
    return np.where(z <= 1, near, np.where(z < 2, far, 0.0))


def _gc_gaussian(distances, radius):
    d = np.asarray(distances, dtype=float)
    return np.exp(-0.5 * (d / radius) ** 2)            # une gaussienne : pas de support compact


GASPARI_COHN = Exercise(
    id="gaspari-cohn",
    title="Le taper de Gaspari–Cohn",
    chapter="assimilation-ensemble",
    signature="gaspari_cohn(distances, radius) -> rho",
    parameters=("distances", "radius"),
    outputs=(Output("rho", "matrice"),),
    make_cases=_gc_cases,
    solution=gaspari_cohn_solution,
    shapes_hint="distances : tableau de distances ≥ 0 (toute forme), radius > 0 ou np.inf ; rho : même forme",
    mistakes=(
        Mistake("no-scale", "rayon sans le facteur 1,82",
                "Avec la convention de DAPPER, le polynôme est évalué en z = d/c avec c = 1,82 × radius : le "
                "taper vaut alors 0,63 à la distance radius et s'annule à 2c = 3,64 × radius. Avec c = radius, "
                "il s'annule dès 2 × radius : la localisation est presque deux fois trop étroite.",
                _gc_no_scale, culprit=(r"/\s*radius",)),
        Mistake("no-cutoff", "le taper n'est pas nul au-delà de 2c",
                "Le taper de Gaspari–Cohn est à support compact : ρ = 0 dès z = d/c ≥ 2. La seconde branche du "
                "polynôme, prolongée au-delà, devient négative puis explose : il faut une troisième branche, nulle.",
                _gc_no_cutoff),
        Mistake("missing-term", "il manque le terme − 2/(3z) de la seconde branche",
                "Pour 1 < z < 2, ρ = z⁵/12 − z⁴/2 + 5z³/8 + 5z²/3 − 5z + 4 − 2/(3z) : sans le dernier terme, "
                "le taper saute en z = 1 (il n'est plus continu) et ne s'annule pas en z = 2.",
                _gc_missing_term),
        Mistake("gaussian", "une gaussienne au lieu du polynôme de Gaspari–Cohn",
                "exp(−d²/(2 radius²)) ressemble au taper de Gaspari–Cohn près de 0, mais ne s'annule jamais : "
                "toutes les observations, même lointaines, gardent un poids. Le polynôme de Gaspari et Cohn (1999) "
                "est à support compact : écrivez ses trois branches.",
                _gc_gaussian, culprit=(r"np\.exp",)),
    ),
)
