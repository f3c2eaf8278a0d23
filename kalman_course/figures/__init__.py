"""Registre des figures du livre : ``draw(nom)`` construit une figure, ``names()`` les liste.

Les chapitres appellent ``draw`` ; la commande ``python -m kalman_course.figures`` écrit toutes les
figures dans des fichiers (diapositives, polycopiés). Une figure = une fonction à graine fixe.
"""

from . import voltage  # noqa: F401  (enregistre les figures du chapitre)
from ._registry import REGISTRY, FigureSpec, draw, names, new_figure, register

__all__ = ["REGISTRY", "FigureSpec", "draw", "names", "new_figure", "register"]
