"""Les travaux pratiques sur l'ordinateur d'un étudiant, depuis le site publié (issue 34).

Le site construit sert, dans son dossier ``travaux-pratiques/``, la roue du paquet (construite par la
construction elle-même, à partir de l'arbre), ses contraintes de versions et les carnets à compléter ; chaque
page de TP donne les commandes, l'adresse du site remplie par la page. Le test fait ce que ferait un étudiant :
le site servi sur http://127.0.0.1, la page de TP ouverte dans Chromium (les commandes telles qu'affichées),
un environnement virtuel neuf, la roue installée depuis le site servi avec la commande de la page, puis la
première vérification du carnet, avec une réponse juste (verte) et une fausse (rouge, en français).

Coût : l'environnement neuf reçoit les dépendances de la roue (numpy, scipy, matplotlib…) depuis le cache local
d'uv que remplit ``scripts/setup.sh`` (liens, pas de téléchargement), aux versions de ``contraintes.txt`` servi
par le site ; la roue elle-même vient du site servi (``--no-deps``, la commande de la page). pip lui-même
vérifie aussi l'adresse et la roue (``pip install --dry-run`` de la commande de la page, sans dépendances).
"""

from __future__ import annotations

import json
import re
import shlex
import subprocess
import sys
import urllib.request
import zipfile
from pathlib import Path

import pytest

import kalman_course as kc
from kalman_course.practice.notebooks import lab_pages, notebook_name
from kalman_course.sphinx.workspace import CONSTRAINTS, PLACEHOLDER, commands, repository_links

from test_browser import CHROMIUM, CHROMIUM_ARGS, served

ROOT = Path(__file__).resolve().parent.parent
BOOK = ROOT / "book"
FOLDER = "travaux-pratiques"


# --------------------------------------------------------------------------- sans construction


def test_every_lab_page_has_the_workspace_box_and_the_commands_install_from_the_site():
    for page in lab_pages(BOOK):
        assert "```{comment-travailler}\n```" in page.read_text(), page.name
    text = commands("tp5-helicoptere-samu.ipynb", kc.practice.wheel_name())
    lines = text.splitlines()
    assert lines[0] == "python3 -m venv tp-kalman" and lines[1] == "source tp-kalman/bin/activate"
    wheel_line = next(line for line in lines if ".whl" in line)
    assert f'-c "{PLACEHOLDER}/{FOLDER}/{CONSTRAINTS}"' in wheel_line
    assert f'"{PLACEHOLDER}/{FOLDER}/{kc.practice.wheel_name()}"' in wheel_line
    assert any("jupyterlab-language-pack-fr-fr" in line for line in lines)
    assert lines[-1] == "jupyter lab tp5-helicoptere-samu.ipynb"


def test_repository_links_only_when_the_config_names_a_repository():
    class Config:
        def __init__(self, options):
            self.html_theme_options = options

    assert repository_links(Config({"repository_url": ""})) == {}
    assert repository_links(Config({"repository_url": "https://github.com/executablebooks/jupyter-book"})) == {}
    links = repository_links(Config({"repository_url": "https://github.com/ecole/filtre-de-kalman",
                                     "repository_branch": "main",
                                     "launch_buttons": {"binderhub_url": "https://mybinder.org",
                                                        "jupyterhub_url": "https://jupyter.ecole.fr"}}))
    assert links == {"url": "https://github.com/ecole/filtre-de-kalman",
                     "binder": "https://mybinder.org/v2/gh/ecole/filtre-de-kalman/main",
                     "jupyterhub": "https://jupyter.ecole.fr"}


# --------------------------------------------------------------------------- le site construit


@pytest.mark.book
def test_the_site_serves_the_wheel_its_constraints_and_the_notebooks(built_book):
    folder = built_book / FOLDER
    wheel = folder / kc.practice.wheel_name()
    assert wheel.is_file()
    with zipfile.ZipFile(wheel) as archive:
        names = archive.namelist()
        metadata = archive.read(next(n for n in names if n.endswith(".dist-info/METADATA"))).decode()
    assert "kalman_course/practice/grading.py" in names and "kalman_course/datasets/data/adsb.json" in names
    assert any(n.endswith("share/jupyter/lab/settings/overrides.json") for n in names)  # JupyterLab en français
    assert not any("__pycache__" in n or n.startswith("tests/") for n in names)
    for dependency in ("numpy", "scipy", "matplotlib"):
        assert re.search(rf"^Requires-Dist: {dependency}\b", metadata, re.M), dependency
    requirements = (ROOT / "requirements.txt").read_text()
    assert (folder / CONSTRAINTS).read_text().endswith(requirements)
    for page in lab_pages(BOOK):
        name = notebook_name(page)
        assert (folder / name).read_bytes() == (BOOK / FOLDER / name).read_bytes()
        html = (built_book / "book" / f"{page.stem}.html").read_text()
        box = html.split("kc-comment-travailler", 1)[1].split("</script>", 1)[0]
        assert PLACEHOLDER in box and "document.baseURI" in box and name in box
        assert "scripts/lab.sh" not in box  # _config.yml ne nomme pas de dépôt : pas de renvoi à un dépôt inconnu


def _venv_python(venv: Path) -> Path:
    return venv / ("Scripts/python.exe" if sys.platform == "win32" else "bin/python")


#: Dans l'environnement neuf, un seul processus (une seule importation) : pour chaque réponse, les cellules du
#: carnet dans l'ordre, la fonction à écrire remplacée par la réponse, jusqu'à la première vérification.
_CHECK = r"""
import json, sys
notebook, answers = json.load(open(sys.argv[1])), json.loads(sys.argv[2])
verdicts = []
for answer in answers:
    namespace = {}
    for cell in notebook["cells"]:
        if cell["cell_type"] != "code":
            continue
        source = "".join(cell["source"])
        if "raise NotImplementedError" in source:
            source = answer
        if source.startswith("practice.check("):
            verdict = eval(source, namespace)
            verdicts.append({"passed": verdict.passed, "feedback": verdict.feedback, "mistake": verdict.mistake})
            break
        exec(source, namespace)
import kalman_course
print(json.dumps({"verdicts": verdicts, "package": kalman_course.__file__}))
"""

_RIGHT = "def predict(x, P, A, Q):\n    return A @ x, A @ P @ A.T + Q\n"
_WRONG = "def predict(x, P, A, Q):\n    return A @ x, A @ P @ A + Q\n"


@pytest.mark.book
@pytest.mark.browser
def test_a_student_installs_the_package_from_the_served_site_and_runs_a_lab_check(built_book, tmp_path):
    from playwright.sync_api import sync_playwright

    page_file = lab_pages(BOOK)[0]
    notebook = notebook_name(page_file)
    with served(built_book) as site, sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        try:
            page = browser.new_page()
            page.goto(site.base + f"book/{page_file.stem}.html")
            printed = page.locator(".kc-comment-travailler pre").first.inner_text()
            note = page.locator(".kc-comment-travailler .kc-adresse").first.inner_text()
            # une copie locale du site, ouverte depuis le disque : des chemins de fichiers, que pip accepte
            local = browser.new_page()
            local.goto((built_book / "book" / f"{page_file.stem}.html").as_uri())
            printed_local = local.locator(".kc-comment-travailler pre").first.inner_text()
        finally:
            browser.close()
        folder = f"{site.base}{FOLDER}"
        assert PLACEHOLDER not in printed and f'"{folder}/{kc.practice.wheel_name()}"' in printed
        assert f'"{built_book / FOLDER / kc.practice.wheel_name()}"' in printed_local
        assert note == f"Les adresses ont été remplies d\u2019après celle de cette page\u00a0: {site.base}."
        wheel_command = next(shlex.split(line) for line in printed.splitlines() if ".whl" in line)
        assert wheel_command[:4] == ["python", "-m", "pip", "install"]
        arguments = wheel_command[4:]  # -c <contraintes du site> <roue du site>, comme sur la page
        # pip lui-même accepte l'adresse et la roue (sans rien installer)
        dry = subprocess.run([sys.executable, "-m", "pip", "install", "--dry-run", "--no-deps", "--quiet",
                              "--disable-pip-version-check", "--report", "-", *arguments[2:]],
                             capture_output=True, text=True, timeout=120)
        assert dry.returncode == 0, dry.stderr
        assert json.loads(dry.stdout)["install"][0]["metadata"]["name"].lower().replace("-", "_") == "kalman_course"
        # un environnement virtuel neuf
        uv = Path(sys.executable).parent / "uv"
        venv = tmp_path / "tp-kalman"
        made = subprocess.run([str(uv), "venv", "--quiet", "--python", sys.executable, str(venv)],
                              capture_output=True, text=True, timeout=120)
        assert made.returncode == 0, made.stderr
        python = _venv_python(venv)
        # les dépendances déclarées par la roue, aux versions du contraintes.txt servi, depuis le cache local d'uv
        constraints = tmp_path / CONSTRAINTS
        constraints.write_bytes(urllib.request.urlopen(arguments[1], timeout=30).read())
        wheel_file = tmp_path / Path(arguments[2]).name
        wheel_file.write_bytes(urllib.request.urlopen(arguments[2], timeout=30).read())
        with zipfile.ZipFile(wheel_file) as archive:
            metadata = archive.read(next(n for n in archive.namelist() if n.endswith("METADATA"))).decode()
        requires = [r for r in re.findall(r"^Requires-Dist: ([^;\n]+)$", metadata, re.M)]
        deps = subprocess.run([str(uv), "pip", "install", "--quiet", "--offline", "--python", str(python),
                               "-c", str(constraints), *requires], capture_output=True, text=True, timeout=300)
        assert deps.returncode == 0, deps.stderr
        # la roue, depuis le site servi, avec les arguments de la page (dépendances déjà là)
        wheel = subprocess.run([str(uv), "pip", "install", "--quiet", "--no-deps", "--python", str(python),
                                *arguments], capture_output=True, text=True, timeout=120)
        assert wheel.returncode == 0, wheel.stderr
        # le carnet du site : sa première vérification, juste puis fausse
        nb = tmp_path / notebook
        nb.write_bytes(urllib.request.urlopen(f"{folder}/{notebook}", timeout=30).read())
    env = {"PATH": str(python.parent), "MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1", "HOME": str(tmp_path)}
    run = subprocess.run([str(python), "-c", _CHECK, str(nb), json.dumps([_RIGHT, _WRONG])], capture_output=True,
                         text=True, timeout=300, cwd=tmp_path, env=env)
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout.strip().splitlines()[-1])
    right, wrong = out["verdicts"]
    assert right["passed"], right["feedback"]
    assert not wrong["passed"] and wrong["mistake"] == "apa"
    assert "Erreur classique : A P A au lieu de A P Aᵀ" in wrong["feedback"] and "transposée" in wrong["feedback"]
    # le paquet qui a répondu est celui de l'environnement neuf, pas celui du dépôt
    assert out["package"].startswith(str(venv)) and not out["package"].startswith(str(ROOT))
