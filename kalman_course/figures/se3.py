"""Figures du chapitre « EKF itéré sur SE(3) : pose d'une cible vue par une caméra »."""

from __future__ import annotations

import numpy as np

from ..geometry.camera import camera_measurement
from ..lecture.errata_se3 import notes_literal_iterates
from ..geometry.lie import se3_inverse, se3_log
from ..scenarios.camera_target import camera_map_estimate, camera_target_problem
from ._registry import new_figure, register

CHAPTER = "ekf-itere-se3"

# arêtes du pavé : les coins 0…7 diffèrent d'un seul bit (x, y, z)
_EDGES = [(i, j) for i in range(8) for j in range(i + 1, 8) if bin(i ^ j).count("1") == 1]


def _wireframe(ax, T, problem, label, **style):
    uv = camera_measurement(T, problem.points, problem.camera).reshape(-1, 2)
    for k, (i, j) in enumerate(_EDGES):
        ax.plot(uv[[i, j], 0], uv[[i, j], 1], label=label if k == 0 else None, **style)


@register("se3-reprojection", chapter=CHAPTER,
          title="Pose d'une cible vue par une caméra : reprojection et convergence de l'EKF itéré sur SE(3)")
def se3_reprojection():
    p = camera_target_problem()
    out = p.iekf()
    T_map = camera_map_estimate(p)
    fig, (ax, ac) = new_figure(1, 2, width=10.0, height=4.4, gridspec_kw={"width_ratios": [1.35, 1]})

    # plan image
    cam = p.camera
    _wireframe(ax, p.T_pred, p, color="tab:orange", ls="--", lw=1.0, label=r"a priori $\hat T_-$")
    _wireframe(ax, out.iterates[1], p, color="tab:red", ls=":", lw=1.1, label="EKF (1 itération)")
    _wireframe(ax, out.T, p, color="tab:blue", lw=1.0, label=f"EKF itéré ({out.n_iter} itérations)")
    uv = p.y.reshape(-1, 2)
    ax.plot(uv[:, 0], uv[:, 1], "k+", ms=8, mew=1.3, label="pixels mesurés $y$")
    # cadrage sur la cible (l'image entière fait cam.width × cam.height px)
    ax.set_xlim(190, 470)
    ax.set_ylim(345, 120)  # v vers le bas, comme dans l'image
    ax.set_aspect("equal")
    ax.set_xlabel("u (px)")
    ax.set_ylabel("v (px)")
    ax.set_title(f"Plan image (détail ; image {cam.width} × {cam.height} px)", fontsize=10)
    ax.legend(loc="upper right", fontsize=7, framealpha=0.9)

    # convergence : distance au MAP (norme du vecteur tangent)
    def dist(Ts):
        return np.array([np.linalg.norm(se3_log(se3_inverse(T_map) @ T)) for T in Ts])

    approx = p.iekf(use_right_jacobian=False)
    notes = notes_literal_iterates(p.T_pred, p.P_pred, p.y, p.points, p.camera, p.sigma_px)
    floor = 1e-16
    ac.semilogy(np.arange(out.iterates.shape[0]), np.maximum(dist(out.iterates), floor), "-o", color="tab:blue",
                ms=4, label=r"EKF itéré ($\mathcal{J}_i = \mathcal{J}_r(\xi_i)$)")
    ac.semilogy(np.arange(approx.iterates.shape[0]), np.maximum(dist(approx.iterates), floor), "-s",
                color="tab:green", ms=3, label=r"variante $\mathcal{J}_i \approx I$")
    ac.semilogy(np.arange(notes.shape[0]), np.maximum(dist(notes), floor), "-D", color="tab:purple", ms=3,
                label="boucle des notes (a priori oublié)")
    ac.axhline(1e-10, color="0.5", lw=0.8, ls=":", label=r"seuil d'arrêt $10^{-10}$")
    ac.set_xlabel("itération i")
    ac.set_ylabel(r"distance au MAP $\|\mathrm{Log}(T_{\mathrm{MAP}}^{-1}T_i)\|$ (m et rad)")
    ac.set_title("Convergence", fontsize=10)
    ac.grid(alpha=0.3, which="both")
    ac.legend(loc="upper right", fontsize=7, framealpha=0.9)
    return fig
