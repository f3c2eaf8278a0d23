r"""Exercices du filtre linéaire : prédiction, correction, forme de Joseph, NIS.

Références : les étapes du paquet (:func:`kalman_course.predict`, :func:`kalman_course.update`) et des
formes closes (Joseph, NIS), indépendantes de ce qu'écrit l'étudiant. Chaque erreur classique est
documentée par l'implémentation fausse qu'écrirait un étudiant.
"""

from __future__ import annotations

import re

import numpy as np

from ..core.models import LinearGaussianModel
from ..filters.kalman import predict as kf_predict
from ..filters.kalman import update as kf_update
from .grading import Case, Exercise, Mistake, Output, close
from .matrices import generator, nonsymmetric, spd

__all__ = ["KF_PREDICT", "KF_UPDATE", "JOSEPH_UPDATE", "NIS"]


# --------------------------------------------------------------------------- prédiction


def _model(A=None, C=None, Q=None, R=None, n=None, m=1) -> LinearGaussianModel:
    n = n if A is None else A.shape[0]
    A = np.eye(n) if A is None else A
    C = np.eye(m, n) if C is None else C
    Q = np.eye(n) if Q is None else Q
    R = np.eye(C.shape[0]) if R is None else R
    return LinearGaussianModel(A, C, Q, R)


def _predict_case(label, x, P, A, Q) -> Case:
    ref = kf_predict(_model(A=A, Q=Q), x, P)
    return Case(label, (x, P, A, Q), (ref.x, ref.P), (x.shape, P.shape))


def _predict_cases() -> list[Case]:
    rng = generator(101)
    cases = [_predict_case("n = 1 (la tension constante)", np.array([-0.3]), np.array([[0.5]]), np.array([[1.0]]),
                           np.array([[1e-5]]))]
    dt = 0.1
    cases.append(_predict_case("n = 2, A non symétrique (position–vitesse)", np.array([1.0, -0.5]),
                               spd(rng, 2), np.array([[1.0, dt], [0.0, 1.0]]),
                               0.3 * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])))
    for n, label in ((3, "n = 3, A quelconque"), (5, "n = 5, A non symétrique, P pleine")):
        cases.append(_predict_case(label, rng.standard_normal(n), spd(rng, n), nonsymmetric(rng, n), spd(rng, n, 0.1)))
    n = 4
    cases.append(_predict_case("n = 4, Q nulle (aucun bruit d'état)", rng.standard_normal(n), spd(rng, n),
                               nonsymmetric(rng, n), np.zeros((n, n))))
    return cases


def predict_solution(x, P, A, Q):
    """Solution de référence (appelle le paquet)."""
    ref = kf_predict(_model(A=np.asarray(A, float), Q=np.asarray(Q, float)), x, P)
    return ref.x, ref.P


def _predict_apa(x, P, A, Q):
    return A @ x, A @ P @ A + Q


def _predict_atpa(x, P, A, Q):
    return A @ x, A.T @ P @ A + Q


def _predict_no_q(x, P, A, Q):
    return A @ x, A @ P @ A.T


def _predict_elementwise(x, P, A, Q):
    return A @ x, A * P * A.T + Q


def _predict_p_plus_q(x, P, A, Q):
    return A @ x, P + Q


def _predict_x_not_propagated(x, P, A, Q):
    return x, A @ P @ A.T + Q


KF_PREDICT = Exercise(
    id="kf-predict",
    title="Prédiction du filtre de Kalman",
    chapter="predicteur-correcteur",
    signature="predict(x, P, A, Q) -> (x_pred, P_pred)",
    parameters=("x", "P", "A", "Q"),
    outputs=(Output("x_pred"), Output("P_pred", "covariance")),
    make_cases=_predict_cases,
    solution=predict_solution,
    shapes_hint="x (n,), P (n, n), A (n, n), Q (n, n) ; x_pred (n,), P_pred (n, n)",
    mistakes=(
        Mistake("apa", "A P A au lieu de A P Aᵀ",
                "La covariance prédite est P⁻ = A P Aᵀ + Q : si x a la covariance P, A x a la covariance A P Aᵀ. "
                "Sans la transposée, P⁻ n'est même plus symétrique dès que A ne l'est pas (écrivez `A @ P @ A.T`).",
                _predict_apa, outputs=(1,), output=1),
        Mistake("atpa", "Aᵀ P A au lieu de A P Aᵀ",
                "La transposée est du mauvais côté : Cov(A x) = A P Aᵀ (`A @ P @ A.T`), pas Aᵀ P A. "
                "Les deux coïncident seulement quand A est symétrique.",
                _predict_atpa, outputs=(1,), output=1),
        Mistake("no-q", "Q oubliée",
                "La prédiction ajoute l'incertitude du modèle : P⁻ = A P Aᵀ + Q. Sans Q, la covariance décroît "
                "sans fin et le filtre finit par ignorer les mesures.",
                _predict_no_q, outputs=(1,), output=1),
        Mistake("elementwise", "`*` au lieu de `@` (produit élément par élément)",
                "En numpy, `*` multiplie élément par élément ; le produit matriciel s'écrit `@` (ou `np.dot`). "
                "Les deux ne coïncident qu'en dimension 1 : le cas n = 1 passait, les autres non.",
                _predict_elementwise, outputs=(1,), output=1),
        Mistake("p-plus-q", "A oubliée dans la covariance",
                "La covariance se propage par la dynamique : P⁻ = A P Aᵀ + Q, pas P + Q (ce n'est juste que si "
                "A = I, comme pour la tension constante).",
                _predict_p_plus_q, outputs=(1,), output=1),
        Mistake("x-not-propagated", "l'état n'est pas propagé",
                "La moyenne prédite est x⁻ = A x : sans A, l'état prédit reste l'ancien (juste seulement si A = I).",
                _predict_x_not_propagated, outputs=(0,), output=0),
    ),
)


# --------------------------------------------------------------------------- correction


def _update_case(label, x, P, y, C, R) -> Case:
    ref = kf_update(_model(C=C, R=R, n=x.shape[0], m=C.shape[0]), x, P, y)
    return Case(label, (x, P, y, C, R), (ref.x, ref.P), (x.shape, P.shape))


def _update_cases() -> list[Case]:
    rng = generator(202)
    cases = [_update_case("n = 1, m = 1 (la tension constante)", np.array([0.0]), np.array([[1.0]]),
                          np.array([-0.37]), np.array([[1.0]]), np.array([[0.01]])),
             _update_case("n = 2, m = 1 (capteur de position)", np.array([0.5, 1.0]), spd(rng, 2),
                          np.array([0.8]), np.array([[1.0, 0.0]]), np.array([[0.04]]))]
    for n, m, label in ((3, 2, "n = 3, m = 2, C quelconque, R pleine"), (4, 3, "n = 4, m = 3, R pleine")):
        x, P = rng.standard_normal(n), spd(rng, n)
        C = rng.standard_normal((m, n))
        cases.append(_update_case(label, x, P, C @ x + rng.standard_normal(m), C, spd(rng, m, 0.5)))
    x, P = rng.standard_normal(2), spd(rng, 2)
    C = np.array([[1.0, 0.5], [-0.3, 1.0]])
    cases.append(_update_case("n = 2, m = 2, capteur très précis (R = 10⁻⁸ I)", x, P,
                              C @ x + rng.standard_normal(2), C, 1e-8 * np.eye(2)))
    return cases


def update_solution(x_pred, P_pred, y, C, R):
    """Solution de référence (appelle le paquet)."""
    C, R = np.asarray(C, float), np.asarray(R, float)
    ref = kf_update(_model(C=C, R=R, n=C.shape[1], m=C.shape[0]), x_pred, P_pred, y)
    return ref.x, ref.P


def _update_gain_r(x_pred, P_pred, y, C, R):
    K = P_pred @ C.T @ np.linalg.inv(R)
    x = x_pred + K @ (y - C @ x_pred)
    P = (np.eye(len(x_pred)) - K @ C) @ P_pred
    return x, P


def _update_p_before_k(x_pred, P_pred, y, C, R):
    S = C @ P_pred @ C.T + R
    P = P_pred - P_pred @ C.T @ np.linalg.inv(S) @ C @ P_pred
    K = P @ C.T @ np.linalg.inv(S)
    x = x_pred + K @ (y - C @ x_pred)
    return x, P


def _update_innovation_sign(x_pred, P_pred, y, C, R):
    S = C @ P_pred @ C.T + R
    K = P_pred @ C.T @ np.linalg.inv(S)
    x = x_pred + K @ (C @ x_pred - y)
    P = (np.eye(len(x_pred)) - K @ C) @ P_pred
    return x, P


def _update_s_without_r(x_pred, P_pred, y, C, R):
    S = C @ P_pred @ C.T
    K = P_pred @ C.T @ np.linalg.inv(S)
    x = x_pred + K @ (y - C @ x_pred)
    P = (np.eye(len(x_pred)) - K @ C) @ P_pred
    return x, P


def _update_no_inverse(x_pred, P_pred, y, C, R):
    S = C @ P_pred @ C.T + R
    K = P_pred @ C.T @ S
    x = x_pred + K @ (y - C @ x_pred)
    P = (np.eye(len(x_pred)) - K @ C) @ P_pred
    return x, P


def _update_joseph_incomplete(x_pred, P_pred, y, C, R):
    S = C @ P_pred @ C.T + R
    K = P_pred @ C.T @ np.linalg.inv(S)
    x = x_pred + K @ (y - C @ x_pred)
    I_KC = np.eye(len(x_pred)) - K @ C
    P = I_KC @ P_pred @ I_KC.T
    return x, P


def _update_identity_size(x_pred, P_pred, y, C, R):
    S = C @ P_pred @ C.T + R
    K = P_pred @ C.T @ np.linalg.inv(S)
    x = x_pred + K @ (y - C @ x_pred)
    P = (np.eye(len(y)) - K @ C) @ P_pred
    return x, P


def _identity_size_error(exc: BaseException, line: str) -> bool:
    """``np.eye(m) - K @ C`` (identité de la taille de la mesure) : numpy ne peut pas diffuser (m, m) sur (n, n)."""
    code = line.split("#", 1)[0]
    return isinstance(exc, ValueError) and "broadcast" in str(exc) and re.search(r"eye\(", code) is not None \
        and re.search(r"eye\(\s*(len\(\s*y|y\.|m\b|C\.shape\[0\]|R\.shape)", code) is not None


def _detect_identity_size(outs, case):
    """Mesure scalaire (m = 1) : ``np.eye(1) - K @ C`` est diffusée, élément par élément, en ``1 − K C``."""
    x_pred, P_pred, y, C, R = case.args
    if y.shape[0] != 1 or x_pred.shape[0] == 1:
        return False
    wrong = _update_identity_size(*case.args)
    return close(outs[1], wrong[1]) and not close(wrong[1], case.expected[1])


def _update_p_not_updated(x_pred, P_pred, y, C, R):
    S = C @ P_pred @ C.T + R
    K = P_pred @ C.T @ np.linalg.inv(S)
    return x_pred + K @ (y - C @ x_pred), P_pred


_GAIN_LINE = (r"^\s*K\w*\s*=",)

KF_UPDATE = Exercise(
    id="kf-update",
    title="Correction du filtre de Kalman",
    chapter="predicteur-correcteur",
    signature="update(x_pred, P_pred, y, C, R) -> (x, P)",
    parameters=("x_pred", "P_pred", "y", "C", "R"),
    outputs=(Output("x"), Output("P", "covariance")),
    make_cases=_update_cases,
    solution=update_solution,
    shapes_hint="x_pred (n,), P_pred (n, n), y (m,), C (m, n), R (m, m) ; S (m, m), K (n, m)",
    mistakes=(
        Mistake("gain-r", "gain P Cᵀ R⁻¹ au lieu de P⁻ Cᵀ S⁻¹",
                "Le gain divise par la covariance de l'innovation S = C P⁻ Cᵀ + R, pas par R seule : "
                "K = P⁻ Cᵀ S⁻¹. (La forme K = P⁺ Cᵀ R⁻¹ existe, mais avec la covariance a posteriori P⁺.)",
                _update_gain_r, culprit=_GAIN_LINE, confirm=(r"\bR",), refute=(r"\bS\b",)),
        Mistake("p-before-k", "P mise à jour avant de calculer K",
                "K = P⁻ Cᵀ S⁻¹ se calcule avec la covariance prédite P⁻ : si P est déjà remplacée par P⁺ quand "
                "vous calculez K, le gain est faux. Calculez S, puis K, puis x et enfin P.",
                _update_p_before_k, outputs=(0,), culprit=_GAIN_LINE, confirm=(r"\bP\b",)),
        Mistake("innovation-sign", "innovation C x⁻ − y au lieu de y − C x⁻",
                "L'innovation est la mesure moins sa prédiction : ν = y − C x⁻. Avec le signe opposé, la "
                "correction éloigne l'estimation de la mesure.",
                _update_innovation_sign, outputs=(0,), culprit=(r"C\w*\s*@\s*x\w*\s*-\s*y", r"dot\(\s*x\w*\s*\)\s*-\s*y")),
        Mistake("s-without-r", "S = C P⁻ Cᵀ (R oubliée)",
                "La covariance de l'innovation contient le bruit de mesure : S = C P⁻ Cᵀ + R. Sans R, le filtre "
                "croit la mesure parfaite et recopie y.",
                _update_s_without_r, culprit=(r"^\s*S\w*\s*=",), refute=(r"\bR\b",)),
        Mistake("no-inverse", "S non inversée dans le gain",
                "K = P⁻ Cᵀ S⁻¹ : il faut diviser par S (`np.linalg.solve(S, C @ P_pred).T`, ou `@ np.linalg.inv(S)`), "
                "pas multiplier.",
                _update_no_inverse, culprit=_GAIN_LINE, refute=(r"inv|solve|/|lstsq",)),
        Mistake("joseph-incomplete", "forme de Joseph sans le terme K R Kᵀ",
                "La forme de Joseph est P = (I − K C) P⁻ (I − K C)ᵀ + K R Kᵀ : le dernier terme (le bruit de "
                "la mesure qui entre par le gain) est indispensable. Ou bien la forme courte P = (I − K C) P⁻.",
                _update_joseph_incomplete, outputs=(1,), output=1),
        Mistake("p-not-updated", "la covariance n'est pas corrigée",
                "Une mesure apporte de l'information : P = (I − K C) P⁻ est plus petite que P⁻. Votre fonction "
                "renvoie P⁻ telle quelle.",
                _update_p_not_updated, outputs=(1,), output=1),
        Mistake("identity-size", "identité de la taille de la mesure au lieu de celle de l'état",
                "Dans P = (I − K C) P⁻, K C est une matrice (n, n) : l'identité est celle de l'état, "
                "`np.eye(len(x_pred))`, pas `np.eye(len(y))`. Avec une mesure scalaire, numpy diffuse "
                "silencieusement `np.eye(1) - K @ C` en 1 − K C élément par élément ; sinon les formes ne vont pas "
                "ensemble.",
                _update_identity_size, detect=_detect_identity_size, exception=_identity_size_error,
                culprit=(r"eye\(\s*(len\(\s*y|y\.|m\b|C\.shape\[0\]|R\.shape)",), output=1),
    ),
)


# --------------------------------------------------------------------------- forme de Joseph


def joseph_reference(x_pred, P_pred, y, C, R, K):
    r"""Forme close : :math:`x = x^- + K(y - Cx^-)`, :math:`P = (I-KC)P^-(I-KC)^T + KRK^T` (tout gain)."""
    I_KC = np.eye(len(x_pred)) - K @ C
    return x_pred + K @ (y - C @ x_pred), I_KC @ P_pred @ I_KC.T + K @ R @ K.T


def _joseph_case(label, x, P, y, C, R, K) -> Case:
    ref = joseph_reference(x, P, y, C, R, K)
    return Case(label, (x, P, y, C, R, K), ref, (x.shape, P.shape))


def _optimal_gain(P, C, R):
    return np.linalg.solve(C @ P @ C.T + R, C @ P).T


def _joseph_cases() -> list[Case]:
    rng = generator(303)
    cases = []
    x, P = np.array([0.0]), np.array([[1.0]])
    C, R = np.array([[1.0]]), np.array([[0.01]])
    cases.append(_joseph_case("n = 1, gain fixe K = 0,5 (sous-optimal)", x, P, np.array([-0.37]), C, R,
                              np.array([[0.5]])))
    for n, m, factor, label in ((2, 1, 0.5, "n = 2, m = 1, moitié du gain optimal"),
                                (3, 2, None, "n = 3, m = 2, gain quelconque"),
                                (4, 2, 1.0, "n = 4, m = 2, gain optimal (toutes les formes coïncident)")):
        x, P = rng.standard_normal(n), spd(rng, n)
        C, R = rng.standard_normal((m, n)), spd(rng, m, 0.5)
        K = 0.3 * rng.standard_normal((n, m)) if factor is None else factor * _optimal_gain(P, C, R)
        cases.append(_joseph_case(label, x, P, C @ x + rng.standard_normal(m), C, R, K))
    n, m = 3, 1
    x, P = rng.standard_normal(n), spd(rng, n)
    C = rng.standard_normal((m, n))
    cases.append(_joseph_case("n = 3, m = 1, gain nul (la mesure est ignorée)", x, P, rng.standard_normal(m), C,
                              np.array([[0.2]]), np.zeros((n, m))))
    return cases


def _joseph_short(x_pred, P_pred, y, C, R, K):
    return x_pred + K @ (y - C @ x_pred), (np.eye(len(x_pred)) - K @ C) @ P_pred


def _joseph_no_krk(x_pred, P_pred, y, C, R, K):
    I_KC = np.eye(len(x_pred)) - K @ C
    return x_pred + K @ (y - C @ x_pred), I_KC @ P_pred @ I_KC.T


def _joseph_no_transpose(x_pred, P_pred, y, C, R, K):
    I_KC = np.eye(len(x_pred)) - K @ C
    return x_pred + K @ (y - C @ x_pred), I_KC @ P_pred @ I_KC + K @ R @ K.T


def _joseph_recomputed_gain(x_pred, P_pred, y, C, R, K):
    K = P_pred @ C.T @ np.linalg.inv(C @ P_pred @ C.T + R)
    I_KC = np.eye(len(x_pred)) - K @ C
    return x_pred + K @ (y - C @ x_pred), I_KC @ P_pred @ I_KC.T + K @ R @ K.T


JOSEPH_UPDATE = Exercise(
    id="joseph-update",
    title="Correction avec un gain quelconque (forme de Joseph)",
    chapter="pratique-synthese",
    signature="joseph_update(x_pred, P_pred, y, C, R, K) -> (x, P)",
    parameters=("x_pred", "P_pred", "y", "C", "R", "K"),
    outputs=(Output("x"), Output("P", "covariance")),
    make_cases=_joseph_cases,
    solution=joseph_reference,
    shapes_hint="x_pred (n,), P_pred (n, n), y (m,), C (m, n), R (m, m), K (n, m)",
    mistakes=(
        Mistake("short-form", "forme courte (I − K C) P⁻ avec un gain quelconque",
                "P = (I − K C) P⁻ n'est juste que pour le gain optimal. Pour un gain quelconque, seule la "
                "forme de Joseph P = (I − K C) P⁻ (I − K C)ᵀ + K R Kᵀ donne la vraie covariance de l'erreur.",
                _joseph_short, outputs=(1,), output=1),
        Mistake("no-krk", "terme K R Kᵀ oublié",
                "Le bruit de mesure entre dans l'erreur par le gain : il faut ajouter K R Kᵀ à "
                "(I − K C) P⁻ (I − K C)ᵀ.",
                _joseph_no_krk, outputs=(1,), output=1),
        Mistake("no-transpose", "(I − K C) P⁻ (I − K C) sans transposée",
                "La forme de Joseph est une congruence : (I − K C) P⁻ (I − K C)ᵀ, avec la transposée à droite ; "
                "sans elle, P n'est plus symétrique.",
                _joseph_no_transpose, outputs=(1,), output=1),
        Mistake("recomputed-gain", "gain optimal recalculé au lieu du gain K donné",
                "L'exercice donne le gain K (par exemple un gain fixe, ou le gain d'un filtre mal réglé) : "
                "utilisez-le tel quel, ne recalculez pas P⁻ Cᵀ S⁻¹.",
                _joseph_recomputed_gain, culprit=_GAIN_LINE, confirm=(r"\bC\b",)),
    ),
)


# --------------------------------------------------------------------------- NIS


def nis_reference(innovations, S):
    r"""Forme close : :math:`\epsilon_k = \nu_k^T S_k^{-1}\nu_k` par résolution linéaire, forme (T,)."""
    return np.einsum("ti,ti->t", innovations, np.linalg.solve(S, innovations[..., None])[..., 0])


def _nis_case(label, nu, S) -> Case:
    return Case(label, (nu, S), (nis_reference(nu, S),), ((nu.shape[0],),))


def _nis_cases() -> list[Case]:
    rng = generator(404)
    cases = [_nis_case("T = 5, m = 1", rng.standard_normal((5, 1)), np.full((5, 1, 1), 0.5))]
    for T, m, label in ((10, 2, "T = 10, m = 2, S pleine"), (4, 3, "T = 4, m = 3, S pleine")):
        S = np.array([spd(rng, m) for _ in range(T)])
        cases.append(_nis_case(label, rng.standard_normal((T, m)), S))
    cases.append(_nis_case("T = 1, m = 2, innovation nulle", np.zeros((1, 2)), spd(rng, 2)[None]))
    return cases


def nis_solution(innovations, S):
    """Solution de référence (forme close, résolution linéaire)."""
    return nis_reference(np.asarray(innovations, float), np.asarray(S, float))


def _nis_s_not_inverted(innovations, S):
    return np.array([nu @ Sk @ nu for nu, Sk in zip(innovations, S)])


def _nis_no_s(innovations, S):
    return np.array([nu @ nu for nu in innovations])


def _nis_sum(innovations, S):
    return sum(nu @ np.linalg.inv(Sk) @ nu for nu, Sk in zip(innovations, S))


def _nis_diagonal(innovations, S):
    return np.array([np.sum(nu**2 / np.diag(Sk)) for nu, Sk in zip(innovations, S)])


def _nis_divided(innovations, S):
    return np.array([nu @ np.linalg.inv(Sk) @ nu / len(nu) for nu, Sk in zip(innovations, S)])


NIS = Exercise(
    id="nis",
    title="Innovation normalisée au carré (NIS)",
    chapter="tests-statistiques",
    signature="nis(innovations, S) -> eps",
    parameters=("innovations", "S"),
    outputs=(Output("eps"),),
    make_cases=_nis_cases,
    solution=nis_solution,
    shapes_hint="innovations (T, m), S (T, m, m) ; eps (T,), une valeur par pas",
    mistakes=(
        Mistake("s-not-inverted", "νᵀ S ν au lieu de νᵀ S⁻¹ ν",
                "La NIS normalise l'innovation par sa covariance : ε = νᵀ S⁻¹ ν (`nu @ np.linalg.solve(S_k, nu)`). "
                "Avec S au lieu de S⁻¹, ε n'a plus la loi du χ² à m degrés de liberté.", _nis_s_not_inverted),
        Mistake("no-s", "S oubliée (νᵀ ν)",
                "ε = νᵀ S⁻¹ ν : sans S, la taille de l'innovation n'est pas comparée à ce que le filtre attend, "
                "et le test du χ² n'a plus de sens (unités, échelles).", _nis_no_s),
        Mistake("sum", "somme sur le temps au lieu d'une valeur par pas",
                "La fonction doit renvoyer une NIS par pas, forme (T,) : la somme (ou la moyenne) se fait ensuite, "
                "pour le test du χ² à T m degrés de liberté.", _nis_sum,
                detect=lambda outs, case: outs[0].shape == () and close(outs[0], case.expected[0].sum())),
        Mistake("diagonal-only", "seulement la diagonale de S",
                "Σ νᵢ² / Sᵢᵢ ignore les corrélations entre composantes de l'innovation : ce n'est νᵀ S⁻¹ ν que "
                "si S est diagonale. Résolvez le système complet (`np.linalg.solve(S_k, nu)`).", _nis_diagonal),
        Mistake("divided-by-m", "NIS divisé par m",
                "ε = νᵀ S⁻¹ ν suit un χ² à m degrés de liberté, de moyenne m : ne divisez pas par m (la "
                "normalisation se fait dans le test, pas dans ε).", _nis_divided),
    ),
)
