"""kalman_course — le paquet du cours « Filtre de Kalman ».

Les chapitres du livre n'appellent que les noms exportés ici (et les sous-modules ``scenarios``
et ``figures``).
"""

from . import figures, scenarios
from .kf import Prediction, Update, kalman_filter, predict, recipe_step, update
from .models import LinearGaussianModel
from .results import FilterResult
from .simulate import Simulation, simulate
from .validation import KalmanInputError

__all__ = [
    "FilterResult",
    "KalmanInputError",
    "LinearGaussianModel",
    "Prediction",
    "Simulation",
    "Update",
    "figures",
    "kalman_filter",
    "predict",
    "recipe_step",
    "scenarios",
    "simulate",
    "update",
]

__version__ = "0.1.0"
