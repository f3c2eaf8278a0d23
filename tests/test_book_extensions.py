"""Extensions Sphinx du livre, sans construction : extraits de code sans docstring, citations
auteur–année en français (étiquettes et listes rendues par pybtex, comparées à des chaînes écrites à
la main)."""

from __future__ import annotations

import inspect
from pathlib import Path

import pybtex.plugin
import pytest
from pybtex.database import parse_file

import kalman_course.core.linalg as linalg
from kalman_course.book_citations import FORMATTING_STYLE, author_year_label, register
from kalman_course.book_listings import source_without_docstring

ROOT = Path(__file__).resolve().parent.parent


def test_source_listing_drops_the_docstring_only():
    code, path = source_without_docstring("kalman_course.core.linalg.kalman_gain")
    assert path == Path(inspect.getsourcefile(linalg))
    assert code.startswith("def kalman_gain(")
    assert ":math:" not in code and '"""' not in code and "r\"\"\"" not in code
    assert "_posv(S, PHt.T)" in code and code.rstrip().endswith("return Kt.T, S, PHt")
    # une fonction sans docstring est rendue entière
    code2, _ = source_without_docstring("kalman_course.filters.kalman._predict")
    assert code2 == inspect.getsource(__import__("kalman_course.filters.kalman", fromlist=["_predict"])._predict)


def test_source_listing_unknown_name():
    with pytest.raises((ImportError, AttributeError)):
        source_without_docstring("kalman_course.core.linalg.n_existe_pas")


@pytest.fixture(scope="module")
def bib():
    register()
    return parse_file(str(ROOT / "book" / "references.bib"))


def test_author_year_labels_are_french(bib):
    labels = {key: author_year_label(e) for key, e in bib.entries.items()}
    assert labels["kalman1960"] == "Kalman, 1960"
    assert labels["welch2006"] == "Welch et Bishop, 2006"
    assert labels["barshalom2001"] == "Bar-Shalom et al., 2001"
    assert labels["chardon"] == "Chardon, s.\u00a0d."
    assert labels["sarkka2013"] == "Särkkä, 2013"
    assert not any(" and " in label for label in labels.values())


def test_french_bibliography_style(bib):
    style = pybtex.plugin.find_plugin("pybtex.style.formatting", FORMATTING_STYLE)()
    rendered = {e.key: (e.label, e.text.render_as("text")) for e in style.format_entries(bib.entries.values())}
    label, text = rendered["welch2006"]
    assert label == "Welch et Bishop, 2006"
    assert text.startswith("Greg Welch et Gary Bishop. An introduction to the Kalman filter. Rapport technique")
    assert all(" and " not in t.split(". ")[0] for _, t in rendered.values())  # auteurs (les titres restent)
    assert "Technical Report" not in " ".join(t for _, t in rendered.values())
