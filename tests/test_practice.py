"""Travaux pratiques et travaux dirigés : le correcteur ``kalman_course.practice``, les pages TP et TD, les
carnets de l'étudiant et ``scripts/lab.sh``.

Le code « de l'étudiant » est défini ici comme dans une cellule Jupyter (fichier ``ipykernel_…``, texte
dans ``linecache``) : le correcteur doit nommer la ligne. Les implémentations justes viennent des
pages de TP elles-mêmes (leurs solutions) et de filterpy ; les erreurs classiques, des implémentations
fausses documentées par le correcteur et d'autres, écrites ici à la main.
"""

from __future__ import annotations

import contextlib
import json
import linecache
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from fractions import Fraction
from pathlib import Path

import itertools
import math

import numpy as np
import pytest
import scipy
import scipy.linalg
import scipy.spatial.transform
import scipy.stats

import kalman_course as kc
from kalman_course import practice
from kalman_course.practice import linear, nonlinear, sampling
from kalman_course.practice.notebooks import lab_pages, notebook_name, student_notebook, write_student_notebooks

ROOT = Path(__file__).resolve().parent.parent
BOOK = ROOT / "book"
EXERCISES = practice.exercises()
LAB_PAGES = [p.stem for p in lab_pages(BOOK)]
#: Les carnets de l'étudiant, dans l'ordre des TP (tp1-… à tp5-…).
NOTEBOOKS = {page: notebook_name(BOOK / f"{page}.md") for page in LAB_PAGES}
TUTORIAL_PAGES = sorted(p.stem for p in BOOK.glob("td-*.md"))
#: Exercices de taille fixée par l'énoncé : une rotation (3,) ; le modèle plan [e, n, v_e, v_n] (4, 4). Leurs cas
#: varient autre chose (l'angle ; le pas Δt et la densité q).
FIXED_SIZES = {"so3-exp", "cv-model"}
#: SE(2) a une taille fixée : ξ (3,), poses et covariances (3, 3), position (2,) ; les cas varient les angles.
FIXED_SIZES |= {"se2-exp", "se2-invariant-predict", "se2-invariant-update"}

_CELL = iter(range(10**6))


def cell(source: str, name: str):
    """La fonction ``name`` définie par ``source`` comme dans une cellule de Jupyter."""
    filename = f"/tmp/ipykernel_4242/{next(_CELL)}.py"
    linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)
    namespace = {"np": np, "scipy": scipy}  # les imports de la première cellule des carnets
    exec(compile(source, filename, "exec"), namespace)  # noqa: S102 — le code de l'étudiant, ici
    return namespace[name]


# --------------------------------------------------------------------------- la liste des exercices


def test_at_least_twelve_exercises_each_with_an_id_a_french_title_and_a_chapter():
    assert len(EXERCISES) >= 12
    ids = [ex.id for ex in EXERCISES]
    assert len(set(ids)) == len(ids)
    chapters = set(re.findall(r"file: book/([\w-]+)", (ROOT / "_toc.yml").read_text()))
    for ex in EXERCISES:
        assert re.fullmatch(r"[a-z0-9]+(-[a-z0-9]+)*", ex.id)
        assert ex.title and ex.title[0].isupper()
        assert ex.chapter in chapters, f"{ex.id} : chapitre {ex.chapter} absent du livre"


def test_the_six_named_exercises_have_exactly_the_given_signatures():
    signatures = {ex.id: ex.signature for ex in EXERCISES}
    assert signatures["kf-predict"] == "predict(x, P, A, Q) -> (x_pred, P_pred)"
    assert signatures["kf-update"] == "update(x_pred, P_pred, y, C, R) -> (x, P)"
    assert signatures["ekf-update"] == "update(x_pred, P_pred, y, h, H, R) -> (x, P)"
    assert signatures["sigma-points"] == "sigma_points(x, P, alpha, beta, kappa) -> (chi, wm, wc)"
    assert signatures["systematic-resample"] == "systematic_resample(weights, u) -> indices"
    assert signatures["rts-step"] == ("rts_step(x_filt, P_filt, x_smooth_next, P_smooth_next, A, Q) "
                                      "-> (x_smooth, P_smooth)")
    for ex in EXERCISES:  # la signature déclarée et les paramètres appelés sont les mêmes
        assert ex.signature.startswith(ex.signature.split("(")[0] + "(" + ", ".join(ex.parameters) + ")")


def test_every_exercise_documents_at_least_three_mistakes_with_specific_hints():
    for ex in EXERCISES:
        assert len(ex.mistakes) >= 3, ex.id
        ids = [m.id for m in ex.mistakes]
        hints = [m.hint for m in ex.mistakes]
        assert len(set(ids)) == len(ids) and len(set(hints)) == len(hints), ex.id
        for m in ex.mistakes:
            assert len(m.hint) > 60 and len(m.title) > 5, (ex.id, m.id)
            assert callable(m.example), (ex.id, m.id)


def test_every_exercise_is_practised_in_a_lab_page():
    checked = set()
    for page in LAB_PAGES:
        checked |= set(re.findall(r'practice\.check\("([\w-]+)"', (BOOK / f"{page}.md").read_text()))
    assert checked == {ex.id for ex in EXERCISES}


def test_hidden_cases_vary_sizes_and_cover_the_announced_difficulties():
    labels = {ex.id: " ".join(c.label for c in ex.cases()) for ex in EXERCISES}
    assert "non symétrique" in labels["kf-predict"]
    assert "linéaire" in labels["ekf-update"] and "distances" in labels["ekf-update"]
    assert "ω = 0" in labels["so3-exp"] and "u = 0" in labels["systematic-resample"]
    assert "très loin" in labels["particle-weights"]
    for ex in EXERCISES:
        cases = ex.cases()
        assert len(cases) >= 4, ex.id
        if ex.id in FIXED_SIZES:  # une rotation est toujours (3,) : les cas varient l'angle (0, 10⁻⁹, π…)
            continue
        shapes = {tuple(np.shape(a) for a in c.args if isinstance(a, np.ndarray)) for c in cases}
        assert len(shapes) >= 3, f"{ex.id} : les cas cachés ont presque tous les mêmes tailles"


# --------------------------------------------------------------------------- erreurs classiques

MISTAKES = [(ex.id, m.id) for ex in EXERCISES for m in ex.mistakes]


@pytest.mark.parametrize("exercise_id, mistake_id", MISTAKES)
def test_each_documented_mistake_gets_its_specific_hint(exercise_id, mistake_id):
    mistake = next(m for m in practice.exercise(exercise_id).mistakes if m.id == mistake_id)
    verdict = practice.check(exercise_id, mistake.example)
    assert not verdict.passed
    assert verdict.kind == "erreur classique" and verdict.mistake == mistake_id, verdict.feedback
    assert mistake.hint in verdict.feedback


# Erreurs écrites comme un étudiant les écrit (indépendamment des exemples du correcteur) : l'erreur
# reconnue et la ligne nommée (le texte de la ligne fautive).
STUDENT_MISTAKES = [
    ("kf-predict", "apa", "P_pred = A @ P @ A + Q", """\
def predict(x, P, A, Q):
    x_pred = A @ x
    P_pred = A @ P @ A + Q
    return x_pred, P_pred
"""),
    ("kf-predict", "elementwise", "P_pred = A * P * A.T + Q", """\
def predict(x, P, A, Q):
    x_pred = np.dot(A, x)
    P_pred = A * P * A.T + Q
    return x_pred, P_pred
"""),
    ("kf-update", "gain-r", "K = P_pred @ C.T @ np.linalg.inv(R)", """\
def update(x_pred, P_pred, y, C, R):
    nu = y - C @ x_pred
    K = P_pred @ C.T @ np.linalg.inv(R)
    return x_pred + K @ nu, (np.eye(len(x_pred)) - K @ C) @ P_pred
"""),
    ("kf-update", "p-before-k", "K = P @ C.T @ np.linalg.inv(S)", """\
def update(x_pred, P_pred, y, C, R):
    S = C @ P_pred @ C.T + R
    P = P_pred - P_pred @ C.T @ np.linalg.solve(S, C @ P_pred)
    K = P @ C.T @ np.linalg.inv(S)
    x = x_pred + K @ (y - C @ x_pred)
    return x, P
"""),
    ("ekf-update", "hx-innovation", "x = x_pred + K @ (y - Hk @ x_pred)", """\
def update(x_pred, P_pred, y, h, H, R):
    Hk = H(x_pred)
    K = P_pred @ Hk.T @ np.linalg.inv(Hk @ P_pred @ Hk.T + R)
    x = x_pred + K @ (y - Hk @ x_pred)
    return x, P_pred - K @ Hk @ P_pred
"""),
    ("ekf-update", "function-as-array", "S = H @ P_pred @ H.T + R", """\
def update(x_pred, P_pred, y, h, H, R):
    S = H @ P_pred @ H.T + R
    K = P_pred @ H.T @ np.linalg.inv(S)
    return x_pred + K @ (y - h(x_pred)), P_pred
"""),
    ("sigma-points", "cholesky-rows", "chi = np.vstack([x, x + L, x - L])", """\
def sigma_points(x, P, alpha, beta, kappa):
    n = len(x)
    lam = alpha**2 * (n + kappa) - n
    L = np.linalg.cholesky((n + lam) * P)
    chi = np.vstack([x, x + L, x - L])
    wm = np.full(2 * n + 1, 0.5 / (n + lam)); wm[0] = lam / (n + lam)
    wc = wm.copy(); wc[0] += 1 - alpha**2 + beta
    return chi, wm, wc
"""),
    ("sigma-points", "wc-equals-wm", "wc = wm", """\
def sigma_points(x, P, alpha, beta, kappa):
    n = len(x)
    lam = alpha**2 * (n + kappa) - n
    S = np.linalg.cholesky((n + lam) * P)
    chi = np.array([x] + [x + S[:, i] for i in range(n)] + [x - S[:, i] for i in range(n)])
    wm = np.full(2 * n + 1, 0.5 / (n + lam)); wm[0] = lam / (n + lam)
    wc = wm
    return chi, wm, wc
"""),
    ("unscented-transform", "cov-with-wm", "cov = sum(wm[i] * np.outer(Y[i] - mean, Y[i] - mean) for i in range(len(Y)))", """\
def unscented_transform(chi, wm, wc, f):
    Y = np.array([f(c) for c in chi])
    mean = sum(wm[i] * Y[i] for i in range(len(Y)))
    cov = sum(wm[i] * np.outer(Y[i] - mean, Y[i] - mean) for i in range(len(Y)))
    return mean, cov
"""),
    ("systematic-resample", "u-plus-i-over-n", "positions = u + np.arange(N) / N", """\
def systematic_resample(weights, u):
    N = len(weights)
    positions = u + np.arange(N) / N
    return np.searchsorted(np.cumsum(weights), positions, side="right")
"""),
    ("systematic-resample", "left-side", "while c[j] < p:", """\
def systematic_resample(weights, u):
    N = len(weights)
    c = np.cumsum(weights)
    out = []
    j = 0
    for i in range(N):
        p = (u + i) / N
        while c[j] < p:
            j += 1
        out.append(j)
    return np.array(out)
"""),
    ("particle-weights", "no-max-shift", "w = np.exp(logw)", """\
def particle_weights(log_weights, predicted, y, R):
    d = y - predicted
    logw = log_weights - 0.5 * np.einsum("ni,ij,nj->n", d, np.linalg.inv(R), d)
    w = np.exp(logw)
    return w / np.sum(w)
"""),
    ("rts-step", "smoothed-gain", "G = P_filt @ A.T @ np.linalg.inv(P_smooth_next)", """\
def rts_step(x_filt, P_filt, x_smooth_next, P_smooth_next, A, Q):
    P_pred = A @ P_filt @ A.T + Q
    G = P_filt @ A.T @ np.linalg.inv(P_smooth_next)
    x_s = x_filt + G @ (x_smooth_next - A @ x_filt)
    P_s = P_filt + G @ (P_smooth_next - P_pred) @ G.T
    return x_s, P_s
"""),
    ("em-m-step", "means-only", "", """\
def m_step(y, x_smooth, P_smooth, P_lag, A, C):
    r = x_smooth[1:] - x_smooth[:-1] @ A.T
    e = y - x_smooth[1:] @ C.T
    return r.T @ r / len(y), e.T @ e / len(y)
"""),
    ("so3-exp", "nan-at-zero", "k = omega / theta", """\
def so3_exp(omega):
    theta = np.linalg.norm(omega)
    k = omega / theta
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(theta) * K + (1 - np.cos(theta)) * K @ K
"""),
    ("se2-exp", "v-forgotten", "T[:2, 2] = xi[:2]", """\
def se2_exp(xi):
    c, s = np.cos(xi[2]), np.sin(xi[2])
    T = np.eye(3)
    T[:2, :2] = [[c, -s], [s, c]]
    T[:2, 2] = xi[:2]
    return T
"""),
    ("se2-invariant-predict", "adjoint-not-inverted", "F = adjoint(U)", """\
def predict(T, P, u, dt, Q):
    def adjoint(M):
        A = np.eye(3)
        A[:2, :2] = M[:2, :2]
        A[:2, 2] = [M[1, 2], -M[0, 2]]
        return A
    a = u[2] * dt
    U = np.array([[np.cos(a), -np.sin(a), u[0] * dt], [np.sin(a), np.cos(a), u[1] * dt], [0, 0, 1]])
    F = adjoint(U)
    G = dt * np.eye(3)
    G[:2, :2] = dt * U[:2, :2].T
    return T @ U, F @ P @ F.T + G @ Q @ G.T
"""),
    ("se2-invariant-update", "world-innovation", "z = y - T_pred[:2, 2]", """\
def update(T_pred, P_pred, y, gnss_std):
    from scipy.linalg import expm
    z = y - T_pred[:2, 2]
    H = np.hstack([np.eye(2), np.zeros((2, 1))])
    S = H @ P_pred @ H.T + gnss_std**2 * np.eye(2)
    K = P_pred @ H.T @ np.linalg.inv(S)
    d = K @ z
    T = T_pred @ expm(np.array([[0, -d[2], d[0]], [d[2], 0, d[1]], [0, 0, 0]]))
    return T, (np.eye(3) - K @ H) @ P_pred
"""),
    ("tag-jacobian", "sign", "", """\
def ranges_jacobian(x, anchors):
    H = np.zeros((len(anchors), 4))
    for i, a in enumerate(anchors):
        d = a - x[:2]
        H[i, :2] = d / np.linalg.norm(d)
    return H
"""),
    ("nis", "s-not-inverted", "return np.array([nu @ Sk @ nu for nu, Sk in zip(innovations, S)])", """\
def nis(innovations, S):
    return np.array([nu @ Sk @ nu for nu, Sk in zip(innovations, S)])
"""),
    ("joseph-update", "short-form", "P = (np.eye(len(x_pred)) - K @ C) @ P_pred", """\
def joseph_update(x_pred, P_pred, y, C, R, K):
    x = x_pred + K @ (y - C @ x_pred)
    P = (np.eye(len(x_pred)) - K @ C) @ P_pred
    return x, P
"""),
]


@pytest.mark.parametrize("exercise_id, mistake_id, line, source", STUDENT_MISTAKES,
                         ids=[f"{e}-{m}" for e, m, _, _ in STUDENT_MISTAKES])
def test_student_written_mistakes_are_recognised_and_their_line_named(exercise_id, mistake_id, line, source):
    name = re.match(r"def (\w+)", source).group(1)
    verdict = practice.check(exercise_id, cell(source, name))
    assert not verdict.passed and verdict.mistake == mistake_id, verdict.feedback
    assert "de votre cellule" in verdict.feedback
    if line:
        number = next(i for i, text in enumerate(source.splitlines(), 1) if text.strip() == line)
        assert verdict.line == number, verdict.feedback
        assert f"`{line}`" in verdict.feedback


# --------------------------------------------------------------------------- solutions justes


def _page_cells(page: str) -> list[tuple[str, str]]:
    """Les cellules de code d'une page : (« skeleton », « solution » ou « other », source)."""
    text = (BOOK / f"{page}.md").read_text()
    cells = []
    for m in re.finditer(r"```\{code-cell\}[^\n]*\n(.*?)```", text, re.S):
        before = text[:m.start()]
        inside = before.rfind("```{solution-start}") > before.rfind("```{solution-end}")
        body = re.sub(r"^(:[\w-]+:.*\n)+", "", m.group(1))
        kind = "solution" if inside else ("skeleton" if "raise NotImplementedError" in body else "other")
        cells.append((kind, body))
    return cells


def _lab_functions(page: str, kind: str) -> dict[str, tuple[str, object]]:
    """Exercice → fonction (squelettes ou solutions de la page), d'après la vérification qui suit."""
    cells = _page_cells(page)
    out = {}
    last = {}
    for k, body in cells:
        if k == kind:
            name = re.match(r"def (\w+)", body).group(1)
            last[name] = cell(body, name)
        m = re.match(r'practice\.check\("([\w-]+)", (\w+)\)', body.strip())
        if m:
            out[m.group(1)] = last[m.group(2)]
    return out


@pytest.mark.parametrize("page", LAB_PAGES)
def test_lab_page_solutions_pass_and_skeletons_are_not_yet_written(page):
    solutions = _lab_functions(page, "solution")
    skeletons = _lab_functions(page, "skeleton")
    assert solutions and solutions.keys() == skeletons.keys()
    for exercise_id, fn in solutions.items():
        verdict = practice.check(exercise_id, fn)
        assert verdict.passed, verdict.feedback
        assert verdict._repr_html_().count("kc-verdict-reussi") == 1
    for exercise_id, fn in skeletons.items():
        verdict = practice.check(exercise_id, fn)
        assert not verdict.passed and verdict.kind == "pas écrite"
        assert "pas encore écrite" in verdict.feedback and "`raise NotImplementedError`" in verdict.feedback
        assert verdict.line is not None


def test_independent_implementations_from_filterpy_pass(monkeypatch):
    """filterpy (fonctions predict/update, MerweScaledSigmaPoints, unscented_transform,
    systematic_resample) : écrit par d'autres, il passe le correcteur — les cas cachés et leurs
    références ne dépendent pas de nos propres conventions."""
    import filterpy.kalman as fk
    import filterpy.monte_carlo.resampling as fr

    def predict(x, P, A, Q):
        return fk.predict(x, P, A, Q)

    def update(x_pred, P_pred, y, C, R):
        return fk.update(x_pred, P_pred, y, R, C)

    def sigma_points(x, P, alpha, beta, kappa):
        points = fk.MerweScaledSigmaPoints(len(x), alpha, beta, kappa)
        return points.sigma_points(x, P), points.Wm, points.Wc

    def unscented_transform(chi, wm, wc, f):
        return fk.unscented_transform(np.array([f(c) for c in chi]), wm, wc)

    def systematic_resample(weights, u):
        monkeypatch.setattr(fr, "random", lambda: u)
        return fr.systematic_resample(weights)

    for exercise_id, fn in (("kf-predict", predict), ("kf-update", update), ("sigma-points", sigma_points),
                            ("unscented-transform", unscented_transform)):
        verdict = practice.check(exercise_id, fn)
        assert verdict.passed, (exercise_id, verdict.feedback)
    # filterpy 2.0.0 ne force pas la dernière somme cumulée à 1 : sur le cas caché de l'arrondi (27 poids égaux,
    # somme cumulée 1 − 8 × 10⁻¹⁶ sous la dernière position), sa boucle sort du tableau. Il passe tous les autres.
    verdict = practice.check("systematic-resample", systematic_resample)
    assert not verdict.passed and "IndexError" in verdict.feedback and "(arrondi)" in verdict.feedback
    for case in practice.exercise("systematic-resample").cases():
        if "arrondi" not in case.label:
            assert np.array_equal(systematic_resample(*case.args), case.expected[0]), case.label


def test_closed_form_references_agree_with_independent_computations():
    rng = np.random.default_rng(0)
    # forme de Joseph au gain optimal = correction de filterpy (qui utilise Joseph)
    import filterpy.kalman as fk

    for case in linear.JOSEPH_UPDATE.cases():
        x, P, y, C, R, K = case.args
        optimal = np.linalg.solve(C @ P @ C.T + R, C @ P).T
        x_ref, P_ref = linear.joseph_reference(x, P, y, C, R, optimal)
        x_fp, P_fp = fk.update(x, P, y, R, C)
        assert np.allclose(x_ref, x_fp, atol=1e-10) and np.allclose(P_ref, P_fp, atol=1e-10)
    # NIS = kc.nis d'un vrai filtre
    model = kc.LinearGaussianModel(np.eye(2), rng.standard_normal((2, 2)), 0.1 * np.eye(2), np.eye(2))
    res = kc.kalman_filter(model, rng.standard_normal((20, 2)), np.zeros(2), np.eye(2))
    assert np.allclose(linear.nis_reference(res.innovation, res.S), kc.nis(res), rtol=1e-10)
    # poids des particules = densités gaussiennes directes, normalisées (cas sans débordement)
    log_w = np.log(rng.dirichlet(np.ones(7)))
    pred, y, R = rng.standard_normal((7, 2)), rng.standard_normal(2), np.array([[0.5, 0.1], [0.1, 0.3]])
    direct = np.exp(log_w) * scipy.stats.multivariate_normal(y, R).pdf(pred)
    assert np.allclose(sampling.particle_weights_reference(log_w, pred, y, R), direct / direct.sum(), rtol=1e-10)
    # jacobienne des distances = différences finies ; exponentielle de SO(3) = scipy Rotation
    for case in nonlinear.TAG_JACOBIAN.cases():
        x, anchors = case.args
        numeric = kc.numerical_jacobian(lambda z: np.linalg.norm(z[:2] - anchors, axis=1), x)
        assert np.allclose(case.expected[0], numeric, atol=1e-6)
    for case in nonlinear.SO3_EXP.cases():
        rotation = scipy.spatial.transform.Rotation.from_rotvec(case.args[0]).as_matrix()
        assert np.allclose(case.expected[0], rotation, atol=1e-12)


# --------------------------------------------------------------------------- jamais d'exception

_NASTY = {
    "exception": "def predict(x, P, A, Q):\n    raise ValueError('oups')\n",
    "exception maison": "class Erreur(Exception):\n    pass\n\ndef predict(x, P, A, Q):\n    raise Erreur()\n",
    "nom inconnu": "def predict(x, P, A, Q):\n    return A @ x, A @ PP @ A.T + Q\n",
    "division par zéro": "def predict(x, P, A, Q):\n    return A @ x, P / 0\n",
    "récursion": "def predict(x, P, A, Q):\n    return predict(x, P, A, Q)\n",
    "sys.exit": "import sys\n\ndef predict(x, P, A, Q):\n    sys.exit(1)\n",
    "rien": "def predict(x, P, A, Q):\n    x_pred = A @ x\n",
    "texte": "def predict(x, P, A, Q):\n    return 'x', 'P'\n",
    "trois valeurs": "def predict(x, P, A, Q):\n    return A @ x, A @ P @ A.T + Q, 0\n",
    "une seule valeur": "def predict(x, P, A, Q):\n    return A @ P @ A.T + Q\n",
    "générateur": "def predict(x, P, A, Q):\n    yield A @ x\n",
    "objet étrange": ("class Bizarre:\n    def __array__(self, *a, **k):\n        raise RuntimeError('non')\n\n"
                      "def predict(x, P, A, Q):\n    return Bizarre(), Bizarre()\n"),
    "dictionnaire": "def predict(x, P, A, Q):\n    return {'x': x}, P\n",
    "NaN": "def predict(x, P, A, Q):\n    return A @ x, np.full(P.shape, np.nan)\n",
    "non symétrique": "def predict(x, P, A, Q):\n    return A @ x, A @ P @ A.T + Q + np.triu(np.ones_like(P), 1)\n",
    "colonne": "def predict(x, P, A, Q):\n    return (A @ x)[:, None], A @ P @ A.T + Q\n",
    "mauvaise forme": "def predict(x, P, A, Q):\n    return A @ x, np.zeros(3)\n",
    "modifie P": "def predict(x, P, A, Q):\n    P += Q\n    return A @ x, A @ P @ A.T\n",
    "hasard": "def predict(x, P, A, Q):\n    return A @ x + 1e-3 * np.random.standard_normal(len(x)), A @ P @ A.T + Q\n",
    "bavarde": "def predict(x, P, A, Q):\n    print('coucou')\n    np.log(-1.0)\n    return A @ x, A @ P\n",
    "boucle sans fin": "def predict(x, P, A, Q):\n    while True:\n        pass\n",
    "mauvaise signature": "def predict(x, P):\n    return x, P\n",
}


@pytest.mark.parametrize("what", list(_NASTY))
def test_check_never_raises_and_explains_in_french(what, monkeypatch, capsys):
    monkeypatch.setattr(practice.student, "TIME_LIMIT", 0.5)
    fn = cell(_NASTY[what], "predict")
    verdict = practice.check("kf-predict", fn)
    assert isinstance(verdict, practice.Verdict) and not verdict.passed
    assert verdict.feedback and "Traceback" not in verdict.feedback
    assert re.search(r"[éèàù]|votre|Votre", verdict.feedback), verdict.feedback
    if what in ("modifie P",):
        assert "sur place" in verdict.feedback and "`P += Q`" in verdict.feedback
    if what == "boucle sans fin":
        assert "n'a pas rendu la main" in verdict.feedback
    if what == "colonne":
        assert "(1, 1)" in verdict.feedback and "attendu (1,)" in verdict.feedback
    if what == "non symétrique":
        assert "pas symétrique" in verdict.feedback
    if what == "hasard":
        assert "deux résultats" in verdict.feedback


def test_check_refuses_gently_what_is_not_a_function_or_not_an_exercise():
    fn = cell("def predict(x, P, A, Q):\n    return A @ x, A @ P @ A.T + Q\n", "predict")
    assert practice.check("kf-predict", fn).passed
    for verdict in (practice.check("kf-predict", 3), practice.check("kf-predit", fn), practice.check(None, fn)):
        assert not verdict.passed and verdict.feedback
    assert "Exercices : kf-predict" in practice.check("kf-predit", fn).feedback
    with pytest.raises(kc.KalmanInputError, match="Exercice inconnu"):
        practice.exercise("kf-predit")


def test_verdict_displays_as_a_box_that_says_the_result_in_words_not_only_in_colour():
    good = practice.check("kf-predict", linear.predict_solution)
    bad = practice.check("kf-predict", cell("def predict(x, P, A, Q):\n    raise NotImplementedError\n", "predict"))
    for verdict, word, css in ((good, "✔ Réussi", "kc-verdict-reussi"), (bad, "✘ À corriger", "kc-verdict-a-corriger")):
        html = verdict._repr_html_()
        assert css in html and 'role="status"' in html and word in html and word in str(verdict)
        assert "<code>raise NotImplementedError</code>" in html or verdict.passed
    assert "<script" not in practice.check("kf-predict", cell(
        "def predict(x, P, A, Q):\n    raise ValueError('<script>alert(1)</script>')\n", "predict"))._repr_html_()


# --------------------------------------------------------------------------- TP : expériences et figures


def test_lab_experiments_with_the_page_solutions_equal_the_package_filters():
    s = {**_lab_functions("tp-filtre-lineaire", "solution"), **_lab_functions("tp-ekf-tag", "solution"),
         **_lab_functions("tp-ukf-particulaire", "solution"), **_lab_functions("tp-lissage-em", "solution")}
    labs = kc.scenarios.labs
    run = labs.voltage_lab(s["kf-predict"], s["kf-update"])
    assert run.message is None
    assert np.allclose(run.student["x"], run.reference["x"], atol=1e-12)
    assert np.allclose(run.student["P"], run.reference["P"], rtol=1e-10)
    run = labs.tag_lab(s["ekf-update"], s["tag-jacobian"])
    assert run.message is None and np.allclose(run.student["x"], run.reference["x"], atol=1e-8)
    run = labs.pendulum_lab(s["sigma-points"], s["unscented-transform"], s["systematic-resample"],
                            s["particle-weights"])
    assert run.message is None and np.allclose(run.student["ukf"], run.reference["ukf"], atol=1e-9)
    # filtre particulaire : mêmes lois, tirages différents — même précision, pas mêmes valeurs
    truth = run.data["true"][:, 0]
    rmse = [np.sqrt(np.mean((x[:, 0] - truth) ** 2)) for x in (run.student["pf"], run.reference["pf"])]
    assert 0.5 < rmse[0] / rmse[1] < 2.0
    run = labs.nile_lab(s["rts-step"], s["em-m-step"])
    assert run.message is None
    assert np.allclose(run.student["smoothed"], run.reference["smoothed"], rtol=1e-10)
    assert np.allclose(run.student["variances"], run.reference["variances"], rtol=1e-8)


def test_lab_figures_show_only_the_package_and_say_why_when_the_student_code_fails():
    blank = cell("def predict(x, P, A, Q):\n    raise NotImplementedError\n", "predict")
    fig = kc.figures.draw("tp-tension", predict=blank)
    assert "pas encore écrite" in fig._suptitle.get_text() and "ligne 2 de votre cellule" in fig._suptitle.get_text()
    assert len(fig.axes[0].get_lines()) == 3  # valeur vraie, mesures, paquet : pas de courbe de l'étudiant
    broken = cell("def update(x_pred, P_pred, y, h, H, R):\n    return x_pred\n", "update")
    run = kc.scenarios.labs.tag_lab(update=broken)
    assert run.student is None and run.message
    assert kc.figures.draw("tp-tension")._suptitle is None


# --------------------------------------------------------------------------- TD : réponses recalculées


def _page(page: str) -> str:
    return (BOOK / f"{page}.md").read_text()


def test_tutorial_one_answers_are_the_package_values():
    text = _page("td-filtre-lineaire")
    step = kc.scenarios.tutorials.thermometer_update()
    assert "$S = 4 + 1 = 5$, $K = 4/5 = 0{,}8$" in text
    assert r"$\hat x = 20 + 0{,}8 \times (23 - 20) = 22{,}4$ °C" in text
    assert r"$P = (1 - 0{,}8) \times 4 = 0{,}8$ °C²" in text
    assert step.K[0, 0] == pytest.approx(0.8, abs=1e-14) and step.S[0, 0] == pytest.approx(5.0)
    assert step.x[0] == pytest.approx(22.4, abs=1e-12) and step.P[0, 0] == pytest.approx(0.8, abs=1e-14)
    # les rapports cités : la mesure est quatre fois plus précise que l'a priori (4 / 1), la variance a
    # posteriori cinq fois plus petite que celle de l'a priori (4 / 0,8) — et non « quatre fois plus sûre »
    c = kc.scenarios.tutorials.THERMOMETER
    assert "quatre fois plus précise que l'a priori" in text and "cinq\nfois plus petite" in text
    assert c["P_prior"] / c["R"] == pytest.approx(4.0) and c["P_prior"] / step.P[0, 0] == pytest.approx(5.0)
    assert "quatre fois plus sûre" not in text


def test_tutorial_two_answers_are_the_package_values():
    text = _page("td-filtres-a-points")
    ut = kc.scenarios.tutorials.square_transform()
    assert r"$\chi = (0,\ \sqrt3,\ -\sqrt3)$" in text and r"$W^m = W^c = (2/3,\ 1/6,\ 1/6)$" in text
    assert np.allclose(ut.points, [0.0, np.sqrt(3), -np.sqrt(3)], atol=1e-14)
    assert np.allclose(ut.Wm, [2 / 3, 1 / 6, 1 / 6], atol=1e-14) and np.allclose(ut.Wc, ut.Wm, atol=1e-14)
    assert r"\tfrac16 \cdot 3 = 1$" in text and r"\tfrac43 = 2$" in text
    assert ut.mean == pytest.approx(1.0, abs=1e-12) and ut.variance == pytest.approx(2.0, abs=1e-12)
    assert "$f(0) = 0$ et $f'(0)^2 \\cdot 1 = 0$" in text
    assert ut.linearised_mean == 0.0 and ut.linearised_variance == 0.0
    # rééchantillonnage : positions, sommes cumulées, particules copiées (numérotées à partir de 1)
    assert "Positions : $0{,}125$, $0{,}375$, $0{,}625$, $0{,}875$" in text
    assert "Le nouveau nuage est $(x^2, x^3, x^4, x^4)$" in text
    assert list(kc.scenarios.tutorials.four_particles() + 1) == [2, 3, 4, 4]
    assert "$N w^4 = 1{,}6$ copies" in text and "toujours 1 ou 2" in text
    weights = kc.scenarios.tutorials.FOUR_WEIGHTS
    assert 4 * weights[3] == pytest.approx(1.6)
    copies = {int(np.sum(kc.systematic_resample(weights, u) == 3)) for u in np.linspace(0, 1, 200, endpoint=False)}
    assert copies == {1, 2}
    # EnKF : (1 − K)² P + K² R = (1 − K) P = 0,8 ; sans perturbation 0,16
    spread = kc.scenarios.tutorials.ensemble_spread()
    assert r"$0{,}04 \times 4 + 0{,}64 \times 1 = 0{,}8$ ; sans, $0{,}16$" in text
    assert spread["exact"] == pytest.approx(0.8, abs=1e-14)
    assert spread["exact_unperturbed"] == pytest.approx(0.16, abs=1e-14)
    assert spread["perturbed"] == pytest.approx(0.8, rel=0.02)
    assert spread["unperturbed"] == pytest.approx(0.16, rel=0.02)


def _fractions(text: str, symbol: str) -> list[Fraction]:
    """Les valeurs « symbole = … = a/b » écrites dans la page (la dernière égalité de chaque calcul)."""
    pattern = re.escape(symbol) + r"[^$]*?= (\d+)/(\d+)(?=[$,])"
    return [Fraction(int(a), int(b)) for a, b in re.findall(pattern, text)]


def test_tutorial_three_answers_are_the_package_values():
    text = _page("td-lissage-em")
    steps = kc.scenarios.tutorials.three_step_smoothing()
    for k in (1, 2, 3):
        assert _fractions(text, rf"\hat x_{{{k}|{k}}}")[0] == pytest.approx(steps.x[k - 1], abs=1e-14)
        assert _fractions(text, rf"P_{{{k}|{k}}}")[0] == pytest.approx(steps.P[k - 1], abs=1e-14)
        assert _fractions(text, rf"\hat x_{{{k}|3}}")[0] == pytest.approx(steps.xs[k - 1], abs=1e-14) \
            if k < 3 else True
    for k in (1, 2):
        assert _fractions(text, rf"P_{{{k}|3}}")[0] == pytest.approx(steps.Ps[k - 1], abs=1e-14)
        assert _fractions(text, rf"G_{k}")[0] == pytest.approx(steps.G[k - 1], abs=1e-14)
    assert "$\\hat x_{3|3} = 43/21$, $P_{3|3} = 13/21$" in text  # le départ du lisseur
    assert steps.xs[2] == pytest.approx(43 / 21) and steps.Ps[2] == pytest.approx(13 / 21)
    assert _fractions(text, "R'")[-1] == pytest.approx(steps.R_new, abs=1e-14)
    assert "= 40/49$" in text


def test_tutorial_invariant_answers_are_the_package_values():
    """TD 7 : Exp(1, 0, π/2), l'adjointe de la pose (90°, (3, 1)) et la correction de l'EKF invariant, écrites à
    la main dans la page, contre le paquet (kc.se2_exp, kc.se2_adjoint, se2_invariant_update) et contre des
    calculs indépendants écrits ici (scipy.linalg.expm, formule de Kalman)."""
    import scipy.linalg

    text = _page("td-filtrage-invariant")
    hand = kc.scenarios.tutorials.se2_by_hand()
    r = 2 / np.pi
    exp_hand = np.array([[0, -1, r], [1, 0, r], [0, 0, 1.0]])
    hat = np.array([[0, -np.pi / 2, 1.0], [np.pi / 2, 0, 0], [0, 0, 0]])
    np.testing.assert_allclose(hand.exp, exp_hand, atol=1e-15)
    np.testing.assert_allclose(scipy.linalg.expm(hat), exp_hand, atol=1e-13)
    assert r"V(\pi/2)\rho = (2/\pi,\ 2/\pi) \approx (0{,}637 ;\ 0{,}637)" in text
    assert r"\begin{bmatrix} 0 & -1 & 2/\pi \\ 1 & 0 & 2/\pi \\ 0 & 0 & 1 \end{bmatrix}" in text
    ad_hand = np.array([[0, -1, 1], [1, 0, -3], [0, 0, 1.0]])
    np.testing.assert_array_equal(hand.adjoint, ad_hand)
    assert r"\mathrm{Ad}_{\hat T} = \begin{bmatrix} 0 & -1 & 1 \\ 1 & 0 & -3 \\ 0 & 0 & 1 \end{bmatrix}" in text
    eps = 1e-3  # Ad δ = (ε, −3ε, ε) : la rotation d'angle ε autour de la position (3, 1)
    np.testing.assert_allclose(hand.adjoint @ [0, 0, eps], [eps, -3 * eps, eps], atol=1e-18)
    assert r"(\varepsilon, -3\varepsilon, \varepsilon)" in text
    up = hand.update
    c = kc.scenarios.tutorials.SE2_BY_HAND
    P, H = np.array(c["P_pred"]), np.hstack([np.eye(2), np.zeros((2, 1))])
    K = P @ H.T @ np.linalg.inv(H @ P @ H.T + np.eye(2))
    np.testing.assert_allclose(up.innovation, [2.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(up.S, 2 * np.eye(2), atol=1e-15)
    np.testing.assert_allclose(up.K, [[0.5, 0], [0, 0.5], [np.pi / 4, 0]], atol=1e-15)
    np.testing.assert_allclose(up.K, K, atol=1e-15)
    np.testing.assert_allclose(up.K @ up.innovation, [1.0, 0.0, np.pi / 2], atol=1e-15)
    assert "$z = (2, 0)$" in text and "$Kz = (1, 0, \\pi/2)$" in text
    np.testing.assert_allclose(up.T[:2, :2], -np.eye(2), atol=1e-15)  # cap 180°
    np.testing.assert_allclose(up.T[:2, 2], [3 - r, 1 + r], atol=1e-14)
    assert "(3 - 2/\\pi,\\ 1 + 2/\\pi) \\approx (2{,}363 ;\\ 1{,}637)" in text and "cap **180°**" in text
    assert f"{3 - r:.3f}" == "2.363" and f"{1 + r:.3f}" == "1.637"
    P_plus = np.array([[0.5, 0, np.pi / 4], [0, 0.5, 0], [np.pi / 4, 0, 4 - np.pi**2 / 8]])
    np.testing.assert_allclose(up.P, P_plus, atol=1e-14)
    np.testing.assert_allclose(up.P, (np.eye(3) - K @ H) @ P, atol=1e-14)
    assert "4 - \\pi^2/8 \\approx 2{,}766" in text and f"{4 - np.pi**2 / 8:.3f}" == "2.766"
    # question 5 : tourner le monde ne change ni z, ni K, ni P₊
    g = kc.se2_exp([0.0, 0.0, 0.7])
    turned = kc.filters.invariant.se2_invariant_update(g @ np.array(c["T_pred"]), P, g[:2, :2] @ np.array(c["y"]), 1.0)
    for field in ("innovation", "K", "P"):
        np.testing.assert_allclose(getattr(turned, field), getattr(up, field), atol=1e-12)
    np.testing.assert_allclose(turned.T, g @ up.T, atol=1e-12)


# --------------------------------------------------------------------------- carnets de l'étudiant


def test_student_notebooks_follow_the_lab_pages(tmp_path):
    written = write_student_notebooks(BOOK, tmp_path)
    assert [p.name for p in written] == [NOTEBOOKS[page] for page in LAB_PAGES]
    # ils se rangent dans l'ordre du cours, TP 1 … TP 5, dans un explorateur de fichiers
    assert sorted(p.name for p in written) == [p.name for p in written]
    assert [p.name[:3] for p in written] == [f"tp{k}" for k in range(1, len(written) + 1)]
    assert sorted(p.name for p in (BOOK / "travaux-pratiques").glob("*.ipynb")) == [p.name for p in written]
    for path in written:
        committed = BOOK / "travaux-pratiques" / path.name
        assert committed.is_file(), f"{committed} manque : python -m kalman_course.practice --notebooks book/travaux-pratiques"
        assert committed.read_bytes() == path.read_bytes(), (
            f"{committed.name} ne suit plus sa page : python -m kalman_course.practice --notebooks book/travaux-pratiques")


@pytest.mark.parametrize("page", LAB_PAGES)
def test_student_notebook_has_the_blanks_the_checks_and_no_solution(page):
    nb = student_notebook(BOOK / f"{page}.md", BOOK)
    code = [c.source for c in nb.cells if c.cell_type == "code"]
    text = "\n".join(c.source for c in nb.cells)
    skeletons = [body.strip() for kind, body in _page_cells(page) if kind == "skeleton"]
    solutions = [body.strip() for kind, body in _page_cells(page) if kind == "solution"]
    assert skeletons and all(s in code for s in skeletons)
    assert all("# À vous" in s for s in skeletons)
    assert not any(s in text for s in solutions)
    assert "solution-start" not in text and "{exercise}" not in text and "{doc}" not in text
    assert sum("practice.check(" in c for c in code) == len(skeletons)
    assert any("kc.figures.draw(" in c for c in code) and code[0].startswith("import numpy as np")
    assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code")


@pytest.mark.parametrize("page", LAB_PAGES)
def test_student_notebook_text_is_made_for_the_notebook_and_carries_the_quiz(page):
    """Le carnet ne parle pas du site (« Téléchargez… », blocs repliés, encadré « Comment travailler ») ; sa
    première cellule dit comment travailler et quoi faire si `import kalman_course` échoue ; le quiz de la
    page y est, chaque réponse repliée avec son explication."""
    from test_chapter_pedagogy import quiz_questions

    nb = student_notebook(BOOK / f"{page}.md", BOOK)
    first = nb.cells[0].source
    assert nb.cells[0].cell_type == "markdown"
    assert "import kalman_course" in first and "ModuleNotFoundError" in first and "bash scripts/lab.sh" in first
    assert kc.practice.wheel_name() in first and "activate" in first
    rest = "\n".join(c.source for c in nb.cells[1:] if c.cell_type == "markdown")
    for web_only in ("Téléchargez", "blocs repliés", "solutions sont repliées", "Comment travailler",
                     "comment-travailler", "sur la page du cours", "ADRESSE-DU-COURS"):
        assert web_only not in rest, web_only
    questions = quiz_questions(_page(page))
    assert rest.count("<details><summary>Réponse</summary>") == len(questions) >= 3
    for q in questions:
        right = q["choices"][q["answer"] - 1]
        assert f"** {right} — " in rest, right


@pytest.mark.parametrize("page", LAB_PAGES)
def test_student_notebook_runs_and_every_check_says_not_yet_written(page, monkeypatch):
    """Le carnet de l'étudiant, exécuté tel quel (cellule par cellule, comme Jupyter) : aucune
    exception, chaque vérification répond « pas encore écrite », la figure ne montre que le paquet."""
    nb = student_notebook(BOOK / f"{page}.md", BOOK)
    namespace: dict = {}
    verdicts, figures = [], []
    for c in nb.cells:
        if c.cell_type != "code":
            continue
        source = c.source
        filename = f"/tmp/ipykernel_4242/{page}-{c['id']}.py"
        linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)
        if source.startswith(("practice.", "kc.")):  # une expression : sa valeur est affichée
            value = eval(compile(source.strip(), filename, "eval"), namespace)  # noqa: S307
            (verdicts if isinstance(value, practice.Verdict) else figures).append(value)
        else:
            exec(compile(source, filename, "exec"), namespace)  # noqa: S102
    assert verdicts and all(v.kind == "pas écrite" and "pas encore écrite" in v.feedback for v in verdicts)
    assert figures and all("pas encore écrite" in f._suptitle.get_text() for f in figures)


# --------------------------------------------------------------------------- scripts/lab.sh


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_lab_script_opens_jupyterlab_offline_on_the_lab_notebooks(tmp_path):
    """``bash scripts/lab.sh`` : copie les carnets dans travaux-pratiques/ (sans écraser un carnet
    commencé) et sert JupyterLab sur ce dossier ; l'API liste les carnets et la page /lab se charge."""
    work = ROOT / "travaux-pratiques"
    had_work = work.exists()
    if not had_work:  # un carnet « commencé » par l'étudiant : lab.sh ne doit pas l'écraser
        work.mkdir()
        first = NOTEBOOKS[LAB_PAGES[0]]
        (work / first).write_text((BOOK / "travaux-pratiques" / first).read_text().replace("# À vous", "# commencé"))
    existed = {p.name: p.read_bytes() for p in work.glob("*.ipynb")}
    port = _free_port()
    log = tmp_path / "lab.log"
    env = {**os.environ, "JUPYTER_CONFIG_DIR": str(tmp_path / "config"), "JUPYTER_RUNTIME_DIR": str(tmp_path / "rt"),
           "JUPYTERLAB_SETTINGS_DIR": str(tmp_path / "settings"), "JUPYTERLAB_WORKSPACES_DIR": str(tmp_path / "ws")}
    with open(log, "w") as out:
        proc = subprocess.Popen(["bash", str(ROOT / "scripts" / "lab.sh"), "--no-browser", f"--port={port}",
                                 "--ServerApp.port_retries=0", "--IdentityProvider.token=", "--ServerApp.ip=127.0.0.1"],
                                cwd=ROOT, stdout=out, stderr=subprocess.STDOUT, env=env, start_new_session=True)
    try:
        listing = None
        for _ in range(240):
            with contextlib.suppress(OSError):
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/api/contents", timeout=5) as r:
                    listing = r.read().decode()
                break
            assert proc.poll() is None, log.read_text()[-3000:]
            time.sleep(0.5)
        assert listing is not None, log.read_text()[-3000:]
        names = set(re.findall(r'"name": ?"([^"]+\.ipynb)"', listing))
        assert names >= set(NOTEBOOKS.values())
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/lab", timeout=10) as r:
            assert r.status == 200 and "JupyterLab" in r.read().decode()
        # en français, sans la question des nouvelles (en anglais) ni la recherche de mises à jour
        settings = f"http://127.0.0.1:{port}/lab/api/settings/"
        with urllib.request.urlopen(settings + "@jupyterlab/apputils-extension:notification", timeout=10) as r:
            notification = json.loads(r.read().decode())["schema"]["properties"]
        assert notification["fetchNews"]["default"] == "false"
        assert notification["checkForUpdates"]["default"] is False
        with urllib.request.urlopen(settings + "@jupyterlab/translation-extension:plugin", timeout=10) as r:
            assert json.loads(r.read().decode())["schema"]["properties"]["locale"]["default"] == "fr_FR"
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/lab/api/translations/fr_FR", timeout=10) as r:
            assert "Fichier" in r.read().decode()  # le paquet de langue est installé
        for name, content in existed.items():  # un carnet commencé n'est jamais écrasé
            assert (work / name).read_bytes() == content
        for name in NOTEBOOKS.values():
            assert (work / name).is_file()
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGTERM)
        proc.wait(timeout=30)
        if not had_work:  # le dossier de travail n'existait pas : on le retire
            shutil.rmtree(work, ignore_errors=True)


def test_binder_opens_the_lab_notebooks_with_the_pinned_jupyterlab():
    post = (ROOT / "binder" / "postBuild").read_text()
    folder = re.search(r'default_url = "/lab/tree/([^"]+)"', post).group(1)
    assert sorted(p.name for p in (ROOT / folder).glob("*.ipynb")) == [NOTEBOOKS[page] for page in LAB_PAGES]
    assert "-r ../requirements.txt" in (ROOT / "binder" / "requirements.txt").read_text()
    assert re.search(r"(?m)^jupyterlab==\d", (ROOT / "requirements.txt").read_text())


# --------------------------------------------------------------------------- livre construit


@pytest.mark.book
@pytest.mark.parametrize("page", LAB_PAGES)
def test_built_lab_page_ran_its_solutions_and_offers_the_student_notebook(built_book, page):
    """La construction exécute chaque TP avec ses solutions : toutes les vérifications sont vertes,
    la figure de l'étudiant est tracée, et le carnet à compléter se télécharge."""
    html = (built_book / "book" / f"{page}.html").read_text()
    checks = len(re.findall(r"^practice\.check\(", _page(page), re.M))
    assert html.count('class="kc-verdict kc-verdict-reussi"') == checks
    assert "kc-verdict-a-corriger" not in html and "Fonction pas encore écrite" not in html
    assert "Votre filtre n&#39;a pas pu tourner" not in html and "Votre filtre n'a pas pu tourner" not in html
    name = re.escape(NOTEBOOKS[page])
    link = re.search(rf'href="(\.\./_downloads/[0-9a-f]+/{name})"', html)
    assert link, f"{page} : pas de lien de téléchargement du carnet"
    downloaded = (built_book / "book" / link.group(1)).resolve()
    assert downloaded.read_bytes() == (BOOK / "travaux-pratiques" / NOTEBOOKS[page]).read_bytes()
    served = built_book / "travaux-pratiques" / NOTEBOOKS[page]
    assert served.read_bytes() == downloaded.read_bytes()
    assert 'class="solution dropdown' in html


# --------------------------------------------------------------------------- issue 34 : faux succès, indices trompeurs


def test_so3_hidden_angles_cover_every_regime_and_refuse_a_wide_small_angle_branch():
    """« if θ < 0,3 : return I » passait (angles cachés 0, 10⁻⁹ puis 0,37 rad) : les cas couvrent maintenant
    les petits (10⁻⁵, 0,05), moyens, grands angles et au-delà de π ; une branche petit angle fausse n'est pas
    prise pour une erreur de la formule générale."""
    thetas = sorted(c.info["theta"] for c in nonlinear.SO3_EXP.cases())
    assert thetas[0] == 0.0 and any(1e-6 < t < 1e-3 for t in thetas) and any(1e-2 < t < 0.1 for t in thetas)
    assert any(0.9 < t < 1.1 for t in thetas) and any(t > np.pi for t in thetas)
    rodrigues = """\
def so3_exp(omega):
    theta = np.linalg.norm(omega)
    if theta < {threshold}:
        return {small}
    k = omega / theta
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(theta) * K + (1 - np.cos(theta)) * K @ K
"""
    hat = "np.array([[0, -omega[2], omega[1]], [omega[2], 0, -omega[0]], [-omega[1], omega[0], 0]])"
    assert practice.check("so3-exp", cell(rodrigues.format(threshold=1e-8, small=f"np.eye(3) + {hat}"), "so3_exp")).passed
    assert practice.check("so3-exp", cell(rodrigues.format(threshold=1e-3, small=f"np.eye(3) + {hat}"), "so3_exp")).passed
    wide = practice.check("so3-exp", cell(rodrigues.format(threshold=0.3, small="np.eye(3)"), "so3_exp"))
    assert not wide.passed and "petit angle" in wide.feedback
    # une branche petit angle de signe faux : la formule de Rodrigues est juste ailleurs, aucune erreur
    # classique de la formule générale (« axe non normé », « rotation inverse ») n'est invoquée
    sign = practice.check("so3-exp", cell(rodrigues.format(threshold=1e-3, small=f"np.eye(3) - {hat}"), "so3_exp"))
    assert not sign.passed and sign.mistake is None and "presque nul" in sign.feedback, sign.feedback
    assert sign.line == 4, sign.feedback  # la branche qui a rendu la main, pas la formule de Rodrigues


def test_systematic_resampling_has_the_rounding_case_and_names_the_forgotten_last_cumulative_weight():
    labels = [c.label for c in sampling.SYSTEMATIC_RESAMPLE.cases()]
    rounding = next(c for c in sampling.SYSTEMATIC_RESAMPLE.cases() if "arrondi" in c.label)
    w, u = rounding.args
    assert np.cumsum(w)[-1] < (u + w.size - 1) / w.size < 1.0  # la dernière position dépasse la somme cumulée
    assert len(labels) >= 7
    naive = """\
def systematic_resample(weights, u):
    N = len(weights)
    positions = (u + np.arange(N)) / N
    c = np.cumsum(weights)
    return np.searchsorted(c, positions, side="right")
"""
    verdict = practice.check("systematic-resample", cell(naive, "systematic_resample"))
    assert verdict.mistake == "last-cumsum" and verdict.line == 4, verdict.feedback


def test_one_based_positions_are_not_reported_as_u_plus_i_over_n():
    """Sur le cas du TD (quatre particules), i = 1…N et u + i/N donnent les mêmes indices (une fois bornés) :
    le correcteur choisit l'erreur qui explique tous les cas."""
    source = """\
def systematic_resample(weights, u):
    N = len(weights)
    positions = (u + np.arange(1, N + 1)) / N
    c = np.cumsum(weights)
    c[-1] = 1.0
    return np.minimum(np.searchsorted(c, positions, side="right"), N - 1)
"""
    verdict = practice.check("systematic-resample", cell(source, "systematic_resample"))
    assert verdict.mistake == "one-based", verdict.feedback
    assert verdict.line == 3


def test_a_correct_line_is_never_named_for_a_mistake_made_elsewhere():
    """« S = C P Cᵀ + R » juste, mais le gain recalcule S sans R : l'erreur est reconnue, la ligne de S n'est
    pas accusée (aucune ligne n'est nommée quand le correcteur n'est pas sûr)."""
    source = """\
def update(x_pred, P_pred, y, C, R):
    S = C @ P_pred @ C.T + R
    K = P_pred @ C.T @ np.linalg.inv(C @ P_pred @ C.T)
    x = x_pred + K @ (y - C @ x_pred)
    P = (np.eye(len(x_pred)) - K @ C) @ P_pred
    return x, P
"""
    verdict = practice.check("kf-update", cell(source, "update"))
    assert verdict.mistake == "s-without-r" and verdict.line is None, verdict.feedback
    assert "S = C @ P_pred @ C.T + R" not in verdict.feedback


@pytest.mark.parametrize("source, mistake, line", [
    ("""\
def update(x_pred, P_pred, y, C, R):
    S = C @ P_pred @ C.T + R
    K = np.linalg.solve(S, C @ P_pred).T
    x = x_pred + K @ (y - C @ x_pred)
    P = (np.eye(len(y)) - K @ C) @ P_pred
    return x, P
""", "identity-size", 5),
], ids=["identite-de-la-mesure"])
def test_wrong_identity_size_is_named_not_a_forgotten_transpose(source, mistake, line):
    verdict = practice.check("kf-update", cell(source, "update"))
    assert verdict.mistake == mistake and verdict.line == line, verdict.feedback
    assert "transposée" not in verdict.feedback


def test_jacobian_at_the_corrected_state_is_named():
    source = """\
def update(x_pred, P_pred, y, h, H, R):
    Hp = H(x_pred)
    S = Hp @ P_pred @ Hp.T + R
    K = P_pred @ Hp.T @ np.linalg.inv(S)
    x = x_pred + K @ (y - h(x_pred))
    P = (np.eye(len(x)) - K @ H(x)) @ P_pred
    return x, P
"""
    verdict = practice.check("ekf-update", cell(source, "update"))
    assert verdict.mistake == "h-at-corrected" and verdict.line == 6, verdict.feedback
    assert "transposée" not in verdict.feedback


def test_rts_gain_without_the_transpose_after_solve_is_recognised_on_its_line():
    """L'énoncé du TP 4 prescrit `np.linalg.solve(P_pred, A @ P_filt)` : le `.T` oublié donne Gᵀ, juste en
    dimension 1 et faux ensuite ; le correcteur le dit sur la ligne du gain."""
    source = """\
def rts_step(x_filt, P_filt, x_smooth_next, P_smooth_next, A, Q):
    P_pred = A @ P_filt @ A.T + Q
    G = np.linalg.solve(P_pred, A @ P_filt)
    x_smooth = x_filt + G @ (x_smooth_next - A @ x_filt)
    P_smooth = P_filt + G @ (P_smooth_next - P_pred) @ G.T
    return x_smooth, P_smooth
"""
    verdict = practice.check("rts-step", cell(source, "rts_step"))
    assert verdict.mistake == "gain-transposed" and verdict.line == 3, verdict.feedback


def test_a_bare_except_around_an_endless_loop_does_not_swallow_the_time_limit(monkeypatch):
    monkeypatch.setattr(practice.student, "TIME_LIMIT", 0.3)
    source = """\
def predict(x, P, A, Q):
    while True:
        try:
            x = A @ x
        except:
            pass
"""
    start = time.monotonic()
    verdict = practice.check("kf-predict", cell(source, "predict"))
    assert time.monotonic() - start < 10
    assert not verdict.passed and verdict.kind == "temps" and "n'a pas rendu la main" in verdict.feedback
    swallowed = """\
def predict(x, P, A, Q):
    try:
        while True:
            pass
    except BaseException:
        return A @ x, A @ P @ A.T + Q
"""
    verdict = practice.check("kf-predict", cell(swallowed, "predict"))
    assert not verdict.passed and verdict.kind == "temps"


def test_a_lab_figure_blames_the_student_function_not_the_package():
    """`update` sans `return` : la figure du TP 1 le reproche à la fonction de l'étudiant, sur sa ligne, et
    jamais à une ligne de `labs.py`."""
    no_return = cell("def update(x_pred, P_pred, y, C, R):\n    x = x_pred\n", "update")
    run = kc.scenarios.labs.voltage_lab(update=no_return)
    assert run.student is None and "labs.py" not in run.message
    assert "`update`" in run.message and "ne renvoie rien" in run.message and "votre cellule" in run.message
    fig = kc.figures.draw("tp-tension", update=no_return)
    assert "labs.py" not in fig._suptitle.get_text() and "ne renvoie rien" in fig._suptitle.get_text()
    too_big = cell("def update(x_pred, P_pred, y, C, R):\n    return x_pred, np.zeros((2, 2))\n", "update")
    run = kc.scenarios.labs.voltage_lab(update=too_big)
    assert run.student is None and "labs.py" not in run.message and "ligne" not in run.message, run.message


def test_hidden_cases_include_the_smallest_size_and_a_larger_one():
    """Chaque régime : n = 1 (ou N = 1, m = 1, une seule ancre) et une taille ≥ 3 — une transposée oubliée
    ou une identité de mauvaise taille passe en dimension 1."""
    for ex in EXERCISES:
        if ex.id in FIXED_SIZES:
            continue
        # (un tableau vide — un relevé sans détection — n'est pas une taille)
        sizes = [min(min(a.shape) for a in c.args if isinstance(a, np.ndarray) and a.ndim >= 1 and a.size)
                 for c in ex.cases()]
        largest = [max(max(a.shape) for a in c.args if isinstance(a, np.ndarray) and a.ndim >= 1 and a.size)
                   for c in ex.cases()]
        assert min(sizes) == 1 and max(largest) >= 3, (ex.id, sizes, largest)


def test_tracking_references_agree_with_independent_computations():
    """TP 5 : l'intégrale de bruit par quadrature = la méthode de Van Loan du paquet = la forme close de la vitesse
    presque constante ; le mélange et la combinaison de l'IMM = ceux d'`IMMEstimator` de filterpy ; la porte =
    le quantile −2 ln(1 − p) quand m = 2."""
    from filterpy.kalman import IMMEstimator, KalmanFilter

    from kalman_course.practice import tracking

    for case in tracking.VAN_LOAN.cases():
        F, L, Qc, dt = case.args
        A, Q = kc.discretize(F, L, Qc, dt)
        assert np.allclose(case.expected[0], A, atol=1e-12) and np.allclose(case.expected[1], Q, rtol=1e-9, atol=1e-12)
    for case in tracking.CV_MODEL.cases():
        dt, q = case.args
        A, Q = kc.constant_velocity(dt, q, dim=2)
        assert np.allclose(case.expected[0], A) and np.allclose(case.expected[1], Q, rtol=1e-9, atol=1e-15)
        one_axis = q * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
        assert np.allclose(case.expected[1][np.ix_([0, 2], [0, 2])], one_axis, rtol=1e-9, atol=1e-15)
    for case in tracking.NIS_GATE.cases():
        if case.info["m"] == 2:
            assert case.expected[1] == pytest.approx(-2 * np.log(1 - case.args[2]), rel=1e-10)
    for case in tracking.IMM_MIX.cases() + tracking.IMM_MERGE.cases():
        X, P, mu = case.args[:3]
        r, n = X.shape
        if r == 1:
            continue
        filters = []
        for j in range(r):
            f = KalmanFilter(dim_x=n, dim_z=1)
            f.x, f.P, f.F, f.Q = X[j].copy(), P[j].copy(), np.eye(n), np.zeros((n, n))
            filters.append(f)
        transition = case.args[3] if len(case.args) == 4 else np.full((r, r), 1.0 / r)
        imm = IMMEstimator(filters, mu.copy(), transition)
        if len(case.args) == 4:  # mélange : la prédiction de filterpy avec des régimes immobiles
            imm.predict()
            assert np.allclose(imm.cbar, case.expected[0])
            assert np.allclose([f.x for f in filters], case.expected[1])
            assert np.allclose([f.P for f in filters], case.expected[2])
        else:  # combinaison : l'estimation de filterpy avant toute prédiction
            assert np.allclose(imm.x, case.expected[0]) and np.allclose(imm.P, case.expected[1])


def test_the_lab_environment_holds_only_what_a_tp_needs():
    """`scripts/lab.sh` (environnement .venv-tp/) installe `scripts/lab-requirements.txt` sous les contraintes de
    requirements.txt : résolu hors ligne par uv, l'ensemble contient JupyterLab, son paquet de langue, le noyau
    et les dépendances du paquet, aux versions figées, et rien de ce qui construit ou teste le livre."""
    import tomllib

    uv = Path(sys.executable).parent / "uv"
    done = subprocess.run([str(uv), "pip", "compile", "--offline", "--quiet", "--python", sys.executable,
                           "scripts/lab-requirements.txt", "-c", "requirements.txt", "--no-header", "--no-annotate"],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    resolved = dict(re.findall(r"(?m)^([\w.-]+)==(\S+)$", done.stdout))
    names = {n.lower().replace("_", "-") for n in resolved}
    pins = {n.lower().replace("_", "-"): v for n, v in re.findall(r"(?m)^([\w.-]+)==(\S+)$",
                                                                 (ROOT / "requirements.txt").read_text())}
    assert {"jupyterlab", "jupyterlab-language-pack-fr-fr", "ipykernel", "numpy", "scipy", "matplotlib"} <= names
    for heavy in ("playwright", "jupyter-book", "sphinx", "myst-nb", "filterpy", "statsmodels", "bokeh", "pytest"):
        assert heavy not in names, heavy
    assert all(pins[n.lower().replace("_", "-")] == v for n, v in resolved.items())
    assert len(names) < 0.8 * len(pins)
    package = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    lab = {ln.strip() for ln in (ROOT / "scripts" / "lab-requirements.txt").read_text().splitlines()
           if ln.strip() and not ln.startswith("#")}
    assert set(package) <= lab
    script = (ROOT / "scripts" / "install_requirements.sh").read_text()
    lab_part = script.split('"--lab" ]', 1)[1].split("exit 0", 1)[0]
    assert "--quiet" not in lab_part  # la progression d'uv s'affiche


# --------------------------------------------------------------------------- TD 4, TD 5, examen, TP 5 : réponses recalculées


def test_tutorial_four_answers_are_recomputed():
    """TD 4 : Q par l'intégrale (forme close), le seuil −2 ln(1 − p) (contre scipy), le pas d'IMM (calcul direct
    écrit ici, contre kc.imm_filter)."""
    text = _page("td-cibles-reelles")
    assert "Durée indicative" in text
    # 1. Q pour Δt = 2 s, q = 3 m²/s³
    dt, q = 2.0, 3.0
    Q = q * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
    assert np.allclose(Q, [[8, 6], [6, 6]]) and np.linalg.det(Q) == pytest.approx(12.0)
    assert np.linalg.det(Q - np.diag([8.0, 0.0])) == pytest.approx(-36.0)
    assert r"\begin{bmatrix} 8 & 6 \\ 6 & 6 \end{bmatrix}" in text and r"\det Q = 48 - 36 = 12 > 0" in text
    assert r"\det = 0 \times 6 - 36 = -36 < 0" in text
    assert np.allclose(kc.scenarios.tutorials.cv_noise_example().Q, Q, rtol=1e-10)
    # 2. la porte pour m = 2
    for p, shown in ((0.99, "9{,}21"), (0.999, "13{,}82")):
        threshold = -2 * np.log(1 - p)
        assert threshold == pytest.approx(scipy.stats.chi2.ppf(p, 2), rel=1e-12)
        assert f"{threshold:.2f}".replace(".", "{,}") == shown and shown in text
    assert (3**2 + 4**2) / 4 == 6.25 and (6**2 + 8**2) / 4 == 25.0 and "6{,}25" in text
    gate = kc.scenarios.tutorials.gate_example()
    assert np.allclose(gate["nis"], [6.25, 25.0]) and np.allclose(gate["thresholds"], [-2 * np.log(0.01), -2 * np.log(0.001)])
    assert "13,28" in text and scipy.stats.chi2.ppf(0.99, 4) == pytest.approx(13.28, abs=0.005)
    # 3. le pas d'IMM, à la main
    mu, Pi = np.array([0.5, 0.5]), np.array([[0.9, 0.1], [0.3, 0.7]])
    cbar = mu @ Pi
    W = Pi * mu[:, None] / cbar
    X, P = np.array([0.0, 4.0]), np.array([1.0, 1.0])
    x0 = W.T @ X
    P0 = np.array([sum(W[i, j] * (P[i] + (X[i] - x0[j]) ** 2) for i in range(2)) for j in range(2)])
    assert np.allclose(cbar, [0.6, 0.4]) and np.allclose(W, [[0.75, 0.125], [0.25, 0.875]])
    assert np.allclose(x0, [1.0, 3.5]) and np.allclose(P0, [4.0, 2.75])
    Pm = P0 + np.array([0.0, 1.25])
    S = Pm + 1.0
    nu = 3.0 - x0
    K = Pm / S
    xm, Pp = x0 + K * nu, (1 - K) * Pm
    assert np.allclose(S, [5, 5]) and np.allclose(xm, [2.6, 3.1]) and np.allclose(Pp, [0.8, 0.8])
    ratio = cbar[1] / cbar[0] * np.exp((nu[0] ** 2 - nu[1] ** 2) / (2 * 5.0))
    assert ratio == pytest.approx(0.970, abs=5e-4) and "0{,}970" in text
    mu_new = np.array([1.0, ratio]) / (1 + ratio)
    x = mu_new @ xm
    Pc = mu_new @ Pp + mu_new @ (xm - x) ** 2
    assert f"{mu_new[0]:.3f}" == "0.508" and f"{mu_new[1]:.3f}" == "0.492"
    assert f"{x:.3f}" == "2.846" and f"{Pc:.3f}" == "0.862"
    for shown in ("\\mu_0 = 1/1{,}970 = 0{,}508", "\\mu_1 = 0{,}492", "= 2{,}846", "= 0{,}862"):
        assert shown in text, shown
    step = kc.scenarios.tutorials.imm_step()
    assert np.allclose(step.mu_pred[0], cbar) and np.allclose(step.x_modes[0, :, 0], xm)
    assert np.allclose(step.P_modes[0, :, 0, 0], Pp) and np.allclose(step.mu[0], mu_new, rtol=1e-12)
    assert step.x[0, 0] == pytest.approx(x, rel=1e-12) and step.P[0, 0, 0] == pytest.approx(Pc, rel=1e-12)


def test_tutorial_five_answers_are_recomputed():
    """TD 5 : éléments et combinaisons du filtre parallèle en fractions exactes (formules du chapitre, écrites
    ici), contre le filtre de Kalman du TD 3 et le paquet ; le pas du filtre d'information en fractions."""
    text = _page("td-autres-formes")
    assert "Durée indicative" in text
    F = Fraction

    def element(y, first=False):
        S, K = F(2), F(1, 2)
        if first:  # a priori (0, 1), prédiction (0, 2), gain 2/3
            return (F(0), F(2, 3) * y, F(2, 3), F(0), F(0))
        return (1 - K, K * y, (1 - K) * 1, y / S, 1 / S)

    def combine(a, b):
        Fi, bi, Si, ei, Ji = a
        Fj, bj, Sj, ej, Jj = b
        M = 1 / (1 + Si * Jj)
        return (Fj * M * Fi, Fj * M * (bi + Si * ej) + bj, Fj**2 * M * Si + Sj, Fi * M * (ej - Jj * bi) + ei,
                Fi**2 * M * Jj + Ji)

    a1, a2, a3 = element(F(1), True), element(F(3)), element(F(2))
    a12, a23 = combine(a1, a2), combine(a2, a3)
    a1_23 = combine(a1, a23)
    assert a2 == (F(1, 2), F(3, 2), F(1, 2), F(3, 2), F(1, 2)) and a3 == (F(1, 2), F(1), F(1, 2), F(1), F(1, 2))
    assert a12[:3] == (0, F(17, 8), F(5, 8)) and a23 == (F(1, 5), F(9, 5), F(3, 5), F(8, 5), F(3, 5))
    assert a1_23[:3] == (0, F(43, 21), F(13, 21)) and combine(a12, a3)[:3] == a1_23[:3]
    steps = kc.scenarios.tutorials.three_step_smoothing()  # le TD 3 : le filtre de Kalman sur les mêmes mesures
    assert float(a12[1]) == pytest.approx(steps.x[1]) and float(a1_23[2]) == pytest.approx(steps.P[2])
    package = kc.scenarios.tutorials.parallel_elements()
    for name, value in (("a1", a1), ("a2", a2), ("a3", a3), ("a12", a12), ("a23", a23), ("a1_23", a1_23)):
        assert np.allclose(package[name], [float(v) for v in value], atol=1e-14), name
    for shown in ("(0,\\ 2/3,\\ 2/3,\\ 0,\\ 0)", "(1/2,\\ 3/2,\\ 1/2,\\ 3/2,\\ 1/2)", "= 17/8", "= 5/8", "= 9/5",
                  "= 3/5", "= 8/5", "= 43/21", "= 13/21", "M = 1/(1 + \\tfrac23 \\cdot \\tfrac35) = 5/7"):
        assert shown in text, shown
    # 2. le filtre d'information : fractions exactes
    Pm = np.array([[F(2), F(1)], [F(1), F(2)]], dtype=object)
    det = Pm[0, 0] * Pm[1, 1] - Pm[0, 1] ** 2
    Ym = np.array([[Pm[1, 1], -Pm[0, 1]], [-Pm[1, 0], Pm[0, 0]]], dtype=object) / det
    zeta_m = Ym @ np.array([F(1), F(0)], dtype=object)
    Y = Ym + np.array([[F(1), F(0)], [F(0), F(0)]], dtype=object)
    zeta = zeta_m + np.array([F(3), F(0)], dtype=object)
    detY = Y[0, 0] * Y[1, 1] - Y[0, 1] * Y[1, 0]
    P = np.array([[Y[1, 1], -Y[0, 1]], [-Y[1, 0], Y[0, 0]]], dtype=object) / detY
    x = P @ zeta
    assert detY == 1 and list(zeta_m) == [F(2, 3), F(-1, 3)] and list(zeta) == [F(11, 3), F(-1, 3)]
    assert list(x) == [F(7, 3), F(2, 3)] and P.tolist() == [[F(2, 3), F(1, 3)], [F(1, 3), F(5, 3)]]
    for shown in ("\\zeta^- = (2/3,\\ -1/3)", "(11/3,\\ -1/3)", "\\hat x = P\\zeta = (7/3,\\ 2/3)",
                  "\\begin{bmatrix} 2/3 & 1/3 \\\\ 1/3 & 5/3 \\end{bmatrix}", "K = P^-C^T/S = (2/3,\\ 1/3)"):
        assert shown in text, shown
    info = kc.scenarios.tutorials.information_step()
    assert np.allclose(info["x"], [7 / 3, 2 / 3]) and np.allclose(info["P"], P.astype(float))
    assert np.allclose(info["Y"], Y.astype(float)) and np.allclose(info["kalman_x"], info["x"])


def test_exam_has_a_two_hour_paper_a_marking_scheme_summing_to_twenty_and_checked_answers():
    text = _page("sujet-examen")
    assert "**Durée : 2 heures.**" in text
    rows = [r for r in text.split("**Barème**", 1)[1].split("\n\n", 2)[1].splitlines() if r.startswith("| ") and
            not r.startswith("| exercice")]
    points = [[float(c.strip().replace(",", ".")) if c.strip() not in ("—", "") else 0.0 for c in r.strip("|").split("|")[1:]]
              for r in rows]
    assert len(points) == 4 and all(sum(p[:-1]) == p[-1] for p in points) and sum(p[-1] for p in points) == 20
    for k, total in enumerate(p[-1] for p in points):
        assert re.search(rf"## Exercice {k + 1} — .*\({total:g} points\)", text), (k, total)
    # chaque question de l'énoncé porte les points du barème
    for k, p in enumerate(points, 1):
        statement = text.split(f"## Exercice {k} —", 1)[1].split("```{solution-start}", 1)[0]
        marks = [float(v.replace(",", ".")) for v in re.findall(r"\((\d+(?:,\d+)?) pts?\)", statement)]
        assert marks == [v for v in p[:-1] if v], (k, marks)
    # 1. gain stationnaire : le nombre d'or
    phi = (1 + np.sqrt(5)) / 2
    run = kc.scenarios.tutorials.exam_stationary()
    assert run["P_pred"][-1] == pytest.approx(phi, rel=1e-9) and run["K"][-1] == pytest.approx(1 / phi, rel=1e-9)
    assert run["P"][-1] == pytest.approx(1 / phi, rel=1e-9) and run["S"][-1] == pytest.approx(phi**2, rel=1e-9)
    assert phi**2 == pytest.approx(phi + 1) and (1 / phi) * (1 - 1 / phi) ** 3 == pytest.approx(phi**-7)
    for shown in ("\\approx 1{,}618", "\\approx 0{,}618", "\\approx 2{,}618", "\\approx 0{,}034", "= 0{,}742",
                  "= 1{,}296"):
        assert shown in text, shown
    assert f"{phi**-7:.3f}" == "0.034"
    assert np.allclose(scipy.stats.chi2.ppf([0.025, 0.975], 100), [74.22, 129.56], atol=0.005)
    # 2. EKF sur une distance
    H = np.array([0.6, 0.8])
    S = H @ H + 0.25
    K = H / S
    x = np.array([3.0, 4.0]) + K * 0.5
    P = np.eye(2) - np.outer(K, H)
    assert S == pytest.approx(1.25) and np.allclose(K, [0.48, 0.64]) and np.allclose(x, [3.24, 4.32])
    assert np.allclose(P, [[0.712, -0.384], [-0.384, 0.488]]) and H @ P @ H == pytest.approx(0.2)
    assert np.array([-0.8, 0.6]) @ P @ np.array([-0.8, 0.6]) == pytest.approx(1.0)
    ekf = kc.scenarios.tutorials.exam_range_update()
    assert np.allclose(ekf.x, x) and np.allclose(ekf.P, P) and np.allclose(ekf.K[:, 0], K)
    for shown in ("(0{,}48 ;\\ 0{,}64)", "(3{,}24 ;\\ 4{,}32)", "0{,}712 & -0{,}384", "= 5{,}1$ m"):
        assert shown in text, shown
    mc = np.random.default_rng(0).multivariate_normal([3.0, 4.0], np.eye(2), size=400_000)
    assert np.hypot(mc[:, 0], mc[:, 1]).mean() == pytest.approx(5.1, abs=0.005)  # l'ordre 2 : 5,1 m
    # 3. lissage et R'
    F = Fraction
    two = kc.scenarios.tutorials.exam_smoothing()
    for value, exact in ((two.x[0], F(4, 3)), (two.P[0], F(2, 3)), (two.x[1], F(1, 2)), (two.P[1], F(5, 8)),
                         (two.G[0], F(2, 5)), (two.xs[0], F(1)), (two.Ps[0], F(1, 2)), (two.R_new, F(19, 16))):
        assert value == pytest.approx(float(exact), abs=1e-14)
    assert F(1, 2) * ((2 - 1) ** 2 + F(1, 2) + F(1, 2) ** 2 + F(5, 8)) == F(19, 16) and "= 19/16$" in text
    # 4. pistage
    track = kc.scenarios.tutorials.exam_tracking()
    assert np.allclose(track["Q"], 6 * np.array([[1 / 3, 1 / 2], [1 / 2, 1]])) and np.allclose(track["Q"], [[2, 3], [3, 6]])
    assert np.allclose(track["nis"], [2.0, 13.0]) and -2 * np.log(0.01) < 13 < -2 * np.log(0.001)
    assert np.allclose(track["cbar"], [0.61, 0.39])
    assert np.allclose(track["weights"], [[0.57 / 0.61, 0.03 / 0.39], [0.04 / 0.61, 0.36 / 0.39]])
    for shown in ("0{,}57/0{,}61 = 0{,}934", "0{,}04/0{,}61 =\n   0{,}066", "0{,}03/0{,}39 = 0{,}077",
                  "0{,}36/0{,}39 = 0{,}923", "\\epsilon = 36/4 + 4/1 = 13"):
        assert shown in text, shown


def test_capstone_lab_quiz_numbers_and_lab_constants_are_recomputed():
    """TP 5 : les nombres du quiz (quantiles du χ², c̄, Δt³/3) et les réglages de l'expérience (appris au chapitre)."""
    text = _page("tp-helicoptere-samu")
    assert "Durée indicative : 3 h 30" in text
    assert f"{scipy.stats.chi2.ppf(0.999, 1):.1f}" == "10.8" and f"{scipy.stats.chi2.ppf(0.999, 2):.1f}" == "13.8"
    assert "seuil 10,8 au lieu de 13,8" in text
    assert np.array([0.5, 0.5]) @ np.array([[0.95, 0.05], [0.2, 0.8]]) == pytest.approx([0.575, 0.425])
    assert "\\bar c_1 = 0{,}05 \\times 0{,}5 + 0{,}80 \\times 0{,}5 = 0{,}425" in text
    assert round(8.0**3 / 3) == 171 and "\\Delta t^3/3 \\approx 171" in text
    labs = kc.scenarios.labs
    q, sp = kc.scenarios.helicopter.fitted_parameters("position")
    assert labs.LAB_SAMU_Q == pytest.approx(q, rel=0.02) and labs.LAB_SAMU_POSITION_STD == pytest.approx(sp, rel=0.03)
    assert "q = 12{,}5" in text and "1,9 m" in text and "q = 3" in text and "q = 100" in text and "0,02" in text
    assert labs.LAB_SAMU_MODES == (3.0, 100.0) and labs.LAB_SAMU_SWITCH == 0.02 and labs.LAB_SAMU_GATE == 0.999


def test_capstone_lab_with_its_solutions_equals_the_package_and_each_classic_mistake_breaks_it():
    s = _lab_functions("tp-helicoptere-samu", "solution")
    run = kc.scenarios.labs.samu_lab(**{name: s[ex] for name, ex in (
        ("cv_model", "cv-model"), ("nis_gate", "nis-gate"), ("van_loan", "van-loan"), ("imm_mix", "imm-mix"),
        ("mode_probabilities", "mode-probabilities"), ("imm_merge", "imm-merge"))})
    assert run.message is None
    assert np.allclose(run.student["gate_x"], run.reference["gate_x"], atol=1e-8)
    assert np.array_equal(run.student["rejected"], run.reference["rejected"])
    assert set(run.data["outliers"]) <= set(np.flatnonzero(run.reference["rejected"]))
    assert np.allclose(run.student["imm_x"], run.reference["imm_x"], atol=1e-8)
    assert np.allclose(run.student["mu"], run.reference["mu"], atol=1e-10)
    # l'IMM suit les virages : μ(agité) est plus forte quand la vitesse de virage mesurée est grande
    turning = np.interp(run.data["t"], run.data["rate_t"], np.abs(run.data["rate"])) > 3.0
    assert run.reference["mu"][turning, 1].mean() > 0.5 > run.reference["mu"][~turning, 1].mean()
    # une erreur classique se voit sur le vol : la vraisemblance des régimes sans det S_j favorise l'agité
    # (la transition du TP est symétrique : l'y transposer ne changerait rien, d'où les cas cachés non symétriques)
    no_det = next(m.example for m in practice.exercise("mode-probabilities").mistakes if m.id == "no-determinant")
    wrong = kc.scenarios.labs.samu_lab(mode_probabilities=no_det)
    assert wrong.student["mu"][:, 1].mean() > run.reference["mu"][:, 1].mean() + 0.05


# --------------------------------------------------------------------------- assimilation de données (issue 33)


def test_tutorial_four_answers_are_the_package_values():
    """TD 6 : l'analyse de l'ETKF à deux membres et le taper de Gaspari–Cohn, recalculés par le paquet (et
    la racine de Cholesky de numpy, pour la question 5)."""
    text = _page("td-assimilation")
    E = np.array([[1.0, 0.0], [3.0, 2.0]])
    Ea = kc.etkf_update(E, [3.5], [[1.0, 0.0]], [[2.0]])
    assert r"$K = (2,\ 2)^T/(2 + 2) = (0{,}5,\ 0{,}5)^T$" in text
    assert r"(0{,}5,\ 0{,}5) =" in text and r"(2{,}75,\ 1{,}75)$" in text
    np.testing.assert_allclose(Ea.mean(axis=0), [2.75, 1.75], atol=1e-12)
    np.testing.assert_allclose(Ea, [[2.75 - 2**-0.5, 1.75 - 2**-0.5], [2.75 + 2**-0.5, 1.75 + 2**-0.5]], atol=1e-12)
    assert r"\approx (2{,}043,\ 1{,}043)$" in text and r"\approx (3{,}457,\ 2{,}457)$" in text
    assert np.round(Ea, 3).tolist() == [[2.043, 1.043], [3.457, 2.457]]
    np.testing.assert_allclose(np.cov(Ea.T), np.ones((2, 2)), atol=1e-12)  # (I − KH)P
    # la transformée symétrique : valeurs propres 1 et 2 de M, TA = A/√2
    M = np.eye(2) + np.outer([-1.0, 1.0], [-1.0, 1.0]) / 2.0
    assert "M = \\begin{pmatrix}1{,}5 & -0{,}5\\\\ -0{,}5 & 1{,}5\\end{pmatrix}" in text
    np.testing.assert_allclose(np.linalg.eigvalsh(M), [1.0, 2.0], atol=1e-14)
    # question 5 : la racine de Cholesky déplace la moyenne
    L = np.linalg.cholesky(np.linalg.inv(M))
    LA = L @ (E - E.mean(axis=0))
    assert "0{,}75 & 0{,}25" in text and r"\approx 0{,}528\,(1, 1)$" in text
    assert r"$-0{,}338\,(1, 1)$" in text and r"$-0{,}169\,(1, 1)$" in text
    np.testing.assert_allclose(np.linalg.inv(M), [[0.75, 0.25], [0.25, 0.75]], atol=1e-14)
    assert round(LA[1, 0], 3) == 0.528 and round(LA.sum(axis=0)[0], 3) == -0.338 and round(LA.mean(axis=0)[0], 3) == -0.169
    # exercice 2 : le taper de demi-support c = 2
    rho = kc.gaspari_cohn(np.arange(5.0), 2.0 / 1.82)
    for fraction, value in (("263/384", rho[1]), ("5/24", rho[2]), ("19/1152", rho[3])):
        assert fraction in text
        num, den = map(int, fraction.split("/"))
        assert Fraction(num, den) == pytest.approx(value, abs=1e-14)
    assert rho[0] == 1.0 and rho[4] == 0.0
    assert r"$-3 + 12 + 30 - 160 + 384$" in text or "{-3 + 12 + 30 - 160 + 384}" in text
    assert r"\tfrac{59}{128}" in text
    assert r"$1/\rho = 384/263" in text and r"\approx 1{,}46$" in text and round(384 / 263, 2) == 1.46
    assert r"à $2c = 4$" in text and r"$c = 1{,}82 \times 2 = 3{,}64$" in text and r"$2c = 7{,}28$" in text
    assert kc.gaspari_cohn(np.array([7.27, 7.29]), 2.0).tolist()[1] == 0.0 and kc.gaspari_cohn(7.27, 2.0) > 0
    assert "**Durée indicative**" in text


def test_etkf_lab_with_the_page_solutions_equals_the_package_and_reports_failures():
    s = _lab_functions("tp-assimilation", "solution")
    run = kc.scenarios.assimilation.etkf_lab(s["etkf-update"], s["gaspari-cohn"])
    assert run.message is None
    np.testing.assert_allclose(run.student["rmse"], run.reference["rmse"], rtol=1e-8)
    np.testing.assert_allclose(run.student["taper"], run.reference["taper"], atol=1e-14)
    assert run.reference["rmse"][20:].mean() < 0.5  # l'ETKF suit la vérité (erreur des observations : 1)
    blank = cell("def etkf_update(E, y, H, R, inflation):\n    raise NotImplementedError\n", "etkf_update")
    fig = kc.figures.draw("tp-etkf", etkf_update=blank)
    assert "pas encore écrite" in fig._suptitle.get_text()
    assert len(fig.axes[0].get_lines()) == 2  # paquet et erreur des observations : pas de courbe de l'étudiant
    wrong = practice.exercise("etkf-update").mistakes[0].example  # racine de Cholesky : la moyenne glisse
    run = kc.scenarios.assimilation.etkf_lab(wrong)
    assert run.message is None and np.abs(run.student["rmse"] - run.reference["rmse"]).max() > 1e-3


# --------------------------------------------------------------------------- plusieurs cibles (issue 37)


def test_tutorial_eight_answers_are_the_package_values():
    text = _page("td-plusieurs-cibles")
    step = kc.scenarios.tutorials.pda_by_hand()
    gate = kc.validation_gate(kc.LinearGaussianModel(1.0, 1.0, 0.0, 1.0), [[0.0]], [[[3.0]]], [[1.0], [-2.0]],
                              gate_probability=0.9)
    assert "$2\\sqrt{\\gamma S} =\n   2\\sqrt{2{,}706 \\times 4} = 6{,}58$" in text
    assert gate.volume[0] == pytest.approx(6.58, abs=5e-3) and 0.1 * gate.volume[0] == pytest.approx(0.658, abs=5e-4)
    assert gate.threshold == pytest.approx(2.706, abs=5e-4) and list(gate.nis[0]) == [0.25, 1.0]
    assert "$\\beta = (0{,}105 ;\\ 0{,}530 ;\\ 0{,}364)$" in text
    np.testing.assert_allclose(step.weights, [0.105, 0.530, 0.364], atol=5e-4)
    assert "$\\hat x = 0 + 0{,}75 \\times (-0{,}199) = -0{,}149$" in text and step.x[0] == pytest.approx(-0.149, abs=5e-4)
    assert "= 2{,}083$" in text and step.P[0, 0] == pytest.approx(2.083, abs=5e-4)
    # les nombres intermédiaires : densités, poids, dispersion, variance sans dispersion (quiz)
    dens = scipy.stats.norm(0.0, 2.0).pdf([1.0, -2.0])
    assert "= 0{,}1760$" in text and "0{,}1210$" in text
    np.testing.assert_allclose(dens, [0.1760, 0.1210], atol=5e-5)
    b = step.weights
    nu_bar = b[1] * 1.0 + b[2] * -2.0
    assert "$K^2 \\times 1{,}948 = 1{,}096$" in text
    assert b[1] + 4 * b[2] - nu_bar**2 == pytest.approx(1.948, abs=5e-4)
    assert 0.5625 * (b[1] + 4 * b[2] - nu_bar**2) == pytest.approx(1.096, abs=5e-4)
    assert "$0{,}987$ au lieu de $2{,}083$" in text
    assert b[0] * 3 + (1 - b[0]) * 0.75 == pytest.approx(0.987, abs=5e-4)
    # JPDA : le paquet, une énumération écrite ici, et les fractions du texte
    beta = kc.scenarios.tutorials.jpda_by_hand()
    w = np.array(kc.scenarios.tutorials.JPDA_WEIGHTS)
    manual = np.zeros_like(w)
    for a, c in itertools.product(range(3), repeat=2):
        if a == 0 or a != c:
            manual[0, a] += w[0, a] * w[1, c]
            manual[1, c] += w[0, a] * w[1, c]
    np.testing.assert_allclose(beta, manual / manual.sum(axis=1, keepdims=True), rtol=1e-14)
    np.testing.assert_allclose(beta, [[0.24, 0.64, 0.12], [0.24, 0.16, 0.60]], atol=1e-14)
    assert "Total : $25$" in text and "$(4 + 12)/25 = 0{,}64$" in text and "$(3 + 12)/25 = 0{,}60$" in text
    assert "pour $k = 3$ : $1 + 9 + 18 + 6 = 34$" in text
    assert sum(math.comb(3, i) ** 2 * math.factorial(i) for i in range(4)) == 34


def test_stonesoup_pda_passes_the_checker():
    """Une implémentation indépendante (les poids et la correction de Stone Soup, ``PDAHypothesiser`` et
    ``PDAUpdater``) passe le correcteur : ses cas cachés ne dépendent pas des conventions du paquet."""
    pytest.importorskip("stonesoup")
    import datetime

    from stonesoup.hypothesiser.probability import PDAHypothesiser
    from stonesoup.models.measurement.linear import LinearGaussian
    from stonesoup.predictor.kalman import KalmanPredictor
    from stonesoup.types.detection import Detection
    from stonesoup.types.hypothesis import SingleProbabilityHypothesis
    from stonesoup.types.multihypothesis import MultipleHypothesis
    from stonesoup.types.state import GaussianState
    from stonesoup.types.track import Track
    from stonesoup.updater.kalman import KalmanUpdater
    from stonesoup.updater.probability import PDAUpdater
    from stonesoup.models.transition.linear import RandomWalk, CombinedLinearGaussianTransitionModel

    t0 = datetime.datetime(2024, 1, 1)

    def parts(n, C, R):
        mm = LinearGaussian(ndim_state=n, mapping=tuple(range(n)), noise_covar=np.asarray(R))
        mm.matrix = lambda **kw: np.asarray(C)  # une matrice d'observation quelconque
        predictor = KalmanPredictor(CombinedLinearGaussianTransitionModel([RandomWalk(0.0)] * n))
        return mm, predictor, KalmanUpdater(mm)

    def ss_weights(innovations, S, detection_probability, clutter_density, gate_probability):
        m = S.shape[0]
        mm, predictor, updater = parts(m, np.eye(m), S)
        track = Track([GaussianState(np.zeros((m, 1)), np.zeros((m, m)), timestamp=t0)])
        dets = [Detection(nu[:, None], timestamp=t0, measurement_model=mm) for nu in innovations]
        hyps = PDAHypothesiser(predictor, updater, clutter_spatial_density=clutter_density,
                               prob_detect=detection_probability, prob_gate=gate_probability).hypothesise(
            track, set(dets), t0)
        beta = np.zeros(len(dets) + 1)
        for h in hyps:
            beta[0 if not h else 1 + next(j for j, d in enumerate(dets) if d is h.measurement)] = float(h.probability)
        return beta

    def ss_update(x_pred, P_pred, detections, C, R, beta):
        n = x_pred.shape[0]
        mm, predictor, updater = parts(n, C, R)
        prediction = predictor.predict(Track([GaussianState(x_pred[:, None], P_pred, timestamp=t0)]), timestamp=t0)
        hyps = [SingleProbabilityHypothesis(prediction, __import__("stonesoup.types.detection", fromlist=["x"])
                                            .MissedDetection(timestamp=t0), beta[0])]
        for z, b in zip(detections, beta[1:]):
            det = Detection(z[:, None], timestamp=t0, measurement_model=mm)
            hyps.append(SingleProbabilityHypothesis(prediction, det, b, updater.predict_measurement(prediction, mm)))
        upd = PDAUpdater(mm).update(MultipleHypothesis(hyps, normalise=False))
        return np.asarray(upd.state_vector, float).ravel(), np.asarray(upd.covar, float)

    for exercise_id, fn in (("pda-weights", ss_weights), ("pda-update", ss_update)):
        verdict = practice.check(exercise_id, fn)
        assert verdict.passed, verdict.feedback


PDA_STUDENT_MISTAKES = [
    ("pda-weights", "no-missed", "beta = w / w.sum()", """\
def pda_weights(innovations, S, detection_probability, clutter_density, gate_probability):
    m = S.shape[0]
    nis = np.sum(innovations * np.linalg.solve(S, innovations.T).T, axis=1)
    dens = np.exp(-nis / 2) / np.sqrt((2 * np.pi) ** m * np.linalg.det(S))
    w = np.where(nis <= scipy.stats.chi2.ppf(gate_probability, m), detection_probability * dens / clutter_density, 0)
    beta = w / w.sum()
    return beta
"""),
    ("pda-weights", "not-normalised", "return np.concatenate([[1 - detection_probability * gate_probability], w])", """\
def pda_weights(innovations, S, detection_probability, clutter_density, gate_probability):
    m = S.shape[0]
    nis = np.sum(innovations * np.linalg.solve(S, innovations.T).T, axis=1)
    dens = np.exp(-nis / 2) / np.sqrt((2 * np.pi) ** m * np.linalg.det(S))
    w = np.where(nis <= scipy.stats.chi2.ppf(gate_probability, m), detection_probability * dens / clutter_density, 0)
    return np.concatenate([[1 - detection_probability * gate_probability], w])
"""),
    ("pda-weights", "swapped", "w = np.where(nis <= scipy.stats.chi2.ppf(gate_probability, m), clutter_density * dens / detection_probability, 0)", """\
def pda_weights(innovations, S, detection_probability, clutter_density, gate_probability):
    m = S.shape[0]
    nis = np.sum(innovations * np.linalg.solve(S, innovations.T).T, axis=1)
    dens = np.exp(-nis / 2) / np.sqrt((2 * np.pi) ** m * np.linalg.det(S))
    w = np.where(nis <= scipy.stats.chi2.ppf(gate_probability, m), clutter_density * dens / detection_probability, 0)
    w = np.concatenate([[1 - detection_probability * gate_probability], w])
    return w / w.sum()
"""),
    ("pda-update", "no-spread", "P = beta[0] * P_pred + (1 - beta[0]) * (P_pred - K @ S @ K.T)", """\
def pda_update(x_pred, P_pred, detections, C, R, beta):
    S = C @ P_pred @ C.T + R
    K = np.linalg.solve(S, C @ P_pred).T
    nu_bar = beta[1:] @ (detections - C @ x_pred)
    P = beta[0] * P_pred + (1 - beta[0]) * (P_pred - K @ S @ K.T)
    return x_pred + K @ nu_bar, P
"""),
]


@pytest.mark.parametrize("exercise_id, mistake_id, line, source", PDA_STUDENT_MISTAKES,
                         ids=[f"{e}-{m}" for e, m, _, _ in PDA_STUDENT_MISTAKES])
def test_pda_mistakes_written_by_hand_are_recognised(exercise_id, mistake_id, line, source):
    name = re.match(r"def (\w+)", source).group(1)
    verdict = practice.check(exercise_id, cell(source, name))
    assert not verdict.passed and verdict.mistake == mistake_id, verdict.feedback
    if line:
        number = next(i for i, text in enumerate(source.splitlines(), 1) if text.strip() == line)
        assert verdict.line == number, verdict.feedback


def test_pda_hidden_cases_cover_every_regime():
    labels = {ex.id: " ".join(c.label for c in ex.cases()) for ex in EXERCISES if ex.id.startswith("pda-")}
    weights, update = labels["pda-weights"], labels["pda-update"]
    for regime in ("N = 0", "hors de la fenêtre", "aucune détection dans la fenêtre", "P_D = 1", "m = 1", "m = 3",
                   "fouillis dense"):
        assert regime in weights, regime
    for regime in ("N = 0", "hors de la fenêtre", "β = (0, 1)", "β₀ grand", "C pleine"):
        assert regime in update, regime
    cases = practice.exercise("pda-weights").cases()
    outside = next(c for c in cases if c.label == "aucune détection dans la fenêtre")
    np.testing.assert_array_equal(outside.expected[0], [1.0, 0.0, 0.0])  # la prédiction seule

