"""Outils communs aux tests : filterpy comme référence, modèles aléatoires, construction du livre
(dans un dossier temporaire : le _build/ de l'utilisateur reste tel quel)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
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


# --------------------------------------------------------------------------- construction du livre
# Les tests construisent le livre dans un dossier temporaire (jupyter-book --path-output) : le _build/
# de l'utilisateur (site, cache d'exécution, empreinte) n'est jamais modifié. Si son cache d'exécution
# a été rempli par le paquet actuel (même empreinte, scripts/package_hash.py), les tests en partent
# d'une copie : aucun carnet n'est relancé pour rien.

sys.path.insert(0, str(ROOT / "scripts"))
from package_hash import STAMP_NAME, package_hash  # noqa: E402

#: Statistiques des constructions de la session, imprimées en fin de tests (pytest_terminal_summary).
BUILD_REPORT: list[str] = []
_EXECUTED = re.compile(r"Executing notebook using")
_FROM_CACHE = re.compile(r"Using cached notebook")


def tree_state(path: Path) -> dict[str, tuple[int, int]]:
    """Chemin relatif → (taille, date de modification en ns) de chaque fichier sous ``path``."""
    if not path.exists():
        return {}
    return {p.relative_to(path).as_posix(): (p.stat().st_size, p.stat().st_mtime_ns)
            for p in path.rglob("*") if p.is_file() or p.is_symlink()}


def run_jupyter_book(out: Path, *args: str, label: str) -> str:
    """``jupyter-book build ROOT --path-output out`` (cwd = ROOT) ; renvoie le journal et note combien de
    carnets ont été exécutés ou repris du cache."""
    jb = Path(sys.executable).parent / "jupyter-book"
    start = time.perf_counter()
    proc = subprocess.run(
        [str(jb), "build", str(ROOT), "-W", "--keep-going", "--path-output", str(out), *args],
        cwd=ROOT, capture_output=True, text=True, timeout=3000,
    )
    elapsed = time.perf_counter() - start
    log = proc.stdout + proc.stderr
    BUILD_REPORT.append(
        f"{label} : {len(_EXECUTED.findall(log))} carnet(s) exécuté(s), {len(_FROM_CACHE.findall(log))} "
        f"repris du cache, {elapsed:.0f} s (dans {out})"
    )
    if proc.returncode != 0:
        pytest.fail(f"{label} : échec (code {proc.returncode}) :\n{log[-6000:]}")
    return log


@pytest.fixture(scope="session")
def user_build_before() -> dict[str, tuple[int, int]]:
    """L'état du _build/ de l'utilisateur au début de la session (relevé avant toute construction)."""
    return tree_state(ROOT / "_build")


@pytest.fixture(scope="session")
def book_build_dir(tmp_path_factory, user_build_before) -> Path:
    """Dossier où les tests construisent le livre (site et PDF) : temporaire, ou
    ``KALMAN_BOOK_BUILD_DIR`` s'il est donné (sauf la racine du dépôt). Son cache d'exécution est une
    copie de celui de l'utilisateur quand celui-ci a été rempli par le paquet actuel."""
    wanted = os.environ.get("KALMAN_BOOK_BUILD_DIR")
    out = Path(wanted).resolve() if wanted else tmp_path_factory.mktemp("livre")
    if out == ROOT:
        pytest.fail("KALMAN_BOOK_BUILD_DIR ne doit pas être la racine du dépôt : les tests gardent _build/ intact.")
    build, user = out / "_build", ROOT / "_build"
    sha = package_hash()
    stamp = build / STAMP_NAME
    if not stamp.is_file() or stamp.read_text().strip() != sha:
        shutil.rmtree(build / ".jupyter_cache", ignore_errors=True)  # rempli par un autre paquet
    user_stamp = user / STAMP_NAME
    if (not (build / ".jupyter_cache").exists() and (user / ".jupyter_cache").is_dir()
            and user_stamp.is_file() and user_stamp.read_text().strip() == sha):
        shutil.copytree(user / ".jupyter_cache", build / ".jupyter_cache")
        BUILD_REPORT.append(f"cache d'exécution copié de {user} (paquet inchangé)")
    build.mkdir(parents=True, exist_ok=True)
    stamp.write_text(sha + "\n")
    return out


@pytest.fixture(scope="session")
def built_book(book_build_dir) -> Path:
    """Construit le site une fois par session (toutes les pages, -W) ; renvoie le dossier html.

    Le journal est écrit dans ``_build/build.log`` du dossier de construction.
    """
    log = run_jupyter_book(book_build_dir, "--all", label="construction du site (tests)")
    (book_build_dir / "_build" / "build.log").write_text(log)
    return book_build_dir / "_build" / "html"


def pytest_terminal_summary(terminalreporter):
    if BUILD_REPORT:
        terminalreporter.section("constructions du livre")
        for line in BUILD_REPORT:
            terminalreporter.write_line(line)
