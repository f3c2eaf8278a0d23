"""Registre des figures du livre : ``draw(nom)`` construit une figure, ``names()`` les liste.

Les chapitres appellent ``draw`` ; la commande ``python -m kalman_course.figures`` écrit toutes les
figures dans des fichiers (diapositives, polycopiés). Une figure = une fonction à graine fixe.
"""

from . import intuition  # noqa: F401  (chapitre « Le filtre de Kalman en images »)
from . import system  # noqa: F401  (chapitre « Contrôle d'un système dynamique »)
from . import estimator  # noqa: F401  (chapitre « Construction d'un estimateur »)
from . import gain  # noqa: F401  (chapitres « Prédicteur–correcteur » et « Gain optimal »)
from . import voltage  # noqa: F401  (enregistre les figures du chapitre)
from . import practice  # noqa: F401  (chapitre « Implémentation pratique et synthèse »)
from . import consistency  # noqa: F401  (chapitre « Vérifier les hypothèses : tests statistiques »)
from . import ekf  # noqa: F401  (chapitre « Dynamique non linéaire — le filtre de Kalman étendu »)
from . import tag  # noqa: F401  (chapitre « Exemple — suivi d'un tag radio (UWB) »)
from . import iekf  # noqa: F401  (chapitre « Filtre de Kalman étendu itéré »)
from . import unscented  # noqa: F401  (chapitre « Le filtre de Kalman *unscented* (UKF) »)
from . import particle  # noqa: F401  (chapitre « Le filtre particulaire »)
from . import ensemble  # noqa: F401  (chapitre « Le filtre de Kalman d'ensemble (EnKF) »)
from . import srif  # noqa: F401  (chapitre « Filtre d'information en racine carrée (SRIF) »)
from . import se3  # noqa: F401  (chapitre « EKF itéré sur SE(3) : pose d'une cible vue par une caméra »)
from . import smoothing  # noqa: F401  (chapitre « Lissage : le lisseur RTS »)
from . import likelihood  # noqa: F401  (chapitre « Apprendre Q et R : vraisemblance et données réelles »)
from . import labs  # noqa: F401  (travaux pratiques : le filtre de l'étudiant contre celui du paquet)
from . import tutorials  # noqa: F401  (travaux dirigés : les calculs à la main)
from . import tracking  # noqa: F401  (chapitres « Plusieurs capteurs, temps irrégulier » et « Cibles qui manœuvrent »)
from . import gaussian  # noqa: F401  (chapitre « Un seul filtre gaussien »)
from . import filter_choice  # noqa: F401  (chapitre « Quel filtre choisir ? »)
from . import parallel  # noqa: F401  (chapitre « Filtrer en parallèle dans le temps »)
from . import invariant  # noqa: F401  (chapitre « Filtrage invariant sur les groupes de Lie »)
from . import assimilation  # noqa: F401  (partie « Assimilation de données » et son TP)
from . import multitarget  # noqa: F401  (chapitres « Fouillis et association », « Gérer les pistes » : issue 37)
from ._registry import REGISTRY, FigureSpec, draw, names, new_figure, register

__all__ = ["REGISTRY", "FigureSpec", "draw", "names", "new_figure", "register"]
