r"""Le débit annuel du Nil à Assouan, 1871–1970 : la série de Durbin & Koopman (2012, § 2.2).

Cent valeurs annuelles du volume écoulé, en :math:`10^8` m³, lues dans les jeux de données de
statsmodels (``statsmodels.datasets.nile``, donc sans téléchargement). La série montre une baisse
nette de niveau vers 1899 (Cobb 1978), souvent attribuée à la mise en service du premier barrage
d'Assouan (1902) et à un changement de régime des crues ; c'est l'exemple classique du modèle à niveau
local.

Durbin & Koopman (2012, § 2.7) traitent aussi une version à données manquantes : les observations
:math:`t = 21, \dots, 40` et :math:`t = 61, \dots, 80` (années 1891–1910 et 1931–1950) sont retirées,
pour montrer que le filtre et le lisseur les traversent sans rien changer à leurs formules.
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..core.results import freeze
from ..core.validation import KalmanInputError

__all__ = ["AnnualSeries", "NILE_MISSING_YEARS", "nile"]

#: Années retirées dans la version à données manquantes de Durbin & Koopman (bornes incluses).
NILE_MISSING_YEARS = ((1891, 1910), (1931, 1950))


@dataclass(frozen=True, eq=False)
class AnnualSeries:
    """Une série annuelle : ``year`` (T,) entiers, ``flow`` (T,) valeurs (NaN : année manquante),
    ``unit`` (unité de ``flow``), ``name`` et ``source`` (pour les légendes et les références)."""

    year: np.ndarray
    flow: np.ndarray
    unit: str
    name: str
    source: str

    def __post_init__(self) -> None:
        year = np.array(self.year, dtype=int, copy=True)
        year.setflags(write=False)
        object.__setattr__(self, "year", year)
        object.__setattr__(self, "flow", freeze(self.flow))

    @property
    def missing(self) -> np.ndarray:
        """Masque (T,) des années manquantes."""
        return np.isnan(self.flow)

    def __len__(self) -> int:
        return int(self.year.size)

    def __repr__(self) -> str:
        return (f"<{self.name} : {self.year[0]}–{self.year[-1]}, {len(self)} valeurs en {self.unit}, "
                f"{int(self.missing.sum())} manquantes>")


def _csv_path() -> Path | None:
    """Le fichier ``nile.csv`` livré avec statsmodels, trouvé sans importer statsmodels (ni pandas)."""
    spec = importlib.util.find_spec("statsmodels")  # ne fait que chercher le paquet, sans l'exécuter
    if spec is None or not spec.submodule_search_locations:
        return None
    path = Path(next(iter(spec.submodule_search_locations))) / "datasets" / "nile" / "nile.csv"
    return path if path.is_file() else None


@lru_cache(maxsize=1)
def _load() -> tuple[np.ndarray, np.ndarray]:
    r"""Années et débits. Le fichier de statsmodels (colonnes ``year,volume``) est lu directement : importer
    ``statsmodels.datasets`` chargerait pandas et statsmodels (≈ 0,4 s) pour cent nombres. Si le fichier
    n'est pas à sa place, on passe par ``statsmodels.datasets.nile.load()``."""
    path = _csv_path()
    if path is not None:
        with open(path, encoding="utf-8") as handle:
            header = handle.readline().strip().split(",")
            table = np.loadtxt(handle, delimiter=",", dtype=float, ndmin=2)
        if header[:2] != ["year", "volume"]:
            raise RuntimeError(f"{path} n'a pas les colonnes attendues (year, volume) : {header}.")
        year, flow = table[:, 0], table[:, 1]
    else:
        from statsmodels.datasets import nile as sm_nile  # importé ici : statsmodels ne charge qu'à l'usage

        data = sm_nile.load().data
        year = np.asarray(data["year"], dtype=float)
        flow = np.asarray(data["volume"], dtype=float)
    if year.shape != (100,) or not np.array_equal(year, np.arange(1871, 1971)):
        raise RuntimeError("Les données du Nil de statsmodels n'ont pas la forme attendue (1871–1970).")
    return year.astype(int), flow


def nile(missing: bool = False) -> AnnualSeries:
    r"""Débit annuel du Nil à Assouan, 1871–1970, en :math:`10^8` m³ (100 valeurs).

    ``missing=True`` : la version de Durbin & Koopman (2012, § 2.7), années 1891–1910 et 1931–1950
    remplacées par NaN (:data:`NILE_MISSING_YEARS`).
    """
    if not isinstance(missing, (bool, np.bool_)):
        raise KalmanInputError(f"« missing » doit être un booléen (True ou False) ; reçu {missing!r}.")
    year, flow = _load()
    flow = flow.copy()
    name = "Débit du Nil à Assouan"
    if missing:
        for first, last in NILE_MISSING_YEARS:
            flow[(year >= first) & (year <= last)] = np.nan
        name += " (années manquantes de Durbin & Koopman)"
    return AnnualSeries(year=year, flow=flow, unit="10⁸ m³", name=name,
                        source="statsmodels.datasets.nile (Durbin & Koopman 2012 ; Cobb 1978)")
