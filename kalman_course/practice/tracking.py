r"""Exercices du pistage (TP 5, l'hélicoptère du SAMU 31) : modèle à vitesse presque constante, discrétisation
de Van Loan, porte sur la NIS, et les trois calculs propres à l'IMM (mélange, probabilités des régimes,
combinaison).

Références indépendantes de ce qu'écrit l'étudiant : l'intégrale
:math:`Q = \int_0^{\Delta t} e^{Fs}LQ_cL^Te^{F^Ts}\,\mathrm ds` par quadrature adaptative
(:func:`scipy.integrate.quad_vec`) et :math:`A = e^{F\Delta t}` par :func:`scipy.linalg.expm` (pas par la
méthode de Van Loan) ; le quantile du :math:`\chi^2` de :mod:`scipy.stats` ; les étapes de l'IMM du paquet
(:func:`kalman_course.filters.imm.mode_mixing`, :func:`kalman_course.filters.imm.imm_family`), et les
densités gaussiennes de :mod:`scipy.stats` normalisées par ``logsumexp`` (:mod:`scipy.special`).
"""

from __future__ import annotations

import re

import numpy as np
import scipy.linalg

from .grading import Case, Exercise, Mistake, Output, close
from .matrices import generator, spd

__all__ = ["CV_MODEL", "VAN_LOAN", "NIS_GATE", "IMM_MIX", "MODE_PROBABILITIES", "IMM_MERGE",
           "noise_integral", "cv_sde"]


# --------------------------------------------------------------------------- références


def noise_integral(F: np.ndarray, L: np.ndarray, Qc: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    r""":math:`A = e^{F\Delta t}` (``expm``) et :math:`Q = \int_0^{\Delta t} e^{Fs}LQ_cL^Te^{F^Ts}\,\mathrm ds`
    par quadrature adaptative (``scipy.integrate.quad_vec``), sans la méthode de Van Loan."""
    import scipy.integrate

    G = L @ Qc @ L.T

    def integrand(s):
        E = scipy.linalg.expm(F * s)
        return E @ G @ E.T

    Q, _ = scipy.integrate.quad_vec(integrand, 0.0, dt, epsabs=1e-13, epsrel=1e-12)
    return scipy.linalg.expm(F * dt), 0.5 * (Q + Q.T)


def cv_sde(dim: int = 2) -> tuple[np.ndarray, np.ndarray]:
    r"""La vitesse presque constante en temps continu, état positions puis vitesses :
    :math:`F = \begin{bmatrix} 0 & I \\ 0 & 0\end{bmatrix}`, :math:`L = \begin{bmatrix} 0 \\ I\end{bmatrix}`."""
    F = np.zeros((2 * dim, 2 * dim))
    F[:dim, dim:] = np.eye(dim)
    L = np.zeros((2 * dim, dim))
    L[dim:] = np.eye(dim)
    return F, L


# --------------------------------------------------------------------------- modèle à vitesse presque constante


def _cv_case(label, dt, q) -> Case:
    F, L = cv_sde(2)
    A, Q = noise_integral(F, L, q * np.eye(2), dt)
    return Case(label, (dt, q), (A, Q), ((4, 4), (4, 4)), {"dt": dt, "q": q})


def _cv_cases() -> list[Case]:
    return [
        _cv_case("Δt = 1 s, q = 1 m²/s³", 1.0, 1.0),
        _cv_case("Δt = 0,4 s, q = 12,5 m²/s³ (deux messages rapprochés de l'hélicoptère)", 0.4, 12.5),
        _cv_case("Δt = 8 s, q = 0,1 m²/s³ (un long silence)", 8.0, 0.1),
        _cv_case("Δt = 3 s, q = 30 m²/s³ (régime agité)", 3.0, 30.0),
        _cv_case("Δt = 10⁻³ s, q = 2 m²/s³ (pas minuscule)", 1e-3, 2.0),
    ]


def _cv_blocks(dt, q, a, b, c):
    """État [e, n, v_e, v_n] : A exacte, Q = q [[a I, b I], [b I, c I]]."""
    I2 = np.eye(2)
    A = np.block([[I2, dt * I2], [np.zeros((2, 2)), I2]])
    return A, q * np.block([[a * I2, b * I2], [b * I2, c * I2]])


def cv_model_solution(dt, q):
    """Solution de référence (forme close de l'intégrale)."""
    return _cv_blocks(float(dt), float(q), dt**3 / 3, dt**2 / 2, dt)


def _cv_no_dt3(dt, q):
    return _cv_blocks(dt, q, 0.0, dt**2 / 2, dt)


def _cv_discrete_white_noise(dt, q):
    return _cv_blocks(dt, q, dt**4 / 4, dt**3 / 2, dt**2)


def _cv_not_halved(dt, q):
    return _cv_blocks(dt, q, dt**3 / 3, dt**2, dt)


def _cv_euler(dt, q):
    return _cv_blocks(dt, q, 0.0, 0.0, dt)


def _cv_interleaved(dt, q):
    A1 = np.array([[1.0, dt], [0.0, 1.0]])
    Q1 = q * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
    return np.kron(np.eye(2), A1), np.kron(np.eye(2), Q1)


def _cv_a_transposed(dt, q):
    A, Q = cv_model_solution(dt, q)
    return A.T, Q


def _cv_dt3_over_2(dt, q):
    return _cv_blocks(dt, q, dt**3 / 2, dt**2 / 2, dt)


CV_MODEL = Exercise(
    id="cv-model",
    title="Modèle à vitesse presque constante : A et Q pour un pas Δt",
    chapter="capteurs-temps-irregulier",
    signature="cv_model(dt, q) -> (A, Q)",
    parameters=("dt", "q"),
    outputs=(Output("A", "matrice"), Output("Q", "covariance")),
    make_cases=_cv_cases,
    solution=cv_model_solution,
    shapes_hint="dt (s) et q (m²/s³) des nombres ; A (4, 4), Q (4, 4), état [e, n, v_e, v_n]",
    mistakes=(
        Mistake("no-dt3", "Q sans le terme Δt³/3 des positions",
                "L'accélération blanche agit aussi sur les positions : Q = q [[Δt³/3 I, Δt²/2 I], [Δt²/2 I, Δt I]]. "
                "Sans le bloc Δt³/3, Q n'est même plus semi-définie positive (son déterminant par axe vaut "
                "−q²Δt⁴/4) : le filtre croirait connaître la position sans incertitude de modèle.",
                _cv_no_dt3, outputs=(1,), output=1),
        Mistake("discrete-white-noise", "accélération constante par morceaux (Δt⁴/4, Δt³/2, Δt²)",
                "q [[Δt⁴/4, Δt³/2], [Δt³/2, Δt²]] est le modèle d'une accélération **constante sur le pas** et de "
                "variance q (`Q_discrete_white_noise` de filterpy) ; une accélération **blanche** de densité q donne "
                "l'intégrale q [[Δt³/3, Δt²/2], [Δt²/2, Δt]]. Les unités le disent : q est en m²/s³.",
                _cv_discrete_white_noise, outputs=(1,), output=1),
        Mistake("not-halved", "Δt² au lieu de Δt²/2 hors de la diagonale",
                "Le terme croisé position–vitesse est ∫₀^Δt s ds = Δt²/2 (fois q), pas Δt².",
                _cv_not_halved, outputs=(1,), output=1),
        Mistake("dt3-over-2", "Δt³/2 au lieu de Δt³/3",
                "Le bloc des positions est ∫₀^Δt s² ds = Δt³/3 (fois q) : la position au bout du pas accumule "
                "l'accélération intégrée deux fois.",
                _cv_dt3_over_2, outputs=(1,), output=1),
        Mistake("euler", "bruit sur les vitesses seulement (Q = q Δt sur les vitesses)",
                "Q = q Δt sur les vitesses est l'approximation d'Euler, au premier ordre en Δt : juste pour un pas "
                "minuscule, fausse dès que Δt n'est plus petit (les positions ont leur propre incertitude, "
                "q Δt³/3, et la corrélation q Δt²/2).",
                _cv_euler, outputs=(1,), output=1),
        Mistake("interleaved", "état rangé [e, v_e, n, v_n] au lieu de [e, n, v_e, v_n]",
                "Le cours range l'état positions d'abord, puis vitesses : x = [e, n, v_e, v_n] (c'est ce que "
                "mesure C = [I₂ 0]). Vos matrices sont celles de l'ordre [e, v_e, n, v_n], axe par axe (l'ordre de "
                "filterpy) : permutez les lignes et les colonnes.",
                _cv_interleaved),
        Mistake("a-transposed", "Δt sous la diagonale de A",
                "La position avance de la vitesse : e_k = e_{k−1} + Δt v_{e,k−1}. Le bloc Δt I est donc en haut à "
                "droite de A (ligne des positions, colonne des vitesses), pas en bas à gauche.",
                _cv_a_transposed, outputs=(0,), output=0),
    ),
)


# --------------------------------------------------------------------------- Van Loan


def _van_loan_case(label, F, L, Qc, dt) -> Case:
    A, Q = noise_integral(F, L, Qc, dt)
    n = F.shape[0]
    return Case(label, (F, L, Qc, dt), (A, Q), ((n, n), (n, n)))


def _van_loan_cases() -> list[Case]:
    rng = generator(1414)
    F1, L1 = cv_sde(1)
    F2, L2 = cv_sde(2)
    Fa = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
    La = np.array([[0.0], [0.0], [1.0]])
    Fs = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -0.5]])  # Singer : accélération amortie
    w, zeta = 2.0, 0.1
    Fo = np.array([[0.0, 1.0], [-w**2, -2 * zeta * w]])  # oscillateur amorti
    return [
        _van_loan_case("vitesse presque constante sur un axe, n = 2, Δt = 0,5 s", F1, L1, np.array([[3.0]]), 0.5),
        _van_loan_case("vitesse presque constante en 2-D, n = 4, Qc = diag(1 ; 4), Δt = 2 s", F2, L2,
                       np.diag([1.0, 4.0]), 2.0),
        _van_loan_case("Ornstein–Uhlenbeck, n = 1 (F = −0,3), Δt = 5 s", np.array([[-0.3]]), np.array([[1.0]]),
                       np.array([[0.8]]), 5.0),
        _van_loan_case("accélération presque constante, n = 3, Δt = 1,5 s", Fa, La, np.array([[0.2]]), 1.5),
        _van_loan_case("modèle de Singer (accélération amortie), n = 3, Δt = 0,7 s", Fs, La, np.array([[2.0]]), 0.7),
        _van_loan_case("oscillateur amorti, F non nilpotente, n = 2, Δt = 1,3 s", Fo, np.array([[0.0], [1.0]]),
                       np.array([[0.5]]), 1.3),
        _van_loan_case("n = 3, F, L (3, 2) et Qc pleine quelconques, Δt = 0,25 s", 0.5 * rng.standard_normal((3, 3)),
                       rng.standard_normal((3, 2)), spd(rng, 2), 0.25),
    ]


def van_loan_solution(F, L, Qc, dt):
    """Solution de référence (méthode de Van Loan, comme dans le paquet)."""
    F, L, Qc = (np.asarray(a, dtype=float) for a in (F, L, Qc))
    n = F.shape[0]
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n], M[:n, n:], M[n:, n:] = -F, L @ Qc @ L.T, F.T
    E = scipy.linalg.expm(M * dt)
    A = E[n:, n:].T
    Q = A @ E[:n, n:]
    return A, 0.5 * (Q + Q.T)


def _vl_blocks(F, L, Qc, dt, top_left=None, scale=True):
    n = F.shape[0]
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n] = -F if top_left is None else top_left
    M[:n, n:] = L @ Qc @ L.T
    M[n:, n:] = F.T
    return scipy.linalg.expm(M * dt if scale else M), n


def _vl_plus_f(F, L, Qc, dt):
    E, n = _vl_blocks(F, L, Qc, dt, top_left=F)
    A = E[n:, n:].T
    return A, A @ E[:n, n:]


def _vl_no_dt(F, L, Qc, dt):
    E, n = _vl_blocks(F, L, Qc, dt, scale=False)
    A = E[n:, n:].T
    return A, A @ E[:n, n:]


def _vl_block_is_q(F, L, Qc, dt):
    E, n = _vl_blocks(F, L, Qc, dt)
    return E[n:, n:].T, E[:n, n:]


def _vl_a_not_transposed(F, L, Qc, dt):
    E, n = _vl_blocks(F, L, Qc, dt)
    A = E[n:, n:]
    return A, A @ E[:n, n:]


def _vl_wrong_side(F, L, Qc, dt):
    E, n = _vl_blocks(F, L, Qc, dt)
    A = E[n:, n:].T
    return A, E[:n, n:] @ A


def _vl_euler(F, L, Qc, dt):
    return scipy.linalg.expm(F * dt), L @ Qc @ L.T * dt


def _qc_without_l(exc: BaseException, line: str) -> bool:
    """``M[:n, n:] = Qc`` (sans L … Lᵀ) : numpy ne peut pas placer (q, q) dans le bloc (n, n)."""
    code = line.split("#", 1)[0]
    return isinstance(exc, ValueError) and "broadcast" in str(exc) and re.search(r"\bQc\b", code) is not None \
        and re.search(r"\bL\b", code) is None


def _vl_qc_without_l(F, L, Qc, dt):
    n = F.shape[0]
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n], M[:n, n:], M[n:, n:] = -F, Qc, F.T
    E = scipy.linalg.expm(M * dt)
    A = E[n:, n:].T
    return A, A @ E[:n, n:]


def _detect_qc_without_l(outs, case):
    """Qc (1, 1) diffusée dans le bloc (n, n) : pas d'exception, des valeurs fausses."""
    F, L, Qc, dt = case.args
    if Qc.shape[0] != 1 or L.shape[0] == 1:
        return False
    A, Q = _vl_qc_without_l(F, L, Qc, dt)
    return close(outs[0], A) and close(outs[1], Q)


VAN_LOAN = Exercise(
    id="van-loan",
    title="Discrétisation exacte par la méthode de Van Loan",
    chapter="capteurs-temps-irregulier",
    signature="van_loan(F, L, Qc, dt) -> (A, Q)",
    parameters=("F", "L", "Qc", "dt"),
    outputs=(Output("A", "matrice"), Output("Q", "covariance")),
    make_cases=_van_loan_cases,
    solution=van_loan_solution,
    shapes_hint="F (n, n), L (n, q), Qc (q, q), dt (s) un nombre ; A (n, n), Q (n, n)",
    mistakes=(
        Mistake("plus-f", "F au lieu de −F dans le bloc en haut à gauche",
                "La matrice de Van Loan est M = [[−F, L Qc Lᵀ], [0, Fᵀ]] Δt : avec −F en haut à gauche, le bloc en "
                "haut à droite de e^M vaut ∫₀^Δt e^{−F(Δt−s)} … e^{Fᵀs} ds = A⁻¹Q. Avec +F, ce n'est plus A⁻¹Q "
                "(l'erreur ne se voit pas quand F = 0).",
                _vl_plus_f, outputs=(1,), output=1),
        Mistake("no-dt", "M sans le facteur Δt",
                "L'exponentielle est celle de M Δt : sans Δt, vous discrétisez toujours sur une seconde (juste "
                "seulement si Δt = 1 s).",
                _vl_no_dt, culprit=(r"expm\(",), refute=(r"dt|\bh\b|delta",)),
        Mistake("block-is-q", "bloc en haut à droite pris pour Q",
                "Le bloc en haut à droite de e^{MΔt} est A⁻¹Q, pas Q : multipliez-le à gauche par A "
                "(`Q = A @ E[:n, n:]`). Les deux coïncident seulement quand A = I.",
                _vl_block_is_q, outputs=(1,), output=1),
        Mistake("a-not-transposed", "bloc en bas à droite pris pour A (il vaut Aᵀ)",
                "Le bloc en bas à droite de e^{MΔt} est e^{FᵀΔt} = Aᵀ : transposez-le (`A = E[n:, n:].T`).",
                _vl_a_not_transposed, outputs=(0,), output=0),
        Mistake("wrong-side", "(A⁻¹Q) A au lieu de A (A⁻¹Q)",
                "Q = A · (A⁻¹Q) : le facteur A est à gauche du bloc. (A⁻¹Q) A = A⁻¹ Q A n'est pas Q, ni même "
                "symétrique.",
                _vl_wrong_side, outputs=(1,), output=1),
        Mistake("euler", "Q ≈ L Qc Lᵀ Δt (premier ordre)",
                "L Qc Lᵀ Δt est l'approximation d'Euler de l'intégrale, juste quand Δt est petit devant les "
                "temps propres de F ; la méthode de Van Loan donne l'intégrale exacte.",
                _vl_euler, outputs=(1,), output=1),
        Mistake("qc-without-l", "Qc au lieu de L Qc Lᵀ dans la matrice de Van Loan",
                "Le bruit entre dans l'état par L : le bloc en haut à droite de M est L Qc Lᵀ, de forme (n, n) "
                "(Qc est (q, q), en général plus petite).",
                _vl_qc_without_l, detect=_detect_qc_without_l, exception=_qc_without_l),
    ),
)


# --------------------------------------------------------------------------- porte sur la NIS


def _chi2(p, m):
    import scipy.stats

    return float(scipy.stats.chi2.ppf(p, m))


def _gate_case(label, nu, S, p) -> Case:
    eps = float(nu @ np.linalg.solve(S, nu))
    threshold = _chi2(p, nu.shape[0])
    return Case(label, (nu, S, p), (np.array(eps), np.array(threshold), np.array(float(eps <= threshold))),
                ((), (), ()), {"m": nu.shape[0]})


def _gate_cases() -> list[Case]:
    rng = generator(1515)
    S2 = np.array([[16.0, 3.0], [3.0, 9.0]])
    S3 = spd(rng, 3, 2.0)
    S4 = spd(rng, 4)
    return [
        _gate_case("m = 2, p = 0,999, innovation de 30 m (une position aberrante de l'hélicoptère)",
                   np.array([24.0, -18.0]), S2, 0.999),
        _gate_case("m = 2, p = 0,99, innovation ordinaire (acceptée)", np.array([3.0, 2.5]), S2, 0.99),
        _gate_case("m = 1, p = 0,95, ε juste sous le seuil", np.array([3.8]), np.array([[3.8**2 / 3.8]]), 0.95),
        _gate_case("m = 3, S pleine, p = 0,99", np.array([2.0, -3.5, 1.0]), S3, 0.99),
        _gate_case("m = 4 (positions et vitesses), p = 0,9", np.array([1.2, -0.8, 2.1, 0.5]), S4, 0.9),
        _gate_case("m = 2, p = 0,5 (porte médiane)", np.array([1.0, 1.0]), np.eye(2), 0.5),
    ]


def nis_gate_solution(nu, S, p):
    """Solution de référence : ε par résolution linéaire, seuil χ²_m(p) (scipy)."""
    nu, S = np.asarray(nu, dtype=float), np.asarray(S, dtype=float)
    eps = float(nu @ np.linalg.solve(S, nu))
    threshold = _chi2(p, nu.shape[0])
    return eps, threshold, eps <= threshold


def _gate_dof(d):
    def wrong(nu, S, p):
        eps = float(nu @ np.linalg.solve(S, nu))
        threshold = _chi2(p, d)
        return eps, threshold, eps <= threshold
    return wrong


def _detect_wrong_dof(outs, case):
    m, p = case.info["m"], case.args[2]
    return any(close(outs[1], _chi2(p, d)) for d in range(1, 7) if d != m)


def _gate_one_minus_p(nu, S, p):
    eps = float(nu @ np.linalg.solve(S, nu))
    threshold = _chi2(1 - p, len(nu))
    return eps, threshold, eps <= threshold


def _gate_sqrt(nu, S, p):
    eps = float(np.sqrt(nu @ np.linalg.solve(S, nu)))
    threshold = _chi2(p, len(nu))
    return eps, threshold, eps <= threshold


def _gate_s_not_inverted(nu, S, p):
    eps = float(nu @ S @ nu)
    threshold = _chi2(p, len(nu))
    return eps, threshold, eps <= threshold


def _gate_inverted(nu, S, p):
    eps = float(nu @ np.linalg.solve(S, nu))
    threshold = _chi2(p, len(nu))
    return eps, threshold, eps > threshold


NIS_GATE = Exercise(
    id="nis-gate",
    title="Porte sur la NIS : accepter ou rejeter une mesure",
    chapter="capteurs-temps-irregulier",
    signature="nis_gate(nu, S, p) -> (eps, threshold, accept)",
    parameters=("nu", "S", "p"),
    outputs=(Output("eps", "scalaire"), Output("threshold", "scalaire"), Output("accept", "scalaire")),
    make_cases=_gate_cases,
    solution=nis_gate_solution,
    shapes_hint="nu (m,), S (m, m), p dans (0, 1) ; eps, threshold des nombres, accept un booléen",
    mistakes=(
        Mistake("wrong-dof", "quantile du χ² avec un mauvais nombre de degrés de liberté",
                "Si le modèle est juste, ε = νᵀ S⁻¹ ν suit une loi du χ² à **m** degrés de liberté, m = len(nu) "
                "le nombre de composantes **mesurées** (2 pour une position plane, 4 avec les vitesses) : ni 1, ni "
                "la dimension n de l'état. Le seuil est `scipy.stats.chi2.ppf(p, len(nu))`.",
                _gate_dof(1), detect=_detect_wrong_dof, culprit=(r"ppf\(|chi2|isf\(",),
                refute=(r"len\(\s*nu|nu\.(shape|size)|\bm\b",), output=1),
        Mistake("one-minus-p", "quantile 1 − p au lieu de p",
                "La porte garde une mesure conforme au modèle avec la probabilité p : le seuil est le quantile p, "
                "`chi2.ppf(p, m)` (ou `chi2.isf(1 - p, m)`). Le quantile 1 − p rejette presque tout.",
                _gate_one_minus_p, outputs=(1,), output=1, culprit=(r"ppf\(|isf\(",)),
        Mistake("sqrt", "distance de Mahalanobis √ε comparée au quantile du χ²",
                "Le quantile du χ² se compare à ε = νᵀ S⁻¹ ν lui-même, pas à sa racine (la distance de Mahalanobis, "
                "qu'il faudrait comparer à la racine du quantile).",
                _gate_sqrt, outputs=(0,), output=0, culprit=(r"sqrt",)),
        Mistake("s-not-inverted", "νᵀ S ν au lieu de νᵀ S⁻¹ ν",
                "La NIS normalise l'innovation par sa covariance : ε = νᵀ S⁻¹ ν (`nu @ np.linalg.solve(S, nu)`).",
                _gate_s_not_inverted, outputs=(0,), output=0),
        Mistake("inverted-decision", "décision inversée",
                "On accepte la mesure quand elle est **dans** la porte, ε ≤ seuil ; on la rejette quand ε dépasse "
                "le seuil.",
                _gate_inverted, outputs=(2,), output=2),
    ),
)


# --------------------------------------------------------------------------- IMM : mélange


def _mix_reference(X, P, mu, transition):
    """Le mélange du paquet : :func:`~kalman_course.filters.imm.mode_mixing` pour c̄ et les poids, puis la
    prédiction de l'IMM du paquet par des régimes immobiles (A = I, Q = 0), qui rend x⁰ et P⁰."""
    from ..core.models import LinearGaussianModel
    from ..filters.imm import IMMState, ModeSet, imm_family, mode_mixing

    r, n = X.shape
    cbar, _ = mode_mixing(transition, mu)
    still = [LinearGaussianModel(np.eye(n), np.eye(1, n), np.zeros((n, n)), 1.0) for _ in range(r)]
    state = imm_family().predict(ModeSet(still, transition), IMMState(X, P, mu, mu), None)
    return cbar, state.X, state.P


def _mix_case(label, X, P, mu, transition) -> Case:
    ref = _mix_reference(X, P, mu, transition)
    r, n = X.shape
    return Case(label, (X, P, mu, transition), ref, ((r,), (r, n), (r, n, n)))


def _mix_cases() -> list[Case]:
    rng = generator(1616)
    cases = []
    cases.append(_mix_case("r = 2, n = 1, transition non symétrique", np.array([[1.0], [3.0]]),
                           np.array([[[0.5]], [[2.0]]]), np.array([0.7, 0.3]), np.array([[0.9, 0.1], [0.4, 0.6]])))
    X = np.array([[100.0, 50.0, 12.0, -3.0], [104.0, 47.0, 9.0, 1.0]])
    P = np.array([spd(rng, 4, 4.0), spd(rng, 4, 9.0)])
    cases.append(_mix_case("r = 2, n = 4 (l'hélicoptère : calme et agité), transition [[0,95 ; 0,05], [0,2 ; 0,8]]",
                           X, P, np.array([0.85, 0.15]), np.array([[0.95, 0.05], [0.2, 0.8]])))
    T3 = np.array([[0.8, 0.15, 0.05], [0.1, 0.7, 0.2], [0.3, 0.1, 0.6]])
    cases.append(_mix_case("r = 3, n = 2, transition pleine", rng.standard_normal((3, 2)) * 3,
                           np.array([spd(rng, 2) for _ in range(3)]), np.array([0.5, 0.3, 0.2]), T3))
    cases.append(_mix_case("r = 2, n = 2, un régime presque certain (μ = 0,999 ; 0,001)", rng.standard_normal((2, 2)),
                           np.array([spd(rng, 2) for _ in range(2)]), np.array([0.999, 0.001]),
                           np.array([[0.97, 0.03], [0.1, 0.9]])))
    cases.append(_mix_case("r = 1 (un seul régime : rien à mélanger)", np.array([[1.0, -1.0, 0.5]]),
                           spd(rng, 3)[None], np.array([1.0]), np.array([[1.0]])))
    return cases


def imm_mix_solution(X, P, mu, transition):
    """Solution de référence (appelle le paquet)."""
    return _mix_reference(*(np.asarray(a, dtype=float) for a in (X, P, mu, transition)))


def _mix_formula(X, P, mu, Pi, spread=True, normalise=True):
    r = len(mu)
    cbar = mu @ Pi
    W = Pi * mu[:, None]
    if normalise:
        W = W / cbar
    X0 = W.T @ X
    P0 = np.zeros_like(P)
    for j in range(r):
        for i in range(r):
            d = X[i] - X0[j]
            P0[j] += W[i, j] * (P[i] + (np.outer(d, d) if spread else 0.0))
    return cbar, X0, P0


def _mix_transposed(X, P, mu, transition):
    return _mix_formula(X, P, mu, transition.T)


def _mix_no_spread(X, P, mu, transition):
    return _mix_formula(X, P, mu, transition, spread=False)


def _mix_not_normalised(X, P, mu, transition):
    return _mix_formula(X, P, mu, transition, normalise=False)


def _mix_none(X, P, mu, transition):
    return mu @ transition, X.copy(), P.copy()


def _mix_row_normalised(X, P, mu, transition):
    cbar = mu @ transition
    W = transition * mu[:, None]
    W = W / W.sum(axis=1, keepdims=True)
    X0 = W.T @ X
    P0 = np.array([sum(W[i, j] * (P[i] + np.outer(X[i] - X0[j], X[i] - X0[j])) for i in range(len(mu)))
                   for j in range(len(mu))])
    return cbar, X0, P0


IMM_MIX = Exercise(
    id="imm-mix",
    title="IMM : mélange des estimations des régimes",
    chapter="cibles-manoeuvrantes",
    signature="imm_mix(X, P, mu, transition) -> (cbar, X0, P0)",
    parameters=("X", "P", "mu", "transition"),
    outputs=(Output("cbar"), Output("X0", "matrice"), Output("P0", "matrice")),
    make_cases=_mix_cases,
    solution=imm_mix_solution,
    shapes_hint=("X (r, n), P (r, n, n), mu (r,), transition (r, r) avec transition[i, j] = P(régime j | régime i) ; "
                 "cbar (r,), X0 (r, n), P0 (r, n, n)"),
    mistakes=(
        Mistake("transposed-transition", "matrice de transition transposée",
                "transition[i, j] est la probabilité de passer **du** régime i **au** régime j : c̄_j = Σ_i π_ij μ_i "
                "(`mu @ transition`), et ω_ij = π_ij μ_i / c̄_j. Avec `transition @ mu` (πᵀ), vous sommez sur le "
                "mauvais indice ; l'erreur ne se voit pas quand la matrice est symétrique.",
                _mix_transposed),
        Mistake("no-spread", "P⁰ sans le terme d'écart entre les moyennes",
                "Le mélange de plusieurs gaussiennes a pour covariance la moyenne des covariances **plus** la "
                "dispersion des moyennes : P⁰_j = Σ_i ω_ij [P_i + (x_i − x⁰_j)(x_i − x⁰_j)ᵀ]. Sans ce terme, "
                "le filtre est trop confiant juste quand les régimes ne sont pas d'accord.",
                _mix_no_spread, outputs=(2,), output=2),
        Mistake("not-normalised", "poids de mélange non divisés par c̄_j",
                "Les poids ω_ij = π_ij μ_i / c̄_j de chaque régime j somment à 1 sur i : sans la division par "
                "c̄_j = Σ_i π_ij μ_i, x⁰_j n'est pas une moyenne (ses poids ne somment pas à 1).",
                _mix_not_normalised, outputs=(1,), output=1),
        Mistake("row-normalised", "poids normalisés sur j au lieu de i",
                "Pour le régime j, on mélange les estimations **d'origine** i : les poids ω_ij somment à 1 sur i "
                "(colonne j), en divisant par c̄_j = Σ_i π_ij μ_i ; pas sur j.",
                _mix_row_normalised, outputs=(1,), output=1),
        Mistake("no-mixing", "aucun mélange : chaque régime repart de sa propre estimation",
                "Sans mélange, les filtres des régimes tournent chacun de leur côté : c'est un banc de filtres, pas "
                "un IMM. Chaque régime j repart de x⁰_j = Σ_i ω_ij x_i, qui tient compte des autres régimes.",
                _mix_none, outputs=(1,), output=1),
    ),
)


# --------------------------------------------------------------------------- IMM : probabilités des régimes


def _probabilities_reference(cbar, nu, S):
    import scipy.special
    import scipy.stats

    log_l = np.array([scipy.stats.multivariate_normal(np.zeros(nu.shape[1]), S[j]).logpdf(nu[j])
                      for j in range(len(cbar))])
    with np.errstate(divide="ignore"):
        a = np.log(cbar) + log_l
    return np.exp(a - scipy.special.logsumexp(a))


def _prob_case(label, cbar, nu, S) -> Case:
    mu = _probabilities_reference(cbar, nu, S)
    return Case(label, (cbar, nu, S), (mu,), (mu.shape,), {"far": "loin" in label})


def _prob_cases() -> list[Case]:
    rng = generator(1717)
    S_quiet = np.array([[9.0, 1.0], [1.0, 8.0]])
    S_agitated = np.array([[60.0, 5.0], [5.0, 45.0]])
    return [
        _prob_case("r = 2, m = 2, innovations semblables, covariances très différentes", np.array([0.9, 0.1]),
                   np.array([[2.0, -1.0], [2.5, -1.5]]), np.array([S_quiet, S_agitated])),
        _prob_case("r = 2, m = 2, un virage : l'innovation du régime calme est grande", np.array([0.95, 0.05]),
                   np.array([[12.0, 9.0], [6.0, 4.0]]), np.array([S_quiet, S_agitated])),
        _prob_case("r = 3, m = 1", np.array([0.5, 0.3, 0.2]), np.array([[0.5], [-1.0], [2.0]]),
                   np.array([[[1.0]], [[4.0]], [[0.5]]])),
        _prob_case("mesure très loin de tous les régimes (vraisemblances < 10⁻³⁰⁰)", np.array([0.6, 0.4]),
                   np.array([[120.0, 80.0], [110.0, 75.0]]), np.array([np.eye(2), 2.0 * np.eye(2)])),
        _prob_case("r = 1", np.array([1.0]), rng.standard_normal((1, 3)), spd(rng, 3)[None]),
    ]


def mode_probabilities_solution(cbar, nu, S):
    """Solution de référence (numpy : Cholesky de chaque S_j, log-vraisemblances, log-sum-exp) ; les cas cachés
    sont jugés, eux, par les densités de scipy."""
    cbar, nu, S = (np.asarray(a, dtype=float) for a in (cbar, nu, S))
    L = np.linalg.cholesky(S)
    z = np.linalg.solve(L, nu[..., None])[..., 0]
    with np.errstate(divide="ignore"):
        a = np.log(cbar) - 0.5 * np.sum(z**2, axis=1) - np.log(np.diagonal(L, axis1=1, axis2=2)).sum(axis=1)
    w = np.exp(a - a.max())
    return w / w.sum()


def _quadratic(nu, S):
    return np.array([n @ np.linalg.solve(s, n) for n, s in zip(nu, S)])


def _prob_no_determinant(cbar, nu, S):
    a = np.log(cbar) - 0.5 * _quadratic(nu, S)
    w = np.exp(a - a.max())
    return w / w.sum()


def _prob_prior_ignored(cbar, nu, S):
    a = -0.5 * _quadratic(nu, S) - 0.5 * np.log(np.linalg.det(S))
    w = np.exp(a - a.max())
    return w / w.sum()


def _prob_no_shift(cbar, nu, S):
    w = cbar * np.exp(-0.5 * _quadratic(nu, S)) / np.sqrt(np.linalg.det(2 * np.pi * S))
    return w / w.sum()


def _prob_not_normalised(cbar, nu, S):
    return cbar * np.exp(-0.5 * _quadratic(nu, S)) / np.sqrt(np.linalg.det(2 * np.pi * S))


def _prob_s_not_inverted(cbar, nu, S):
    q = np.array([n @ s @ n for n, s in zip(nu, S)])
    a = np.log(cbar) - 0.5 * q - 0.5 * np.log(np.linalg.det(S))
    w = np.exp(a - a.max())
    return w / w.sum()


def _detect_no_shift(outs, case):
    return case.info["far"] and not np.isfinite(outs[0]).all()


def _detect_not_normalised(outs, case):
    w = outs[0]
    s = float(w.sum())
    return np.isfinite(s) and s > 0 and not np.isclose(s, 1.0) and close(w / s, case.expected[0])


MODE_PROBABILITIES = Exercise(
    id="mode-probabilities",
    title="IMM : probabilités des régimes après la mesure",
    chapter="cibles-manoeuvrantes",
    signature="mode_probabilities(cbar, nu, S) -> mu",
    parameters=("cbar", "nu", "S"),
    outputs=(Output("mu", "poids"),),
    make_cases=_prob_cases,
    solution=mode_probabilities_solution,
    shapes_hint="cbar (r,), nu (r, m) l'innovation de chaque régime, S (r, m, m) ; mu (r,), de somme 1",
    mistakes=(
        Mistake("no-determinant", "vraisemblance sans le facteur |S_j|^(−1/2)",
                "La vraisemblance d'un régime est la densité N(ν_j ; 0, S_j) = exp(−½ ν_jᵀ S_j⁻¹ ν_j) / "
                "√det(2π S_j). Le facteur (2π)^(m/2) est commun et se simplifie, **pas** det(S_j) : il diffère "
                "d'un régime à l'autre. Sans lui, le régime agité (S large) est favorisé à tort.",
                _prob_no_determinant),
        Mistake("prior-ignored", "probabilités prédites c̄ oubliées",
                "μ_j ∝ c̄_j ℓ_j : la vraisemblance de la mesure se combine avec la probabilité **prédite** du régime "
                "(le mélange de la chaîne de Markov), sinon l'IMM oublie tout à chaque pas.",
                _prob_prior_ignored),
        Mistake("no-max-shift", "exponentielle sans soustraire le maximum",
                "Loin de la mesure, toutes les vraisemblances valent 0 en flottant et 0/0 donne NaN : calculez "
                "log c̄_j + log ℓ_j, retranchez le plus grand avant l'exponentielle (log-sum-exp).",
                _prob_no_shift, detect=_detect_no_shift, culprit=(r"np\.exp\(",), refute=(r"max|logsumexp",)),
        Mistake("not-normalised", "probabilités non normalisées",
                "Les probabilités des régimes somment à 1 : divisez par Σ_i c̄_i ℓ_i.",
                _prob_not_normalised, detect=_detect_not_normalised),
        Mistake("s-not-inverted", "νᵀ S ν au lieu de νᵀ S⁻¹ ν",
                "La forme quadratique de la densité gaussienne utilise S⁻¹ (`np.linalg.solve(S[j], nu[j])`).",
                _prob_s_not_inverted),
    ),
)


# --------------------------------------------------------------------------- IMM : combinaison


def _merge_reference(X, P, mu):
    from ..filters.imm import IMMState, imm_family

    return imm_family().moments(IMMState(X, P, mu, mu))


def _merge_case(label, X, P, mu) -> Case:
    x, Pm = _merge_reference(X, P, mu)
    return Case(label, (X, P, mu), (x, Pm), (x.shape, Pm.shape))


def _merge_cases() -> list[Case]:
    rng = generator(1818)
    return [
        _merge_case("r = 2, n = 1", np.array([[0.0], [4.0]]), np.array([[[1.0]], [[1.0]]]), np.array([0.5, 0.5])),
        _merge_case("r = 2, n = 4 (l'hélicoptère dans un virage)",
                    np.array([[100.0, 50.0, 12.0, -3.0], [96.0, 58.0, 8.0, 4.0]]),
                    np.array([spd(rng, 4, 4.0), spd(rng, 4, 25.0)]), np.array([0.4, 0.6])),
        _merge_case("r = 3, n = 2", rng.standard_normal((3, 2)) * 2, np.array([spd(rng, 2) for _ in range(3)]),
                    np.array([0.2, 0.5, 0.3])),
        _merge_case("r = 2, n = 3, un régime presque certain", rng.standard_normal((2, 3)),
                    np.array([spd(rng, 3) for _ in range(2)]), np.array([0.99, 0.01])),
        _merge_case("r = 1", np.array([[1.0, 2.0]]), spd(rng, 2)[None], np.array([1.0])),
    ]


def imm_merge_solution(X, P, mu):
    """Solution de référence (appelle le paquet)."""
    return _merge_reference(*(np.asarray(a, dtype=float) for a in (X, P, mu)))


def _merge_no_spread(X, P, mu):
    return mu @ X, np.einsum("j,jkl->kl", mu, P)


def _merge_uncentred(X, P, mu):
    return mu @ X, np.einsum("j,jkl->kl", mu, P) + np.einsum("j,jk,jl->kl", mu, X, X)


def _merge_unweighted_spread(X, P, mu):
    x = mu @ X
    D = X - x
    return x, np.einsum("j,jkl->kl", mu, P) + D.T @ D


def _merge_best(X, P, mu):
    j = int(np.argmax(mu))
    return X[j].copy(), P[j].copy()


def _merge_plain_mean(X, P, mu):
    x = X.mean(axis=0)
    D = X - x
    return x, P.mean(axis=0) + D.T @ D / len(mu)


IMM_MERGE = Exercise(
    id="imm-merge",
    title="IMM : combinaison des régimes en une estimation",
    chapter="cibles-manoeuvrantes",
    signature="imm_merge(X, P, mu) -> (x, P_comb)",
    parameters=("X", "P", "mu"),
    outputs=(Output("x"), Output("P_comb", "covariance")),
    make_cases=_merge_cases,
    solution=imm_merge_solution,
    shapes_hint="X (r, n), P (r, n, n), mu (r,) ; x (n,), P_comb (n, n)",
    mistakes=(
        Mistake("no-spread", "P sans le terme d'écart entre les régimes",
                "La covariance de l'estimation combinée est P = Σ_j μ_j [P_j + (x_j − x)(x_j − x)ᵀ] : quand les "
                "régimes ne sont pas d'accord, leur désaccord fait partie de l'incertitude. Sans ce terme, le "
                "filtre est trop confiant au début de chaque virage.",
                _merge_no_spread, outputs=(1,), output=1),
        Mistake("uncentred", "écarts non centrés (x_j x_jᵀ au lieu de (x_j − x)(x_j − x)ᵀ)",
                "Le terme de dispersion se calcule autour de la moyenne combinée x : (x_j − x)(x_j − x)ᵀ.",
                _merge_uncentred, outputs=(1,), output=1),
        Mistake("unweighted-spread", "écarts sommés sans les poids μ_j",
                "Chaque écart (x_j − x)(x_j − x)ᵀ est pondéré par la probabilité μ_j de son régime, comme P_j.",
                _merge_unweighted_spread, outputs=(1,), output=1),
        Mistake("best-mode", "estimation du régime le plus probable au lieu de la combinaison",
                "Garder le seul régime le plus probable jette l'information des autres (et fait sauter l'estimation "
                "à chaque changement) : l'IMM combine, x = Σ_j μ_j x_j.",
                _merge_best),
        Mistake("plain-mean", "moyenne simple des régimes (poids 1/r)",
                "Les régimes ne pèsent pas autant : x = Σ_j μ_j x_j, avec leurs probabilités.",
                _merge_plain_mean, outputs=(0,), output=0),
    ),
)
