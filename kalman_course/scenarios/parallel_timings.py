"""Temps CPU mesurés par benchmarks/parallel.py --write (secondes, meilleur de plusieurs essais) : la
figure du chapitre « Filtrer en parallèle dans le temps » les lit ; le livre ne chronomètre rien."""

DATE = '2026-11-28'
MACHINE = 'AMD EPYC, 2 cœurs, Linux x86_64'
SOFTWARE = 'Python 3.11.7, numpy 2.4.6'
T = (1000, 3000, 10000, 30000, 100000)
SEQUENTIAL = (0.02192, 0.07111, 0.21792, 0.6706, 2.65055)
PARALLEL = (0.00658, 0.01217, 0.02702, 0.0735, 0.3882)
SEQUENTIAL_SMOOTHER = (0.03564, 0.11258, 0.34762, 1.07144, 3.98227)
PARALLEL_SMOOTHER = (0.011, 0.02317, 0.0582, 0.16812, 0.75169)
