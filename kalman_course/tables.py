"""Petits tableaux de résultats affichés dans le livre (Markdown rendu par Jupyter / MyST-NB), sans pandas."""

from __future__ import annotations

import html
import re
from typing import Any, Sequence

import numpy as np

from .core.validation import KalmanInputError
from .typography import apply_rules

__all__ = ["Table"]

#: Un champ de format ``{:spec}`` dans le format d'une colonne.
_FIELD = re.compile(r"\{:([^{}]*)\}")


def _html_cell(text: str) -> str:
    """Échappe le HTML hors des formules, avec la typographie française du texte courant
    (:func:`~kalman_course.typography.apply_rules` : apostrophe « ’ », espaces insécables ; la sortie HTML
    d'une cellule échappe à l'extension Sphinx qui la donne au reste du livre) ; ``$…$`` devient
    ``\\(…\\)``."""
    parts = re.split(r"\$([^$]+)\$", text)
    out = []
    for i, part in enumerate(parts):
        out.append(f"\\({html.escape(part, quote=False)}\\)" if i % 2 else html.escape(apply_rules(part), quote=False))
    return "".join(out)


class Table:
    r"""Tableau de colonnes numériques (ou textuelles), formaté colonne par colonne.

    ``headers`` : en-têtes (Markdown, formules :math:`\LaTeX` permises) ; ``columns`` : une séquence de
    valeurs par colonne, toutes de même longueur ; ``formats`` : un format à la Python par colonne
    (``"{:.4g}"``, ``"{:.2e}"``…, éventuellement entouré de texte : ``"{:.1f} cm"``), ``None`` pour le
    format par défaut. Les nombres sont toujours écrits en français par
    :func:`kalman_course.numbers.format_spec` (virgule décimale, :math:`\times 10^{n}`) ; un texte est
    recopié tel quel. S'affiche en HTML dans un carnet et dans le livre (``_repr_html_``, formules pour
    MathJax) ; ``str(table)`` donne le Markdown.
    """

    def __init__(
        self,
        headers: Sequence[str],
        columns: Sequence[Sequence[Any]],
        formats: Sequence[str | None] | None = None,
    ) -> None:
        if len(headers) != len(columns):
            raise KalmanInputError(
                f"« headers » ({len(headers)}) et « columns » ({len(columns)}) doivent avoir la même longueur."
            )
        lengths = {len(c) for c in columns}
        if len(lengths) > 1:
            raise KalmanInputError(f"Les colonnes doivent avoir la même longueur ; reçu {sorted(lengths)}.")
        formats = [None] * len(headers) if formats is None else list(formats)
        if len(formats) != len(headers):
            raise KalmanInputError("« formats » doit donner un format par colonne.")
        for fmt in formats:
            if fmt is not None and (not isinstance(fmt, str) or len(_FIELD.findall(fmt)) != 1):
                raise KalmanInputError(
                    f"Chaque format de colonne doit contenir un champ « {{:…}} » (par exemple \"{{:.3f}}\") ; "
                    f"reçu {fmt!r}."
                )
        self.headers = list(headers)
        self.columns = [list(np.asarray(c).tolist()) if isinstance(c, np.ndarray) else list(c) for c in columns]
        self.formats = formats

    @property
    def n_rows(self) -> int:
        """Nombre de lignes."""
        return len(self.columns[0]) if self.columns else 0

    def cell(self, row: int, col: int) -> str:
        """Texte de la case (ligne ``row``, colonne ``col``)."""
        from .numbers import format_integer, format_spec  # Babel, chargé à l'affichage seulement

        value = self.columns[col][row]
        fmt = self.formats[col]
        if isinstance(value, str) or value is None:
            return "" if value is None else value
        if fmt is None:
            if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
                return format_integer(value)
            return format_spec(value, "g")
        return _FIELD.sub(lambda m: format_spec(value, m[1]), fmt)

    def to_markdown(self) -> str:
        """Le tableau en Markdown (tableau à barres verticales)."""
        lines = [
            "| " + " | ".join(self.headers) + " |",
            "|" + "|".join("---:" for _ in self.headers) + "|",
        ]
        for r in range(self.n_rows):
            lines.append("| " + " | ".join(self.cell(r, c) for c in range(len(self.headers))) + " |")
        return "\n".join(lines)

    def to_html(self) -> str:
        r"""Le tableau en HTML (les formules ``$…$`` deviennent ``\(…\)`` pour MathJax)."""
        head = "".join(f"<th>{_html_cell(h)}</th>" for h in self.headers)
        rows = "".join(
            "<tr>" + "".join(f"<td>{_html_cell(self.cell(r, c))}</td>" for c in range(len(self.headers))) + "</tr>"
            for r in range(self.n_rows)
        )
        return f'<table class="table dataframe kc-table"><thead><tr>{head}</tr></thead><tbody>{rows}</tbody></table>'

    def _repr_html_(self) -> str:
        return self.to_html()

    def _repr_markdown_(self) -> str:
        return self.to_markdown()

    def __str__(self) -> str:
        return self.to_markdown()

    def __repr__(self) -> str:
        return self.to_markdown()
