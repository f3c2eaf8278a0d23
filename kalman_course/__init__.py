"""kalman_course — le paquet du cours « Filtre de Kalman ».

Les chapitres du livre n'appellent que les noms exportés ici et les sous-modules ``scenarios``
(exemples du cours), ``figures`` (registre des figures), ``errata`` (formules imprimées fausses, pour
les démontrer) et ``interactive`` (curseurs ; importé à la demande, seul à dépendre de bokeh et
d'ipywidgets).
"""

from . import errata, figures, scenarios
from .ekf import (
    IteratedUpdate,
    ekf_predict,
    ekf_update,
    extended_kalman_filter,
    iekf_update,
    iterated_extended_kalman_filter,
    map_cost,
)
from .estimator import (
    MeanError,
    covariance_for_gain,
    error_transition,
    filter_matrices,
    linear_estimator,
    mean_error_recursion,
    measurement_initialisation,
    spectral_radius,
)
from .jacobians import JacobianCheck, check_jacobian, numerical_jacobian, wrap_angle
from .kf import Prediction, Update, kalman_filter, predict, recipe_step, update
from .models import LinearGaussianModel, NonlinearModel
from .results import FilterResult
from .simulate import MonteCarlo, Simulation, monte_carlo, simulate
from .tables import Table
from .ukf_reference import filterpy_unscented_filter
from .validation import KalmanInputError

__all__ = [
    # modèles, résultat, erreurs
    "LinearGaussianModel",
    "NonlinearModel",
    "FilterResult",
    "KalmanInputError",
    # filtre linéaire
    "Prediction",
    "Update",
    "predict",
    "update",
    "kalman_filter",
    "recipe_step",
    # construction de l'estimateur (chapitres 2 à 4)
    "MeanError",
    "covariance_for_gain",
    "error_transition",
    "filter_matrices",
    "linear_estimator",
    "mean_error_recursion",
    "measurement_initialisation",
    "spectral_radius",
    # filtrage non linéaire
    "IteratedUpdate",
    "ekf_predict",
    "ekf_update",
    "iekf_update",
    "extended_kalman_filter",
    "iterated_extended_kalman_filter",
    "map_cost",
    "JacobianCheck",
    "check_jacobian",
    "numerical_jacobian",
    "wrap_angle",
    "filterpy_unscented_filter",
    # simulation et présentation
    "Simulation",
    "simulate",
    "MonteCarlo",
    "monte_carlo",
    "Table",
    # sous-modules
    "errata",
    "figures",
    "scenarios",
    "interactive",
]

__version__ = "0.1.0"


def __getattr__(name: str):
    # ``kc.interactive`` à la demande : bokeh et ipywidgets ne sont importés que si l'on s'en sert.
    if name == "interactive":
        import importlib

        return importlib.import_module(".interactive", __name__)
    raise AttributeError(f"module 'kalman_course' has no attribute {name!r}")
