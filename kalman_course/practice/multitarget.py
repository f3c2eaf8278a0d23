r"""Exercices de la partie « Plusieurs cibles » : les poids de la PDA et sa correction.

Références : :func:`kalman_course.pda_update` (poids) et le noyau de correction du paquet
(:func:`kalman_course.multitarget.pda.combine`), indépendants de ce qu'écrit l'étudiant. Chaque erreur
classique est documentée par l'implémentation fausse qu'écrirait un étudiant : hypothèse « aucune
détection » oubliée, poids non normalisés, :math:`\lambda` et :math:`P_D` échangés, terme de dispersion
oublié…
"""

from __future__ import annotations

import numpy as np
import scipy.stats

from ..core.models import LinearGaussianModel
from ..multitarget.gate import innovations
from ..multitarget.pda import combine, pda_update as package_pda_update
from .grading import Case, Exercise, Mistake, Output, close
from .matrices import generator, spd

__all__ = ["PDA_WEIGHTS", "PDA_UPDATE"]


# --------------------------------------------------------------------------- poids


def weights_solution(innovations, S, detection_probability, clutter_density, gate_probability):
    r"""Solution de référence : :func:`kalman_course.pda_update` sur une piste dont la mesure prédite est 0
    et la covariance d'innovation ``S`` (``C = I``, ``P_pred = 0``, ``R = S``)."""
    nu = np.asarray(innovations, dtype=float)
    S = np.asarray(S, dtype=float)
    m = S.shape[0]
    model = LinearGaussianModel(np.eye(m), np.eye(m), np.zeros((m, m)), S)
    return package_pda_update(model, np.zeros(m), np.zeros((m, m)), nu.reshape(-1, m),
                              detection_probability=detection_probability, clutter_density=clutter_density,
                              gate_probability=gate_probability).weights


def _weights_case(label, nu, S, pd, lam, pg) -> Case:
    return Case(label, (nu, S, pd, lam, pg), (weights_solution(nu, S, pd, lam, pg),), ((nu.shape[0] + 1,),),
                {"m": S.shape[0]})


def _weights_cases() -> list[Case]:
    rng = generator(3701)
    S2 = np.array([[400.0, 120.0], [120.0, 250.0]])
    L2 = np.linalg.cholesky(S2)
    cases = [
        _weights_case("m = 2, deux détections dans la fenêtre", (L2 @ np.array([[0.5, -0.3], [-1.2, 1.0]]).T).T,
                      S2, 0.9, 1e-4, 0.99),
        _weights_case("m = 2, une détection sur trois hors de la fenêtre",
                      (L2 @ np.array([[0.3, 0.8], [5.0, 1.0], [-1.0, -1.4]]).T).T, S2, 0.8, 5e-5, 0.99),
        _weights_case("m = 1, quatre détections, fouillis dense", np.array([[0.4], [-1.5], [2.2], [0.9]]),
                      np.array([[1.5]]), 0.7, 0.8, 0.95),
        _weights_case("N = 0 : un relevé vide (innovations de forme (0, 2))", np.empty((0, 2)), S2, 0.9, 1e-4, 0.99),
        _weights_case("P_D = 1 : une cible toujours détectée", (L2 @ np.array([[0.2, 0.1], [1.5, -1.0]]).T).T, S2,
                      1.0, 2e-4, 0.99),
        _weights_case("aucune détection dans la fenêtre", (L2 @ np.array([[6.0, 0.0], [0.0, -7.0]]).T).T, S2, 0.9,
                      1e-4, 0.99),
    ]
    S3 = spd(rng, 3, 50.0)
    nu3 = (np.linalg.cholesky(S3) @ rng.normal(0.0, 1.2, (5, 3)).T).T
    cases.append(_weights_case("m = 3, cinq détections, fenêtre étroite (P_G = 0,9)", nu3, S3, 0.85, 1e-3, 0.9))
    return cases


def _gauss(nu, S):
    nu, S = np.asarray(nu, float), np.asarray(S, float)
    m = S.shape[0]
    nis = np.einsum("ij,jk,ik->i", nu, np.linalg.inv(S), nu)
    return nis, np.exp(-0.5 * nis) / np.sqrt((2 * np.pi) ** m * np.linalg.det(S))


def _pw_no_missed(innovations, S, detection_probability, clutter_density, gate_probability):
    nis, g = _gauss(innovations, S)
    inside = nis <= scipy.stats.chi2.ppf(gate_probability, S.shape[0])
    w = np.where(inside, detection_probability * g / clutter_density, 0.0)
    return np.concatenate([[0.0], w / w.sum()])


def _pw_not_normalised(innovations, S, detection_probability, clutter_density, gate_probability):
    nis, g = _gauss(innovations, S)
    inside = nis <= scipy.stats.chi2.ppf(gate_probability, S.shape[0])
    w = np.where(inside, detection_probability * g / clutter_density, 0.0)
    return np.concatenate([[1 - detection_probability * gate_probability], w])


def _pw_swapped(innovations, S, detection_probability, clutter_density, gate_probability):
    nis, g = _gauss(innovations, S)
    inside = nis <= scipy.stats.chi2.ppf(gate_probability, S.shape[0])
    w = np.concatenate([[1 - detection_probability * gate_probability],
                        np.where(inside, clutter_density * g / detection_probability, 0.0)])
    return w / w.sum()


def _pw_no_gate(innovations, S, detection_probability, clutter_density, gate_probability):
    _, g = _gauss(innovations, S)
    w = np.concatenate([[1 - detection_probability * gate_probability], detection_probability * g / clutter_density])
    return w / w.sum()


def _pw_missed_one_minus_pd(innovations, S, detection_probability, clutter_density, gate_probability):
    nis, g = _gauss(innovations, S)
    inside = nis <= scipy.stats.chi2.ppf(gate_probability, S.shape[0])
    w = np.concatenate([[1 - detection_probability], np.where(inside, detection_probability * g / clutter_density, 0.0)])
    return w / w.sum()


def _detect_no_missed(outputs, case: Case) -> bool:
    """Sans l'hypothèse « aucune détection » : les poids des détections seules, normalisés entre eux, avec ou
    sans la case 0 (forme (N,) ou (N + 1,) avec β₀ = 0)."""
    beta = np.asarray(outputs[0], dtype=float)
    wrong = _pw_no_missed(*case.args)
    if not np.isfinite(wrong).all() or close(wrong, case.expected[0]):
        return False
    return close(beta, wrong) or close(beta, wrong[1:])


def _detect_not_normalised(outputs, case: Case) -> bool:
    beta = np.asarray(outputs[0], dtype=float)
    expected = case.expected[0]
    total = beta.sum()
    return beta.shape == expected.shape and abs(total - 1.0) > 1e-6 and total > 0 and close(beta / total, expected)


_WEIGHT_LINE = (r"^\s*w\w*\s*=", r"^\s*beta\w*\s*=", r"^\s*weights?\w*\s*=")  # ligne des poids

PDA_WEIGHTS = Exercise(
    id="pda-weights",
    title="Les poids de l'association probabiliste (PDA)",
    chapter="fouillis-association",
    signature="pda_weights(innovations, S, detection_probability, clutter_density, gate_probability) -> beta",
    parameters=("innovations", "S", "detection_probability", "clutter_density", "gate_probability"),
    outputs=(Output("beta", "poids"),),
    make_cases=_weights_cases,
    solution=weights_solution,
    shapes_hint="innovations (N, m), S (m, m) ; beta (N + 1,) : beta[0] pour « aucune détection », beta[1 + j] "
                "pour la détection j",
    mistakes=(
        Mistake("no-missed", "hypothèse « aucune détection » oubliée",
                "Il y a N + 1 hypothèses : aucune des détections ne vient de la cible (poids 1 − P_D P_G : elle n'a "
                "pas été détectée, ou hors de la fenêtre), ou c'est la détection j. Sans la première, la piste croit "
                "toujours qu'une détection est la bonne, même quand toutes viennent du fouillis.",
                _pw_no_missed, detect=_detect_no_missed, culprit=(r"/\s*\(?\s*\w+\.sum\(", r"/\s*np\.sum\(")),
        Mistake("not-normalised", "poids non normalisés",
                "Les β sont des probabilités : divisez les poids w₀ = 1 − P_D P_G et w_j = P_D N(ν_j ; 0, S)/λ par "
                "leur somme. Sans cela, leur somme vaut n'importe quoi et la correction n'a plus d'échelle.",
                _pw_not_normalised, detect=_detect_not_normalised),
        Mistake("swapped", "λ et P_D échangés",
                "Le poids d'une détection est P_D N(ν_j ; 0, S) / λ : la probabilité de détection multiplie la "
                "vraisemblance de la cible, la densité du fouillis la divise (une détection est d'autant moins "
                "crédible que le fouillis est dense). Vous avez écrit λ N / P_D.",
                _pw_swapped, culprit=(r"(clutter_density|lam\w*)\s*\*", r"/\s*(detection_probability|p_?d)\b")),
        Mistake("no-gate", "détections hors de la fenêtre gardées",
                "Seules les détections de la fenêtre, NIS νᵀ S⁻¹ ν ≤ γ = χ²_m(P_G) (`scipy.stats.chi2.ppf(P_G, m)`), "
                "ont un poids ; les autres ont β = 0. Le poids 1 − P_D P_G suppose cette fenêtre.",
                _pw_no_gate),
        Mistake("missed-1-pd", "poids de « aucune détection » = 1 − P_D au lieu de 1 − P_D P_G",
                "La cible peut ne pas être détectée (1 − P_D), mais aussi être détectée hors de la fenêtre "
                "(P_D (1 − P_G)) : au total 1 − P_D P_G.",
                _pw_missed_one_minus_pd, culprit=_WEIGHT_LINE),
    ),
)


# --------------------------------------------------------------------------- correction


def update_solution(x_pred, P_pred, detections, C, R, beta):
    r"""Solution de référence : le noyau de correction PDA du paquet (:func:`~kalman_course.multitarget.pda.combine`)."""
    x, P = np.asarray(x_pred, float), np.asarray(P_pred, float)
    C, R = np.asarray(C, float), np.asarray(R, float)
    z = np.asarray(detections, float).reshape(-1, C.shape[0])
    inn = innovations(C, R, x[None], P[None], z)
    x_new, P_new = combine(x[None], P[None], inn, np.asarray(beta, float)[None])
    return x_new[0], P_new[0]


def _update_case(label, x, P, z, C, R, beta) -> Case:
    return Case(label, (x, P, z, C, R, beta), update_solution(x, P, z, C, R, beta), (x.shape, P.shape))


def _beta_for(x, P, z, C, R, pd, lam, pg):
    S = C @ P @ C.T + R
    return weights_solution(z - C @ x, S, pd, lam, pg)


def _update_cases() -> list[Case]:
    rng = generator(3702)
    cases = []
    # n = 4, m = 2 : le pisteur radar ; deux détections dans la porte
    x = np.array([100.0, -50.0, 20.0, 5.0])
    P = spd(rng, 4, 200.0)
    C = np.hstack([np.eye(2), np.zeros((2, 2))])
    R = np.diag([900.0, 400.0])
    z = C @ x + np.array([[20.0, -10.0], [-35.0, 30.0]])
    cases.append(_update_case("n = 4, m = 2 (radar), deux détections dans la fenêtre", x, P, z, C, R,
                              _beta_for(x, P, z, C, R, 0.9, 1e-5, 0.99)))
    # n = 2, m = 1, trois détections, une hors de la porte
    x2, P2 = np.array([0.0, 1.0]), np.array([[2.0, 0.5], [0.5, 1.0]])
    C2, R2 = np.array([[1.0, 0.0]]), np.array([[1.0]])
    z2 = np.array([[0.8], [-1.5], [9.0]])
    cases.append(_update_case("n = 2, m = 1, trois détections dont une hors de la fenêtre", x2, P2, z2, C2, R2,
                              _beta_for(x2, P2, z2, C2, R2, 0.8, 0.2, 0.99)))
    # relevé vide : β = [1], la prédiction
    cases.append(_update_case("N = 0 : relevé vide (β = [1]), la correction rend la prédiction", x, P,
                              np.empty((0, 2)), C, R, np.array([1.0])))
    # une détection porte tout le poids : la correction de Kalman
    cases.append(_update_case("β = (0, 1) : une seule détection, certaine (correction de Kalman)", x2, P2,
                              np.array([[0.3]]), C2, R2, np.array([0.0, 1.0])))
    # β₀ grand : la cible est probablement manquée
    z3 = C @ x + np.array([[60.0, 50.0]])
    cases.append(_update_case("n = 4, m = 2, une détection lointaine (β₀ grand)", x, P, z3, C, R,
                              _beta_for(x, P, z3, C, R, 0.6, 1e-4, 0.999)))
    # n = 6, m = 3, C pleine, quatre détections, poids quelconques
    x6, P6 = rng.standard_normal(6), spd(rng, 6, 2.0)
    C6, R6 = rng.standard_normal((3, 6)), spd(rng, 3, 0.5)
    z6 = C6 @ x6 + rng.normal(0.0, 1.0, (4, 3))
    b6 = rng.uniform(0.1, 1.0, 5)
    cases.append(_update_case("n = 6, m = 3, C pleine, quatre détections, poids quelconques", x6, P6, z6, C6, R6,
                              b6 / b6.sum()))
    return cases


def _kalman_parts(x_pred, P_pred, detections, C, R):
    S = C @ P_pred @ C.T + R
    K = np.linalg.solve(S, C @ P_pred).T
    nu = np.asarray(detections, float).reshape(-1, C.shape[0]) - C @ x_pred
    return S, K, nu


def _pu_no_spread(x_pred, P_pred, detections, C, R, beta):
    S, K, nu = _kalman_parts(x_pred, P_pred, detections, C, R)
    nu_bar = beta[1:] @ nu
    P = beta[0] * P_pred + (1 - beta[0]) * (P_pred - K @ S @ K.T)
    return x_pred + K @ nu_bar, P


def _pu_spread_no_mean(x_pred, P_pred, detections, C, R, beta):
    S, K, nu = _kalman_parts(x_pred, P_pred, detections, C, R)
    nu_bar = beta[1:] @ nu
    spread = (nu.T * beta[1:]) @ nu
    P = beta[0] * P_pred + (1 - beta[0]) * (P_pred - K @ S @ K.T) + K @ spread @ K.T
    return x_pred + K @ nu_bar, P


def _pu_no_mixing(x_pred, P_pred, detections, C, R, beta):
    S, K, nu = _kalman_parts(x_pred, P_pred, detections, C, R)
    nu_bar = beta[1:] @ nu
    spread = (nu.T * beta[1:]) @ nu - np.outer(nu_bar, nu_bar)
    P = P_pred - K @ S @ K.T + K @ spread @ K.T
    return x_pred + K @ nu_bar, P


def _pu_best_only(x_pred, P_pred, detections, C, R, beta):
    S, K, nu = _kalman_parts(x_pred, P_pred, detections, C, R)
    if beta.size == 1 or beta[0] >= beta[1:].max():
        return x_pred, P_pred
    j = int(np.argmax(beta[1:]))
    return x_pred + K @ nu[j], P_pred - K @ S @ K.T


_SPREAD_LINE = (r"^\s*P\w*\s*=", r"spread|dispersion")

PDA_UPDATE = Exercise(
    id="pda-update",
    title="La correction de l'association probabiliste (PDA)",
    chapter="fouillis-association",
    signature="pda_update(x_pred, P_pred, detections, C, R, beta) -> (x, P)",
    parameters=("x_pred", "P_pred", "detections", "C", "R", "beta"),
    outputs=(Output("x"), Output("P", "covariance")),
    make_cases=_update_cases,
    solution=update_solution,
    shapes_hint="x_pred (n,), P_pred (n, n), detections (N, m), C (m, n), R (m, m), beta (N + 1,) ; "
                "innovations (N, m), K (n, m)",
    mistakes=(
        Mistake("no-spread", "terme de dispersion oublié",
                "La covariance PDA est celle d'un mélange : β₀ P⁻ + (1 − β₀)(P⁻ − K S Kᵀ) + K (Σ β_j ν_j ν_jᵀ − "
                "ν̄ ν̄ᵀ) Kᵀ. Le dernier terme, la dispersion des innovations, dit que la PDA ne sait pas quelle "
                "détection est la bonne ; sans lui, la piste est trop sûre d'elle et sa fenêtre trop petite.",
                _pu_no_spread, outputs=(1,), output=1, culprit=_SPREAD_LINE),
        Mistake("spread-no-mean", "dispersion sans retirer ν̄ ν̄ᵀ",
                "La dispersion est une covariance : Σ β_j ν_j ν_jᵀ − ν̄ ν̄ᵀ, avec ν̄ = Σ β_j ν_j. Sans le second "
                "terme, c'est un moment d'ordre deux, pas une covariance.",
                _pu_spread_no_mean, outputs=(1,), output=1, culprit=_SPREAD_LINE),
        Mistake("no-mixing", "β₀ oublié dans la covariance",
                "Avec la probabilité β₀, aucune détection ne vient de la cible et la covariance reste P⁻ : "
                "P = β₀ P⁻ + (1 − β₀)(P⁻ − K S Kᵀ) + dispersion, pas P⁻ − K S Kᵀ + dispersion.",
                _pu_no_mixing, outputs=(1,), output=1, culprit=_SPREAD_LINE),
        Mistake("best-only", "seule la détection la plus probable est utilisée",
                "La PDA ne choisit pas : elle corrige avec l'innovation moyenne ν̄ = Σ β_j ν_j (β₀ compte pour "
                "une innovation nulle). Choisir la plus probable, c'est le plus proche voisin.",
                _pu_best_only, outputs=(0,), output=0, culprit=(r"argmax",)),
    ),
)
