"""Temps CPU par cycle (µs) des filtres d'ensemble sur Lorenz-96, mesurés par
benchmarks/assimilation_costs.py --write : CYCLE[« méthode, n, N »] = (paquet, boucle numpy sur les
membres ou les composantes) pour la prévision RK4 plus l'analyse ; FILTER : le filtre complet
(ensemble_kalman_filter). Le chapitre les cite ; le livre ne chronomètre rien."""

DATE = '2026-11-28'
MACHINE = 'AMD EPYC, 2 cœurs, Linux x86_64'
SOFTWARE = 'Python 3.11.7, numpy 2.4.6'
CYCLE = {
    'EnKF stochastique, n = 40, N = 20': (124.2, 741.6),
    'ETKF, n = 40, N = 20': (159.1, 720.9),
    'DEnKF, n = 40, N = 20': (108.9, 719.9),
    'LETKF (rayon 4), n = 40, N = 20': (1588.8, 3940.8),
    'EnKF stochastique, n = 40, N = 40': (144.6, 1416.6),
    'ETKF, n = 40, N = 40': (287.3, 1467.4),
    'DEnKF, n = 40, N = 40': (126.4, 1372.4),
    'LETKF (rayon 4), n = 40, N = 40': (3264.4, 8378.6),
    'ETKF, n = 400, N = 20': (540.1, 1299.8),
    'LETKF (rayon 4), n = 400, N = 20': (16603.3, 40635.7),
}
FILTER = {
    'EnKF stochastique, n = 40, N = 40': 320.3,
    'ETKF, n = 40, N = 20': 378.2,
    'DEnKF, n = 40, N = 40': 290.1,
    'LETKF (rayon 4), n = 40, N = 7': 690.6,
    'LETKF (rayon 4), n = 400, N = 20': 40614.7,
}
