"""Coût par cycle et par membre des filtres d'ensemble de l'assimilation de données sur Lorenz-96, contre une
boucle numpy sur les membres (et, pour le LETKF, sur les composantes).

Usage : .venv/bin/python benchmarks/assimilation_costs.py [--repeat 5] [--write]

Un cycle = la prévision de l'ensemble (un pas RK4 de 0,05) + l'analyse d'une observation de toutes les
variables (R = I). Deux écritures du même calcul :

* **paquet** : la prévision de tout l'ensemble en un appel (``lorenz96(n).f`` vectorisé, (N, n)) et l'analyse
  d'un cycle du filtre (``ensemble_family`` : ``etkf_analysis``, ``denkf_analysis``, ``letkf_analysis`` — les
  n analyses locales en lot, un seul ``eigh`` sur une pile de matrices —, et l'analyse stochastique), avec
  R^{-1/2} et les poids de Gaspari–Cohn calculés une fois ; la dernière colonne donne aussi le coût des
  fonctions publiques (``kc.etkf_update``…), qui vérifient leurs entrées à chaque appel ;
* **boucle** : le même RK4 membre par membre, et l'analyse écrite avec une boucle Python sur les membres (gain
  ou transformée calculés une fois) — pour le LETKF, une boucle sur les n composantes, une analyse ETKF
  locale (``eigh`` N × N) par composante.

Pour n = 40 : N = 20 et 40, les quatre méthodes ; pour n = 400 (un anneau dix fois plus long, mêmes
équations) : N = 20, le LETKF (rayon 4) seulement — les analyses globales y divergent avec N ≪ n, c'est la
raison d'être de la localisation — et l'ETKF global pour comparer le coût. Le filtre complet
(``kc.ensemble_kalman_filter``, 200 cycles pour n = 40, 20 pour n = 400) ajoute le moteur : résultat empilé
(x, P, K, S à chaque cycle : pour n = 400, 5 Mo par cycle).

Imprime le temps CPU (meilleur de --repeat essais) par cycle et par membre, et le rapport boucle / paquet.
Les deux écritures donnent le même ensemble (vérifié à 10⁻⁹ près avant de chronométrer). --write réécrit
kalman_course/scenarios/assimilation_costs.py (la mesure datée que cite le chapitre).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import kalman_course as kc
from kalman_course.core.lorenz import lorenz96_tendency, rk4
from kalman_course.filters.ensemble_analysis import (
    denkf_analysis,
    ensemble_gain,
    etkf_analysis,
    letkf_analysis,
    symmetric_inverse_root,
)
from kalman_course.numbers import format_spec
from kalman_course.scenarios.assimilation import attractor_start, ring_distances
from _timing import best_time, write_measurement

OUTPUT = Path(__file__).resolve().parent.parent / "kalman_course" / "scenarios" / "assimilation_costs.py"
RADIUS, INFLATION = 4.0, 1.04


# --------------------------------------------------------------------------- boucles numpy sur les membres


def loop_forecast(E, dt=0.05):
    return np.array([rk4(lorenz96_tendency, e, dt, 1) for e in E])


def loop_stochastic(E, y, R, V):
    N = E.shape[0]
    x = E.mean(axis=0)
    A, Y = E - x, E - x  # h(x) = x
    S = Y.T @ Y / (N - 1) + R
    K = np.linalg.solve(S, (A.T @ Y / (N - 1)).T).T
    out = np.empty_like(E)
    for i in range(N):
        out[i] = E[i] + K @ (y + V[i] - E[i])
    xa = out.mean(axis=0)
    for i in range(N):
        out[i] = xa + INFLATION * (out[i] - xa)
    return out


def loop_etkf(E, y, Ri):
    N = E.shape[0]
    x = E.mean(axis=0)
    A = E - x
    s, V = np.linalg.eigh(A @ Ri @ A.T + (N - 1) * np.eye(N))
    T = V @ np.diag(np.sqrt((N - 1) / s)) @ V.T
    xa = x + A.T @ (V @ np.diag(1 / s) @ V.T @ A @ Ri @ (y - x))
    out = np.empty_like(E)
    for i in range(N):
        out[i] = xa + INFLATION * (T[i] @ A)
    return out


def loop_denkf(E, y, R):
    N = E.shape[0]
    x = E.mean(axis=0)
    A = E - x
    K = np.linalg.solve(A.T @ A / (N - 1) + R, A.T @ A / (N - 1)).T
    xa = x + K @ (y - x)
    out = np.empty_like(E)
    for i in range(N):
        out[i] = xa + INFLATION * (A[i] - 0.5 * K @ A[i])
    return out


def loop_letkf(E, y, W, rho):
    N, n = E.shape
    x = E.mean(axis=0)
    A = E - x
    Yt, dt = A @ W, W @ (y - x)
    out = np.empty_like(E)
    for j in range(n):  # une analyse ETKF locale par composante
        sq = np.sqrt(rho[:, j])
        Yj, dj = Yt * sq, dt * sq
        s, V = np.linalg.eigh(Yj @ Yj.T)
        s = np.clip(s, 0, None) + N - 1
        w = V @ ((V.T @ (Yj @ dj)) / s)
        Tj = V @ np.diag(np.sqrt((N - 1) / s)) @ V.T
        out[:, j] = x[j] + A[:, j] @ w + INFLATION * Tj @ A[:, j]
    return out


# --------------------------------------------------------------------------- mesures


def ensemble_on_attractor(n, N, seed=0):
    """Un ensemble de N membres autour d'un état de l'anneau de n variables, prévu 20 cycles (anomalies
    dépendantes de l'écoulement, comme dans un cycle d'assimilation)."""
    rng = np.random.default_rng(seed)
    start = np.resize(attractor_start(), n) if n != 40 else np.asarray(attractor_start())
    model = kc.lorenz96(n)
    E = start + rng.standard_normal((N, n))
    for _ in range(20):
        E = model.f(E, None)
    y = E.mean(axis=0) + rng.standard_normal(n)
    return model, E, y


def measure(n, N, methods, repeat):
    model, E, y = ensemble_on_attractor(n, N)
    R = np.eye(n)
    D = ring_distances(n)
    rho = kc.gaspari_cohn(D, RADIUS)
    V = np.random.default_rng(1).standard_normal((N, n))
    LR = np.linalg.cholesky(R)

    def stochastic(E):  # l'analyse stochastique de ensemble_kalman_filter, perturbations V données
        x = E.mean(axis=0)
        A = E - x
        K = ensemble_gain(A, A, R)[0]
        X = E + (y + V @ LR.T - E) @ K.T
        xa = X.mean(axis=0)
        return xa + INFLATION * (X - xa)

    W, Ri = symmetric_inverse_root(R), np.linalg.inv(R)

    def moments(E):
        x = E.mean(axis=0)
        A = E - x
        return x, A, A, y - x  # h(x) = x : Y = A

    def denkf(E):
        x, A, Y, d = moments(E)
        return denkf_analysis(x, A, Y, d, R, INFLATION, K=ensemble_gain(A, Y, R)[0])

    # le calcul d'un cycle du filtre (ensemble_family) : R^{-1/2} et ρ calculés une fois, avant le premier cycle
    package = {
        "EnKF stochastique": stochastic,
        "ETKF": lambda E: etkf_analysis(*moments(E), R, INFLATION, W=W),
        "DEnKF": denkf,
        "LETKF (rayon 4)": lambda E: letkf_analysis(*moments(E), R, rho, INFLATION, W=W),
    }
    public = {  # les fonctions publiques, qui vérifient leurs entrées (et calculent ρ) à chaque appel
        "ETKF": lambda E: kc.etkf_update(E, y, np.eye(n), R, inflation=INFLATION),
        "DEnKF": lambda E: kc.denkf_update(E, y, np.eye(n), R, inflation=INFLATION),
        "LETKF (rayon 4)": lambda E: kc.letkf_update(E, y, np.eye(n), R, D, radius=RADIUS, inflation=INFLATION),
    }
    loops = {
        "EnKF stochastique": lambda E: loop_stochastic(E, y, R, V),
        "ETKF": lambda E: loop_etkf(E, y, Ri),
        "DEnKF": lambda E: loop_denkf(E, y, R),
        "LETKF (rayon 4)": lambda E: loop_letkf(E, y, W, rho),
    }
    np.testing.assert_allclose(model.f(E, None), loop_forecast(E), atol=1e-12)
    out = {}
    t_forecast = best_time(lambda: model.f(E, None), repeat, time.process_time)[0]
    t_forecast_loop = best_time(lambda: loop_forecast(E), repeat, time.process_time)[0]
    for name in methods:
        np.testing.assert_allclose(package[name](E), loops[name](E), atol=1e-9, err_msg=name)
        if name in public:
            np.testing.assert_allclose(public[name](E), package[name](E), atol=1e-9, err_msg=name)
        t_pkg = best_time(lambda: package[name](E), repeat, time.process_time)[0] + t_forecast
        t_loop = best_time(lambda: loops[name](E), repeat, time.process_time)[0] + t_forecast_loop
        t_pub = (best_time(lambda: public[name](E), repeat, time.process_time)[0] + t_forecast
                 if name in public else float("nan"))
        out[name] = (t_pkg * 1e6, t_loop * 1e6, t_pub * 1e6)
    return out


def full_filter(n, N, method, cycles, repeat, **kwargs):
    """Temps CPU par cycle de kc.ensemble_kalman_filter (prévision, analyse, moteur, résultat empilé)."""
    start = np.resize(attractor_start(), n)
    model = kc.lorenz96(n)
    sim = kc.simulate(model, start, cycles, rng=0)
    t = best_time(lambda: kc.ensemble_kalman_filter(model, sim.y, start, np.eye(n), n_members=N, rng=1,
                                                    method=method, inflation=INFLATION, **kwargs),
                  repeat, time.process_time)[0]
    return t / cycles * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="nombre d'essais (on garde le meilleur)")
    parser.add_argument("--write", action="store_true", help="réécrire kalman_course/scenarios/assimilation_costs.py")
    args = parser.parse_args()
    all_methods = ("EnKF stochastique", "ETKF", "DEnKF", "LETKF (rayon 4)")
    table, calls = {}, {}
    for n, N, methods in ((40, 20, all_methods), (40, 40, all_methods), (400, 20, ("ETKF", "LETKF (rayon 4)"))):
        for name, (pkg, loop, pub) in measure(n, N, methods, args.repeat).items():
            table[f"{name}, n = {n}, N = {N}"] = (round(pkg, 1), round(loop, 1))
            calls[f"{name}, n = {n}, N = {N}"] = pub
    print("Temps CPU par cycle (prévision RK4 + analyse), meilleur de", args.repeat, "essais")
    print(f"{'méthode':36s} {'paquet (µs)':>12s} {'par membre':>11s} {'boucle (µs)':>12s} {'boucle / paquet':>16s}"
          f" {'fonction publique (µs)':>23s}")
    for key, (pkg, loop) in table.items():
        N = int(key.rsplit("N = ", 1)[1])
        pub = calls[key]
        print(f"{key:36s} {format_spec(pkg, '.0f'):>12s} {format_spec(pkg / N, '.1f'):>11s} "
              f"{format_spec(loop, '.0f'):>12s} {format_spec(loop / pkg, '.1f'):>15s}× "
              f"{'—' if np.isnan(pub) else format_spec(pub, '.0f'):>23s}")
    filters = {
        "EnKF stochastique, n = 40, N = 40": full_filter(40, 40, "stochastic", 200, args.repeat),
        "ETKF, n = 40, N = 20": full_filter(40, 20, "etkf", 200, args.repeat),
        "DEnKF, n = 40, N = 40": full_filter(40, 40, "denkf", 200, args.repeat),
        "LETKF (rayon 4), n = 40, N = 7": full_filter(40, 7, "etkf", 200, args.repeat, localization=RADIUS,
                                                      distances=ring_distances(40)),
        "LETKF (rayon 4), n = 400, N = 20": full_filter(400, 20, "etkf", 20, max(1, args.repeat // 2),
                                                        localization=RADIUS, distances=ring_distances(400)),
    }
    print("\nFiltre complet (kc.ensemble_kalman_filter) : temps CPU par cycle")
    for key, us in filters.items():
        print(f"{key:36s} {format_spec(us, '.0f'):>12s} µs")
    if args.write:
        write_measurement(
            OUTPUT,
            "Temps CPU par cycle (µs) des filtres d'ensemble sur Lorenz-96, mesurés par\n"
            "benchmarks/assimilation_costs.py --write : CYCLE[« méthode, n, N »] = (paquet, boucle numpy sur les\n"
            "membres ou les composantes) pour la prévision RK4 plus l'analyse ; FILTER : le filtre complet\n"
            "(ensemble_kalman_filter). Le chapitre les cite ; le livre ne chronomètre rien.",
            {"CYCLE": table, "FILTER": {k: round(v, 1) for k, v in filters.items()}},
        )


if __name__ == "__main__":
    main()
