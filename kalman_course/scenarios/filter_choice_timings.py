"""Temps CPU par pas (µs) mesurés par benchmarks/filter_choice.py --write sur la cible lointaine : le
tableau du chapitre « Quel filtre choisir ? » les cite ; le livre ne chronomètre rien."""

DATE = '2026-11-25'
MACHINE = 'AMD EPYC, 2 cœurs, Linux x86_64'
SOFTWARE = 'Python 3.11.2, numpy 2.4.6'
MICROSECONDS_PER_STEP = {
    'EKF': 129.5,
    'EKF itéré': 523.3,
    'UKF': 389.2,
    'CKF': 384.0,
    'GHKF': 384.1,
    'filtre particulaire': 1205.7,
    'EnKF': 452.1,
}
