"""Figures du chapitre « Lissage : le lisseur RTS » : la cible qui perd son capteur pendant 20 s
(:mod:`kalman_course.scenarios.smoothing`)."""

from __future__ import annotations


from ..numbers import matplotlib_formatter
from ..scenarios.smoothing import target_run
from ._registry import new_figure, register

CHAPTER = "lissage"

FILTER_COLOR = "tab:orange"
SMOOTHER_COLOR = "tab:blue"


def french_axes(ax) -> None:
    """Graduations à la française (virgule décimale, signe moins typographique) et grille légère."""
    ax.xaxis.set_major_formatter(matplotlib_formatter())
    ax.yaxis.set_major_formatter(matplotlib_formatter())
    ax.grid(alpha=0.3)


def log_axis(ax) -> None:
    """Ordonnée logarithmique graduée en 1, 2, 5 × 10ⁿ, à la française."""
    from matplotlib.ticker import LogLocator, NullFormatter

    ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(matplotlib_formatter())
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.grid(alpha=0.3, which="both")


def shade(ax, t0: float, t1: float, label: str | None = None) -> None:
    """Zone grisée des instants sans mesure."""
    ax.axvspan(t0, t1, color="0.88", zorder=0, label=label)


@register("lissage-cible", chapter=CHAPTER, title="Filtre et lisseur sur une cible qui perd son capteur")
def target_estimates():
    run = target_run()
    t = run.time
    g0, g1 = run.gap
    fig, axes = new_figure(2, 1, width=7.5, height=6.0, sharex=True)
    ax = axes[0]
    shade(ax, t[g0] - 0.5, t[g1 - 1] + 0.5, "relevés perdus")
    ax.plot(t, run.y, "+", color="tab:red", ms=5, label="relevés $y_k$")
    ax.plot(t, run.truth[:, 0], color="black", lw=1.2, label="position vraie")
    for res, color, label in ((run.filtered, FILTER_COLOR, r"filtre $\hat x_{k\mid k}$"),
                              (run.smoothed, SMOOTHER_COLOR, r"lisseur $\hat x_{k\mid T}$")):
        p, s = res.x[:, 0], res.std()[:, 0]
        ax.plot(t, p, color=color, lw=1.6, label=label)
        ax.fill_between(t, p - 2 * s, p + 2 * s, color=color, alpha=0.18, lw=0)
    ax.set_ylabel("position (m)")
    ax.set_title("Estimations et bandes ± 2σ")
    ax.legend(loc="upper left", fontsize=8, ncol=2)
    french_axes(ax)
    ax = axes[1]
    shade(ax, t[g0] - 0.5, t[g1 - 1] + 0.5)
    ax.axhline(0.0, color="black", lw=0.8)
    for res, color, label in ((run.filtered, FILTER_COLOR, "filtre"), (run.smoothed, SMOOTHER_COLOR, "lisseur")):
        err, s = res.x[:, 0] - run.truth[:, 0], res.std()[:, 0]
        ax.plot(t, err, color=color, lw=1.4, label=f"erreur du {label}")
        ax.fill_between(t, -2 * s, 2 * s, color=color, alpha=0.15, lw=0)
    ax.set_xlabel("temps (s)")
    ax.set_ylabel("erreur de position (m)")
    ax.set_title("Erreurs (courbes) et ± 2σ annoncés (bandes)")
    ax.legend(loc="lower left", fontsize=8)
    french_axes(ax)
    return fig


@register("lissage-ecarts-types", chapter=CHAPTER, title="Écarts-types du filtre et du lisseur")
def target_stds():
    run = target_run()
    t = run.time
    g0, g1 = run.gap
    fig, axes = new_figure(1, 2, width=8.0, height=3.4)
    for ax, j, name, unit in ((axes[0], 0, "position", "m"), (axes[1], 1, "vitesse", "m/s")):
        shade(ax, t[g0] - 0.5, t[g1 - 1] + 0.5, "relevés perdus" if j == 0 else None)
        ax.plot(t, run.filtered.std()[:, j], color=FILTER_COLOR, lw=1.6, label=r"filtre $\sqrt{P_{k\mid k}}$")
        ax.plot(t, run.smoothed.std()[:, j], color=SMOOTHER_COLOR, lw=1.6, label=r"lisseur $\sqrt{P_{k\mid T}}$")
        ax.set_yscale("log")
        ax.set_xlabel("temps (s)")
        ax.set_ylabel(f"écart-type de la {name} ({unit})")
        ax.set_title(name.capitalize())
        log_axis(ax)
        ax.xaxis.set_major_formatter(matplotlib_formatter())
    axes[0].legend(loc="upper right", fontsize=8)
    return fig


__all__ = ["target_estimates", "target_stds", "french_axes", "log_axis", "shade"]
