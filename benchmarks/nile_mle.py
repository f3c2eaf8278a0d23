"""Maximum de vraisemblance du niveau local sur le Nil : kc.maximum_likelihood contre statsmodels.

Usage : .venv/bin/python benchmarks/nile_mle.py [--repeat 3]
Même modèle (niveau local, départ diffus exact), même point de départ (σ²_ε, σ²_η) = (10⁴, 10³).
Imprime, pour chacun : le temps (meilleur de --repeat essais), le nombre d'évaluations de la
vraisemblance, les variances et log L trouvés ; puis les rapports de temps. Le temps du paquet est donné
avec et sans le calcul de la hessienne (écarts-types), que statsmodels fait à part (cov_type="opg" par
défaut, par gradients analytiques).
"""

from __future__ import annotations

import argparse

import numpy as np
import statsmodels.api as sm

import kalman_course as kc
from kalman_course.numbers import format_spec
from kalman_course.scenarios.nile import local_level_from_log
from _timing import best_time

THETA0 = np.log([1e4, 1e3])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="nombre d'essais (on garde le meilleur)")
    args = parser.parse_args()
    y = kc.datasets.nile().flow
    model = sm.tsa.UnobservedComponents(y, "llevel", use_exact_diffuse=True)

    t_sm, ref = best_time(lambda: model.fit(start_params=np.exp(THETA0), disp=False), args.repeat)
    t_ours, ours = best_time(lambda: kc.maximum_likelihood(local_level_from_log, y, THETA0), args.repeat)
    calls = [0]

    def counted(theta):
        calls[0] += 1
        return local_level_from_log(theta)

    kc.maximum_likelihood(counted, y, THETA0)
    n_ll = kc.log_likelihood  # une évaluation, pour le coût unitaire
    t_one, _ = best_time(lambda: n_ll(ours.model, y), max(args.repeat, 10))
    t_sm_one, _ = best_time(lambda: model.loglike(ref.params), max(args.repeat, 10))
    # sans la hessienne (estimation) : les évaluations de BFGS au coût d'une vraisemblance seule ; la
    # hessienne (ses points sont évalués en lot) prend le reste
    t_ours_opt = min(t_ours, ours.n_evaluations * t_one)
    var = np.exp(ours.theta)
    fcalls = ref.mle_retvals.get("fcalls")
    sm_calls = "?" if fcalls is None else format_spec(fcalls, "d")
    print(f"statsmodels   : {format_spec(t_sm * 1e3, '.1f'):>8s} ms  "
          f"σ²_ε = {format_spec(ref.params[0], '.1f'):>9s}  σ²_η = {format_spec(ref.params[1], '.1f'):>7s}  "
          f"log L = {format_spec(ref.llf, '.6f')}  ({sm_calls} évaluations)")
    print(f"kalman_course : {format_spec(t_ours * 1e3, '.1f'):>8s} ms  "
          f"σ²_ε = {format_spec(var[0], '.1f'):>9s}  σ²_η = {format_spec(var[1], '.1f'):>7s}  "
          f"log L = {format_spec(ours.log_likelihood, '.6f')}  ({format_spec(ours.n_evaluations, 'd')} évaluations "
          f"pour BFGS, {format_spec(calls[0], 'd')} au total avec la hessienne)")
    print(f"une vraisemblance : kalman_course {format_spec(t_one * 1e3, '.2f')} ms, "
          f"statsmodels {format_spec(t_sm_one * 1e3, '.2f')} ms, rapport {format_spec(t_one / t_sm_one, '.1f')}")
    print(f"rapport des temps (kalman_course / statsmodels) : {format_spec(t_ours / t_sm, '.1f')} avec la hessienne, "
          f"≈ {format_spec(t_ours_opt / t_sm, '.1f')} sans "
          f"(hessienne ≈ {format_spec((t_ours - t_ours_opt) * 1e3, '.0f')} ms)")
    print(f"écart de log L : {format_spec(ours.log_likelihood - ref.llf, '+.2e')} ; écarts relatifs des variances : "
          f"{format_spec(var[0] / ref.params[0] - 1, '+.2%')}, {format_spec(var[1] / ref.params[1] - 1, '+.2%')}")


if __name__ == "__main__":
    main()
