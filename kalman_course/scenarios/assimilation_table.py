"""Le tableau de DAPPER reproduit, mesuré par benchmarks/assimilation_table.py --write : pour chaque ligne de
kalman_course.scenarios.assimilation.DAPPER_TABLE (même ordre), rmse.a moyen (MEAN) et écart-type entre
graines (STD) sur N_SEEDS graines (0, 1, …) de N_CYCLES cycles, valeur de la graine 0 (SEED0), temps CPU
par expérience (SECONDS). Les chapitres citent ces nombres ; les tests relancent la graine 0 de quatre
lignes et vérifient qu'elle redonne SEED0."""

DATE = '2026-11-28'
MACHINE = 'AMD EPYC, 2 cœurs, Linux x86_64'
SOFTWARE = 'Python 3.11.7, numpy 2.4.6'
N_CYCLES = 1000
N_SEEDS = 8
MEAN = (0.22062, 0.1782, 0.18069, 0.20066, 0.21414, 1.04373, 1.24917, 0.23824, 0.43934, 0.93696, 0.73251)
STD = (0.00494, 0.00429, 0.00617, 0.00348, 0.0044, 0.02863, 0.01141, 0.00842, 0.01342, 0.00365, 0.14715)
SEED0 = (0.21963033340521415, 0.17866127188130254, 0.18341640885251947, 0.20102544856148427, 0.21286359339144476, 1.0231321578828112, 1.248031330765194, 0.23274543893486077, 0.42370447851994686, 0.9383950197201267, 0.578973894765262)
SECONDS = (0.551, 0.459, 0.605, 0.762, 1.098, 0.133, 0.086, 0.606, 0.299, 0.222, 1.738)
