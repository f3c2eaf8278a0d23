"""Le registre des figures : chaque figure du livre est une fonction nommée, sans argument, à graine fixe."""

from __future__ import annotations

import io
from dataclasses import dataclass
from typing import Callable

from matplotlib.figure import Figure

from ..core.validation import KalmanInputError
from ..numbers import french_figure

__all__ = ["CHAPTER_TITLES", "CourseFigure", "FigureSpec", "REGISTRY", "register", "draw", "names", "new_figure"]

#: Titre de chaque chapitre (nom du fichier ``book/<nom>.md`` → titre de niveau 1), pour
#: ``python -m kalman_course.figures --list`` ; ``tests/test_book.py`` vérifie qu'ils suivent le livre.
CHAPTER_TITLES: dict[str, str] = {
    "intuition": "Le filtre de Kalman en images",
    "controle-systeme": "Contrôle d'un système dynamique",
    "estimateur": "Construction d'un estimateur",
    "predicteur-correcteur": "Le filtre prédicteur–correcteur",
    "gain-optimal": "Dynamique de l'erreur et gain optimal",
    "tension-constante": "Exemple — estimation d'une tension constante",
    "pratique-synthese": "Implémentation pratique et synthèse",
    "tests-statistiques": "Vérifier les hypothèses : tests statistiques",
    "ekf": "Dynamique non linéaire — le filtre de Kalman étendu",
    "suivi-tag": "Exemple — suivi d'un tag radio (UWB)",
    "ekf-itere": "Filtre de Kalman étendu itéré",
    "ukf": "Le filtre de Kalman *unscented* (UKF)",
    "filtre-particulaire": "Le filtre particulaire",
    "enkf": "Le filtre de Kalman d'ensemble (EnKF)",
    "lissage": "Lissage : le lisseur de Rauch–Tung–Striebel",
    "vraisemblance": "Apprendre Q et R : vraisemblance et données réelles",
    "capteurs-temps-irregulier": "Plusieurs capteurs, temps irrégulier",
    "cibles-manoeuvrantes": "Cibles qui manœuvrent : filtres adaptatifs et IMM",
    "srif": "Filtre d'information en racine carrée (SRIF)",
    "ekf-itere-se3": "EKF itéré sur SE(3) : pose d'une cible vue par une caméra",
    "tp-filtre-lineaire": "TP 1 — Le filtre de Kalman linéaire : la tension constante",
    "tp-ekf-tag": "TP 2 — Le filtre de Kalman étendu : suivre le tag radio",
    "tp-ukf-particulaire": "TP 3 — UKF et filtre particulaire : le pendule",
    "tp-lissage-em": "TP 4 — Lisser et apprendre : le Nil",
    "tp-helicoptere-samu": "TP 5 — Pister l'hélicoptère du SAMU 31",
    "td-cibles-reelles": "TD 4 — Pister des cibles réelles à la main",
    "td-autres-formes": "TD 5 — Autres formes du filtre à la main",
    "sujet-examen": "Sujet d'examen",
    "td-filtre-lineaire": "TD 1 — Le gain de Kalman à la main",
    "td-filtres-a-points": "TD 2 — Filtres à points : calculs à la main",
    "td-lissage-em": "TD 3 — Lissage et EM à la main",
    "filtre-gaussien": "Un seul filtre gaussien : linéarisation, points sigma, cubature, Gauss–Hermite",
    "quel-filtre": "Quel filtre choisir ?",
    "filtrage-parallele": "Filtrer en parallèle dans le temps",
    "filtrage-invariant": "Filtrage invariant sur les groupes de Lie",
    "td-filtrage-invariant": "TD 7 — L'EKF invariant à la main",
    "assimilation-ensemble": "Le filtre d'ensemble en grande dimension",
    "methodes-variationnelles": "Méthodes variationnelles",
    "td-assimilation": "TD 6 — Assimilation de données à la main",
    "tp-assimilation": "TP 6 — L'ETKF sur Lorenz-96",
    # plusieurs cibles (issue 37)
    "fouillis-association": "Fouillis et association",
    "gestion-pistes": "Gérer les pistes",
    "td-plusieurs-cibles": "TD 8 — Plusieurs cibles à la main",
    "tp-plusieurs-cibles": "TP 7 — Plusieurs cibles : l'association probabiliste (PDA)",
}

#: Résolution des figures affichées dans les carnets (pixels par pouce).
DISPLAY_DPI = 144


class CourseFigure(Figure):
    """Une ``Figure`` matplotlib qui s'affiche d'elle-même dans Jupyter (PNG), sans pyplot ni backend global."""

    def _repr_png_(self):
        buffer = io.BytesIO()
        self.savefig(buffer, format="png", dpi=DISPLAY_DPI)
        width, height = self.get_size_inches()
        # affichée à 100 px par pouce, rendue à 144 : nette sur un écran haute densité
        return buffer.getvalue(), {"width": int(width * 100), "height": int(height * 100)}

    def __repr__(self) -> str:
        return f"<Figure du cours {self.get_size_inches()[0]:.0f}×{self.get_size_inches()[1]:.0f} pouces>"


@dataclass(frozen=True)
class FigureSpec:
    """Une entrée du registre : nom (identifiant de fichier), chapitre, titre en français, fonction."""

    name: str
    chapter: str
    title: str
    build: Callable[[], Figure]

    @property
    def description(self) -> str:
        """Ce que montre la figure, en français (son titre dans le registre)."""
        return self.title

    @property
    def chapter_title(self) -> str:
        """Titre du chapitre qui montre la figure (le nom de fichier s'il n'est pas dans
        :data:`CHAPTER_TITLES`)."""
        return CHAPTER_TITLES.get(self.chapter, self.chapter)


REGISTRY: dict[str, FigureSpec] = {}


def register(name: str, *, chapter: str, title: str):
    """Décorateur : inscrit une fonction ``() -> Figure`` sous ``name`` (unique)."""

    def decorator(func: Callable[[], Figure]) -> Callable[[], Figure]:
        if name in REGISTRY:
            raise RuntimeError(f"Figure « {name} » déjà enregistrée.")
        REGISTRY[name] = FigureSpec(name=name, chapter=chapter, title=title, build=func)
        return func

    return decorator


def names() -> list[str]:
    """Noms de toutes les figures, dans l'ordre des chapitres."""
    return list(REGISTRY)


def draw(name: str, **inputs) -> Figure:
    """Construit la figure ``name`` (une nouvelle ``matplotlib.figure.Figure``, sans état global pyplot).

    ``inputs`` : ce que la figure accepte en plus (les figures des travaux pratiques prennent les
    fonctions de l'étudiant, ``draw("tp-tension", predict=predict, update=update)``) ; sans eux, chaque
    figure se dessine seule, à graine fixe.

    Graduations (virgule décimale, puissances de dix) et textes (espaces insécables) sont mis à la
    française par :func:`kalman_course.numbers.french_figure` : une seule fois ici, pour toutes les figures."""
    try:
        spec = REGISTRY[name]
    except KeyError:
        raise KalmanInputError(
            f"Figure inconnue « {name} ». Figures disponibles : {', '.join(REGISTRY)}."
        ) from None
    figure = spec.build(**inputs)
    french_figure(figure)
    return figure


def new_figure(nrows: int = 1, ncols: int = 1, *, width: float = 7.0, height: float = 3.6, **kwargs):
    """Une figure et ses axes, créés sans pyplot (rien de global n'est modifié)."""
    fig = CourseFigure(figsize=(width, height), layout="constrained")
    axes = fig.subplots(nrows, ncols, **kwargs)
    return fig, axes
