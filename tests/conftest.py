"""Outils communs aux tests : filterpy comme référence, modèles aléatoires, construction du livre."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter

import kalman_course as kc

ROOT = Path(__file__).resolve().parent.parent


def filterpy_kf(model: kc.LinearGaussianModel, y, x0, P0, u=None):
    """Boucle predict()/update() de filterpy (vecteurs colonnes) ; renvoie x (T, n), P (T, n, n),
    x_prior (T, n), P_prior (T, n, n). Une ligne NaN de ``y`` : prédiction seule."""
    n, m = model.n_state, model.n_obs
    y = np.asarray(y, dtype=float).reshape(len(y), m)
    f = KalmanFilter(dim_x=n, dim_z=m, dim_u=max(model.n_control, 1))
    f.F = np.array(model.A)
    f.H = np.array(model.C)
    f.Q = np.array(model.Q)
    f.R = np.array(model.R)
    if model.B is not None:
        f.B = np.array(model.B)
    f.x = np.asarray(x0, dtype=float).reshape(n, 1)
    f.P = np.asarray(P0, dtype=float).reshape(n, n)
    xs, Ps, xps, Pps = [], [], [], []
    for k in range(len(y)):
        f.predict(u=None if u is None else np.asarray(u[k], dtype=float).reshape(-1, 1))
        xps.append(f.x.ravel().copy())
        Pps.append(f.P.copy())
        if not np.isnan(y[k]).all():
            f.update(y[k].reshape(m, 1))
        xs.append(f.x.ravel().copy())
        Ps.append(f.P.copy())
    return np.array(xs), np.array(Ps), np.array(xps), np.array(Pps)


def random_model(rng: np.random.Generator, n: int, m: int, p: int) -> kc.LinearGaussianModel:
    """Système aléatoire (transition proche de l'identité, covariances pleines bien conditionnées)."""
    A = np.eye(n) + 0.3 * rng.standard_normal((n, n)) / np.sqrt(n)
    C = rng.standard_normal((m, n))
    Lq = 0.3 * rng.standard_normal((n, n))
    Lr = 0.5 * rng.standard_normal((m, m))
    Q = Lq @ Lq.T + 0.01 * np.eye(n)
    R = Lr @ Lr.T + 0.1 * np.eye(m)
    B = rng.standard_normal((n, p)) if p else None
    return kc.LinearGaussianModel(A, C, Q, R, B=B)


@pytest.fixture(scope="session")
def built_book() -> Path:
    """Construit le livre une fois par session (propre, -W) ; renvoie le dossier html.

    ``KALMAN_BOOK_BUILD_DIR`` choisit le dossier sous lequel écrire ``_build/`` (défaut : la racine du
    dépôt). ``_build`` est d'abord effacé, cache d'exécution compris : les pages sont recalculées par
    le paquet testé.
    """
    out = Path(os.environ.get("KALMAN_BOOK_BUILD_DIR", ROOT))  # le site va dans out/_build/html
    shutil.rmtree(out / "_build", ignore_errors=True)
    jb = Path(sys.executable).parent / "jupyter-book"
    proc = subprocess.run(
        [str(jb), "build", str(ROOT), "--all", "-W", "--keep-going", "--path-output", str(out)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=3000,
    )
    log = proc.stdout + proc.stderr
    (out / "_build").mkdir(parents=True, exist_ok=True)
    (out / "_build" / "build.log").write_text(log)
    if proc.returncode != 0:
        pytest.fail(f"La construction du livre a échoué (code {proc.returncode}) :\n{log[-6000:]}")
    return out / "_build" / "html"
