r"""Curseurs du chapitre « suivi d'un tag radio (UWB) » : réglages :math:`\sigma_a` et :math:`\sigma_r` de l'EKF.

Les données sont celles du chapitre (:func:`~kalman_course.scenarios.tag.tag_data`, graine fixe) ; seuls
les réglages du filtre changent : écart-type de l'accélération :math:`\sigma_a` (m/s², fixe
:math:`Q = \sigma_a^2 GG^T`) et écart-type supposé des distances :math:`\sigma_r` (m, fixe
:math:`R = \sigma_r^2 I`). La position par défaut (0,5 m/s², 0,10 m) redonne exactement l'exécution des
figures du chapitre (:func:`~kalman_course.scenarios.tag.run_tag_ekf` avec ses valeurs par défaut).
"""

from __future__ import annotations

import numpy as np

from ..scenarios.tag import TAG_ACCEL_STD, TAG_RANGE_STD, TAG_ROOM, run_tag_ekf, tag_data
from ..core.validation import KalmanInputError, as_float_array
from .figure import SliderSpec, register_sliders
from .grid import ParameterAxis, ParameterGrid, log_grid, precompute_grid
from .spec import Glyph, Panel

__all__ = ["tag_axes", "tag_run", "tag_grid", "tag_panels", "tag_sliders", "live_tag_explorer"]

LIVE_HINT = "kc.interactive.live_tag_explorer()"


def tag_axes(per_decade: int = 3) -> tuple[ParameterAxis, ParameterAxis]:
    r""":math:`\sigma_a \in [0{,}05 ; 5]` m/s² et :math:`\sigma_r \in [0{,}01 ; 1]` m, ``per_decade`` points par
    décade (7 × 7 par défaut), centrés exactement sur les réglages du chapitre."""
    return (
        ParameterAxis("accel_std", "σₐ", "bruit d'accélération du modèle", "m/s²",
                      log_grid(TAG_ACCEL_STD, 1, 1, per_decade), default=per_decade),
        ParameterAxis("range_std", "σᵣ", "bruit de distance supposé", "m",
                      log_grid(TAG_RANGE_STD, 1, 1, per_decade), default=per_decade),
    )


def tag_run(accel_std: float, range_std: float, data=None) -> dict[str, np.ndarray]:
    r"""Une exécution de l'EKF du chapitre ; séries de forme (T,) : position estimée ``px``, ``py`` (m),
    erreur de position ``err`` :math:`=\lVert\hat p_k - p_k\rVert` (m) et écart-type annoncé par le filtre
    ``sigma`` :math:`=\sqrt{P_{xx} + P_{yy}}` (m)."""
    data = tag_data() if data is None else data
    result = run_tag_ekf(accel_std, range_std, data=data)
    err = np.linalg.norm(result.x[:, :2] - data.x_true[:, :2], axis=1)
    sigma = np.sqrt(result.P[:, 0, 0] + result.P[:, 1, 1])
    return {"px": result.x[:, 0], "py": result.x[:, 1], "err": err, "sigma": sigma}


def tag_grid(per_decade: int = 3) -> ParameterGrid:
    r"""Toutes les exécutions :math:`(\sigma_a, \sigma_r)` de la grille sur les données du chapitre."""
    data = tag_data()
    accel, ranges = tag_axes(per_decade)
    return precompute_grid(lambda a, r: tag_run(a, r, data=data), accel, ranges, time=data.t)


def tag_panels() -> tuple[Panel, ...]:
    """La figure : la pièce vue de dessus (trajectoires vraie et estimée), puis l'erreur de position au
    cours du temps avec l'écart-type que le filtre s'attribue."""
    L, W = TAG_ROOM
    return (
        Panel(
            "Trajectoire dans la pièce de 10 m × 8 m (vue de dessus)",
            "y (m)",
            (
                Glyph("py_true", "line", "green", "trajectoire vraie", x="px_true"),
                Glyph("py", "line", "royalblue", "estimation EKF", x="px"),
            ),
            x_label="x (m)",
            x_range=(-0.5, L + 0.5),
            y_range=(-0.5, W + 0.5),
            equal_aspect=True,
        ),
        Panel(
            "Erreur de position et écart-type annoncé par le filtre",
            "distance (m)",
            (
                Glyph("err", "line", "firebrick", "erreur ‖p̂ₖ − pₖ‖"),
                Glyph("sigma", "line", "royalblue", "écart-type annoncé √(Pxx + Pyy)"),
            ),
            y_log=True,
        ),
    )


def _fixed(data) -> dict[str, np.ndarray]:
    return {"px_true": data.x_true[:, 0], "py_true": data.x_true[:, 1]}


def tag_sliders(per_decade: int = 3):
    r"""Figure à curseurs statiques :math:`\sigma_a` et :math:`\sigma_r` (Bokeh) pour l'EKF du tag."""
    from .static import StaticSliders

    data = tag_data()
    return StaticSliders(
        tag_grid(per_decade),
        tag_panels(),
        x_label="temps t (s)",
        fixed=_fixed(data),
        name="tag-curseurs",
        title=f"Tag UWB : réglez l'EKF (mêmes distances mesurées, {data.t[-1]:.0f} s)",
        live_hint=LIVE_HINT,
    )


def _check_positive(name: str, value) -> float:
    v = as_float_array(name, value)
    if v.ndim != 0 or not v > 0:
        raise KalmanInputError(f"« {name} » doit être un écart-type strictement positif ; reçu {value!r}.")
    return float(v)


def live_tag_explorer(accel_std: float = TAG_ACCEL_STD, range_std: float = TAG_RANGE_STD):
    r"""Curseurs interactifs (ipywidgets) :math:`\sigma_a`, :math:`\sigma_r` : relancent l'EKF (noyau requis)."""
    from .live import LiveExplorer, LogParameter

    data = tag_data()
    return LiveExplorer(
        run=lambda accel_std, range_std: tag_run(accel_std, range_std, data=data),
        parameters=(
            LogParameter("accel_std", "σₐ (accélération)", "m/s²", _check_positive("accel_std", accel_std), -2.0, 1.0),
            LogParameter("range_std", "σᵣ (distance)", "m", _check_positive("range_std", range_std), -3.0, 0.5),
        ),
        time=data.t,
        panels=tag_panels(),
        x_label="temps t (s)",
        fixed=_fixed(data),
    )


def tag_readout(series, values) -> str:
    """Le texte sous les curseurs : l'erreur de position vraie et l'écart-type annoncé, en moyenne."""
    from .figure import number

    err, sigma = series["err"], series["sigma"]
    rms = float(np.sqrt(np.mean(err ** 2)))
    announced = float(np.sqrt(np.mean(sigma ** 2)))
    return (f"Erreur de position (moyenne quadratique) : {number(rms, 'm')} ; écart-type annoncé par le filtre : "
            f"{number(announced, 'm')} (rapport {number(announced / rms)} ; proche de 1 si le filtre est cohérent).")


@register_sliders("tag-curseurs", chapter="suivi-tag")
def tag_spec(per_decade: int = 3) -> SliderSpec:
    r"""La figure :math:`(\sigma_a, \sigma_r)` du chapitre au registre des figures à curseurs (même grille
    que :func:`tag_grid`, mêmes panneaux que :func:`tag_sliders`)."""
    data = tag_data()
    return SliderSpec(
        name="tag-curseurs",
        chapter="suivi-tag",
        title=f"Tag UWB : réglez l'EKF (mêmes distances mesurées, {data.t[-1]:.0f} s)",
        x_label="temps t (s)",
        axes=tag_axes(per_decade),
        run=lambda a, r: tag_run(a, r, data=data),
        time=data.t,
        panels=tag_panels(),
        fixed=_fixed(data),
        readout=tag_readout,
    )
