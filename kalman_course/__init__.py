"""kalman_course — le paquet du cours « Filtre de Kalman ».

Les chapitres du livre n'appellent que les noms exportés ici et les sous-modules ``scenarios``
(exemples du cours), ``figures`` (registre des figures), ``errata`` (formules imprimées fausses, pour
les démontrer), ``geometry`` (SO(3), SE(3), caméra), ``numbers`` (les nombres en français),
``interactive`` (curseurs) et ``datasets`` (données réelles). Pas d'alias : un module se nomme par son
chemin (``kc.geometry.camera``, ``kalman_course.filters.square_root_information``).

Importer le paquet ne charge que les filtres (numpy et scipy) : ``figures`` (matplotlib),
``scenarios``, ``interactive`` (bokeh, ipywidgets), ``numbers`` (Babel) et ``datasets`` se chargent à
leur première utilisation (``kc.figures.draw(...)`` suffit). filterpy n'est jamais importé par le paquet :
c'est la référence des tests.
"""

from .core.angles import wrap_angle
from .core.jacobians import JacobianCheck, check_jacobian, numerical_jacobian
from .core.models import LinearGaussianModel, NonlinearModel
from .core.results import FilterResult, FilterRuns
from .core.simulation import Simulation, simulate
from .core.validation import KalmanInputError
from .diagnostics.consistency import (
    CentringTest,
    ChiSquareTest,
    WhitenessTest,
    autocorrelation,
    centring_test,
    chi2_band,
    chi2_mean_test,
    consistency_table,
    nees,
    nis,
    nis_test,
    whitened_innovations,
    whiteness_test,
)
from .diagnostics.monte_carlo import ConsistencyRuns, MonteCarlo, monte_carlo, monte_carlo_consistency
from .filters.diffuse import DiffuseFilterResult, diffuse_kalman_filter
from .filters.ensemble import EnsembleFilterResult, ensemble_kalman_filter
from .filters.extended import ekf_predict, ekf_update, extended_kalman_filter, extended_kalman_filter_runs
from .filters.iterated import (
    IteratedUpdate,
    iekf_update,
    iterated_extended_kalman_filter,
    iterated_extended_kalman_filter_runs,
    map_cost,
)
from .filters.kalman import Prediction, Update, kalman_filter, kalman_filter_runs, predict, recipe_step, update
# temps continu, pistage : modèles de mouvement, filtre à Q adaptative, IMM
from .core.motion import (
    constant_acceleration,
    constant_acceleration_sde,
    constant_velocity,
    constant_velocity_model,
    constant_velocity_sde,
    coordinated_turn,
    discretize,
)
from .core.motion import straight_flight  # issue 37 : régime « ligne droite » de l'IMM vitesse constante / virage
from .filters.adaptive import AdaptiveResult, adaptive_kalman_filter
from .filters.imm import IMMResult, imm_filter
from .filters.particle import (
    RESAMPLING_SCHEMES,
    ParticleFilterResult,
    effective_sample_size,
    multinomial_resample,
    particle_filter,
    resample,
    residual_resample,
    stratified_resample,
    systematic_resample,
)
from .filters.se3 import (
    CameraPoseModel,
    SE3FilterResult,
    SE3Update,
    se3_ekf_update,
    se3_iekf_update,
    se3_iterated_filter,
    se3_map_cost,
    se3_nees,
    se3_predict,
)
from .filters.smoothers import SmootherResult, extended_rts_smoother, rts_smoother, unscented_rts_smoother
from .filters.square_root_information import (
    SquareRootInformation,
    SrifUpdate,
    StateEstimate,
    extended_square_root_information_filter,
    extended_srif_predict,
    extended_srif_update,
    information_rank,
    information_to_state,
    noise_factor,
    square_root_information_filter,
    srif_predict,
    srif_update,
    state_to_information,
)
from .filters.unscented import (
    SigmaPoints,
    UnscentedTransform,
    sigma_points,
    sigma_weights,
    unscented_kalman_filter,
    unscented_kalman_filter_runs,
    unscented_transform,
)
from .geometry.camera import PinholeCamera, camera_measurement, camera_measurement_jacobian
from .geometry.lie import oplus, ominus, se3_adjoint, se3_exp, se3_log, se3_right_jacobian
from .lecture import errata
from .lecture.estimator import (
    MeanError,
    covariance_for_gain,
    error_transition,
    filter_matrices,
    linear_estimator,
    linear_estimator_runs,
    mean_error_recursion,
    measurement_initialisation,
    spectral_radius,
)
from .likelihood import (
    EMResult,
    MaximumLikelihood,
    expectation_maximization,
    filter_log_likelihood,
    log_likelihood,
    log_likelihood_terms,
    maximum_likelihood,
)
from .tables import Table
# un seul filtre gaussien, des règles d'intégration
from .filters.gaussian import GaussianRule, gaussian_filter, gaussian_filter_runs, gaussian_predict, gaussian_update
from .filters.extended import Linearization
from .filters.unscented import UnscentedRule
from .filters.cubature import CubatureRule, cubature_kalman_filter, cubature_kalman_filter_runs
from .filters.gauss_hermite import GaussHermiteRule, gauss_hermite_kalman_filter, gauss_hermite_kalman_filter_runs
from .filters.posterior_linearization import iterated_posterior_linearization_filter
# filtrer et lisser en parallèle dans le temps
from .filters.parallel import parallel_kalman_filter, parallel_rts_smoother
# filtrage invariant sur SE(2) (issue 35)
from .filters.invariant import (
    OdometryGnssModel,
    SE2FilterResult,
    se2_invariant_ekf,
    se2_invariant_ekf_runs,
    se2_standard_ekf,
    se2_standard_ekf_runs,
)
from .geometry.lie import se2_adjoint, se2_exp, se2_left_jacobian, se2_log, se2_right_jacobian
# assimilation de données : Lorenz-63/96, ETKF, DEnKF, LETKF, 3D-Var, interpolation optimale (issue 33)
from .core.lorenz import lorenz63, lorenz96
from .filters.ensemble_analysis import denkf_update, etkf_update, gaspari_cohn, letkf_update
from .filters.variational import optimal_interpolation, three_dimensional_var, var3d_update
# plusieurs cibles dans le fouillis : porte, association, gestion des pistes, GOSPA (issue 37)
from .multitarget import (
    GOSPA,
    Gate,
    MultiTargetResult,
    PDAUpdate,
    gnn_assign,
    gospa,
    jpda_probabilities,
    multi_target_tracker,
    nn_assign,
    ospa,
    pda_update,
    validation_gate,
)

__all__ = [
    # modèles, résultats, erreurs
    "LinearGaussianModel",
    "NonlinearModel",
    "FilterResult",
    "FilterRuns",
    "KalmanInputError",
    # filtre linéaire
    "Prediction",
    "Update",
    "predict",
    "update",
    "kalman_filter",
    "kalman_filter_runs",
    "recipe_step",
    # construction de l'estimateur (chapitres 2 à 4)
    "MeanError",
    "covariance_for_gain",
    "error_transition",
    "filter_matrices",
    "linear_estimator",
    "linear_estimator_runs",
    "mean_error_recursion",
    "measurement_initialisation",
    "spectral_radius",
    # cohérence (tests statistiques)
    "ChiSquareTest",
    "WhitenessTest",
    "CentringTest",
    "ConsistencyRuns",
    "nis",
    "nees",
    "whitened_innovations",
    "chi2_band",
    "chi2_mean_test",
    "nis_test",
    "autocorrelation",
    "whiteness_test",
    "centring_test",
    "monte_carlo_consistency",
    "consistency_table",
    # filtrage non linéaire
    "IteratedUpdate",
    "ekf_predict",
    "ekf_update",
    "iekf_update",
    "extended_kalman_filter",
    "extended_kalman_filter_runs",
    "iterated_extended_kalman_filter",
    "iterated_extended_kalman_filter_runs",
    "map_cost",
    "JacobianCheck",
    "check_jacobian",
    "numerical_jacobian",
    "wrap_angle",
    # filtres à points : UKF, filtre particulaire, EnKF
    "SigmaPoints",
    "UnscentedTransform",
    "sigma_points",
    "sigma_weights",
    "unscented_transform",
    "unscented_kalman_filter",
    "unscented_kalman_filter_runs",
    "RESAMPLING_SCHEMES",
    "ParticleFilterResult",
    "effective_sample_size",
    "multinomial_resample",
    "stratified_resample",
    "systematic_resample",
    "residual_resample",
    "resample",
    "particle_filter",
    "EnsembleFilterResult",
    "ensemble_kalman_filter",
    # filtre d'information en racine carrée
    "SquareRootInformation",
    "SrifUpdate",
    "StateEstimate",
    "srif_predict",
    "srif_update",
    "state_to_information",
    "information_to_state",
    "noise_factor",
    "information_rank",
    "square_root_information_filter",
    "extended_srif_predict",
    "extended_srif_update",
    "extended_square_root_information_filter",
    # simulation et présentation
    "Simulation",
    "simulate",
    "MonteCarlo",
    "monte_carlo",
    "Table",
    # EKF itéré sur SE(3) avec une caméra
    "PinholeCamera",
    "camera_measurement",
    "camera_measurement_jacobian",
    "oplus",
    "ominus",
    "se3_adjoint",
    "se3_exp",
    "se3_log",
    "se3_right_jacobian",
    "CameraPoseModel",
    "SE3FilterResult",
    "SE3Update",
    "se3_predict",
    "se3_ekf_update",
    "se3_iekf_update",
    "se3_iterated_filter",
    "se3_map_cost",
    "se3_nees",
    # lissage, vraisemblance, apprentissage de Q et R
    "DiffuseFilterResult",
    "diffuse_kalman_filter",
    "SmootherResult",
    "rts_smoother",
    "extended_rts_smoother",
    "unscented_rts_smoother",
    "log_likelihood_terms",
    "filter_log_likelihood",
    "log_likelihood",
    "MaximumLikelihood",
    "maximum_likelihood",
    "EMResult",
    "expectation_maximization",
    # temps continu et pistage
    "discretize",
    "constant_velocity",
    "constant_acceleration",
    "constant_velocity_sde",
    "constant_acceleration_sde",
    "constant_velocity_model",
    "coordinated_turn",
    "straight_flight",
    "imm_filter",
    "IMMResult",
    "adaptive_kalman_filter",
    "AdaptiveResult",
    # un seul filtre gaussien, des règles d'intégration
    "GaussianRule",
    "Linearization",
    "UnscentedRule",
    "CubatureRule",
    "GaussHermiteRule",
    "gaussian_filter",
    "gaussian_filter_runs",
    "gaussian_predict",
    "gaussian_update",
    "cubature_kalman_filter",
    "cubature_kalman_filter_runs",
    "gauss_hermite_kalman_filter",
    "gauss_hermite_kalman_filter_runs",
    "iterated_posterior_linearization_filter",
    "parallel_kalman_filter",
    "parallel_rts_smoother",
    # filtrage invariant sur SE(2)
    "se2_exp",
    "se2_log",
    "se2_adjoint",
    "se2_right_jacobian",
    "se2_left_jacobian",
    "OdometryGnssModel",
    "SE2FilterResult",
    "se2_invariant_ekf",
    "se2_standard_ekf",
    "se2_invariant_ekf_runs",
    "se2_standard_ekf_runs",
    # assimilation de données (issue 33)
    "lorenz96",
    "lorenz63",
    "etkf_update",
    "denkf_update",
    "gaspari_cohn",
    "letkf_update",
    "var3d_update",
    "three_dimensional_var",
    "optimal_interpolation",
    # plusieurs cibles dans le fouillis (issue 37)
    "validation_gate",
    "Gate",
    "nn_assign",
    "gnn_assign",
    "pda_update",
    "PDAUpdate",
    "jpda_probabilities",
    "gospa",
    "GOSPA",
    "ospa",
    "multi_target_tracker",
    "MultiTargetResult",
    # sous-modules
    "errata",
    "geometry",
    "figures",
    "numbers",
    "scenarios",
    "interactive",
    "datasets",
    "practice",
]

__version__ = "0.1.0"


#: Sous-modules chargés à la première utilisation (voir l'en-tête).
_LAZY_SUBMODULES = ("figures", "scenarios", "interactive", "numbers", "datasets", "practice")


def __getattr__(name: str):
    if name in _LAZY_SUBMODULES:
        import importlib

        module = importlib.import_module(f".{name}", __name__)
        globals()[name] = module
        return module
    raise AttributeError(f"le module « kalman_course » n'a pas d'attribut {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY_SUBMODULES))
