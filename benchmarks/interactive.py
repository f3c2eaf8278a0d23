"""Mesures de l'interactivité du livre, comparées aux objectifs (rien n'est un test chronométré).

1. Précalcul des grilles : 15 × 15 exécutions de 50 pas (tension constante), objectif < 1 s ;
   puis chaque figure à curseurs du registre (une par chapitre au moins), pour information.
2. Poids des pages (site construit, portable 1366 × 768) : au premier chargement (ce que la page charge
   avant qu'une figure à curseurs n'approche de l'écran), objectif ≤ 2,5 Mo par chapitre ; puis figures
   comprises (BokehJS et exécutions précalculées, chargés à la demande) ; premier rendu (« first
   contentful paint ») servi par un serveur local, objectif < 1 s.
3. Réponse des curseurs dans Chromium headless : de l'événement clavier réel (touche flèche sur la
   poignée) à la recopie des données (rappel CustomJS), puis à la fin du rendu des panneaux par BokehJS
   (fin du dernier requestAnimationFrame qu'il a demandé) ; objectif < 50 ms. Puis le glissé à la souris :
   travail du fil principal de la page à l'appui sur la poignée et au relâchement (métriques de Chromium :
   tâches, dont recalcul des styles), objectif < 50 ms chacun (avant la règle de kc-pages.css sur body,
   ≈ 200 ms sur un chapitre à curseurs : tout le style de la page recalculé).

Usage : python benchmarks/interactive.py [--site _build/html] [--moves 40] [--only grilles,poids,réponse]
"""

from __future__ import annotations

import argparse
import functools
import http.server
import statistics
import threading
import time
from pathlib import Path
from urllib.parse import urlsplit

import kalman_course.interactive as ki
from kalman_course.interactive.static import MARKER, PLOTTED_SOURCE
from kalman_course.numbers import format_spec

CHROMIUM_ARGS = [
    "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
]
PLAIN_PAGE = "book/references.html"  # page sans figure interactive, pour comparaison


def _pages() -> list[str]:
    """Les pages du livre qui ont une figure à curseurs, dans l'ordre de la table des matières."""
    import yaml

    root = Path(__file__).resolve().parent.parent
    toc = yaml.safe_load((root / "_toc.yml").read_text())
    files = [toc["root"]] + [c["file"] for part in toc["parts"] for c in part["chapters"]]
    return [f"{f}.html" for f in files if Path(f).name not in ("references", "errata")]  # annexes sans curseurs


PAGES = _pages()


def best_time(func, repeat: int = 5) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        func()
        times.append(time.perf_counter() - t)
    return min(times)


def bench_grids() -> None:
    print("1. Précalcul des grilles (meilleur de 5)")
    ki.voltage_grid()  # échauffement (imports, caches)
    t = best_time(ki.voltage_grid)
    g = ki.voltage_grid()
    n = g.shape[0] * g.shape[1]
    print(f"   tension constante  {format_spec(g.shape[0], 'd')}×{format_spec(g.shape[1], 'd')} exécutions × "
          f"{format_spec(g.time.size, 'd')} pas : {format_spec(t * 1e3, '.1f'):>7s} ms"
          f"  (objectif < {format_spec(1000, 'd')} ms : {'atteint' if t < 1 else 'MANQUÉ'}, "
          f"{format_spec(t / n * 1e6, '.0f')} µs par exécution)")
    t = best_time(lambda: ki.voltage_sliders().html(), repeat=3)
    print(f"   figure Bokeh complète de la tension (grille + document + HTML) : {format_spec(t * 1e3, '.1f'):>7s} ms")
    print("   figures à curseurs du registre (une exécution : grille + document + HTML) :")
    for name in ki.slider_names():
        spec_factory = ki.SLIDER_FIGURES[name][1]
        t0 = time.perf_counter()
        spec = spec_factory()
        grid = spec.grid()
        t1 = time.perf_counter()
        html = spec.static().html()
        t2 = time.perf_counter()
        sizes = " × ".join(format_spec(size, "d") for size in grid.shape)
        print(f"     {name:28s} {sizes:>8s} points : grille {format_spec(t1 - t0, '.2f'):>6s} s, "
              f"figure {format_spec(1e3 * (t2 - t1), '.0f'):>6s} ms, HTML {format_spec(len(html) / 1e3, '.0f'):>5s} ko")


def serve(root: Path):
    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args):
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Quiet, directory=str(root)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, f"http://127.0.0.1:{server.server_address[1]}/"


def open_page(browser, url: str, base: str):
    page = browser.new_page(viewport={"width": 1366, "height": 768})
    loaded, blocked = [], []

    def route(r):
        if r.request.url.startswith(base) or r.request.url.startswith("data:"):
            r.continue_()
        else:
            blocked.append(r.request.url)
            r.abort()

    page.route("**/*", route)
    page.on("response", lambda r: loaded.append(r.url) if r.status < 400 else None)
    page.goto(url, wait_until="load")
    page.evaluate("() => window.MathJax && MathJax.startup ? MathJax.startup.promise.then(() => true) : true")
    return page, loaded, blocked


def load_figures(page) -> None:
    """Dessine toutes les figures à curseurs (elles se chargent d'ordinaire en approchant de l'écran)."""
    if page.evaluate("() => !!window.kcFigures && document.querySelectorAll('.kc-bokeh-root').length > 0"):
        page.evaluate("() => window.kcFigures.loadAll().then(() => true)")
        page.wait_for_function("() => [...document.querySelectorAll('.kc-bokeh-root')].every(r => "
                               "r.dataset.kcReady === '1')", timeout=30000)


def served(root: Path, urls) -> tuple[int, int]:
    """(octets, nombre de fichiers) des fichiers du site servis pour ces adresses (chacune une fois)."""
    files = [(root / urlsplit(u).path.lstrip("/")) for u in dict.fromkeys(urls)]
    files = [f for f in files if f.is_file()]
    return sum(f.stat().st_size for f in files), len(files)


_INSTALL = """(id) => {
  // t0 : horodatage de l'événement clavier réel (même horloge que performance.now()) ;
  // tData : le document Bokeh signale le changement des données tracées (rappel CustomJS terminé) ;
  // tPaint : fin du dernier rendu que BokehJS a demandé (requestAnimationFrame) après cet événement,
  // c'est-à-dire les trois panneaux redessinés.
  const doc = window.kcFigures.documents[id];
  window.kcMoves = [];
  let current = null;
  document.addEventListener('keydown', (e) => {
    current = {t0: e.timeStamp, tData: null, tPaint: null};
    window.kcMoves.push(current);
  }, true);
  doc.on_change((ev) => {
    if (current && ev.attr === 'data' && ev.model.name && ev.model.name.startsWith('%s'))
      current.tData = performance.now() - current.t0;
  });
  const raf = window.requestAnimationFrame.bind(window);
  window.requestAnimationFrame = (cb) => {
    const move = current;
    return raf((t) => {
      cb(t);
      if (move && move.tData !== null) move.tPaint = Math.max(move.tPaint || 0, performance.now() - move.t0);
    });
  };
}""" % PLOTTED_SOURCE


def bench_browser(root: Path, moves: int, sections: set[str]) -> None:
    from playwright.sync_api import sync_playwright

    server, base = serve(root)
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium-headless-shell", args=CHROMIUM_ARGS)
            if "poids" in sections:
                bench_weights(browser, root, base)
            if "réponse" in sections:
                bench_response(browser, root, base, moves)
            browser.close()
    finally:
        server.shutdown()


def bench_weights(browser, root: Path, base: str) -> None:
    print("\n2. Poids des pages (octets des fichiers servis ; portable 1366 × 768)")
    print(f"   {'page':36s} {'1er chargement':>15s} {'requêtes':>9s} {'figures comprises':>18s} "
          f"{'1er rendu':>10s}")
    firsts, paints = [], []
    for rel in [PLAIN_PAGE, *PAGES]:
        html_file = root / rel
        if not html_file.is_file():
            print(f"   {rel} : absente du site")
            continue
        page, loaded, blocked = open_page(browser, base + rel, base)
        page.wait_for_timeout(300)
        first, n_first = served(root, loaded)
        paint = page.evaluate("() => (performance.getEntriesByName('first-contentful-paint')[0] || "
                              "{startTime: NaN}).startTime")
        load_figures(page)
        full, _ = served(root, loaded)
        ok = "" if first <= 2.5e6 else "  MANQUÉ (> 2,5 Mo)"
        print(f"   {rel:36s} {format_spec(first / 1e6, '.2f'):>12s} Mo {format_spec(n_first, 'd'):>9s} "
              f"{format_spec(full / 1e6, '.2f'):>15s} Mo {format_spec(paint, '.0f'):>7s} ms{ok}")
        if blocked:
            print(f"     REQUÊTES NON LOCALES BLOQUÉES : {blocked}")
        if rel != PLAIN_PAGE:
            firsts.append(first)
            paints.append(paint)
        page.close()
    if firsts:
        worst, slow = max(firsts), max(paints)
        print(f"   chapitres : premier chargement de {format_spec(min(firsts) / 1e6, '.2f')} à "
              f"{format_spec(worst / 1e6, '.2f')} Mo (objectif ≤ 2,5 Mo : "
              f"{'atteint' if worst <= 2.5e6 else 'MANQUÉ'}) ; premier rendu médian "
              f"{format_spec(statistics.median(paints), '.0f')} ms, au plus {format_spec(slow, '.0f')} ms "
              f"(objectif < 1 000 ms : {'atteint' if slow < 1000 else 'MANQUÉ'})")


def press_cost(page, cdp, handle) -> tuple[float, float, float, float]:
    """Travail du fil principal de la page (ms : tâches, dont recalcul des styles) à l'appui de la souris sur
    ``handle``, puis au relâchement (300 ms laissées à chacun pour finir son rendu)."""
    def metrics():
        values = {m["name"]: m["value"] for m in cdp.send("Performance.getMetrics")["metrics"]}
        return values["TaskDuration"], values["RecalcStyleDuration"]

    box = handle.bounding_box()
    page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    page.wait_for_timeout(300)
    costs = []
    for action in (page.mouse.down, page.mouse.up):
        before = metrics()
        action()
        page.wait_for_timeout(300)
        after = metrics()
        costs += [1000 * (after[0] - before[0]), 1000 * (after[1] - before[1])]
    return tuple(costs)


def bench_response(browser, root: Path, base: str, moves: int) -> None:
    print(f"\n3. Réponse des curseurs dans Chromium headless "
          f"({format_spec(moves, 'd')} déplacements au clavier par curseur)")
    for rel in PAGES:
        html_file = root / rel
        if not html_file.is_file() or MARKER not in html_file.read_text():
            continue
        page, _, _ = open_page(browser, base + rel, base)
        load_figures(page)
        cdp = page.context.new_cdp_session(page)
        cdp.send("Performance.enable")
        figures = page.locator(f"[{MARKER}]")
        ids = page.evaluate("() => [...document.querySelectorAll('.kc-bokeh-root')].map(r => r.id)")
        for k in range(figures.count()):
            figure, fid = figures.nth(k), ids[k]
            name = figure.get_attribute(MARKER)
            page.locator(f"[{MARKER}] .noUi-handle").first.wait_for()
            page.evaluate(_INSTALL, fid)
            n_sliders = figure.locator(".noUi-handle").count()
            for s in range(n_sliders):
                handle = figure.locator(".noUi-handle").nth(s)
                handle.focus()
                page.keyboard.press("Home")
                page.wait_for_timeout(300)
                page.evaluate("() => { window.kcMoves = []; }")
                model = f"kcFigures.documents['{fid}'].get_model_by_name('kc-slider-{s}')"
                n_pos = int(page.evaluate(f"() => {model}.end"))
                key = "ArrowRight"
                for m in range(moves):
                    value = page.evaluate(f"() => {model}.value")
                    if value >= n_pos:
                        key = "ArrowLeft"
                    elif value <= 0:
                        key = "ArrowRight"
                    page.keyboard.press(key)
                    page.wait_for_timeout(150)  # laisser finir le rendu avant le mouvement suivant
                done = [m for m in page.evaluate("() => window.kcMoves") if m["tPaint"] is not None]
                if len(done) < 2:
                    print(f"   {name}, curseur {format_spec(s + 1, 'd')} : pas assez de mouvements redessinés")
                    continue
                data_ms = [m["tData"] for m in done]
                paint_ms = [m["tPaint"] for m in done]
                label = page.evaluate(f"() => {model}.title").strip()
                med, p90 = statistics.median(paint_ms), statistics.quantiles(paint_ms, n=10, method="inclusive")[-1]
                worst = max(paint_ms)
                ninety = format_spec(0.9, ".0%")
                verdict = "atteint" if worst < 50 else (f"atteint pour {ninety} des mouvements" if p90 < 50
                                                       else "MANQUÉ")
                data_med = format_spec(statistics.median(data_ms), ".1f")
                print(f"   {name}, « {label} » ({format_spec(len(done), 'd')} mouvements) :\n"
                      f"     données recopiées : médiane {data_med:>5s} ms, "
                      f"max {format_spec(max(data_ms), '.1f'):>5s} ms\n"
                      f"     figure redessinée : médiane {format_spec(med, '.1f'):>5s} ms, "
                      f"{ninety} {format_spec(p90, '.1f'):>5s} ms, max {format_spec(worst, '.1f'):>5s} ms"
                      f" — objectif < 50 ms : {verdict}")
                down, down_style, up, up_style = press_cost(page, cdp, handle)
                print(f"     glissé à la souris : appui {format_spec(down, '.0f')} ms (styles "
                      f"{format_spec(down_style, '.0f')} ms), relâchement {format_spec(up, '.0f')} ms (styles "
                      f"{format_spec(up_style, '.0f')} ms) de travail du fil principal — objectif < 50 ms : "
                      f"{'atteint' if max(down, up) < 50 else 'MANQUÉ'}")
        page.close()


def load_note() -> str:
    try:
        import os

        return (f"charge moyenne de la machine (1 min) : {format_spec(os.getloadavg()[0], '.2f')} "
                f"pour {format_spec(os.cpu_count() or 1, 'd')} cœurs")
    except OSError:
        return ""


def main() -> int:
    parser = argparse.ArgumentParser(description="Mesures de l'interactivité du livre (grilles, poids, réponse).")
    parser.add_argument("--site", type=Path, default=Path("_build/html"), help="dossier html du site construit")
    parser.add_argument("--moves", type=int, default=40, help="déplacements mesurés par curseur")
    parser.add_argument("--only", default="grilles,poids,réponse",
                        help="mesures à faire, séparées par des virgules : grilles, poids, réponse")
    args = parser.parse_args()
    sections = {x.strip() for x in args.only.split(",")}
    unknown = sections - {"grilles", "poids", "réponse"}
    if unknown:
        parser.error(f"mesure inconnue : {', '.join(sorted(unknown))} (grilles, poids, réponse)")
    if "grilles" in sections:
        bench_grids()
    if not sections & {"poids", "réponse"}:
        return 0
    if not (args.site / PAGES[0]).is_file():
        print(f"\n(site absent dans {args.site} : construisez le livre pour mesurer le poids et la réponse)")
        return 0
    bench_browser(args.site.resolve(), args.moves, sections)
    print(f"\n({load_note()} ; les maxima dépendent de la charge, les médianes bougent peu)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
