"""Temps CPU mesurés par benchmarks/parallel.py --write (secondes, meilleur de plusieurs essais) : la
figure du chapitre « Filtrer en parallèle dans le temps » les lit ; le livre ne chronomètre rien."""

DATE = '2026-11-25'
MACHINE = 'AMD EPYC, 2 cœurs, Linux x86_64'
SOFTWARE = 'Python 3.11.2, numpy 2.4.6'
T = (1000, 3000, 10000, 30000, 100000)
SEQUENTIAL = (0.04308, 0.13068, 0.44171, 1.318, 4.396)
PARALLEL = (0.01138, 0.0262, 0.08176, 0.2271, 0.87042)
SEQUENTIAL_SMOOTHER = (0.06552, 0.19508, 0.6336, 1.94034, 6.44893)
PARALLEL_SMOOTHER = (0.01638, 0.04202, 0.11754, 0.33884, 1.21149)
