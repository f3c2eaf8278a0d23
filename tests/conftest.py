"""Outils communs aux tests : filterpy comme référence, modèles aléatoires, construction du livre
(dans un dossier temporaire : le _build/ de l'utilisateur reste tel quel)."""

from __future__ import annotations

import os
import re
import shlex
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
#
# Une seule construction du site par session, lancée **en arrière-plan dès la fin de la collecte** (les
# carnets absents du cache d'abord, en parallèle). Les tests qui lisent le livre (marqueurs book, browser,
# pdf ; un test qui demande la fixture ``built_book`` ou ``pdf_build`` reçoit le marqueur qui lui manque)
# passent en dernier, dans cet ordre : dans une session complète, les autres tests tournent pendant la
# construction. Dès que le site est construit, la construction LaTeX (même dossier, même environnement
# Sphinx et même cache d'exécution : aucun carnet relancé, aucune page relue) et la compilation XeLaTeX
# partent à leur tour en arrière-plan, pendant les tests du site et du navigateur ; les tests du PDF lisent
# leur résultat.
#
# ``bash scripts/test.sh`` sans argument lance deux sessions en même temps : celle du livre
# (``-m "book or browser or pdf"``) et celle du paquet (le reste), qui ne construit rien. Les marqueurs
# ajoutés ici le sont avant la sélection par ``-m`` : un test qui lit le livre ne tombe jamais dans la
# session du paquet (où il déclencherait une seconde construction).

sys.path.insert(0, str(ROOT / "scripts"))
from package_hash import STAMP_NAME, package_hash  # noqa: E402
from pdf import TARGET  # noqa: E402

#: Statistiques des constructions de la session, imprimées en fin de tests (pytest_terminal_summary).
BUILD_REPORT: list[str] = []
_EXECUTED = re.compile(r"Executing notebook using|^\[carnets\] book/.*: \d", re.M)
_FROM_CACHE = re.compile(r"Using cached notebook")
#: Une page relue : « reading sources... [ 3%] page » (couleurs ANSI de Sphinx) ; la ligne seule, sans page,
#: dit qu'aucune ne l'est.
_READING = re.compile(r"^(?:\x1b\[[0-9;]*m)*reading sources\.\.\. *(?:\x1b\[[0-9;]*m)*\[ *\d+%\]", re.M)
#: Outils du PDF (TeX Live et poppler-utils).
TEX_TOOLS = ("xelatex", "latexmk", "pdftotext", "pdfinfo", "pdfimages")
#: Étapes des tests qui lisent le livre, dans l'ordre où ils passent.
STAGES = ("book", "browser", "pdf")


def tree_state(path: Path) -> dict[str, tuple[int, int]]:
    """Chemin relatif → (taille, date de modification en ns) de chaque fichier sous ``path``."""
    if not path.exists():
        return {}
    return {p.relative_to(path).as_posix(): (p.stat().st_size, p.stat().st_mtime_ns)
            for p in path.rglob("*") if p.is_file() or p.is_symlink()}


def jupyter_book_command(out: Path, *args: str) -> list[str]:
    """``jupyter-book build ROOT -W --keep-going --path-output out ARGS`` (à lancer depuis ROOT)."""
    jb = Path(sys.executable).parent / "jupyter-book"
    return [str(jb), "build", str(ROOT), "-W", "--keep-going", "--path-output", str(out), *args]


def site_build_command(out: Path) -> list[str]:
    """Les carnets absents du cache exécutés en parallèle (scripts/execute_notebooks.py), puis (les paquets
    Debian installés : scripts/wait_system.sh) la construction du site (``--all``), qui les trouve tous dans
    le cache."""
    execute = [sys.executable, str(ROOT / "scripts" / "execute_notebooks.py"), str(out / "_build" / ".jupyter_cache")]
    wait = ["bash", str(ROOT / "scripts" / "wait_system.sh")]  # Chromium (diagrammes Mermaid) installé
    return ["bash", "-c", " && ".join(shlex.join(c) for c in (execute, wait, jupyter_book_command(out, "--all")))]


class BackgroundBuild:
    """Une construction lancée en arrière-plan (cwd = ROOT), son journal dans un fichier."""

    def __init__(self, label: str, command: list[str], log_path: Path):
        self.label, self.log_path = label, log_path
        self.start = time.perf_counter()
        log_path.parent.mkdir(parents=True, exist_ok=True)
        self._log = open(log_path, "w")
        self.proc = subprocess.Popen(command, cwd=ROOT, stdout=self._log, stderr=subprocess.STDOUT,
                                     stdin=subprocess.DEVNULL)
        self.log: str | None = None
        self.elapsed = self.cpu = 0.0

    def wait(self) -> str:
        """Attend la fin ; renvoie le journal ou fait échouer le test qui l'attend."""
        if self.log is None:
            try:
                # wait4 : le temps CPU de la construction et de ses processus (noyaux, LaTeX), à elle seule
                _, status, usage = os.wait4(self.proc.pid, 0)
                self.proc.returncode = code = os.waitstatus_to_exitcode(status)
            finally:
                self._log.close()
            self.elapsed = time.perf_counter() - self.start
            self.cpu = usage.ru_utime + usage.ru_stime
            self.log = self.log_path.read_text(errors="replace")
            BUILD_REPORT.append(
                f"{self.label} : {len(_EXECUTED.findall(self.log))} carnet(s) exécuté(s), "
                f"{len(_FROM_CACHE.findall(self.log))} repris du cache, sources relues : "
                f"{'oui' if _READING.search(self.log) else 'non'}, {self.elapsed:.0f} s "
                f"(temps CPU {self.cpu:.0f} s ; journal : {self.log_path})"
            )
            self.code = code
        if self.code != 0:
            pytest.fail(f"{self.label} : échec (code {self.code}) :\n{self.log[-6000:]}")
        return self.log

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
        if not self._log.closed:
            self._log.close()


class _Book:
    """L'état des constructions de la session : dossier, état initial du _build/ de l'utilisateur,
    étapes demandées, constructions en cours."""

    out: Path | None = None
    user_before: dict | None = None
    stages: set[str] = set()
    html: BackgroundBuild | None = None
    latex: BackgroundBuild | None = None


BOOK = _Book()


#: Fixture qui lit une construction → marqueur qu'elle impose au test qui la demande.
BUILD_FIXTURES = {"built_book": "book", "pdf_build": "pdf"}


def _stage(item) -> str | None:
    marks = {m.name for m in item.iter_markers()}
    for stage in reversed(STAGES):
        if stage in marks:
            return stage
    return None


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(session, config, items):
    """Marque les tests qui lisent une construction sans le dire (avant la sélection par ``-m``, qui suit
    ce crochet) ; les tests qui lisent le livre passent après tous les autres (site, navigateur, PDF)."""
    for item in items:
        fixtures = getattr(item, "fixturenames", ())
        wanted = [mark for fixture, mark in BUILD_FIXTURES.items() if fixture in fixtures]
        if wanted and not _stage(item):
            item.add_marker(wanted[-1])  # la dernière étape qu'il lit
    staged = [(STAGES.index(s), i, item) for i, item in enumerate(items) if (s := _stage(item))]
    if staged:
        rest = [item for item in items if not _stage(item)]
        items[:] = rest + [item for _, _, item in sorted(staged, key=lambda t: t[:2])]


def wait_for_system() -> None:
    """Attend les paquets Debian (Chromium sans écran, TeX Live) que scripts/test.sh fait installer en
    arrière-plan pendant l'exécution des carnets (``KALMAN_SYSTEM_SETUP`` : scripts/wait_system.sh)."""
    if os.environ.get("KALMAN_SYSTEM_SETUP"):
        done = subprocess.run(["bash", str(ROOT / "scripts" / "wait_system.sh")], capture_output=True, text=True)
        if done.returncode != 0:
            pytest.fail(done.stderr)


def tex_missing() -> list[str]:
    wait_for_system()
    return [tool for tool in TEX_TOOLS if shutil.which(tool) is None]


def _prepare_build_dir(config) -> Path:
    """Dossier où les tests construisent le livre (site et PDF) : temporaire, ou ``KALMAN_BOOK_BUILD_DIR``
    s'il est donné (sauf la racine du dépôt). Son cache d'exécution est une copie de celui de l'utilisateur
    quand celui-ci a été rempli par le paquet actuel."""
    wanted = os.environ.get("KALMAN_BOOK_BUILD_DIR")
    out = Path(wanted).resolve() if wanted else config._tmp_path_factory.mktemp("livre")
    if out == ROOT:
        raise pytest.UsageError("KALMAN_BOOK_BUILD_DIR ne doit pas être la racine du dépôt : les tests gardent _build/ intact.")
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


def _wants_pdf() -> bool:
    return "pdf" in BOOK.stages and not tex_missing()


def _start_latex() -> None:
    """Construction LaTeX puis compilation XeLaTeX (scripts/pdf.py), en arrière-plan."""
    latex_dir = BOOK.out / "_build" / "latex"
    pdf = BOOK.out / "_build" / "pdf" / f"{TARGET}.pdf"
    command = " && ".join([
        shlex.join(jupyter_book_command(BOOK.out, "--builder", "latex")),
        shlex.join([sys.executable, str(ROOT / "scripts" / "pdf.py"), str(latex_dir), str(pdf)]),
    ])
    BOOK.latex = BackgroundBuild("construction LaTeX et PDF (tests)", ["bash", "-c", command],
                                 BOOK.out / "_build" / "latex-pdf.log")


def pytest_collection_finish(session):
    """Lance la construction du livre dès que l'on sait qu'un test retenu la lira (``built_book`` : le
    site ; ``pdf_build`` : le PDF)."""
    config = session.config
    needs = {name for item in session.items for name in getattr(item, "fixturenames", ())}
    BOOK.stages = ({"book"} if "built_book" in needs else set()) | ({"pdf"} if "pdf_build" in needs else set())
    if not BOOK.stages or config.option.collectonly or os.environ.get("PYTEST_XDIST_WORKER"):
        return
    BOOK.user_before = tree_state(ROOT / "_build")
    BOOK.out = _prepare_build_dir(config)
    if "book" in BOOK.stages:
        BOOK.html = BackgroundBuild("construction du site (tests)", site_build_command(BOOK.out),
                                    BOOK.out / "_build" / "build.log")
    elif _wants_pdf():
        _start_latex()


def pytest_sessionfinish(session, exitstatus):
    for job in (BOOK.html, BOOK.latex):
        if job is not None:
            job.stop()


@pytest.fixture(scope="session")
def user_build_before() -> dict[str, tuple[int, int]]:
    """L'état du _build/ de l'utilisateur au début de la session (relevé avant toute construction)."""
    if BOOK.user_before is None:
        BOOK.user_before = tree_state(ROOT / "_build")
    return BOOK.user_before


@pytest.fixture(scope="session")
def book_build_dir(request, user_build_before) -> Path:
    """Le dossier de construction des tests (voir :func:`_prepare_build_dir`)."""
    if BOOK.out is None:
        BOOK.out = _prepare_build_dir(request.config)
    return BOOK.out


@pytest.fixture(scope="session")
def built_book(book_build_dir) -> Path:
    """Le site construit une fois par session (toutes les pages, -W) ; renvoie le dossier html. Le journal
    est ``_build/build.log`` du dossier de construction. Lance ensuite le PDF en arrière-plan."""
    if BOOK.html is None:
        BOOK.html = BackgroundBuild("construction du site (tests)", site_build_command(book_build_dir),
                                    book_build_dir / "_build" / "build.log")
    BOOK.html.wait()
    if BOOK.latex is None and _wants_pdf():
        _start_latex()
    return book_build_dir / "_build" / "html"


def latex_pdf(book_build_dir: Path) -> tuple[str, Path, float]:
    """Attend la construction LaTeX et la compilation du PDF (lancées après le site, ou ici) ; renvoie le
    journal, le chemin du PDF et la durée de la compilation XeLaTeX (s)."""
    if BOOK.latex is None:
        if BOOK.html is not None:
            BOOK.html.wait()  # même environnement Sphinx : le site d'abord
        _start_latex()
    log = BOOK.latex.wait()
    found = re.search(r"\[pdf\] compilation XeLaTeX : (\d+) s", log)
    return log, book_build_dir / "_build" / "pdf" / f"{TARGET}.pdf", float(found.group(1)) if found else float("nan")


def pytest_terminal_summary(terminalreporter):
    if BUILD_REPORT:
        terminalreporter.section("constructions du livre")
        for line in BUILD_REPORT:
            terminalreporter.write_line(line)
