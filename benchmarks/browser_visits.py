"""Visites du navigateur (tests/test_browser.py) : où passe le calcul d'une visite de page.

Les visites de toutes les pages sur deux écrans sont le premier poste de la CI (≈ 45 % du calcul). Ce
banc ouvre quelques pages du site construit comme les tests (mêmes vérifications, un visiteur par écran,
cache HTTP partagé) et imprime, par étape, le **temps CPU de toute la machine** (Chromium, pilote de
Playwright et Python compris : à lancer sur une machine au repos) : ouverture (page et figures), axe-core,
curseurs, quiz, le reste ; puis, pour la page la plus lourde, la part des formules dans le DOM et les
règles d'axe-core les plus coûteuses (``performanceTimer`` d'axe-core).

Usage : ``python benchmarks/browser_visits.py [--site _build/html] [PAGE …]`` (pages sans « .html », dans
``book/`` ; par défaut un échantillon de pages lourdes et légères). Demande Chromium et le site construit
(``bash scripts/build.sh``). Les grilles des curseurs sont lues dans ``KALMAN_GRID_CACHE`` si la variable
désigne un dossier qui les contient, sinon calculées (leur calcul compte alors dans « curseurs »).
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

import test_browser as tb  # noqa: E402  (les vérifications des tests, telles quelles)
from playwright.sync_api import sync_playwright  # noqa: E402

from kalman_course.numbers import format_spec  # noqa: E402

SAMPLE = ["errata", "ukf", "lissage", "cibles-manoeuvrantes", "tension-constante", "intro", "td-lissage-em"]
_TICKS = os.sysconf("SC_CLK_TCK")


def busy() -> float:
    """Secondes de calcul de toute la machine depuis son démarrage (tous les cœurs, /proc/stat)."""
    v = list(map(int, Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]))
    return (sum(v[:8]) - v[3] - v[4]) / _TICKS


def visit_costs(site: tb.Site, pages: list[str]) -> dict[str, Counter]:
    """Par écran, le calcul (s) de chaque étape des visites de ``pages``."""
    toc = set(tb._toc_pages(site.root))
    costs = {"portable": Counter(), "téléphone": Counter()}
    screens = {"portable": (tb._laptop_checks, tb.LAPTOP, "light"), "téléphone": (tb._phone_checks, tb.PHONE, "dark")}
    original_axe = tb.axe_violations
    with sync_playwright() as p:
        for label, (checks_of, viewport, scheme) in screens.items():
            browser = p.chromium.launch(executable_path=tb.CHROMIUM, args=tb.CHROMIUM_ARGS)
            context = browser.new_context(viewport=viewport, color_scheme=scheme)
            cost = costs[label]

            def timed_axe(page, cost=cost):
                start = busy()
                try:
                    return original_axe(page)
                finally:
                    cost["axe-core"] += busy() - start

            tb.axe_violations = timed_axe
            try:
                for name in pages:
                    html_file = site.root / "book" / f"{name}.html"
                    html = html_file.read_text()
                    start = busy()
                    visit = tb.open_page(browser, site.url(html_file), site.base, viewport=viewport,
                                         color_scheme=scheme, context=context)
                    cost["ouverture (page et figures)"] += busy() - start
                    for key, check in checks_of(html_file, html, toc):
                        start, axe_before = busy(), cost["axe-core"]
                        check(site, html_file, visit, [], [])
                        cost[key] += busy() - start - (cost["axe-core"] - axe_before)
                    tb.close_visit(visit, context)
            finally:
                tb.axe_violations = original_axe
                context.close()
                browser.close()
    return costs


def axe_rules(site: tb.Site, name: str) -> tuple[dict, list[tuple[float, str]]]:
    """Pour la page ``name`` (portable) : éléments du DOM (dont formules, et rendus de formules remplacés
    par des boîtes comme dans les tests) et durée (ms) de chaque règle d'axe-core dans une exécution
    complète."""
    messages: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=tb.CHROMIUM, args=tb.CHROMIUM_ARGS)
        page = browser.new_page(viewport=tb.LAPTOP)
        page.on("console", lambda m: messages.append(m.text))
        page.goto(site.url(site.root / "book" / f"{name}.html"), wait_until="load")
        tb.load_figures(page)
        dom = page.evaluate("""() => ({all: document.getElementsByTagName('*').length,
            math: document.querySelectorAll('mjx-container, mjx-container *').length})""")
        page.add_script_tag(url=tb.AXE_PATH)
        dom["boxed"] = page.evaluate(tb.BOX_FORMULAS)["boxed"]  # comme les tests (tb.axe_violations)
        page.evaluate("(options) => axe.run(document, options).then(() => true)",
                      {**tb.AXE_OPTIONS, "performanceTimer": True})
        browser.close()
    rules = [(float(m[2]), m[1]) for m in (re.match(r"Measure rule_([\w-]+) took ([\d.]+)ms", t) for t in messages) if m]
    return dom, sorted(rules, reverse=True)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description="Calcul d'une visite de page, étape par étape (tests du navigateur).")
    parser.add_argument("pages", nargs="*", default=SAMPLE, help="pages de book/ (sans « .html »)")
    parser.add_argument("--site", type=Path, default=ROOT / "_build" / "html", help="dossier du site construit")
    args = parser.parse_args(argv)
    root = args.site.resolve()
    missing = [name for name in args.pages if not (root / "book" / f"{name}.html").is_file()]
    if missing:
        parser.error(f"page(s) introuvable(s) dans {root / 'book'} : {', '.join(missing)} (construisez le site : "
                     "bash scripts/build.sh)")
    with tb.served(root) as site:
        start = busy()
        costs = visit_costs(site, args.pages)
        total = busy() - start
        heaviest = max(args.pages, key=lambda n: (root / "book" / f"{n}.html").stat().st_size)
        dom, rules = axe_rules(site, heaviest)
    print(f"Visites de {len(args.pages)} page(s) sur deux écrans : {format_spec(total, '.1f')} s de calcul "
          f"({format_spec(total / (2 * len(args.pages)), '.1f')} s par visite)")
    for label, cost in costs.items():
        print(f"  {label} :")
        for step, seconds in cost.most_common():
            print(f"    {step:30s} {format_spec(seconds, '.1f'):>6s} s  {format_spec(100 * seconds / total, '.0f'):>3s} %")
    print(f"\naxe-core sur {heaviest} (portable) : {format_spec(dom['all'], 'd')} éléments, dont "
          f"{format_spec(dom['math'], 'd')} dans les formules ({format_spec(100 * dom['math'] / dom['all'], '.0f')} %), "
          f"{format_spec(dom['boxed'], 'd')} rendus de formules en boîtes le temps d'axe-core ; "
          f"{format_spec(sum(ms for ms, _ in rules) / 1000, '.1f')} s de règles, les plus coûteuses :")
    for ms, rule in rules[:6]:
        print(f"    {rule:30s} {format_spec(ms / 1000, '.2f'):>6s} s")


if __name__ == "__main__":
    main()
