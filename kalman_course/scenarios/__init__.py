"""Scénarios de démonstration du cours : un module par exemple, données reproductibles (graines fixées)."""

from .voltage import (
    TRUE_VOLTAGE,
    VOLTAGE_NOISE_STD,
    VOLTAGE_SEED,
    constant_voltage_measurements,
    constant_voltage_model,
)
from . import engine, radar, tag  # noqa: F401  (moteur 2×2 ; suivi du tag UWB ; radar de l'EKF itéré)
from . import sensor_tuning  # noqa: F401  (thermocouple mal réglé : chapitre « Implémentation pratique »)
from . import camera_target  # noqa: F401  (pose d'une cible vue par une caméra, EKF itéré sur SE(3))
from . import diffuse  # noqa: F401  (départ sans a priori : SRIF contre filtre de Kalman)
from . import nile, smoothing  # noqa: F401  (le Nil et le niveau local ; la cible du lissage)
from . import pendulum  # noqa: F401  (pendule : UKF, filtre particulaire)
from . import banana, distant_target  # noqa: F401  (UKF : la « banane » polaire, la cible lointaine)
from . import growth, convergence, importance  # noqa: F401  (filtre particulaire, EnKF : bimodal, convergence, poids)
from . import labs  # noqa: F401  (travaux pratiques : le filtre de l'étudiant contre celui du paquet)
from . import tutorials  # noqa: F401  (travaux dirigés : les exemples calculés à la main)
from . import helicopter, manoeuvre  # noqa: F401  (pistage : l'hélicoptère SAMU 31, la cible qui manœuvre)
from . import grid_bayes  # noqa: F401  (filtre bayésien exact sur une grille : le modèle de croissance)
from . import robot_localization  # noqa: F401  (robot plan, odométrie et GNSS : EKF invariant sur SE(2))
from . import assimilation  # noqa: F401  (assimilation de données : Lorenz-63/96, expériences jumelles de DAPPER)
from .radar import radar_iterations, radar_update_problem
from .tag import position_rmse, run_tag_ekf, run_tag_ukf, tag_data, tag_model

__all__ = [
    "assimilation",
    "banana",
    "convergence",
    "distant_target",
    "growth",
    "helicopter",
    "manoeuvre",
    "grid_bayes",
    "robot_localization",
    "importance",
    "labs",
    "tutorials",
    "diffuse",
    "nile",
    "smoothing",
    "engine",
    "pendulum",
    "position_rmse",
    "radar",
    "radar_iterations",
    "radar_update_problem",
    "sensor_tuning",
    "run_tag_ekf",
    "run_tag_ukf",
    "tag",
    "tag_data",
    "tag_model",
    "TRUE_VOLTAGE",
    "VOLTAGE_NOISE_STD",
    "VOLTAGE_SEED",
    "constant_voltage_measurements",
    "constant_voltage_model",
]
