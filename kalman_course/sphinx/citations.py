r"""Citations et bibliographies du livre en français, dans un seul style auteur–année (extension Sphinx).

sphinxcontrib-bibtex mêle par défaut deux styles : « (Welch and Bishop, 2006) » dans le texte et
« [WB06] » dans les listes (étiquettes *alpha*, ou « [RobotOSROS] » sans auteur). Ce module enregistre :

- le style de renvoi ``kc_auteur_annee`` (``bibtex_reference_style``) : « (Welch et Bishop, 2006) »,
  « (Bar-Shalom *et al.*, 2001) », « (Chardon, s. d.) » pour un document sans date ;
- le style de liste ``kc_fr`` (``bibtex_default_style``) : la même étiquette auteur–année devant chaque
  entrée (« [Welch et Bishop, 2006] »), les auteurs joints par « et », « Rapport technique » et « Dans »
  au lieu de « Technical Report » et « In », entrées triées par auteur puis année.

À déclarer dans ``_config.yml`` (``sphinx: extra_extensions``) avec ces deux réglages.
"""

from __future__ import annotations

import functools
from collections import Counter
from dataclasses import dataclass

__all__ = ["REFERENCE_STYLE", "FORMATTING_STYLE", "author_year_label", "setup"]

#: Nom du style de renvoi (``bibtex_reference_style``).
REFERENCE_STYLE = "kc_auteur_annee"
#: Nom du style de liste (``bibtex_default_style``).
FORMATTING_STYLE = "kc_fr"
#: Année d'un document sans date.
NO_DATE = "s.\u00a0d."
_AND = " et "


def _last_names(entry) -> list[str]:
    persons = entry.persons.get("author") or entry.persons.get("editor") or []
    return [" ".join(p.prelast_names + p.last_names) for p in persons]


def _plain(text: str) -> str:
    """Un champ BibTeX en texte simple, accents LaTeX décodés (``S{\\"a}rkk{\\"a}`` → ``Särkkä``)."""
    from pybtex.richtext import Text

    return Text.from_latex(text).render_as("text").strip()


def author_year_label(entry) -> str:
    """L'étiquette auteur–année d'une entrée pybtex : « Kalman, 1960 », « Welch et Bishop, 2006 »,
    « Bar-Shalom et al., 2001 », « Chardon, s. d. » ; sans auteur ni éditeur, le titre tient lieu
    d'auteur (comme dans les renvois du texte)."""
    names = [_plain(n) for n in _last_names(entry)]
    if not names:
        who = _plain(entry.fields.get("title") or entry.key)  # comme les renvois de sphinxcontrib-bibtex
    elif len(names) == 1:
        who = names[0]
    elif len(names) == 2:
        who = names[0] + _AND + names[1]
    else:
        who = names[0] + " et al."
    year = _plain(entry.fields.get("year", "")) or NO_DATE
    return f"{who}, {year}"


def _label_style():
    from pybtex.style.labels import BaseLabelStyle

    class AuthorYearLabelStyle(BaseLabelStyle):
        """Étiquettes auteur–année ; les doublons reçoivent une lettre (« 2006a », « 2006b »)."""

        def format_labels(self, sorted_entries):
            entries = list(sorted_entries)
            labels = [author_year_label(e) for e in entries]
            counts = Counter(labels)
            seen: Counter = Counter()
            for label in labels:
                if counts[label] > 1:
                    seen[label] += 1
                    yield f"{label}{chr(ord('a') + seen[label] - 1)}"
                else:
                    yield label

    return AuthorYearLabelStyle


def _formatting_style():
    from pybtex.style.formatting.unsrt import Style as UnsrtStyle
    from pybtex.style.formatting.unsrt import date, pages, toplevel
    from pybtex.richtext import Symbol
    from pybtex.style.template import field, first_of, join, optional, optional_field, sentence, together, words
    from pybtex.style.template import names as pybtex_names

    class FrenchStyle(UnsrtStyle):
        """Le style *unsrt* de pybtex, en français, trié par auteur puis année, étiquettes auteur–année."""

        default_sorting_style = "author_year_title"
        default_label_style = "kc_auteur_annee"

        def format_names(self, role, as_sentence=True):
            formatted = pybtex_names(role, sep=", ", sep2=_AND, last_sep=_AND)
            return sentence[formatted] if as_sentence else formatted

        def format_editor(self, e, as_sentence=True):
            editors = self.format_names("editor", as_sentence=False)
            if "editor" not in e.persons:
                return editors
            result = join(sep=", ")[editors, "éd."]
            return sentence[result] if as_sentence else result

        def format_volume_and_series(self, e, as_sentence=True):
            volume_and_series = optional[words[together["Volume" if as_sentence else "volume", field("volume")],
                                               optional[words["de la série", field("series")]]]]
            number_and_series = optional[words[join(sep=Symbol("nbsp"))["Numéro" if as_sentence else "numéro",
                                                                        field("number")],
                                               optional[words["de la série", field("series")]]]]
            result = first_of[volume_and_series, number_and_series, optional_field("series")]
            return sentence(capfirst=True)[result] if as_sentence else result

        def format_edition(self, e):
            # « 4ᵉ édition », « 1ʳᵉ édition » (le style de base écrit « 4 edition »)
            def ordinal(text):
                plain = str(text)
                return text + ("ʳᵉ" if plain == "1" else "ᵉ") if plain.isdigit() else text.lower()

            return optional[words[field("edition", apply_func=ordinal), "édition"]]

        def format_chapter_and_pages(self, e):
            return join(sep=", ")[optional[together["chapitre", field("chapter")]], optional[together["pages", pages]]]

        def format_in_book(self, e, where):
            # « Dans Éd., éd., Titre du recueil, volume …, » puis ``where`` (chapitre, pages) : chapitre d'un
            # ouvrage collectif et communication dans des actes
            return words[
                "Dans",
                sentence[
                    optional[self.format_editor(e, as_sentence=False)],
                    self.format_btitle(e, "booktitle", as_sentence=False),
                    self.format_volume_and_series(e, as_sentence=False),
                    where,
                ],
            ]

        def get_incollection_template(self, e):
            return toplevel[
                sentence[self.format_names("author")],
                self.format_title(e, "title"),
                self.format_in_book(e, self.format_chapter_and_pages(e)),
                sentence[optional_field("publisher"), optional_field("address"), self.format_edition(e), date],
                sentence[optional_field("note")],
                self.format_web_refs(e),
            ]

        def get_techreport_template(self, e):
            return toplevel[
                sentence[self.format_names("author")],
                self.format_title(e, "title"),
                sentence[
                    words[first_of[optional_field("type"), "Rapport technique"], optional_field("number")],
                    field("institution"),
                    optional_field("address"),
                    date,
                ],
                sentence[optional_field("note")],
                self.format_web_refs(e),
            ]

        def get_inproceedings_template(self, e):
            return toplevel[
                sentence[self.format_names("author")],
                self.format_title(e, "title"),
                words[self.format_in_book(e, optional[pages]), self.format_address_organization_publisher_date(e)],
                sentence[optional_field("note")],
                self.format_web_refs(e),
            ]

    return FrenchStyle


def _reference_style():
    from pybtex.richtext import Tag, Text
    from pybtex.style.template import field, first_of, node, optional
    from sphinxcontrib.bibtex.style.referencing import GroupReferenceStyle, PersonStyle
    from sphinxcontrib.bibtex.style.referencing.author_year import AuthorYearReferenceStyle
    from sphinxcontrib.bibtex.style.referencing.basic_author_year import (
        BasicAuthorYearParentheticalReferenceStyle,
        BasicAuthorYearTextualReferenceStyle,
    )
    from sphinxcontrib.bibtex.style.referencing.extra_author import ExtraAuthorReferenceStyle
    from sphinxcontrib.bibtex.style.referencing.extra_empty import ExtraEmptyReferenceStyle
    from sphinxcontrib.bibtex.style.referencing.extra_label import ExtraLabelReferenceStyle
    from sphinxcontrib.bibtex.style.template import join, join2, post_text, pre_text, reference

    @node
    def french_year(children, data):
        assert not children
        return first_of[optional[field("year")], NO_DATE].format_data(data)

    def french_person() -> PersonStyle:
        return PersonStyle(sep=", ", sep2=_AND, last_sep=_AND, other=Text(" ", Tag("em", "et al.")))

    @dataclass
    class Parenthetical(BasicAuthorYearParentheticalReferenceStyle):
        def inner(self, role_name):
            return join2(sep1=self.pre_text_sep, sep2=self.post_text_sep)[
                pre_text,
                reference[join(sep=self.author_year_sep)[
                    self.person.author_or_editor_or_title(full="s" in role_name), french_year]],
                post_text,
            ]

    @dataclass
    class Textual(BasicAuthorYearTextualReferenceStyle):
        def inner(self, role_name):
            return join(sep=self.text_reference_sep)[
                self.person.author_or_editor_or_title(full="s" in role_name),
                join[
                    self.bracket.left,
                    join2(sep1=self.pre_text_sep, sep2=self.post_text_sep)[pre_text, reference[french_year],
                                                                          post_text],
                    self.bracket.right,
                ],
            ]

    @dataclass
    class FrenchAuthorYear(AuthorYearReferenceStyle):
        """« (Welch et Bishop, 2006) » ; « Welch et Bishop (2006) » ; « s. d. » sans date."""

        def __post_init__(self):
            self.person = french_person()
            self.styles.extend([
                Parenthetical(bracket=self.bracket_parenthetical, person=self.person,
                              author_year_sep=self.author_year_sep, pre_text_sep=self.pre_text_sep,
                              post_text_sep=self.post_text_sep),
                Textual(bracket=self.bracket_textual, person=self.person,
                        text_reference_sep=self.text_reference_sep, pre_text_sep=self.pre_text_sep,
                        post_text_sep=self.post_text_sep),
                ExtraAuthorReferenceStyle(bracket=self.bracket_author, person=self.person),
                ExtraLabelReferenceStyle(bracket=self.bracket_label),
                ExtraEmptyReferenceStyle(),
            ])
            GroupReferenceStyle.__post_init__(self)

    return FrenchAuthorYear


def _cache_pybtex_entry_points() -> None:
    """pybtex cherche chaque greffon (style, format de sortie…) parmi les points d'entrée de *tous* les
    paquets installés, à chaque rendu d'un texte : 30 ms par recherche, 22 s par construction du livre
    pour ses 68 références (``importlib.metadata.entry_points`` relit les métadonnées à chaque appel).
    Les paquets installés ne changent pas pendant une construction : la réponse est gardée par (groupe,
    nom). Les greffons enregistrés à l'exécution (``register_plugin``) passent toujours avant."""
    import pybtex.plugin

    if getattr(pybtex.plugin.entry_points, "kc_cached", False):
        return
    lookup = pybtex.plugin.entry_points

    @functools.lru_cache(maxsize=None)
    def cached(group, name):
        return lookup(group=group, name=name) if name is not None else lookup(group=group)

    def entry_points(*, group, name=None):
        return cached(group, name)

    entry_points.kc_cached = True
    pybtex.plugin.entry_points = entry_points


def register() -> None:
    """Enregistre les trois greffons (étiquettes, liste, renvois) auprès de pybtex et de
    sphinxcontrib-bibtex (sans effet s'ils le sont déjà)."""
    import pybtex.plugin
    import sphinxcontrib.bibtex.plugin

    _cache_pybtex_entry_points()

    for group, name, factory in (
        ("pybtex.style.labels", "kc_auteur_annee", _label_style),
        ("pybtex.style.formatting", FORMATTING_STYLE, _formatting_style),
    ):
        try:
            pybtex.plugin.find_plugin(group, name)
        except pybtex.plugin.PluginNotFound:
            pybtex.plugin.register_plugin(group, name, factory())
    group = "sphinxcontrib.bibtex.style.referencing"
    try:
        sphinxcontrib.bibtex.plugin.find_plugin(group, REFERENCE_STYLE)
    except ImportError:
        sphinxcontrib.bibtex.plugin.register_plugin(group, REFERENCE_STYLE, _reference_style())


def setup(app):
    register()
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
