"""Données réelles du cours (chargées à la demande : ``import kalman_course`` n'importe pas statsmodels).

- :func:`nile` : débit annuel du Nil à Assouan, 1871–1970 (Durbin & Koopman), avec sa version à
  années manquantes ;
- :func:`samu31`, :func:`calibration_toulouse` : deux vols ADS-B au-dessus de Toulouse (The OpenSky
  Network, exemples de la bibliothèque traffic), extrait livré avec le paquet et sa provenance ;
- :func:`toulouse_traffic` : cinq vols autour de Toulouse-Blagnac rejoués sur une horloge commune (mêmes
  exemples, partie « Plusieurs cibles »).
"""

from .adsb import Flight, Traffic, calibration_toulouse, samu31, toulouse_traffic
from .nile import NILE_MISSING_YEARS, AnnualSeries, nile

__all__ = ["AnnualSeries", "Flight", "NILE_MISSING_YEARS", "Traffic", "calibration_toulouse", "nile", "samu31",
           "toulouse_traffic"]
