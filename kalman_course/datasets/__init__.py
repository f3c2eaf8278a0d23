"""Données réelles du cours (chargées à la demande : ``import kalman_course`` n'importe pas statsmodels).

- :func:`nile` : débit annuel du Nil à Assouan, 1871–1970 (Durbin & Koopman), avec sa version à
  années manquantes.
"""

from .nile import NILE_MISSING_YEARS, AnnualSeries, nile

__all__ = ["AnnualSeries", "NILE_MISSING_YEARS", "nile"]
