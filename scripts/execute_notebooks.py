"""Exécute en parallèle les carnets du livre absents du cache d'exécution, avant la construction.

Jupyter Book 1 (myst-nb, ``execute_notebooks: cache``) exécute les carnets un par un, pendant la lecture
des pages. Ce script les exécute avant, plusieurs à la fois, et les range dans le même cache
(jupyter-cache, dont la clé est le code des cellules) : la construction qui suit les y trouve et n'en
exécute aucun. Chaque processus de travail garde **un noyau** pour tous ses carnets : les modules importés
(le paquet, scipy, matplotlib, Bokeh, 3 à 4 s par carnet) le restent, et avant chaque carnet le noyau est
remis dans l'état d'un noyau neuf (espace de noms vidé, compteurs remis : voir ``_RESET``) ; les sorties
sont celles d'un noyau neuf. Même lecture que la construction (le lecteur MyST de myst-nb), même
exécution (``single_nb_execution`` de jupyter-cache, dans le dossier du carnet, délai de _config.yml,
arrêt à la première erreur), même rangement. Un carnet en erreur n'est pas rangé : la construction le
relance et échoue sur son erreur, trace comprise.

Les noyaux tournent avec une algèbre linéaire (BLAS) sur un seul fil : ils sont déjà plusieurs à se
partager les cœurs. Les carnets les plus longs partent les premiers (d'après le temps de leur dernière
exécution dans ce cache, à défaut d'après la taille du fichier).

Usage : ``python scripts/execute_notebooks.py DOSSIER_DU_CACHE [--jobs N]`` (``N`` : 0 = un par cœur,
défaut). Imprime une ligne par carnet exécuté et le total.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent
#: Lecteur des carnets MyST (.md) de myst-nb pour jupyter-cache : celui de la construction.
READ_DATA = {"name": "myst_nb_md", "type": "plugin"}
#: Une algèbre linéaire sur un fil par noyau (les noyaux en parallèle occupent déjà les cœurs).
SINGLE_THREAD = {name: "1" for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}


def book_sources(root: Path = ROOT) -> list[Path]:
    """Les pages du sommaire (_toc.yml) qui sont des carnets MyST, dans l'ordre du livre."""
    toc = yaml.safe_load((root / "_toc.yml").read_text())
    docs = [toc["root"]] + [c["file"] for part in toc.get("parts", []) for c in part.get("chapters", [])]
    paths = [root / f"{doc}.md" for doc in docs]
    return [p for p in paths if p.is_file() and "kernelspec" in p.read_text(encoding="utf8")[:2000]]


def _timeout(root: Path = ROOT) -> int:
    config = yaml.safe_load((root / "_config.yml").read_text())
    return int((config.get("execute") or {}).get("timeout", 30))


#: Le noyau du processus de travail (démarré au premier carnet, arrêté à la sortie du processus).
_KERNEL = None
#: Au démarrage du noyau d'un processus de travail : les modules lourds importés une fois, et la valeur du
#: compteur des identifiants Bokeh qu'a un noyau neuf après l'import de ``kalman_course.interactive``
#: (seul module qui crée des objets Bokeh, dont quelques-uns à l'import).
_WARM_UP = """\
import bokeh.util.serialization as _ids
import kalman_course.interactive
_ids._kc_fresh_id = _ids._simple_id
del _ids
"""
#: Avant chaque carnet, l'état d'un noyau neuf : espace de noms vidé, figures matplotlib fermées, compteurs
#: des identifiants Bokeh et des exécutions remis à leur valeur de départ (les sorties sont celles d'un noyau
#: neuf, octet pour octet), dossier du carnet.
_RESET = """\
%reset -f
import os as _os, sys as _sys
_sys.modules["matplotlib.pyplot"].close("all") if "matplotlib.pyplot" in _sys.modules else None
_sys.modules["bokeh.util.serialization"]._simple_id = _sys.modules["bokeh.util.serialization"]._kc_fresh_id
_os.chdir({cwd!r})
del _os, _sys
get_ipython().execution_count = 1  # celui de la première cellule du carnet
"""


def _kernel(cwd: str):
    """Le noyau de ce processus de travail : un seul pour tous ses carnets, les modules déjà importés (le
    paquet, scipy, matplotlib, Bokeh : 3 à 4 s par carnet) le restent ; l'espace de noms est vidé avant
    chaque carnet (:data:`_RESET`). Les tirages aléatoires du livre ont tous leur graine : un carnet ne
    dépend pas de ceux qui l'ont précédé dans le noyau."""
    global _KERNEL
    import nbformat
    from nbclient import execute

    if _KERNEL is not None and not _KERNEL.is_alive():  # noyau mort (carnet qui l'a fait tomber) : un neuf
        _KERNEL = None
    if _KERNEL is None:
        from multiprocessing.util import Finalize

        from jupyter_client.manager import start_new_kernel

        # sans historique : le compteur d'exécution revient à 1 à chaque carnet
        km, kc = start_new_kernel(kernel_name="python3", cwd=cwd, extra_arguments=["--HistoryManager.enabled=False"])
        kc.stop_channels()  # chaque exécution (nbclient) ouvre son propre client
        _KERNEL = km
        Finalize(None, km.shutdown_kernel, kwargs={"now": True}, exitpriority=10)
        warm_up = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(_WARM_UP)])
        execute(warm_up, km=_KERNEL, timeout=120, allow_errors=False)
    reset = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(_RESET.format(cwd=cwd))])
    execute(reset, km=_KERNEL, timeout=60, allow_errors=False)
    return _KERNEL


def _execute(path: str, timeout: int):
    """Dans un processus de travail : lit et exécute le carnet ``path`` dans le noyau du processus ;
    renvoie (chemin, carnet, durée, erreur)."""
    from jupyter_cache.executors.utils import single_nb_execution
    from myst_nb.core.read import myst_nb_reader_plugin

    notebook = myst_nb_reader_plugin(path)
    cwd = str(Path(path).parent)
    result = single_nb_execution(notebook, cwd=cwd, timeout=timeout, allow_errors=False, meta_override=True,
                                 km=_kernel(cwd))
    return path, notebook, result.time, result.exc_string if result.err is not None else None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Exécute en parallèle les carnets du livre absents du cache.")
    parser.add_argument("cache", type=Path, help="dossier du cache d'exécution (…/_build/.jupyter_cache)")
    parser.add_argument("--jobs", type=int, default=0, help="nombre de noyaux en parallèle (0 : un par cœur)")
    args = parser.parse_args(argv)

    from jupyter_cache import get_cache
    from jupyter_cache.base import CacheBundleIn
    from myst_nb.core.read import myst_nb_reader_plugin

    cache = get_cache(str(args.cache))
    previous = {record.uri: (record.data or {}).get("execution_seconds")
                for record in cache.list_cache_records()}
    todo = []
    for path in book_sources():
        notebook = myst_nb_reader_plugin(str(path))
        try:
            cache.match_cache_notebook(notebook)
            continue  # déjà exécuté avec ce code
        except KeyError:
            todo.append(path)
    if not todo:
        print("[carnets] tous les carnets sont dans le cache")
        return 0
    todo.sort(key=lambda p: (previous.get(str(p)) or 0.0, p.stat().st_size), reverse=True)
    jobs = min(args.jobs or os.cpu_count() or 1, len(todo))
    timeout = _timeout()
    os.environ.update(SINGLE_THREAD)  # hérité par les processus de travail et leurs noyaux
    start = time.perf_counter()
    failed = []
    print(f"[carnets] {len(todo)} carnet(s) à exécuter, {jobs} à la fois", flush=True)
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        futures = [pool.submit(_execute, str(path), timeout) for path in todo]
        for future in as_completed(futures):
            path, notebook, seconds, error = future.result()
            name = Path(path).relative_to(ROOT).as_posix()
            if error is not None:
                failed.append(name)
                print(f"[carnets] {name} : ERREUR (la construction le relancera et montrera la trace)", flush=True)
                continue
            record = cache.add_nb_to_project(path, read_data=READ_DATA)
            cache.cache_notebook_bundle(CacheBundleIn(notebook, record.uri, data={"execution_seconds": seconds}),
                                        check_validity=False, overwrite=True)
            print(f"[carnets] {name} : {seconds:.1f} s", flush=True)
    print(f"[carnets] {len(todo) - len(failed)} carnet(s) exécuté(s) en {time.perf_counter() - start:.0f} s "
          f"({jobs} à la fois)" + (f" ; en erreur : {', '.join(failed)}" if failed else ""), flush=True)
    return 0  # les erreurs sont celles de la construction qui suit


if __name__ == "__main__":
    sys.exit(main())
