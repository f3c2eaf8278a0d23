r"""Exercices du lissage et de l'apprentissage : un pas du lisseur RTS, l'étape M d'EM.

Références : le lisseur du paquet (:func:`kalman_course.rts_smoother`) sur un petit filtre de deux pas,
et l'itération d'EM du paquet (:func:`kalman_course.likelihood.em_step`), qui refait elle-même filtre,
lisseur et formules closes : indépendantes de ce qu'écrit l'étudiant.
"""

from __future__ import annotations

import numpy as np

from ..core.models import LinearGaussianModel
from ..core.simulation import simulate
from ..filters.kalman import kalman_filter
from ..filters.smoothers import rts_smoother
from ..likelihood import em_step
from .grading import Case, Exercise, Mistake, Output
from .matrices import generator, nonsymmetric, spd

__all__ = ["RTS_STEP", "EM_M_STEP"]


# --------------------------------------------------------------------------- un pas de RTS


def _rts_case(label, model: LinearGaussianModel, y, x0, P0) -> Case:
    res = kalman_filter(model, y, x0, P0)
    sm = rts_smoother(model, res)
    args = (res.x[0].copy(), res.P[0].copy(), sm.x[1].copy(), sm.P[1].copy(), np.array(model.A), np.array(model.Q))
    return Case(label, args, (sm.x[0], sm.P[0]), (sm.x[0].shape, sm.P[0].shape))


def _rts_cases() -> list[Case]:
    rng = generator(1212)
    cases = [_rts_case("n = 1 (niveau local du Nil)",
                       LinearGaussianModel(1.0, 1.0, 1469.1, 15099.0), np.array([[1120.0], [1160.0]]),
                       np.array([1100.0]), np.array([[1e5]]))]
    dt = 1.0
    A = np.array([[1.0, dt], [0.0, 1.0]])
    Q = 0.5 * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
    cases.append(_rts_case("n = 2, A non symétrique (position–vitesse)",
                           LinearGaussianModel(A, np.array([[1.0, 0.0]]), Q, 0.3),
                           np.array([[0.4], [1.3]]), np.array([0.0, 1.0]), np.diag([1.0, 0.5])))
    for n, m, label in ((3, 2, "n = 3, A quelconque, m = 2"), (4, 1, "n = 4, A non symétrique, m = 1")):
        model = LinearGaussianModel(nonsymmetric(rng, n), rng.standard_normal((m, n)), spd(rng, n, 0.2),
                                    spd(rng, m, 0.5))
        cases.append(_rts_case(label, model, rng.standard_normal((2, m)), rng.standard_normal(n), spd(rng, n)))
    return cases


def rts_step_solution(x_filt, P_filt, x_smooth_next, P_smooth_next, A, Q):
    """Solution de référence : un pas de RTS, gain par résolution linéaire."""
    P_pred = A @ P_filt @ A.T + Q
    G = np.linalg.solve(P_pred, A @ P_filt).T  # P_pred symétrique : G = P Aᵀ P_pred⁻¹
    x_s = x_filt + G @ (x_smooth_next - A @ x_filt)
    P_s = P_filt + G @ (P_smooth_next - P_pred) @ G.T
    return x_s, (P_s + P_s.T) / 2


def _rts_smoothed_gain(x_filt, P_filt, x_smooth_next, P_smooth_next, A, Q):
    P_pred = A @ P_filt @ A.T + Q
    G = P_filt @ A.T @ np.linalg.inv(P_smooth_next)
    return x_filt + G @ (x_smooth_next - A @ x_filt), P_filt + G @ (P_smooth_next - P_pred) @ G.T


def _rts_gain_transposed(x_filt, P_filt, x_smooth_next, P_smooth_next, A, Q):
    P_pred = A @ P_filt @ A.T + Q
    G = np.linalg.solve(P_pred, A @ P_filt)
    return x_filt + G @ (x_smooth_next - A @ x_filt), P_filt + G @ (P_smooth_next - P_pred) @ G.T


def _rts_q_forgotten(x_filt, P_filt, x_smooth_next, P_smooth_next, A, Q):
    P_pred = A @ P_filt @ A.T
    G = P_filt @ A.T @ np.linalg.inv(P_pred)
    return x_filt + G @ (x_smooth_next - A @ x_filt), P_filt + G @ (P_smooth_next - P_pred) @ G.T


def _rts_not_predicted(x_filt, P_filt, x_smooth_next, P_smooth_next, A, Q):
    P_pred = A @ P_filt @ A.T + Q
    G = P_filt @ A.T @ np.linalg.inv(P_pred)
    return x_filt + G @ (x_smooth_next - x_filt), P_filt + G @ (P_smooth_next - P_pred) @ G.T


def _rts_cov_sign(x_filt, P_filt, x_smooth_next, P_smooth_next, A, Q):
    P_pred = A @ P_filt @ A.T + Q
    G = P_filt @ A.T @ np.linalg.inv(P_pred)
    return x_filt + G @ (x_smooth_next - A @ x_filt), P_filt + G @ (P_pred - P_smooth_next) @ G.T


def _rts_no_transpose(x_filt, P_filt, x_smooth_next, P_smooth_next, A, Q):
    P_pred = A @ P_filt @ A.T + Q
    G = P_filt @ A.T @ np.linalg.inv(P_pred)
    return x_filt + G @ (x_smooth_next - A @ x_filt), P_filt + G @ (P_smooth_next - P_pred) @ G


_RTS_GAIN = (r"^\s*G\w*\s*=",)

RTS_STEP = Exercise(
    id="rts-step",
    title="Un pas du lisseur de Rauch–Tung–Striebel",
    chapter="lissage",
    signature="rts_step(x_filt, P_filt, x_smooth_next, P_smooth_next, A, Q) -> (x_smooth, P_smooth)",
    parameters=("x_filt", "P_filt", "x_smooth_next", "P_smooth_next", "A", "Q"),
    outputs=(Output("x_smooth"), Output("P_smooth", "covariance")),
    make_cases=_rts_cases,
    solution=rts_step_solution,
    shapes_hint="x_filt, x_smooth_next (n,) ; P_filt, P_smooth_next, A, Q (n, n)",
    mistakes=(
        Mistake("smoothed-gain", "gain avec la covariance lissée au lieu de la prédite",
                "Le gain du lisseur est G = P_{k|k} Aᵀ (P_{k+1|k})⁻¹, avec la covariance **prédite** "
                "P_{k+1|k} = A P_{k|k} Aᵀ + Q : c'est elle qui relie x_{k+1} à x_k dans la loi jointe. La "
                "covariance lissée P_{k+1|T} n'intervient que dans la correction.",
                _rts_smoothed_gain, culprit=_RTS_GAIN, confirm=(r"smooth|next",)),
        Mistake("gain-transposed", "Gᵀ au lieu de G (`.T` oublié après `solve`)",
                "G = P_{k|k} Aᵀ (P_{k+1|k})⁻¹ est la transposée de la solution X de P_{k+1|k} X = A P_{k|k} : "
                "`np.linalg.solve(P_pred, A @ P_filt)` donne Gᵀ, il faut ajouter `.T`. (En dimension 1, G = Gᵀ : "
                "l'oubli ne se voit qu'à partir de n = 2.)",
                _rts_gain_transposed, culprit=(r"solve\(",), refute=(r"\)\s*\.T\b",)),
        Mistake("q-forgotten", "Q oubliée dans la covariance prédite",
                "P_{k+1|k} = A P_{k|k} Aᵀ + Q : sans Q, le gain et la correction du lisseur sont faux (et "
                "A P Aᵀ peut même être singulière).",
                _rts_q_forgotten, culprit=(r"^\s*P\w*pred\w*\s*=", r"^\s*P\w*\s*=\s*A"), refute=(r"\bQ\b",)),
        Mistake("not-predicted", "x_{k|k} au lieu de A x_{k|k} dans la correction",
                "La correction compare la moyenne lissée suivante à sa **prédiction** : "
                "x_s = x_{k|k} + G (x_{k+1|T} − A x_{k|k}). Sans A, c'est juste seulement si A = I.",
                _rts_not_predicted, outputs=(0,), output=0),
        Mistake("cov-sign", "différence de covariances à l'envers",
                "P_{k|T} = P_{k|k} + G (P_{k+1|T} − P_{k+1|k}) Gᵀ : le lissage réduit l'incertitude, et "
                "P_{k+1|T} ⪯ P_{k+1|k}, donc le terme ajouté est négatif.",
                _rts_cov_sign, outputs=(1,), output=1),
        Mistake("no-transpose", "G (…) G au lieu de G (…) Gᵀ",
                "La correction de la covariance est une congruence : G (P_{k+1|T} − P_{k+1|k}) Gᵀ, avec la "
                "transposée à droite (sinon P n'est plus symétrique).",
                _rts_no_transpose, outputs=(1,), output=1),
    ),
)


# --------------------------------------------------------------------------- étape M d'EM


def _m_step_case(label, model: LinearGaussianModel, T: int, seed: int) -> Case:
    n = model.n_state
    x0, P0 = np.zeros(n), np.eye(n)
    y = simulate(model, x0, T, rng=seed).y
    res = kalman_filter(model, y, x0, P0)
    sm = rts_smoother(model, res, x0, P0)
    x_s = np.concatenate([sm.x_initial[None], sm.x])
    P_s = np.concatenate([sm.P_initial[None], sm.P])
    new = em_step(model, y, x0, P0, None)[1]
    args = (y, x_s, P_s, np.array(sm.P_lag), np.array(model.A), np.array(model.C))
    return Case(label, args, (new.Q, new.R), (new.Q.shape, new.R.shape))


def _m_step_cases() -> list[Case]:
    rng = generator(1313)
    cases = [_m_step_case("n = 1, m = 1 (niveau local), T = 30", LinearGaussianModel(1.0, 1.0, 0.5, 2.0), 30, 1)]
    A = np.array([[1.0, 1.0], [0.0, 1.0]])
    cases.append(_m_step_case("n = 2, m = 1, A non symétrique, T = 40",
                              LinearGaussianModel(A, np.array([[1.0, 0.0]]), spd(rng, 2, 0.1), 0.5), 40, 2))
    cases.append(_m_step_case("n = 2, m = 2, T = 25",
                              LinearGaussianModel(nonsymmetric(rng, 2) * 0.8, rng.standard_normal((2, 2)),
                                                  spd(rng, 2, 0.3), spd(rng, 2, 0.5)), 25, 3))
    cases.append(_m_step_case("n = 3, m = 2, T = 20",
                              LinearGaussianModel(nonsymmetric(rng, 3) * 0.7, rng.standard_normal((2, 3)),
                                                  spd(rng, 3, 0.2), spd(rng, 2, 0.4)), 20, 4))
    return cases


def m_step_solution(y, x_smooth, P_smooth, P_lag, A, C):
    """Solution de référence : les formules closes de l'étape M (boucle sur le temps)."""
    T = y.shape[0]
    Q = np.zeros_like(A, dtype=float)
    R = np.zeros((y.shape[1], y.shape[1]))
    for k in range(1, T + 1):
        r = x_smooth[k] - A @ x_smooth[k - 1]
        L = P_lag[k - 1] @ A.T
        Q += np.outer(r, r) + P_smooth[k] - L - L.T + A @ P_smooth[k - 1] @ A.T
        e = y[k - 1] - C @ x_smooth[k]
        R += np.outer(e, e) + C @ P_smooth[k] @ C.T
    Q, R = Q / T, R / T
    return (Q + Q.T) / 2, (R + R.T) / 2


def _m_means_only(y, x_smooth, P_smooth, P_lag, A, C):
    r = x_smooth[1:] - x_smooth[:-1] @ A.T
    e = y - x_smooth[1:] @ C.T
    return r.T @ r / len(y), e.T @ e / len(y)


def _m_r_without_cpc(y, x_smooth, P_smooth, P_lag, A, C):
    Q, _ = m_step_solution(y, x_smooth, P_smooth, P_lag, A, C)
    e = y - x_smooth[1:] @ C.T
    return Q, e.T @ e / len(y)


def _m_q_without_cov(y, x_smooth, P_smooth, P_lag, A, C):
    _, R = m_step_solution(y, x_smooth, P_smooth, P_lag, A, C)
    r = x_smooth[1:] - x_smooth[:-1] @ A.T
    return r.T @ r / len(y), R


def _m_lag_not_transposed(y, x_smooth, P_smooth, P_lag, A, C):
    T = len(y)
    Q = np.zeros(A.shape)
    for k in range(1, T + 1):
        r = x_smooth[k] - A @ x_smooth[k - 1]
        Q += np.outer(r, r) + P_smooth[k] - P_lag[k - 1] @ A.T - A @ P_lag[k - 1] + A @ P_smooth[k - 1] @ A.T
    _, R = m_step_solution(y, x_smooth, P_smooth, P_lag, A, C)
    return Q / T, R


EM_M_STEP = Exercise(
    id="em-m-step",
    title="Étape M d'EM : nouvelles covariances Q et R",
    chapter="vraisemblance",
    signature="m_step(y, x_smooth, P_smooth, P_lag, A, C) -> (Q, R)",
    parameters=("y", "x_smooth", "P_smooth", "P_lag", "A", "C"),
    outputs=(Output("Q", "covariance"), Output("R", "covariance")),
    make_cases=_m_step_cases,
    solution=m_step_solution,
    shapes_hint=("y (T, m) ; x_smooth (T + 1, n) et P_smooth (T + 1, n, n), ligne 0 = instant 0 ; "
                 "P_lag (T, n, n), P_lag[k − 1] = Cov(x_k, x_{k−1} | y) ; A (n, n), C (m, n)"),
    mistakes=(
        Mistake("means-only", "moyennes lissées seulement, sans leurs covariances",
                "L'étape M prend l'espérance des carrés, pas le carré des espérances : "
                "E[(x_k − A x_{k−1})(…)ᵀ] = r_k r_kᵀ + P_{k|T} − P_{k,k−1} Aᵀ − A P_{k,k−1}ᵀ + A P_{k−1|T} Aᵀ, "
                "et E[(y_k − C x_k)(…)ᵀ] = e_k e_kᵀ + C P_{k|T} Cᵀ. Sans ces termes, Q et R sont sous-estimées.",
                _m_means_only),
        Mistake("r-without-cpc", "terme C P_{k|T} Cᵀ oublié dans R",
                "R' = (1/T) Σ [e_k e_kᵀ + C P_{k|T} Cᵀ] : l'état n'est connu qu'à P_{k|T} près, cette incertitude "
                "compte dans l'écart entre la mesure et C x_k.",
                _m_r_without_cpc, outputs=(1,), output=1),
        Mistake("q-without-covariances", "termes de covariance oubliés dans Q",
                "Q' = (1/T) Σ [r_k r_kᵀ + P_{k|T} − P_{k,k−1} Aᵀ − A P_{k,k−1}ᵀ + A P_{k−1|T} Aᵀ] avec "
                "r_k = x_{k|T} − A x_{k−1|T} : les quatre termes de covariance viennent de l'incertitude du lissage.",
                _m_q_without_cov, outputs=(0,), output=0),
        Mistake("lag-not-transposed", "A P_{k,k−1} au lieu de A P_{k,k−1}ᵀ",
                "Les deux termes croisés sont transposés l'un de l'autre : P_{k,k−1} Aᵀ et A P_{k,k−1}ᵀ "
                "(P_{k,k−1} = Cov(x_k, x_{k−1}) n'est pas symétrique). Sans la transposée, Q n'est plus symétrique.",
                _m_lag_not_transposed, outputs=(0,), output=0),
    ),
)
