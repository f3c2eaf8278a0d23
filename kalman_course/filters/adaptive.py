r"""Filtre de Kalman à bruit d'état adaptatif : :math:`Q` remise à l'échelle par **ajustement de covariance**
(*covariance matching*, Myers & Tapley 1976 ; Bar-Shalom, Li & Kirubarajan 2001, § 11.2).

C'est le filtre de Kalman (:func:`~kalman_course.filters.kalman.kalman_family`) avec l'option d'adaptation du
moteur (:class:`~kalman_course.filters.gating.Adaptation`, équations dans :mod:`~kalman_course.filters.gating`) :
à chaque pas, l'échelle :math:`s_k` de :math:`Q` est celle qui égale, en moyenne sur les :math:`W` derniers
pas, les innovations observées :math:`\nu_j^T\nu_j` et ce qu'annonce le modèle
:math:`\operatorname{tr}(S_j)` — mais seulement quand un test du :math:`\chi^2` sur les NIS de la fenêtre,
lues sous la covariance **nominale** (celle du filtre au repos, :math:`s = s_{\min}`), dit que les
innovations ne sont plus conformes au modèle ; avec de l'hystérésis : une fois enclenchée, l'adaptation ne
se relâche que quand l'estimation elle-même ne demande plus d'inflation. Au repos, :math:`s_k = s_{\min}` :
le filtre redevient celui du modèle.
"""

from __future__ import annotations

from typing import Any

from ..core.models import LinearGaussianModel
from ..core.results import AdaptiveResult
from .engine import run_filter
from .gating import Adaptation
from .kalman import FORMS, kalman_family

__all__ = ["AdaptiveResult", "adaptive_kalman_filter"]


def adaptive_kalman_filter(model: LinearGaussianModel, y: Any, x0: Any, P0: Any, u: Any = None, *,
                           window: int = 10, min_scale: float = 1.0, detect: float | None = 0.99,
                           form: str = FORMS[0], gate: Any = None, fading: Any = None) -> AdaptiveResult:
    r"""Filtre de Kalman dont le bruit d'état :math:`s_kQ` suit les innovations (voir le module).

    Paramètres : comme :func:`~kalman_course.kalman_filter` (``model`` linéaire, éventuellement variable
    dans le temps ; ``y`` (T, m) avec ``NaN`` pour une mesure manquante ; ``x0`` (n,), ``P0`` (n, n) ;
    ``u`` (T, p) ; ``form``, ``gate``, ``fading``), et le réglage de l'adaptation :

    window : :math:`W \ge 1` — pas de la fenêtre du test et constante de temps de l'estimation de l'échelle ;
    min_scale : échelle au repos :math:`s_{\min} > 0` (1 : la :math:`Q` du modèle) ;
    detect : probabilité :math:`p` du test qui enclenche l'adaptation (somme des NIS nominales des :math:`W`
        derniers pas au-delà de :math:`\chi^2_{\sum m_j}(p)`) ; ``None`` : toujours adapter.

    Renvoie un :class:`~kalman_course.core.results.AdaptiveResult` (``q_scale`` (T,) en plus).
    """
    adapt = Adaptation(window=window, min_scale=min_scale, detect=detect)
    return run_filter(kalman_family(form), model, y, x0, P0, u, gate=gate, fading=fading, adapt=adapt)
