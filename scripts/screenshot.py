"""Capture d'écran d'une page du site construit, dans Chromium sans écran (Debian,
/usr/bin/chromium-headless-shell).

Usage : python scripts/screenshot.py _build/html/book/intro.html capture.png [--width 1280] [--full]
[--dark] [--selector "#fig-x"] [--query "?q=mot"]. Un téléphone : --width 390 --height 844.
Le site est servi sur 127.0.0.1 (port libre) ; toute requête non locale est bloquée et signalée.
"""

from __future__ import annotations

import argparse
import functools
import http.server
import threading
from pathlib import Path

from playwright.sync_api import sync_playwright

CHROMIUM_ARGS = [
    "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
]


def main() -> int:
    parser = argparse.ArgumentParser(description="Capture d'écran d'une page du site construit.")
    parser.add_argument("page", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--root", type=Path, default=Path("_build/html"))
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=900)
    parser.add_argument("--full", action="store_true", help="page entière")
    parser.add_argument("--dark", action="store_true", help="mode sombre du thème")
    parser.add_argument("--selector", help="amener cet élément (sélecteur CSS) en haut de l'écran ; avec --full, "
                        "ne capturer que lui, en entier")
    parser.add_argument("--query", default="", help="suffixe de l'adresse (« ?q=porte » pour la recherche)")
    args = parser.parse_args()
    root = args.root.resolve()
    rel = args.page.resolve().relative_to(root).as_posix()
    handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=str(root))
    http.server.SimpleHTTPRequestHandler.log_message = lambda *a: None
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    base = f"http://127.0.0.1:{server.server_address[1]}/"
    blocked: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path="/usr/bin/chromium-headless-shell", args=CHROMIUM_ARGS)
        page = browser.new_page(viewport={"width": args.width, "height": args.height},
                                color_scheme="dark" if args.dark else "light")

        def route(r):
            if r.request.url.startswith(base) or r.request.url.startswith("data:"):
                r.continue_()
            else:
                blocked.append(r.request.url)
                r.abort()

        page.route("**/*", route)
        errors: list[str] = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        if args.dark:  # le thème lit son mode dans localStorage (sinon : « auto », qui suit color_scheme)
            page.add_init_script("localStorage.setItem('mode', 'dark'); localStorage.setItem('theme', 'dark');")
        page.goto(base + rel + args.query, wait_until="networkidle")
        page.wait_for_timeout(1500)
        if args.selector:
            target = page.locator(args.selector).first
            target.scroll_into_view_if_needed()
            page.wait_for_timeout(2500)  # figures à curseurs dessinées quand elles approchent de l'écran
            if args.full:  # l'élément entier (les curseurs collés sous l'en-tête peuvent s'y déplacer)
                target.screenshot(path=str(args.out))
            else:  # l'écran, l'élément en haut : ce que voit le lecteur
                target.evaluate("el => el.scrollIntoView({block: 'start'})")
                page.wait_for_timeout(1000)
                page.screenshot(path=str(args.out))
        else:
            page.screenshot(path=str(args.out), full_page=args.full)
        browser.close()
    server.shutdown()
    for url in blocked:
        print("requête non locale bloquée :", url)
    for e in errors:
        print("erreur de page :", e)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
