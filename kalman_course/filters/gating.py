r"""Les options du moteur, communes à toutes les familles gaussiennes : la **porte** (rejet des mesures
aberrantes), la **mémoire évanescente** (oubli du passé) et l'**adaptation** de :math:`Q` (ajustement de
covariance). Chacune ne lit que ce que rend l'étape de la famille — l'innovation :math:`\nu_k`, sa
covariance :math:`S_k` (ou une racine de :math:`S_k` pour une famille en racine carrée), l'état prédit —
comme le *gater* de Stone Soup se place à côté de son *updater* : :func:`~kalman_course.filters.engine.run_filter`
les applique à toutes les familles qui les déclarent (``gate=``, ``fading=``, ``adapt=``).

**Porte** (*gating*). Sous les hypothèses du filtre, l'innovation :math:`\nu_k = y_k - \hat y_k` suit
:math:`\mathcal N(0, S_k)`, donc la NIS :math:`\epsilon_k = \nu_k^TS_k^{-1}\nu_k` suit une loi du
:math:`\chi^2` à :math:`m_k` degrés de liberté (:math:`m_k` : composantes observées au pas :math:`k`).
Avec ``gate=p``, une mesure dont la NIS dépasse le quantile :math:`\chi^2_{m_k}(p)` est **rejetée** : le pas
se réduit à la prédiction, exactement comme si la mesure manquait (son innovation et :math:`S_k` restent
lisibles dans le résultat, ``result.rejected`` marque le pas, et la log-vraisemblance ne le compte pas). Sur
des données conformes au modèle, une proportion :math:`1 - p` des mesures est rejetée à tort ; une mesure
aberrante (à plusieurs :math:`\sqrt{S}` de la prédiction) l'est toujours. Pour un IMM, chaque régime a sa
porte, et la mesure est gardée si elle tombe dans l'une d'elles (l'union des portes des régimes).

**Mémoire évanescente** (*fading memory*, Sorenson & Sacks 1971). Avec ``fading=α`` (:math:`\alpha \ge 1`),
la covariance a posteriori est gonflée avant d'être propagée :

.. math:: P_{k-1\mid k-1} \leftarrow \alpha^2 P_{k-1\mid k-1},\qquad\text{d'où}\quad
    P_{k\mid k-1} = \alpha^2\,A P_{k-1\mid k-1} A^T + Q

pour un modèle linéaire (la prédiction de l'EKF avec :math:`F` à la place de :math:`A`) : les mesures
anciennes sont pondérées par :math:`\alpha^{-2}` par pas, le filtre oublie le passé et suit plus vite une
cible qui change de régime (c'est le ``KalmanFilter.alpha`` de filterpy). Pour un IMM, chaque régime oublie.

**Adaptation de** :math:`Q` (*covariance matching*, Myers & Tapley 1976 ; Bar-Shalom, Li & Kirubarajan 2001,
§ 11.2), :class:`Adaptation`. Le modèle annonce :math:`\mathbb E[\nu_k\nu_k^T] = S_k = S^0_k + s\,G_k` pour un
bruit d'état :math:`s\,Q`, où :math:`G_k = H_kQH_k^T` est l'image de :math:`Q` dans la mesure (:math:`H_k = C`
pour le filtre linéaire). Chaque pas donne une estimation de :math:`s\operatorname{tr}G_k`,
:math:`d_k = \nu_k^T\nu_k - \operatorname{tr}(S_k) + s_{k-1}\operatorname{tr}(G_k)`, et l'échelle qui égale les
deux en moyenne, avec une mémoire exponentielle de constante de temps :math:`W` (``window``,
:math:`\lambda = 1 - 1/W`), est

.. math:: \hat s_k = \frac{D_k}{\Gamma_k},\qquad D_k = \lambda D_{k-1} + d_k,\quad
    \Gamma_k = \lambda\Gamma_{k-1} + \operatorname{tr}G_k,\qquad s_k = \max(s_{\min}, \hat s_k).

Ce rapport est très bruité quand :math:`Q` est petite devant :math:`R` : on ne l'applique que quand les
innovations le demandent. Le **test** qui enclenche l'adaptation lit la NIS sous la covariance **nominale**
:math:`S^{\mathrm{nom}}_k = S_k - (s_{k-1} - s_{\min})G_k` (celle du filtre au repos ; lue sous :math:`S_k` déjà
gonflée, la NIS redeviendrait conforme dès l'inflation, qui serait aussitôt retirée, et l'échelle
basculerait sans cesse) : l'adaptation s'enclenche quand la somme des NIS nominales des :math:`W` derniers
pas dépasse le quantile :math:`\chi^2_{\sum m_j}(p)` (``detect``), l'estimation repartant alors des sommes de
cette fenêtre. Avec de l'**hystérésis** : une fois enclenchée, elle ne se relâche que quand l'estimation
elle-même ne demande plus d'inflation (:math:`\hat s_k \le s_{\min}`), pas au premier pas où les innovations,
sous la covariance gonflée, paraissent conformes. Hors adaptation, :math:`s_k = s_{\min}`. Un pas sans mesure
(ou rejeté par la porte) ne change rien. Mesuré (``tests/test_tracking_scenarios.py``) : avec une :math:`Q`
vraie 25 fois celle du modèle, l'échelle trouvée est proche de 25 et le NEES moyen proche de celui du filtre
de la vraie :math:`Q`. Limite : si :math:`Q` est très petite devant :math:`R`, les innovations ne révèlent presque
rien de :math:`Q` ; le test s'enclenche rarement.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np
import scipy.linalg

from ..core.validation import KalmanInputError

__all__ = ["gate_probability", "gate_threshold", "fading_factor", "nis_value", "root_nis", "Adaptation",
           "AdaptiveRun"]


def gate_probability(gate: Any, name: str = "gate") -> float | None:
    """Vérifie une probabilité d'option ``name`` (``gate``, ``detect``, ``release``) : ``None`` ou
    :math:`0 < p < 1`."""
    if gate is None:
        return None
    if isinstance(gate, bool) or not isinstance(gate, (int, float, np.floating, np.integer)) \
            or not 0.0 < float(gate) < 1.0:
        examples = {
            "gate": "0,99 : on garde 99 % des mesures conformes au modèle",
            "detect": "0,99 : l'adaptation s'enclenche quand les innovations ont moins de 1 % de chances d'être "
                      "conformes au modèle",
        }
        hint = examples.get(name, "0,99")
        raise KalmanInputError(
            f"« {name} » doit être une probabilité strictement entre 0 et 1 (par exemple {hint}) ; reçu {gate!r}."
        )
    return float(gate)


@lru_cache(maxsize=256)
def gate_threshold(p: float, m: int) -> float:
    r"""Seuil de la porte : le quantile :math:`\chi^2_m(p)`, :math:`m` composantes observées
    (:math:`2\,\Gamma^{-1}_{\text{inf}}(m/2, p)`, par ``scipy.special.gammaincinv``)."""
    import scipy.special

    return float(2.0 * scipy.special.gammaincinv(0.5 * m, p))


def fading_factor(fading: Any) -> float | None:
    r"""Vérifie l'option ``fading`` : ``None`` (pas d'oubli) ou :math:`\alpha \ge 1` ; renvoie
    :math:`\alpha` (``None`` si :math:`\alpha = 1` ou absent : la prédiction ordinaire)."""
    if fading is None:
        return None
    if isinstance(fading, bool) or not isinstance(fading, (int, float, np.floating, np.integer)) \
            or not np.isfinite(fading) or float(fading) < 1.0:
        raise KalmanInputError(
            f"« fading » doit être un facteur α ≥ 1 (1 : filtre ordinaire ; 1,02 : les mesures perdent "
            f"environ 4 % de poids par pas) ; reçu {fading!r}."
        )
    return None if float(fading) == 1.0 else float(fading)


def nis_value(nu: np.ndarray, S: np.ndarray) -> float:
    r"""NIS :math:`\nu^TS^{-1}\nu` d'une innovation ``nu`` (m,) de covariance ``S`` (m, m), par Cholesky."""
    if S.shape[0] == 1:
        return float(nu[0] * nu[0] / S[0, 0])
    c = scipy.linalg.cho_factor(S, lower=True, check_finite=False)
    return float(nu.dot(scipy.linalg.cho_solve(c, nu, check_finite=False)))


def root_nis(nu: np.ndarray, U_S: np.ndarray) -> float:
    r"""NIS :math:`\lVert U_S^{-T}\nu\rVert^2` d'une innovation ``nu`` (m,) dont la covariance est donnée par
    une racine triangulaire supérieure ``U_S`` (:math:`U_S^TU_S = S`) : une résolution triangulaire."""
    w = scipy.linalg.solve_triangular(U_S, nu, trans="T", lower=False, check_finite=False)
    return float(w.dot(w))


@dataclass(frozen=True)
class Adaptation:
    r"""Réglage de l'adaptation de :math:`Q` (voir le module) : ``window`` :math:`W` (pas de la fenêtre du
    test et constante de temps de l'estimation), ``min_scale`` :math:`s_{\min} > 0` (l'échelle au repos),
    ``detect`` :math:`p` (probabilité du test qui enclenche l'adaptation ; ``None`` : toujours adapter, sans
    test)."""

    window: int = 10
    min_scale: float = 1.0
    detect: float | None = 0.99

    def __post_init__(self) -> None:
        window, s_min = self.window, self.min_scale
        if isinstance(window, bool) or not isinstance(window, (int, np.integer)) or window < 1:
            raise KalmanInputError(f"« window » doit être un entier ≥ 1 (nombre de pas moyennés) ; reçu {window!r}.")
        if isinstance(s_min, bool) or not isinstance(s_min, (int, float, np.floating, np.integer)) \
                or not np.isfinite(s_min) or s_min <= 0:
            raise KalmanInputError(
                f"« min_scale » doit être un nombre > 0 (plus petite échelle de Q) ; reçu {s_min!r}.")
        object.__setattr__(self, "window", int(window))
        object.__setattr__(self, "min_scale", float(s_min))
        object.__setattr__(self, "detect", gate_probability(self.detect, "detect"))

    def start(self) -> "AdaptiveRun":
        """L'état de l'adaptation au début d'un filtrage (une fenêtre vide, l'échelle au repos)."""
        return AdaptiveRun(self)


@dataclass
class AdaptiveRun:
    r"""L'adaptation pendant un filtrage : l'échelle :math:`s` en cours, l'état du test (``active``), la
    fenêtre des :math:`W` dernières NIS nominales (et de leurs :math:`d_j`, :math:`\operatorname{tr}G_j`,
    :math:`m_j`) et les sommes à mémoire exponentielle :math:`D_k`, :math:`\Gamma_k` de l'estimation. Le
    moteur appelle :meth:`observe` après chaque correction acceptée."""

    rule: Adaptation
    scale: float = field(init=False)
    active: bool = field(init=False, default=False)
    window: list = field(init=False, default_factory=list)
    D: float = field(init=False, default=0.0)
    Gamma: float = field(init=False, default=0.0)

    def __post_init__(self) -> None:
        self.scale = self.rule.min_scale

    def observe(self, nu: np.ndarray, S: np.ndarray, G: np.ndarray) -> float:
        r"""Une correction : innovation ``nu`` (m,), sa covariance ``S`` (m, m) sous l'échelle en cours et
        l'image ``G`` (m, m) de :math:`Q` dans la mesure ; renvoie l'échelle :math:`s_k` du pas suivant."""
        rule, s, s_min = self.rule, self.scale, self.rule.min_scale
        g = float(np.trace(G))
        d = float(nu.dot(nu) - np.trace(S)) + s * g
        self.window = (self.window + [(d, g, nis_value(nu, S - (s - s_min) * G), len(nu))])[-rule.window:]
        forget = 1.0 - 1.0 / rule.window
        self.D, self.Gamma = forget * self.D + d, forget * self.Gamma + g
        if not self.active:
            if rule.detect is None:
                self.active = True
            else:
                _, _, nis, dof = (sum(col) for col in zip(*self.window))
                self.active = nis > gate_threshold(rule.detect, dof)
            if self.active:  # l'estimation repart de la fenêtre du test
                self.D, self.Gamma = (sum(col) for col in list(zip(*self.window))[:2])
        if self.active:
            ratio = self.D / self.Gamma if self.Gamma > 0 else s
            # hystérésis : l'adaptation ne se relâche que quand l'estimation ne demande plus d'inflation
            self.active = rule.detect is None or ratio > s_min
            self.scale = max(s_min, ratio)
        else:
            self.scale = s_min
        return self.scale
