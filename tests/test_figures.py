"""Le registre des figures et la commande ``python -m kalman_course.figures``.

Registre : chaque figure se dessine, porte des étiquettes d'axes en français avec leur unité entre
parenthèses (ou un compteur sans unité, « itération n »), et deux tracés donnent exactement les mêmes
données. Commande : ``--list``, ``--only``, les trois formats, erreurs en français et code de retour non nul.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

import kalman_course as kc
from kalman_course.figures import REGISTRY

ROOT = Path(__file__).resolve().parent.parent
NAMES = kc.figures.names()

# Un axe sans unité n'est admis que pour un compteur (itération, pas, numéro) ; sinon « (sans unité) ».
COUNTER = re.compile(r"^(itération|pas de temps|numéro|relevé)\b")
UNIT = re.compile(r"\([^()]*\)\s*$")
ENGLISH = {
    "time", "iteration", "iterations", "estimate", "estimated", "measurement", "measurements", "true",
    "error", "state", "step", "value", "voltage", "density", "coverage", "position error",
}


def _figure_data(fig: Figure) -> list:
    """Tout ce qui est tracé : lignes, nuages, surfaces, barres, images et textes, axe par axe."""
    data = []
    for ax in fig.axes:
        for line in ax.get_lines():
            data.append(("line", np.asarray(line.get_xydata(), dtype=float)))
        for coll in ax.collections:
            data.append(("offsets", np.asarray(coll.get_offsets(), dtype=float)))
            for path in coll.get_paths():
                data.append(("path", np.asarray(path.vertices, dtype=float)))
        for patch in ax.patches:
            data.append(("patch", np.asarray(patch.get_path().vertices, dtype=float),
                         np.asarray(patch.get_patch_transform().get_matrix(), dtype=float)))
        for image in ax.images:
            data.append(("image", np.asarray(image.get_array(), dtype=float)))
        data.append(("labels", ax.get_xlabel(), ax.get_ylabel(), ax.get_title()))
    return data


def _same(a, b) -> bool:
    if len(a) != len(b):
        return False
    for x, y in zip(a, b):
        if len(x) != len(y) or x[0] != y[0]:
            return False
        for u, v in zip(x[1:], y[1:]):
            if isinstance(u, np.ndarray):
                if u.shape != v.shape or not np.array_equal(u, v, equal_nan=True):
                    return False
            elif u != v:
                return False
    return True


def test_registry_lists_the_linear_chapters_in_lecture_order():
    linear = [REGISTRY[n].chapter for n in NAMES if REGISTRY[n].chapter in {
        "controle-systeme", "estimateur", "predicteur-correcteur", "gain-optimal", "tension-constante",
        "pratique-synthese"}]
    order = ["controle-systeme", "estimateur", "predicteur-correcteur", "gain-optimal", "tension-constante",
             "pratique-synthese"]
    assert sorted(set(linear), key=order.index) == order
    assert linear == sorted(linear, key=order.index)


def test_unknown_figure_is_a_french_error():
    with pytest.raises(kc.KalmanInputError, match="Figure inconnue"):
        kc.figures.draw("pas-une-figure")


@pytest.mark.parametrize("name", NAMES)
def test_figure_draws_with_french_labels_units_and_identical_data(name):
    fig = kc.figures.draw(name)
    assert isinstance(fig, Figure)
    axes = [ax for ax in fig.axes if ax.get_visible() and (ax.get_lines() or ax.collections or ax.patches or ax.images)]
    assert axes, f"{name} : aucun axe tracé"
    for ax in axes:
        shared = {"x": ax.get_shared_x_axes().get_siblings(ax), "y": ax.get_shared_y_axes().get_siblings(ax)}
        for which, label in (("x", ax.get_xlabel()), ("y", ax.get_ylabel())):
            if not label and len(shared[which]) > 1:
                continue  # axe partagé : l'étiquette est portée par un voisin
            assert label, f"{name} : étiquette d'axe vide"
            assert UNIT.search(label) or COUNTER.match(label), f"{name} : pas d'unité dans « {label} »"
            words = set(re.findall(r"[a-zA-Zéèêàùç]+", re.sub(r"\$[^$]*\$", "", label).lower()))
            assert not (words & ENGLISH), f"{name} : étiquette en anglais « {label} »"
    again = kc.figures.draw(name)
    assert _same(_figure_data(fig), _figure_data(again)), f"{name} : deux tracés différents"


def _run(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "kalman_course.figures", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=600)


def test_cli_list_names_every_figure():
    proc = _run("--list")
    assert proc.returncode == 0, proc.stderr
    listed = [line.split()[0] for line in proc.stdout.splitlines() if line.strip()]
    assert listed == NAMES
    for line, name in zip(proc.stdout.splitlines(), NAMES):  # description et titre du chapitre
        spec = REGISTRY[name]
        assert spec.title in line and f"« {spec.chapter_title} »" in line and f"book/{spec.chapter}.md" in line


def test_cli_parallel_jobs_write_the_same_bytes_as_one_process(tmp_path):
    names = ["gain-limites", "tension-estimation", "tests-nis"]
    only = [arg for name in names for arg in ("--only", name)]
    serial = _run("--out", str(tmp_path / "un"), "--jobs", "1", *only)
    parallel = _run("--out", str(tmp_path / "deux"), "--jobs", "2", *only)
    assert serial.returncode == 0 and parallel.returncode == 0, serial.stderr + parallel.stderr
    assert "2 processus" in parallel.stderr and "100%" in parallel.stderr
    for name in names:
        assert (tmp_path / "un" / f"{name}.png").read_bytes() == (tmp_path / "deux" / f"{name}.png").read_bytes()


def test_cli_writes_every_figure_with_a_progress_bar(tmp_path):
    proc = _run("--out", str(tmp_path), "--format", "png")
    assert proc.returncode == 0, proc.stderr
    for name in NAMES:
        data = (tmp_path / f"{name}.png").read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n", name
    assert sorted(p.stem for p in tmp_path.iterdir()) == sorted(NAMES)
    assert "figures" in proc.stderr and "100%" in proc.stderr  # barre de progression tqdm
    assert f"{len(NAMES)} fichier(s) écrit(s)" in proc.stdout


def test_cli_only_all_formats_and_same_data_twice(tmp_path):
    name = "gain-limites"
    proc = _run("--out", str(tmp_path / "a"), "--format", "png,svg,pdf", "--only", name)
    assert proc.returncode == 0, proc.stderr
    files = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert files == [f"{name}.pdf", f"{name}.png", f"{name}.svg"]
    assert (tmp_path / "a" / f"{name}.pdf").read_bytes()[:5] == b"%PDF-"
    assert b"<svg" in (tmp_path / "a" / f"{name}.svg").read_bytes()[:2000]
    proc = _run("--out", str(tmp_path / "b"), "--format", "png,svg,pdf", "--only", name)
    assert proc.returncode == 0, proc.stderr
    for fmt in ("png", "svg", "pdf"):  # régénérer donne les mêmes octets, dans tous les formats
        assert (tmp_path / "a" / f"{name}.{fmt}").read_bytes() == (tmp_path / "b" / f"{name}.{fmt}").read_bytes()


@pytest.mark.parametrize(
    "args, message",
    [
        (["--format", "png,gif"], "format(s) inconnu(s) : gif"),
        (["--format", ","], "format(s) inconnu(s)"),
        (["--only", "pas-une-figure"], "figure(s) inconnue(s) : pas-une-figure"),
        (["--jobs", "-1"], "entier ≥ 0 attendu"),
        (["--jobs", "deux"], "entier ≥ 0 attendu"),
        ([], "l'option --out DOSSIER est obligatoire"),
    ],
)
def test_cli_bad_input_gives_french_error_and_nonzero_exit(tmp_path, args, message):
    out = [] if not args else ["--out", str(tmp_path)]
    proc = _run(*out, *args)
    assert proc.returncode != 0
    assert message in proc.stderr
    assert "erreur :" in proc.stderr and "utilisation :" in proc.stderr
    assert not any(tmp_path.iterdir())  # rien n'est écrit


def test_cli_chapter_groups_keep_each_figure_once_with_its_chapter():
    from kalman_course.figures.__main__ import chapter_groups

    names = kc.figures.names()
    groups = chapter_groups(names)
    assert sorted(n for g in groups for n in g) == sorted(names)
    for group in groups:
        assert len({kc.figures.REGISTRY[n].chapter for n in group}) == 1
    assert [len(g) for g in groups] == sorted((len(g) for g in groups), reverse=True)
