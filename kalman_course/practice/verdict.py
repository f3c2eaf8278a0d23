"""Le verdict du correcteur : réussi ou non, un texte en français, et son affichage dans Jupyter.

Dans un carnet, le verdict s'affiche en encadré : vert (« ✔ Réussi ») ou rouge (« ✘ À corriger ») ;
le symbole et le mot disent le résultat sans la couleur (lecteurs d'écran, daltonisme), les couleurs
ont un contraste suffisant (RGAA / WCAG 2.1 AA). Le texte brut (console, ``print``) dit la même chose.
"""

from __future__ import annotations

import html
import re
from dataclasses import dataclass

__all__ = ["Verdict"]

#: Couleurs de l'encadré : (bordure, fond, texte) ; contraste texte/fond > 10:1.
_COLORS = {True: ("#1a7f37", "#e8f5ec", "#0b3318"), False: ("#b3261e", "#fdecea", "#5c1410")}


def _french(text: str) -> str:
    """La typographie française (espaces insécables, apostrophe « ’ ») hors des `extraits de code`."""
    from ..typography import french_spacing

    parts = re.split(r"(`[^`]*`)", text)
    return "".join(part if i % 2 else french_spacing(part) for i, part in enumerate(parts))


def _inline(text: str) -> str:
    """Texte → HTML : typographie française, échappement, `code` en <code>."""
    parts = re.split(r"`([^`]*)`", text)
    out = []
    for i, part in enumerate(parts):
        out.append(f"<code>{html.escape(part)}</code>" if i % 2 else html.escape(_french(part)))
    return "".join(out)


@dataclass(frozen=True)
class Verdict:
    """Résultat de :func:`kalman_course.practice.check`.

    ``passed`` : la fonction est juste sur tous les cas cachés ; ``feedback`` : l'explication en
    français (texte brut ; l'affichage, ``str`` et HTML, y met la typographie française) ; ``kind`` : « réussi », « pas écrite », « exception », « erreur classique », « forme »,
    « valeur »… ; ``mistake`` : l'identifiant de l'erreur classique reconnue (ou ``None``) ; ``line`` : le
    numéro de la ligne du code de l'étudiant en cause (ou ``None``).
    """

    exercise: str
    title: str
    passed: bool
    feedback: str
    kind: str
    mistake: str | None = None
    line: int | None = None

    @property
    def headline(self) -> str:
        mark = "✔ Réussi" if self.passed else "✘ À corriger"
        return f"{mark} — {self.title} ({self.exercise})"

    def __str__(self) -> str:
        return _french(f"{self.headline}\n{self.feedback}")

    def __repr__(self) -> str:
        return str(self)

    def _repr_html_(self) -> str:
        border, background, color = _COLORS[self.passed]
        blocks, items = [], []
        for line in [p for p in self.feedback.split("\n") if p.strip()] + [""]:
            if line.startswith("- "):
                items.append(f"<li>{_inline(line[2:])}</li>")
                continue
            if items:  # une liste (les cas cachés réussis)
                blocks.append(f'<ul style="margin:0.2em 0 0.2em 1.2em;padding:0">{"".join(items)}</ul>')
                items = []
            if line:
                blocks.append(f'<p style="margin:0.3em 0">{_inline(line)}</p>')
        paragraphs = "".join(blocks)
        css_class = "kc-verdict kc-verdict-" + ("reussi" if self.passed else "a-corriger")
        return (
            f'<div class="{css_class}" role="status" style="border-left:6px solid {border};'
            f"background:{background};color:{color};padding:0.5em 1em;margin:0.5em 0;"
            f'border-radius:4px;line-height:1.45">'
            f'<p style="margin:0.2em 0;font-weight:bold">{html.escape(_french(self.headline))}</p>'
            f"{paragraphs}</div>"
        )
