"""Filtre particulaire du paquet contre une boucle « bootstrap » numpy écrite à la main (même modèle, mêmes
mesures, même nombre de particules, même rééchantillonnage systématique au seuil ESS < N/2).

Usage : .venv/bin/python benchmarks/particle_filter.py [--repeat 5]
Cibles (issue « UKF et filtre particulaire ») :
  - particle_filter au plus 3 × le temps de la boucle numpy nue ;
  - 10 000 particules × 100 pas du pendule (modèle vectorisé) bien en dessous d'une seconde.
Imprime les temps (meilleur de --repeat essais), le rapport, et l'écart des estimations (les deux filtres
tirent des nombres différents : l'écart est de l'ordre de l'erreur de Monte-Carlo, pas nul).
Aussi : l'UKF du paquet contre celui de filterpy sur le pendule (temps par pas).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import kalman_course as kc
from kalman_course.numbers import format_spec
from kalman_course.scenarios import pendulum
from _timing import best_time

TARGET_RATIO = 3.0
TARGET_SECONDS = 1.0


def plain_bootstrap(y, x0, P0, N, seed, dt=pendulum.PENDULUM_DT, g=pendulum.PENDULUM_G_OVER_L,
                    qc=pendulum.PENDULUM_QC, r=pendulum.PENDULUM_R_STD):
    """Le filtre bootstrap le plus direct en numpy : pas de vérification, pas de résultat empilé."""
    rng = np.random.default_rng(seed)
    Q = qc * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
    LQ = np.linalg.cholesky(Q)
    X = x0 + rng.standard_normal((N, 2)) @ np.linalg.cholesky(P0).T
    logw = np.full(N, -np.log(N))
    w = np.full(N, 1.0 / N)
    means, covs = np.empty((len(y), 2)), np.empty((len(y), 2, 2))
    for k in range(len(y)):
        if 1.0 / np.dot(w, w) < 0.5 * N:
            c = np.cumsum(w)
            c[-1] = 1.0
            X = X[np.searchsorted(c, (rng.random() + np.arange(N)) / N, side="right")]
            logw = np.full(N, -np.log(N))
        th, om = X[:, 0], X[:, 1]
        X = np.stack([th + om * dt, om - g * np.sin(th) * dt], axis=1) + rng.standard_normal((N, 2)) @ LQ.T
        logw = logw - 0.5 * ((y[k, 0] - np.sin(X[:, 0])) / r) ** 2
        top = logw.max()
        logw -= top + np.log(np.exp(logw - top).sum())
        w = np.exp(logw)
        m = w @ X
        D = X - m
        means[k], covs[k] = m, D.T @ (w[:, None] * D)
    return means, covs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()

    data = pendulum.pendulum_data(100)
    model = pendulum.pendulum_model()
    N = 10_000
    t_pkg, res = best_time(lambda: kc.particle_filter(model, data.y, data.x0, data.P0, n_particles=N, rng=1),
                           args.repeat)
    t_np, (m_np, _) = best_time(lambda: plain_bootstrap(data.y, data.x0, data.P0, N, 1), args.repeat)
    ratio = t_pkg / t_np
    gap = np.abs(res.x - m_np).max()
    ok1 = "OK" if ratio <= TARGET_RATIO else "AU-DESSUS DE LA CIBLE"
    ok2 = "OK" if t_pkg < TARGET_SECONDS else "AU-DESSUS DE LA CIBLE"
    print(f"pendule, {format_spec(N, 'd')} particules × {format_spec(len(data.y), 'd')} pas (modèle vectorisé) :")
    print(f"  particle_filter            {format_spec(t_pkg, '.3f'):>7s} s   "
          f"(cible < {format_spec(TARGET_SECONDS, 'g')} s)  {ok2}")
    print(f"  boucle numpy nue           {format_spec(t_np, '.3f'):>7s} s")
    print(f"  rapport                    {format_spec(ratio, '.2f'):>7s}     "
          f"(cible ≤ {format_spec(TARGET_RATIO, 'g')})  {ok1}")
    print(f"  |écart des moyennes| max   {format_spec(gap, '.2e')} rad (erreur de Monte-Carlo, tirages différents)")

    slow = pendulum.pendulum_model(vectorized=False)
    n_slow = 1000
    t_slow, _ = best_time(lambda: kc.particle_filter(slow, data.y, data.x0, data.P0, n_particles=n_slow, rng=1), 1)
    t_fast, _ = best_time(lambda: kc.particle_filter(model, data.y, data.x0, data.P0, n_particles=n_slow, rng=1),
                          args.repeat)
    print(f"  {format_spec(n_slow, 'd')} particules, modèle non vectorisé : {format_spec(t_slow, '.3f')} s ; "
          f"vectorisé : {format_spec(t_fast, '.3f')} s (gain {format_spec(t_slow / t_fast, '.0f')} ×)")

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    from reference_ukf import filterpy_unscented_filter

    long = pendulum.pendulum_data(500)
    t_ukf, _ = best_time(lambda: kc.unscented_kalman_filter(model, long.y, long.x0, long.P0, alpha=1.0, kappa=0.0),
                         args.repeat)
    t_fp, _ = best_time(lambda: filterpy_unscented_filter(model, long.y, long.x0, long.P0, alpha=1.0, kappa=0.0),
                        args.repeat)
    T = len(long.y)
    print(f"UKF, pendule, {format_spec(T, 'd')} pas : paquet {format_spec(t_ukf / T * 1e6, '.1f'):>6s} µs/pas, "
          f"filterpy {format_spec(t_fp / T * 1e6, '.1f'):>6s} µs/pas (rapport {format_spec(t_ukf / t_fp, '.2f')})")
    t_enkf, _ = best_time(lambda: kc.ensemble_kalman_filter(model, long.y, long.x0, long.P0, n_members=1000, rng=1),
                          args.repeat)
    print(f"EnKF, pendule, {format_spec(1000, 'd')} membres × {format_spec(T, 'd')} pas : "
          f"{format_spec(t_enkf, '.3f')} s")


if __name__ == "__main__":
    main()
