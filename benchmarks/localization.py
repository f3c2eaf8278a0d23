"""Filtrage invariant sur SE(2) : coût par pas et banc d'essai de localisation de ukfm (issue 35).

Usage : .venv/bin/python benchmarks/localization.py [--runs 100] [--repeat 3] [--write]

1. Coût par pas (temps CPU, meilleur de --repeat essais) d'un tirage de 3 999 pas : EKF invariant, EKF
   standard, et le filtre de Kalman étendu générique du paquet (``kc.extended_kalman_filter``) sur le même
   robot écrit comme un ``NonlinearModel`` (jacobiennes analytiques) ; puis le coût par tirage et par pas des
   filtres en lot (``se2_*_ekf_runs``). Cible : au plus 0,1 s de CPU par tirage de 3 999 pas.
2. Le tableau du banc d'essai sur --runs tirages (graine SEED), à côté de celui qu'imprime ukfm
   (``python/benchmarks/localization.py``), dont la NEES de l'EKF invariant (2,02) vient d'une matrice G
   qui range [v_x, v_y, ω] dans le mauvais ordre (voir le chapitre « Filtrage invariant sur les groupes de Lie »).

--write réécrit kalman_course/scenarios/robot_localization_results.py : le tableau (avec l'EKF invariant muni
du G de ukfm, qui reproduit sa NEES), les courbes moyennes (un point par 0,2 s) et les temps par pas que cite
le chapitre, qui ne recalcule pas les 100 tirages.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import kalman_course as kc
from kalman_course.numbers import format_spec
from kalman_course.scenarios import robot_localization as rl
from _timing import best_time, machine, software, write_measurement

OUTPUT = Path(__file__).resolve().parent.parent / "kalman_course" / "scenarios" / "robot_localization_results.py"
SEED = 35
#: Courbes écrites : un point toutes les EVERY lignes (0,2 s).
EVERY = 20
#: Courbes gardées pour chaque filtre (l'EKF invariant avec le G de ukfm : ses NEES seulement).
KEPT = {"invariant": rl._CURVE_NAMES, "standard": rl._CURVE_NAMES,
        "invariant_ukfm": ("position_nees", "heading_nees")}


def _rot(a):
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


def generic_ekf_model(model: kc.OdometryGnssModel) -> kc.NonlinearModel:
    """Le même robot pour ``kc.extended_kalman_filter`` : x = [p ; θ], f(x, u) = [p + R(θ) v dt ; θ + ω dt],
    W = dt diag(R(θ), 1), h(x) = p."""
    dt = model.dt
    J = np.array([[0.0, -1.0], [1.0, 0.0]])

    def f(x, u):
        return np.r_[x[:2] + _rot(x[2]) @ u[:2] * dt, x[2] + u[2] * dt]

    def F(x, u):
        M = np.eye(3)
        M[:2, 2] = _rot(x[2]) @ J @ u[:2] * dt
        return M

    def W(x, u):
        M = dt * np.eye(3)
        M[:2, :2] = dt * _rot(x[2])
        return M

    return kc.NonlinearModel(f, lambda x: x[:2], model.Q, model.R, F, np.hstack([np.eye(2), np.zeros((2, 1))]),
                             f_noise_jacobian=W, n_state=3, n_control=3)


def step_costs(repeat: int) -> dict[str, float]:
    """µs de CPU par pas d'un tirage (et par tirage et par pas pour les lots de 50)."""
    data = rl.localization_data(50, rng=SEED)
    y, u, T0, P0, model = data.y[0], data.u[0], data.T0[0], data.P0, data.model
    K = y.shape[0]
    x0 = np.r_[T0[:2, 2], np.arctan2(T0[1, 0], T0[0, 0])]
    generic = generic_ekf_model(model)
    single = {
        "EKF invariant": lambda: kc.se2_invariant_ekf(model, y, T0, P0, u),
        "EKF standard": lambda: kc.se2_standard_ekf(model, y, T0, P0, u),
        "extended_kalman_filter": lambda: kc.extended_kalman_filter(generic, y, x0, P0, u),
    }
    out = {name: best_time(func, repeat, time.process_time)[0] / K * 1e6 for name, func in single.items()}
    batch = {
        "EKF invariant en lot": lambda: kc.se2_invariant_ekf_runs(model, data.y, data.T0, P0, data.u),
        "EKF standard en lot": lambda: kc.se2_standard_ekf_runs(model, data.y, data.T0, P0, data.u),
    }
    for name, func in batch.items():
        out[f"{name} (par tirage)"] = best_time(func, repeat, time.process_time)[0] / (K * data.y.shape[0]) * 1e6
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=100, help="tirages du banc d'essai (100 comme ukfm)")
    parser.add_argument("--repeat", type=int, default=3, help="essais chronométrés (on garde le meilleur)")
    parser.add_argument("--write", action="store_true", help=f"réécrire {OUTPUT.name}")
    args = parser.parse_args()

    print(f"Machine : {machine()} ; {software()}")
    us = step_costs(args.repeat)
    ekf = us["extended_kalman_filter"]
    print(f"\nCoût par pas (CPU, meilleur de {args.repeat}, tirage de {rl.N_INSTANTS - 1} pas) :")
    for name, value in us.items():
        run = value * (rl.N_INSTANTS - 1) / 1e6
        print(f"  {name:34s} {format_spec(value, '.1f'):>7s} µs/pas  {format_spec(value / ekf, '.2f'):>6s} × EKF générique"
              f"  ({format_spec(run, '.3f')} s par tirage ; cible ≤ 0,1 s)")

    t0 = time.process_time()
    curves = rl.localization_curves(args.runs, rng=SEED, ukfm_g=True)
    seconds = time.process_time() - t0
    scores = {kind: curves.scores(kind) for kind in ("invariant", "standard", "invariant_ukfm")}
    print(f"\nBanc d'essai de ukfm, {args.runs} tirages (graine {SEED}, {format_spec(seconds, '.1f')} s de CPU) :")
    print(f"  {'filtre':18s} {'RMSE pos. (m)':>14s} {'RMSE cap (°)':>13s} {'NEES pos.':>10s} {'NEES cap':>9s}"
          f"   | ukfm : {'RMSE pos.':>9s} {'RMSE cap':>9s} {'NEES pos.':>10s} {'NEES cap':>9s}")
    for kind, label in (("invariant", "EKF invariant"), ("standard", "EKF standard"),
                        ("invariant_ukfm", "invariant, G ukfm")):
        s, u = scores[kind], rl.UKFM_TABLE[kind.split("_")[0]]
        print(f"  {label:18s} {format_spec(s.position_rmse, '.3f'):>14s} {format_spec(s.heading_rmse_deg, '.2f'):>13s} "
              f"{format_spec(s.position_nees, '.3g'):>10s} {format_spec(s.heading_nees, '.3g'):>9s}   |        "
              f"{format_spec(u[0], '.2f'):>9s} {format_spec(u[1], '.2f'):>9s} {format_spec(u[2], '.2f'):>10s} "
              f"{format_spec(u[3], '.2f'):>9s}")
    ratio = scores["standard"].position_rmse / scores["invariant"].position_rmse
    print(f"  rapport des RMSE de position standard / invariant : {format_spec(ratio, '.2f')}")

    if args.write:
        pick = slice(EVERY - 1, None, EVERY)  # lignes 19, 39, … : t = 0,2 s, 0,4 s, …
        series = {f"{kind} {name}": tuple(float(f"{v:.4g}") for v in curves.curves[kind][name][pick])
                  for kind, names in KEPT.items() for name in names}
        write_measurement(
            OUTPUT,
            "Banc d'essai de localisation de ukfm (EKF invariant et EKF standard sur SE(2)), calculé par\n"
            "benchmarks/localization.py --write : le chapitre « Filtrage invariant sur les groupes de Lie » cite ce\n"
            "tableau, ces courbes (un point par 0,2 s) et ces temps, sans refaire les 100 tirages ; un test vérifie\n"
            "que localization_curves(N_RUNS, rng=SEED) redonne les mêmes nombres.",
            {"N_RUNS": args.runs, "SEED": SEED,
             "TABLE": {kind: (s.position_rmse, s.heading_rmse_deg, s.position_nees, s.heading_nees)
                       for kind, s in scores.items()},
             "MICROSECONDS_PER_STEP": {k: round(v, 1) for k, v in us.items()},
             "CURVE_TIME": tuple(float(f"{v:.4g}") for v in curves.t[pick]),
             "CURVES": series})


if __name__ == "__main__":
    main()
