r"""Expériences des travaux pratiques : le filtre de l'étudiant, assemblé avec ses fonctions, contre celui
du paquet, sur les données d'un chapitre.

Chaque expérience prend les fonctions de l'étudiant (mêmes signatures que les exercices de
:mod:`kalman_course.practice`) ; sans argument, elle prend les solutions de référence du correcteur.
Le code de l'étudiant n'interrompt jamais l'expérience : s'il échoue, ``student`` vaut ``None`` et
``message`` dit pourquoi, en français (la figure montre alors le seul filtre du paquet).

* :func:`voltage_lab` — TP 1 : ``predict`` et ``update`` sur la tension constante ;
* :func:`tag_lab` — TP 2 : l'EKF du tag avec la correction et la jacobienne de l'étudiant ;
* :func:`pendulum_lab` — TP 3 : un UKF (points sigma et transformée de l'étudiant) et un filtre
  particulaire (poids et rééchantillonnage de l'étudiant) sur le pendule ;
* :func:`nile_lab` — TP 4 : le lisseur RTS et l'étape M de l'étudiant sur le Nil ;
* :func:`samu_lab` — TP 5 : le modèle à vitesse presque constante, la porte, la discrétisation de Van Loan et
  l'IMM de l'étudiant sur le vol réel de l'hélicoptère SAMU 31.
* :func:`pda_lab` — TP 7 : les poids et la correction PDA de l'étudiant, sur l'hélicoptère de la scène de
  Blagnac dans un fouillis dense.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from .. import practice
from ..core.models import LinearGaussianModel
from ..datasets import nile
from ..filters.extended import extended_kalman_filter
from ..filters.kalman import kalman_filter, predict as kf_predict
from ..filters.particle import particle_filter
from ..filters.smoothers import rts_smoother
from ..filters.unscented import unscented_kalman_filter
from ..likelihood import expectation_maximization
from ..practice.nonlinear import point_function
from ..core.motion import constant_velocity
from .nile import NILE_DK_VARIANCES, local_level_model
from .pendulum import pendulum_data, pendulum_model, pendulum_observation, pendulum_transition
from .tag import TAG_RANGE_STD, tag_data, tag_model, tag_ranges
from .voltage import TRUE_VOLTAGE, constant_voltage_measurements, constant_voltage_model

__all__ = [
    "LabRun", "voltage_lab", "tag_lab", "pendulum_lab", "nile_lab", "samu_lab", "pda_lab",
    "LAB_UKF", "LAB_PARTICLES", "LAB_PF_SEED", "LAB_NILE_PRIOR", "LAB_EM_START", "LAB_EM_ITERATIONS",
    "LAB_SAMU_Q", "LAB_SAMU_POSITION_STD", "LAB_SAMU_GATE", "LAB_SAMU_MODES", "LAB_SAMU_SWITCH",
    "LAB_PDA_CLUTTER",
]

#: Points sigma de l'UKF du TP 3 : :math:`\alpha = 1`, :math:`\beta = 2`, :math:`\kappa = 0`.
LAB_UKF = (1.0, 2.0, 0.0)
#: Nombre de particules et graine du filtre particulaire du TP 3.
LAB_PARTICLES = 500
LAB_PF_SEED = 11
#: A priori du TP 4 sur le niveau du Nil : :math:`\hat x_0 = 1000` (10⁸ m³), :math:`P_0 = 10^6`.
LAB_NILE_PRIOR = (np.array([1000.0]), np.array([[1e6]]))
#: Départ d'EM du TP 4 : :math:`(\sigma^2_\varepsilon, \sigma^2_\eta)`, et nombre d'itérations.
LAB_EM_START = (1e4, 1e3)
LAB_EM_ITERATIONS = 30
#: TP 5 : densité (m²/s³) et écart-type des positions (m) du filtre unique, arrondis des valeurs apprises par
#: maximum de vraisemblance au chapitre « Plusieurs capteurs, temps irrégulier » (12,5 m²/s³ et 1,86 m).
LAB_SAMU_Q = 12.5
LAB_SAMU_POSITION_STD = 1.9
#: Probabilité de la porte du TP 5.
LAB_SAMU_GATE = 0.999
#: Densités (m²/s³) des régimes calme et agité de l'IMM du TP 5, et probabilité de quitter son régime.
LAB_SAMU_MODES = (3.0, 100.0)
LAB_SAMU_SWITCH = 0.02
#: Densité du fouillis du TP 7 (par m² et par relevé : 44 fausses détections par relevé sur la zone).
LAB_PDA_CLUTTER = 1e-7


@dataclass(frozen=True, eq=False)
class LabRun:
    """Une expérience de TP : ``data`` (ce que la figure trace : temps, vérité, mesures…), ``reference``
    (le filtre du paquet), ``student`` (le filtre de l'étudiant, ou ``None`` s'il a échoué) et
    ``message`` (pourquoi, en français ; ``None`` si tout va bien). ``reference`` et ``student`` sont
    des dictionnaires de tableaux de mêmes clés."""

    data: dict
    reference: dict
    student: dict | None
    message: str | None


def _solution(exercise_id: str, fn: Callable | None) -> Callable:
    """La fonction de l'étudiant (son résultat vérifié à chaque appel), ou la solution de référence."""
    return practice.exercise(exercise_id).solution if fn is None else practice.validated(exercise_id, fn)


def _run(run: Callable[[], dict]) -> tuple[dict | None, str | None]:
    result = practice.attempt(run)
    return result.value, result.message


# --------------------------------------------------------------------------- TP 1 : tension constante


def voltage_lab(predict: Callable | None = None, update: Callable | None = None, n_steps: int = 50) -> LabRun:
    """Le filtre de l'étudiant (``predict``, ``update``) sur la tension constante (Φ = 10⁻⁵ V²,
    Ψ = 0,01 V², x̂₀ = 0, P₀ = 1 V²), contre :func:`~kalman_course.kalman_filter`."""
    predict, update = _solution("kf-predict", predict), _solution("kf-update", update)
    model = constant_voltage_model(Q=1e-5, R=0.01)
    z = constant_voltage_measurements(n_steps)
    ref = kalman_filter(model, z, 0.0, 1.0)
    A, C, Q, R = (np.array(model.A), np.array(model.C), np.array(model.Q), np.array(model.R))

    def run():
        x, P = np.array([0.0]), np.array([[1.0]])
        xs, Ps = [], []
        for y in z:
            x, P = predict(x, P, A, Q)
            x, P = update(x, P, np.atleast_1d(y), C, R)
            xs.append(np.asarray(x, dtype=float).reshape(1))
            Ps.append(np.asarray(P, dtype=float).reshape(1, 1))
        return {"x": np.array(xs)[:, 0], "P": np.array(Ps)[:, 0, 0]}

    student, message = _run(run)
    data = {"n": np.arange(1, n_steps + 1), "z": np.asarray(z, dtype=float).ravel(), "true": TRUE_VOLTAGE}
    return LabRun(data, {"x": ref.x[:, 0], "P": ref.P[:, 0, 0]}, student, message)


# --------------------------------------------------------------------------- TP 2 : tag UWB


def tag_lab(update: Callable | None = None, ranges_jacobian: Callable | None = None) -> LabRun:
    """L'EKF du tag (prédiction linéaire du paquet) avec la correction ``update`` et la jacobienne
    ``ranges_jacobian`` de l'étudiant, contre :func:`~kalman_course.extended_kalman_filter`."""
    update, jacobian = _solution("ekf-update", update), _solution("tag-jacobian", ranges_jacobian)
    data = tag_data()
    model = tag_model()
    ref = extended_kalman_filter(model, data.y, data.x0, data.P0)
    anchors = np.array(data.anchors)
    linear = LinearGaussianModel(constant_velocity(data.dt, accel_std=0.0).A, np.eye(1, 4), np.array(model.Q), 1.0)
    R = TAG_RANGE_STD**2 * np.eye(anchors.shape[0])

    def h(x):
        return tag_ranges(x, anchors)

    def H(x):
        return jacobian(x, anchors)

    def run():
        x, P = np.array(data.x0), np.array(data.P0)
        xs = []
        for y in data.y:
            pred = kf_predict(linear, x, P)
            x, P = update(pred.x, pred.P, np.array(y), point_function("h", h, 4, "x_pred"),
                          point_function("H", H, 4, "x_pred"), R)
            xs.append(np.asarray(x, dtype=float).reshape(4))
        return {"x": np.array(xs)}

    student, message = _run(run)
    return LabRun({"t": data.t, "true": data.x_true, "anchors": anchors}, {"x": ref.x}, student, message)


# --------------------------------------------------------------------------- TP 3 : pendule


def _ukf_run(data, model, sigma_points, unscented_transform) -> dict:
    alpha, beta, kappa = LAB_UKF
    f = point_function("f", pendulum_transition, 2, "chi[i]")
    h = point_function("h", pendulum_observation, 2, "chi[i]")
    Q, R = np.array(model.Q), np.array(model.R)
    x, P = np.array(data.x0), np.array(data.P0)
    xs = []
    for y in data.y:
        chi, wm, wc = sigma_points(x, P, alpha, beta, kappa)
        x_pred, P_pred = unscented_transform(chi, wm, wc, f)
        x_pred, P_pred = np.asarray(x_pred, dtype=float), np.asarray(P_pred, dtype=float) + Q
        chi, wm, wc = (np.asarray(a, dtype=float) for a in sigma_points(x_pred, P_pred, alpha, beta, kappa))
        y_mean, S = unscented_transform(chi, wm, wc, h)
        y_mean, S = np.asarray(y_mean, dtype=float).reshape(1), np.asarray(S, dtype=float).reshape(1, 1) + R
        images = np.array([pendulum_observation(c) for c in chi])
        cross = (wc[:, None] * (chi - x_pred)).T @ (images - y_mean)
        K = np.linalg.solve(S, cross.T).T
        x = x_pred + K @ (y - y_mean)
        P = P_pred - K @ S @ K.T
        xs.append(x)
    return {"x": np.array(xs)}


def _particle_run(data, model, systematic_resample, particle_weights) -> dict:
    rng = np.random.default_rng(LAB_PF_SEED)
    N = LAB_PARTICLES
    LQ = np.linalg.cholesky(np.array(model.Q))
    R = np.array(model.R)
    X = rng.multivariate_normal(np.array(data.x0), np.array(data.P0), size=N)
    log_w = np.full(N, -np.log(N))
    xs = []
    for y in data.y:
        X = pendulum_transition(X) + rng.standard_normal((N, 2)) @ LQ.T
        w = np.asarray(particle_weights(log_w, pendulum_observation(X), np.array(y), R), dtype=float)
        xs.append(w @ X)
        if 1.0 / np.sum(w**2) < N / 2:
            idx = np.asarray(systematic_resample(w, float(rng.uniform())), dtype=int)
            X, log_w = X[idx], np.full(N, -np.log(N))
        else:
            log_w = np.log(w)
    return {"x": np.array(xs)}


def pendulum_lab(sigma_points: Callable | None = None, unscented_transform: Callable | None = None,
                 systematic_resample: Callable | None = None, particle_weights: Callable | None = None) -> LabRun:
    """Le pendule : l'UKF de l'étudiant (``sigma_points``, ``unscented_transform``) et son filtre
    particulaire (``systematic_resample``, ``particle_weights``), contre
    :func:`~kalman_course.unscented_kalman_filter` et :func:`~kalman_course.particle_filter`.
    ``student`` contient ``ukf`` et ``pf`` (ou ``None`` pour celui qui a échoué, avec son message)."""
    sp, ut = _solution("sigma-points", sigma_points), _solution("unscented-transform", unscented_transform)
    rs, pw = _solution("systematic-resample", systematic_resample), _solution("particle-weights", particle_weights)
    data = pendulum_data()
    model = pendulum_model()
    alpha, beta, kappa = LAB_UKF
    reference = {
        "ukf": unscented_kalman_filter(model, data.y, data.x0, data.P0, alpha=alpha, beta=beta, kappa=kappa).x,
        "pf": particle_filter(model, data.y, data.x0, data.P0, n_particles=LAB_PARTICLES, rng=LAB_PF_SEED).x,
    }
    ukf, ukf_message = _run(lambda: _ukf_run(data, model, sp, ut))
    pf, pf_message = _run(lambda: _particle_run(data, model, rs, pw))
    student = {"ukf": None if ukf is None else ukf["x"], "pf": None if pf is None else pf["x"]}
    messages = [f"UKF : {ukf_message}" if ukf_message else "", f"filtre particulaire : {pf_message}" if pf_message else ""]
    message = " ; ".join(m for m in messages if m) or None
    return LabRun({"t": data.t, "true": data.x_true, "y": data.y}, reference, student, message)


# --------------------------------------------------------------------------- TP 4 : le Nil


def nile_lab(rts_step: Callable | None = None, m_step: Callable | None = None) -> LabRun:
    """Le Nil (niveau local, variances de Durbin et Koopman, a priori :data:`LAB_NILE_PRIOR`) : le lissage
    par le ``rts_step`` de l'étudiant contre :func:`~kalman_course.rts_smoother`, puis
    :data:`LAB_EM_ITERATIONS` itérations d'EM dont l'étape M est le ``m_step`` de l'étudiant (étape E du
    paquet) contre :func:`~kalman_course.expectation_maximization`. ``student`` contient ``smoothed``
    et ``variances`` (ou ``None`` pour la partie qui a échoué)."""
    rts_step, m_step = _solution("rts-step", rts_step), _solution("em-m-step", m_step)
    series = nile()
    y = np.asarray(series.flow, dtype=float)
    x0, P0 = LAB_NILE_PRIOR
    model = local_level_model(*NILE_DK_VARIANCES)
    res = kalman_filter(model, y, x0, P0)
    smoothed = rts_smoother(model, res)
    start = local_level_model(*LAB_EM_START)
    em = expectation_maximization(start, y, x0, P0, max_iter=LAB_EM_ITERATIONS, tol=1e-300)
    reference = {"smoothed": smoothed.x[:, 0], "variances": np.stack([em.R[:, 0, 0], em.Q[:, 0, 0]], axis=1)}
    A, Q = np.array(model.A), np.array(model.Q)

    def smooth():
        xs, Ps = [res.x[-1].copy()], [res.P[-1].copy()]
        for k in range(len(y) - 2, -1, -1):
            x_s, P_s = rts_step(res.x[k].copy(), res.P[k].copy(), xs[0], Ps[0], A, Q)
            xs.insert(0, np.asarray(x_s, dtype=float).reshape(1))
            Ps.insert(0, np.asarray(P_s, dtype=float).reshape(1, 1))
        return np.array(xs)[:, 0]

    def learn():
        current = start
        variances = [(float(current.R[0, 0]), float(current.Q[0, 0]))]
        Y = y[:, None]
        for _ in range(LAB_EM_ITERATIONS):
            r = kalman_filter(current, Y, x0, P0)
            sm = rts_smoother(current, r, x0, P0)
            Q_new, R_new = m_step(Y, np.concatenate([sm.x_initial[None], sm.x]),
                                  np.concatenate([sm.P_initial[None], sm.P]), np.array(sm.P_lag),
                                  np.array(current.A), np.array(current.C))
            Q_new, R_new = np.asarray(Q_new, dtype=float), np.asarray(R_new, dtype=float)
            current = local_level_model(float(R_new.reshape(-1)[0]), float(Q_new.reshape(-1)[0]))
            variances.append((float(current.R[0, 0]), float(current.Q[0, 0])))
        return np.array(variances)

    smooth_values, smooth_message = _run(smooth)
    em_values, em_message = _run(learn)
    student = {"smoothed": smooth_values, "variances": em_values}
    messages = [f"lisseur : {smooth_message}" if smooth_message else "", f"EM : {em_message}" if em_message else ""]
    message = " ; ".join(m for m in messages if m) or None
    return LabRun({"year": np.asarray(series.year), "y": y}, reference, student, message)



# --------------------------------------------------------------------------- TP 5 : l'hélicoptère du SAMU 31


def samu_lab(cv_model: Callable | None = None, nis_gate: Callable | None = None, van_loan: Callable | None = None,
             imm_mix: Callable | None = None, mode_probabilities: Callable | None = None,
             imm_merge: Callable | None = None) -> LabRun:
    r"""Le vol réel de l'hélicoptère SAMU 31 (positions seules, instants irréguliers), deux expériences :

    * **la porte** — un filtre de Kalman dont le modèle de chaque pas vient du ``cv_model`` de l'étudiant
      (:data:`LAB_SAMU_Q`, :data:`LAB_SAMU_POSITION_STD`) et dont chaque position passe par sa ``nis_gate``
      (:data:`LAB_SAMU_GATE`), sur les positions corrompues du chapitre
      (:func:`~kalman_course.scenarios.helicopter.with_outliers`), contre
      :func:`~kalman_course.kalman_filter` ``(…, gate=…)`` ;
    * **l'IMM** calme/agité (:data:`LAB_SAMU_MODES`, :data:`LAB_SAMU_SWITCH`) sur le vol propre : modèle de
      chaque pas par le ``van_loan`` de l'étudiant, mélange, probabilités et combinaison par ses fonctions ;
      prédiction et correction de chaque régime par le paquet (:func:`~kalman_course.predict`,
      :func:`~kalman_course.update`) ; contre :func:`~kalman_course.imm_filter`.

    ``reference`` et ``student`` : ``gate_x`` (K, 4), ``rejected`` (K,) booléens, ``imm_x`` (K, 4), ``mu`` (K, 2)
    (``None`` pour la partie qui a échoué)."""
    from ..core.motion import constant_velocity_sde
    from ..filters.imm import imm_filter
    from ..filters.kalman import kalman_family
    from .helicopter import OUTLIER_ROWS, helicopter_model, helicopter_track, with_outliers

    cv, gate = _solution("cv-model", cv_model), _solution("nis-gate", nis_gate)
    vl, mix = _solution("van-loan", van_loan), _solution("imm-mix", imm_mix)
    probabilities, merge = _solution("mode-probabilities", mode_probabilities), _solution("imm-merge", imm_merge)
    track = helicopter_track("position")
    y, y_bad, dt = np.asarray(track.y), with_outliers(track), np.asarray(track.dt)
    x0, P0, C = np.asarray(track.x0), np.asarray(track.P0), np.asarray(track.C)
    R = LAB_SAMU_POSITION_STD**2 * np.eye(2)
    gated = kalman_filter(helicopter_model(track, LAB_SAMU_Q, LAB_SAMU_POSITION_STD), y_bad, x0, P0,
                          gate=LAB_SAMU_GATE)
    transition = np.array([[1.0 - LAB_SAMU_SWITCH, LAB_SAMU_SWITCH], [LAB_SAMU_SWITCH, 1.0 - LAB_SAMU_SWITCH]])
    mu0 = np.array([1.0 - LAB_SAMU_SWITCH, LAB_SAMU_SWITCH])
    modes = [helicopter_model(track, q, LAB_SAMU_POSITION_STD) for q in LAB_SAMU_MODES]
    imm = imm_filter(modes, y, x0, P0, transition=transition, mu0=mu0)
    reference = {"gate_x": gated.x, "rejected": np.asarray(gated.rejected, dtype=bool), "imm_x": imm.x, "mu": imm.mu}

    kf = kalman_family("textbook")  # les étapes pures du filtre de Kalman du paquet (celles de son moteur)
    K = len(y)

    def gate_run():
        steps = [cv(float(dt[k]), LAB_SAMU_Q) for k in range(K)]
        model = LinearGaussianModel(np.array([a for a, _ in steps]), C, np.array([q for _, q in steps]), R)
        x, P = x0.copy(), P0.copy()
        xs, rejected = [], []
        for k, step in enumerate(model.steps(K)):
            x_pred, P_pred = kf.predict(step, (x, P), None)
            nu = y_bad[k] - C @ x_pred
            S = C @ P_pred @ C.T + R
            accept = bool(np.asarray(gate(nu, S, LAB_SAMU_GATE)[2]))
            (x, P), _ = kf.update(step, (x_pred, P_pred), y_bad[k], None) if accept else ((x_pred, P_pred), None)
            xs.append(x)
            rejected.append(not accept)
        return {"gate_x": np.array(xs), "rejected": np.array(rejected)}

    def imm_run():
        F, L = constant_velocity_sde(2)
        unit = [vl(F, L, np.eye(2), float(dt[k])) for k in range(K)]  # densité 1 : Q est proportionnelle à q
        A, Q1 = np.array([a for a, _ in unit]), np.array([q for _, q in unit])
        per_mode = [LinearGaussianModel(A, C, q * Q1, R).steps(K) for q in LAB_SAMU_MODES]
        X, P = np.tile(x0, (2, 1)), np.tile(P0, (2, 1, 1))
        mu = mu0.copy()
        xs, mus = [], []
        for k in range(K):
            cbar, X0, P0_mixed = mix(X, P, mu, transition)
            X, P = np.empty_like(X), np.empty_like(P)
            nus, Ss = [], []
            for j, steps in enumerate(per_mode):
                predicted = kf.predict(steps[k], (X0[j], P0_mixed[j]), None)
                (X[j], P[j]), correction = kf.update(steps[k], predicted, y[k], None)
                nus.append(correction.innovation)
                Ss.append(correction.S)
            mu = probabilities(cbar, np.array(nus), np.array(Ss))
            x, _ = merge(X, P, mu)
            xs.append(x)
            mus.append(mu)
        return {"imm_x": np.array(xs), "mu": np.array(mus)}

    gate_values, gate_message = _run(gate_run)
    imm_values, imm_message = _run(imm_run)
    student = {**(gate_values or {"gate_x": None, "rejected": None}), **(imm_values or {"imm_x": None, "mu": None})}
    messages = [f"fenêtre de validation : {gate_message}" if gate_message else "",
                f"IMM : {imm_message}" if imm_message else ""]
    message = " ; ".join(m for m in messages if m) or None
    outliers = np.flatnonzero(track.position_rows)[list(OUTLIER_ROWS)]
    from .manoeuvre import measured_turn_rate

    rate_t, rate = measured_turn_rate(track.flight)
    return LabRun({"t": np.asarray(track.t), "y": y, "y_bad": y_bad, "outliers": outliers, "rate_t": rate_t,
                   "rate": rate}, reference, student, message)

# --------------------------------------------------------------------------- TP 7 : la PDA


def pda_lab(pda_weights: Callable | None = None, pda_update: Callable | None = None) -> LabRun:
    r"""Un filtre PDA sur l'hélicoptère SAMU 31 de la scène de Blagnac (:mod:`~kalman_course.scenarios.traffic`,
    :math:`P_D` = 0,9, fouillis :data:`LAB_PDA_CLUTTER`, porte 0,99) : à chaque relevé, prédiction du paquet,
    puis les poids ``pda_weights`` et la correction ``pda_update`` de l'étudiant, contre
    :func:`~kalman_course.pda_update`. Les détections des autres avions sont, pour ce filtre, du fouillis.
    L'a priori est la position et la vitesse vraies au premier relevé, avec la covariance d'une naissance
    par deux points. ``data`` : ``t``, ``truth`` (K, 2), ``detections`` (points des relevés à moins de 1,5 km
    de l'hélicoptère) ; ``reference`` et ``student`` : ``x`` (K, 2) et ``error`` (K,) m."""
    from ..multitarget.pda import pda_update as package_pda_update
    from . import traffic

    pda_weights, pda_update = _solution("pda-weights", pda_weights), _solution("pda-update", pda_update)
    model = traffic.radar_model()
    scans = traffic.radar_scans(traffic.DETECTION_PROBABILITY, LAB_PDA_CLUTTER)
    truth = scans.truth[:, 0]
    A, C, Q, R = (np.array(model.A), np.array(model.C), np.array(model.Q), np.array(model.R))
    dt = traffic.DT
    x0 = np.concatenate([truth[0], (truth[1] - truth[0]) / dt])
    P0 = np.block([[R, R / dt], [R / dt, 2.0 * R / dt ** 2]])
    settings = dict(detection_probability=traffic.DETECTION_PROBABILITY, clutter_density=LAB_PDA_CLUTTER,
                    gate_probability=traffic.GATE_PROBABILITY)

    def package():
        x, P, out = x0, P0, [x0[:2]]
        for z in scans.scans[1:]:
            x, P = A @ x, A @ P @ A.T + Q
            step = package_pda_update(model, x, P, z, **settings)
            x, P = step.x, step.P
            out.append(x[:2])
        return np.array(out)

    def run():
        x, P, out = x0.copy(), P0.copy(), [x0[:2]]
        for z in scans.scans[1:]:
            x, P = A @ x, A @ P @ A.T + Q
            S = C @ P @ C.T + R
            beta = np.asarray(pda_weights(z - C @ x, S, *settings.values()), dtype=float)
            x, P = pda_update(x, P, z, C, R, beta)
            x, P = np.asarray(x, dtype=float).reshape(4), np.asarray(P, dtype=float).reshape(4, 4)
            out.append(x[:2])
        return {"x": np.array(out), "error": np.linalg.norm(np.array(out) - truth, axis=1)}

    ref = package()
    student, message = _run(run)
    near = np.vstack([z[np.linalg.norm(z - truth[k], axis=1) < 1500.0] for k, z in enumerate(scans.scans)])
    data = {"t": scans.t, "truth": truth, "detections": near}
    return LabRun(data, {"x": ref, "error": np.linalg.norm(ref - truth, axis=1)}, student, message)
