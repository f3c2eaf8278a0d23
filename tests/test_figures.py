"""Le registre des figures et la commande ``python -m kalman_course.figures``.

Chaque figure est dessinée **une seule fois** dans la session de tests (:func:`drawn`, comme la commande :
algèbre linéaire sur un fil) ; ce dessin sert à tout : étiquettes d'axes en français avec leur unité
entre parenthèses (ou un compteur sans unité, « itération n »), et, pour les figures de
:data:`NUMBER_CHECKS`, les **nombres tracés** comparés à un calcul indépendant (filterpy, forme close,
scipy) ou aux nombres du scénario que le chapitre cite. Les figures ne sont pas rendues en PNG ici : chaque
chapitre montre toutes les siennes (tests/test_book.py), rendues en PNG par la construction du livre du
même lancement des tests, et le PDF vérifie que chaque image n'est pas vide (tests/test_pdf.py). La
commande, elle, écrit quelques figures dans un autre processus, en PNG, SVG et PDF : ses octets doivent être
ceux du dessin de la session (déterminisme d'un processus à l'autre). Erreurs de la commande en français,
code de retour non nul.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg
import scipy.stats
from matplotlib.figure import Figure

import kalman_course as kc
from kalman_course.figures import REGISTRY
from kalman_course.figures.__main__ import chapter_groups, draw_single_threaded, main, save_figure
from kalman_course.typography import french_spacing

from conftest import filterpy_kf

ROOT = Path(__file__).resolve().parent.parent
NAMES = kc.figures.names()

# Un axe sans unité n'est admis que pour un compteur (itération, pas, numéro) ; sinon « (sans unité) ».
COUNTER = re.compile(r"^(itération|pas de temps|numéro|relevé)\b")
UNIT = re.compile(r"\([^()]*\)\s*$")
ENGLISH = {
    "time", "iteration", "iterations", "estimate", "estimated", "measurement", "measurements", "true",
    "error", "state", "step", "value", "voltage", "density", "coverage", "position error",
}

_DRAWN: dict[str, Figure] = {}


def drawn(name: str) -> Figure:
    """La figure ``name``, dessinée une fois par session (comme la commande : BLAS sur un fil)."""
    if name not in _DRAWN:
        _DRAWN[name] = draw_single_threaded(name)
    return _DRAWN[name]


# --------------------------------------------------------------------------- lecture des figures


def lines(fig: Figure, label: str | None = None, *, ax: int | None = None) -> list[np.ndarray]:
    """Les données (N, 2) des lignes tracées dont la légende contient ``label`` (toutes si None), sur
    l'axe numéro ``ax`` ou sur tous."""
    axes = fig.axes if ax is None else [fig.axes[ax]]
    return [np.asarray(line.get_xydata(), dtype=float) for a in axes for line in a.get_lines()
            if label is None or label in str(line.get_label())]


def line(fig: Figure, label: str, *, ax: int | None = None) -> np.ndarray:
    """Les données (N, 2) de l'unique ligne dont la légende contient ``label``."""
    found = lines(fig, label, ax=ax)
    assert len(found) == 1, f"{len(found)} ligne(s) « {label} »"
    return found[0]


def innovations_filterpy(model, y, x0, P0, u=None) -> tuple[np.ndarray, np.ndarray]:
    """Innovations ν (T, m) et leurs covariances S (T, m, m) recalculées depuis la boucle de filterpy."""
    _, _, x_prior, P_prior = filterpy_kf(model, y, x0, P0, u)
    C, R = np.asarray(model.C), np.asarray(model.R)
    nu = np.asarray(y, dtype=float).reshape(len(y), -1) - x_prior @ C.T
    S = C @ P_prior @ C.T + R
    return nu, S


# --------------------------------------------------------------------------- nombres tracés


def _voltage_check(R):
    def check(fig):
        z = kc.scenarios.constant_voltage_measurements(50)
        # les relevés : la tension vraie plus 0,1 V × N(0, 1), graine du scénario
        noise = np.random.default_rng(kc.scenarios.VOLTAGE_SEED).standard_normal(50)
        np.testing.assert_allclose(z, kc.scenarios.TRUE_VOLTAGE + 0.1 * noise, rtol=0, atol=1e-15)
        x, _, _, _ = filterpy_kf(kc.scenarios.constant_voltage_model(R=R), z, [0.0], [[1.0]])
        estimate = line(fig, "estimation")
        np.testing.assert_allclose(estimate[:, 0], np.arange(1, 51))
        np.testing.assert_allclose(estimate[:, 1], x[:, 0], rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(line(fig, "mesures")[:, 1], z, rtol=0, atol=0)
    return check


def _check_voltage_covariance(fig):
    z = kc.scenarios.constant_voltage_measurements(50)
    _, P, _, _ = filterpy_kf(kc.scenarios.constant_voltage_model(), z, [0.0], [[1.0]])
    np.testing.assert_allclose(line(fig, "P_n")[:, 1], P[:, 0, 0], rtol=1e-10)


def _check_gain_trace(fig):
    # tension constante, pas n = 10 : P(K) = (1 − K)² P⁻ + K² Ψ, P⁻ de filterpy ; minimum en K = P⁻/(P⁻ + Ψ)
    z = kc.scenarios.constant_voltage_measurements(10)
    _, _, _, P_prior = filterpy_kf(kc.scenarios.constant_voltage_model(), z, [0.0], [[1.0]])
    Pm, Psi = P_prior[-1, 0, 0], 0.01
    curve = line(fig, "K^2", ax=0)
    K = curve[:, 0]
    np.testing.assert_allclose(curve[:, 1], 1e3 * ((1 - K) ** 2 * Pm + K**2 * Psi), rtol=1e-12)
    star = line(fig, "gain de Kalman", ax=0)
    np.testing.assert_allclose(star[0], [Pm / (Pm + Psi), 1e3 * Pm * Psi / (Pm + Psi)], rtol=1e-12)
    # moteur : la trace relative vaut 1 en t = 0 et n'est jamais plus petite (six directions)
    ratios = [d for d in lines(fig, ax=1) if d.shape[0] == 81]
    assert len(ratios) == 6
    for d in ratios:
        assert abs(d[40, 0]) < 1e-15 and d[40, 1] == pytest.approx(1.0, rel=1e-12)
        assert d[:, 1].min() >= 1.0 - 1e-12


def _check_printed_recipe(fig):
    z = kc.scenarios.constant_voltage_measurements(50)
    x, P, _, P_prior = filterpy_kf(kc.scenarios.constant_voltage_model(), z, [0.0], [[1.0]])
    K = P_prior[:, 0, 0] / (P_prior[:, 0, 0] + 0.01)
    np.testing.assert_allclose(line(fig, "gain corrigé", ax=0)[:, 1], K, rtol=1e-10)
    np.testing.assert_allclose(line(fig, "estimation, gain corrigé", ax=1)[:, 1], x[:, 0], rtol=1e-10, atol=1e-12)
    # gain imprimé K = (Pₙ + Ψ)/(Pₙ + 2Ψ), puis Pₙ₊₁ = (1 − K)(Pₙ + Φ), récurrence écrite ici : K → 1/2
    Phi, Psi, p, printed = 1e-5, 0.01, 1.0, []
    for _ in range(50):
        k = (p + Psi) / (p + 2 * Psi)
        printed.append(k)
        p = (1 - k) * (p + Phi)
    np.testing.assert_allclose(line(fig, "gain imprimé", ax=0)[:, 1], printed, rtol=1e-10)
    assert printed[-1] == pytest.approx(0.5, abs=1e-3)


def _check_posterior(fig):
    post = kc.scenarios.voltage.posterior_coverage()
    coverage = line(fig, "1{,}96", ax=1)[:, 1] / 100
    np.testing.assert_allclose(coverage, post.coverage, rtol=1e-14)
    # à chaque pas, 2000 tirages indépendants : la couverture est celle d'un intervalle à 95 %
    sem = np.sqrt(0.95 * 0.05 / post.normalised.shape[0])
    assert np.all(np.abs(coverage - 0.95) < 4 * sem) and abs(coverage.mean() - 0.95) < 3 * sem
    grid = line(fig, "mathcal{N}(0, 1)", ax=0)
    np.testing.assert_allclose(grid[:, 1], scipy.stats.norm.pdf(grid[:, 0]), rtol=1e-12)


def _check_practice_innovations(fig):
    run = kc.scenarios.engine.forgotten_command(120)
    y, u = run.simulation.y, kc.scenarios.engine.engine_commands(120)
    x0, P0 = kc.scenarios.engine.ENGINE_X0_HAT, kc.scenarios.engine.ENGINE_P0
    good = innovations_filterpy(kc.scenarios.engine.engine_model(), y, x0, P0, u)
    bad = innovations_filterpy(kc.scenarios.engine.engine_model_without_command(), y, x0, P0)
    for ax, (nu, S) in enumerate((good, bad)):
        np.testing.assert_allclose(line(fig, "sqrt{S_{n,11}}", ax=ax)[:, 1], nu[:, 0] / np.sqrt(S[:, 0, 0]),
                                   rtol=1e-9, atol=1e-9)
    # modèle juste : centrées, de variance 1 ; sans la commande : nettement positives
    assert abs(good[0][:, 0].mean()) < 0.5 * np.sqrt(good[1][:, 0, 0]).mean()
    assert (bad[0][:, 0] / np.sqrt(bad[1][:, 0, 0])).mean() > 2.0


def _check_gain_limits(fig):
    sim, nominal = kc.scenarios.engine.gain_limit_run(1.0)
    u = kc.scenarios.engine.engine_commands(120)
    model = kc.scenarios.engine.engine_model()
    x, _, _, _ = filterpy_kf(model, sim.y, kc.scenarios.engine.ENGINE_X0_HAT, kc.scenarios.engine.ENGINE_P0, u)
    np.testing.assert_allclose(line(fig, "vrai $\\Psi$", ax=0)[:, 1], x[:, 0], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(line(fig, "C^{-1}y_n", ax=0)[:, 1], np.linalg.solve(model.C, sim.y.T)[0],
                               rtol=1e-12)
    to_zero, to_inverse = line(fig, "K_T\\| /", ax=1), line(fig, "K_T - C^{-1}", ax=1)
    assert to_zero[-1, 1] < 1e-3 and to_inverse[0, 1] < 1e-3  # s = 10⁸ : K → 0 ; s = 10⁻⁸ : K → C⁻¹


def _check_ekf_linearisation(fig):
    # EKF : f(x̂) = (10, 0) m ; moyenne exacte (forme close) r̄ e^{−σθ²/2} : le nuage s'en approche
    sr, st = 0.5, np.deg2rad(20.0)
    dots = [d for d in lines(fig, ax=1) if d.shape == (1, 2)]
    ekf = [d for d in dots if np.allclose(d, [[10.0, 0.0]], atol=1e-12)]
    assert len(ekf) == 1
    (mc_mean,) = [d[0] for d in dots if not np.allclose(d, [[10.0, 0.0]], atol=1e-12)]
    exact = np.array([10.0 * np.exp(-st**2 / 2), 0.0])
    sem = np.sqrt(np.array([10**2 * 0.5 * (1 + np.exp(-2 * st**2)) - exact[0] ** 2 + sr**2,
                            10**2 * 0.5 * (1 - np.exp(-2 * st**2))]) / 3000)
    assert np.all(np.abs(mc_mean - exact) < 4 * sem), (mc_mean, exact, sem)
    title = fig.axes[1].get_title()
    assert kc.numbers.format_spec(np.linalg.norm(mc_mean - [10.0, 0.0]), ".2f") in title


def _check_banana(fig):
    comp = kc.scenarios.banana.banana_comparison()
    r, th = kc.scenarios.banana.BANANA_RANGE, kc.scenarios.banana.BANANA_BEARING
    st = kc.scenarios.banana.BANANA_BEARING_STD
    exact = r * np.exp(-st**2 / 2) * np.array([np.cos(th), np.sin(th)])  # forme close de la moyenne
    np.testing.assert_allclose(comp.truth.mean, exact, rtol=1e-12)
    markers = [d[0] for d in lines(fig, ax=1) if d.shape == (1, 2)]
    assert any(np.allclose(m, exact, rtol=1e-12) for m in markers)
    assert any(np.allclose(m, [r * np.cos(th), r * np.sin(th)], rtol=1e-12) for m in markers)  # g(r̄, θ̄)
    cloud = line(fig, "tirages transformés", ax=1)
    polar = lines(fig, ax=0)[0]  # le nuage polaire (m, °)
    np.testing.assert_allclose(cloud, np.column_stack([polar[:, 0] * np.cos(np.deg2rad(polar[:, 1])),
                                                       polar[:, 0] * np.sin(np.deg2rad(polar[:, 1]))]),
                               rtol=1e-9, atol=1e-12)


def _check_ukf_comparison(fig):
    comp = kc.scenarios.tag.tag_comparison()
    data = comp.data
    ekf = line(fig, "EKF (REQM", ax=0)[:, 1] / 100
    ukf = line(fig, "UKF (REQM", ax=0)[:, 1] / 100
    np.testing.assert_allclose(ekf, np.linalg.norm(comp.ekf.x[:, :2] - data.x_true[:, :2], axis=1), rtol=1e-12)
    np.testing.assert_allclose(ukf, np.linalg.norm(comp.ukf.x[:, :2] - data.x_true[:, :2], axis=1), rtol=1e-12)
    skip = kc.scenarios.tag.TAG_TRANSIENT_STEPS
    assert comp.ekf_rmse == pytest.approx(np.sqrt(np.mean(ekf[skip:] ** 2)), rel=1e-12)
    gap = lines(fig, ax=1)[0][:, 1] / 1000
    np.testing.assert_allclose(gap, np.maximum(np.linalg.norm(comp.ekf.x[:, :2] - comp.ukf.x[:, :2], axis=1), 1e-9),
                               rtol=1e-12)


def _check_nis_distribution(fig):
    grid = line(fig, "chi^2_2")
    np.testing.assert_allclose(grid[:, 1], np.exp(-grid[:, 0] / 2) / 2, rtol=1e-12)  # densité du χ²₂
    # l'histogramme : la NIS νᵀS⁻¹ν du modèle juste, ν et S recalculés avec filterpy
    sim = kc.scenarios.engine.engine_simulation(500)
    nu, S = innovations_filterpy(kc.scenarios.engine.engine_model(), sim.y, kc.scenarios.engine.ENGINE_X0_HAT,
                                 kc.scenarios.engine.ENGINE_P0, kc.scenarios.engine.engine_commands(500))
    values = np.einsum("ki,ki->k", nu, np.linalg.solve(S, nu[:, :, None])[:, :, 0])
    heights = np.array([p.get_height() for p in fig.axes[0].patches])
    np.testing.assert_allclose(heights, np.histogram(values, bins=np.linspace(0.0, 12.0, 31), density=True)[0],
                               rtol=1e-12)


def _check_nees(fig):
    lo, hi = scipy.stats.chi2.ppf([0.025, 0.975], 2 * 100) / 100
    assert french_spacing(f"[{kc.numbers.format_spec(lo, '.2f')} ; {kc.numbers.format_spec(hi, '.2f')}]") in " ".join(
        str(t.get_text()) for t in fig.axes[0].get_legend().get_texts())


def _check_autocorrelation(fig):
    for ax in fig.axes[:3]:
        band = [t.get_text() for t in ax.get_legend().get_texts() if "1,96/√T" in t.get_text()]
        assert band and kc.numbers.format_spec(1.96 / np.sqrt(500), ".3f") in band[0]


def _check_centring(fig):
    _, results = kc.scenarios.engine.consistency_runs()
    e = kc.whitened_innovations(results["modèle juste"])
    # innovations blanchies recalculées avec filterpy : ν, S, puis L⁻¹ν (Cholesky de scipy)
    model = kc.scenarios.engine.engine_model()
    sim = kc.scenarios.engine.engine_simulation(500)
    nu, S = innovations_filterpy(model, sim.y, kc.scenarios.engine.ENGINE_X0_HAT, kc.scenarios.engine.ENGINE_P0,
                                 kc.scenarios.engine.engine_commands(500))
    ref = np.array([scipy.linalg.solve_triangular(np.linalg.cholesky(s), v, lower=True) for v, s in zip(nu, S)])
    np.testing.assert_allclose(e, ref, rtol=1e-8, atol=1e-9)
    k = np.arange(1, 501)
    plotted = [d[:, 1] for d in lines(fig, ax=0) if d.shape[0] == 500]
    assert any(np.allclose(p, np.cumsum(ref[:, 0]) / k, rtol=1e-8, atol=1e-9) for p in plotted)


def _check_system(fig):
    u = lines(fig, ax=0)[0]
    np.testing.assert_array_equal(u[:, 1][:120], kc.scenarios.engine.engine_commands(120)[:, 0])
    sim = kc.scenarios.engine.engine_simulation(120)
    np.testing.assert_array_equal(line(fig, "moteur", ax=1)[:, 1], sim.x[:, 0])


def _check_particle_convergence(fig):
    conv = kc.scenarios.convergence.particle_convergence()
    plotted = [d for d in lines(fig) if d.shape[0] == len(conv.sizes)]
    assert any(np.allclose(d[:, 1], conv.mean_error, rtol=1e-12) for d in plotted)
    assert -0.75 < conv.mean_slope < -0.25  # erreur en 1/√N


NUMBER_CHECKS = {
    "tension-estimation": _voltage_check(0.01),
    "tension-psi-grand": _voltage_check(1.0),
    "tension-psi-petit": _voltage_check(1e-4),
    "tension-covariance": _check_voltage_covariance,
    "gain-trace-minimale": _check_gain_trace,
    "recette-gain-imprime": _check_printed_recipe,
    "gain-loi-a-posteriori": _check_posterior,
    "gain-limites": _check_gain_limits,
    "pratique-innovations": _check_practice_innovations,
    "systeme-moteur": _check_system,
    "tests-nis-loi": _check_nis_distribution,
    "tests-nees": _check_nees,
    "tests-autocorrelation": _check_autocorrelation,
    "tests-centrage": _check_centring,
    "ekf-linearisation": _check_ekf_linearisation,
    "ukf-banane": _check_banana,
    "ukf-comparaison": _check_ukf_comparison,
    "pf-convergence": _check_particle_convergence,
}


# --------------------------------------------------------------------------- registre


def test_registry_lists_the_linear_chapters_in_lecture_order():
    linear = [REGISTRY[n].chapter for n in NAMES if REGISTRY[n].chapter in {
        "controle-systeme", "estimateur", "predicteur-correcteur", "gain-optimal", "tension-constante",
        "pratique-synthese"}]
    order = ["controle-systeme", "estimateur", "predicteur-correcteur", "gain-optimal", "tension-constante",
             "pratique-synthese"]
    assert sorted(set(linear), key=order.index) == order
    assert linear == sorted(linear, key=order.index)


def test_unknown_figure_is_a_french_error():
    with pytest.raises(kc.KalmanInputError, match="Figure inconnue"):
        kc.figures.draw("pas-une-figure")


def test_number_checks_name_registered_figures():
    assert set(NUMBER_CHECKS) <= set(NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_figure_has_french_labels_with_units(name):
    fig = drawn(name)
    assert isinstance(fig, Figure)
    axes = [ax for ax in fig.axes if ax.get_visible() and (ax.get_lines() or ax.collections or ax.patches or ax.images)]
    assert axes, f"{name} : aucun axe tracé"
    for ax in axes:
        shared = {"x": ax.get_shared_x_axes().get_siblings(ax), "y": ax.get_shared_y_axes().get_siblings(ax)}
        colorbar = ax.get_label() == "<colorbar>"  # une barre de couleur n'a qu'un axe gradué, qui porte l'étiquette
        for which, label in (("x", ax.get_xlabel()), ("y", ax.get_ylabel())):
            if not label and len(shared[which]) > 1:
                continue  # axe partagé : l'étiquette est portée par un voisin
            if not label and colorbar and (ax.get_xlabel() or ax.get_ylabel()):
                continue
            assert label, f"{name} : étiquette d'axe vide"
            assert UNIT.search(label) or COUNTER.match(label), f"{name} : pas d'unité dans « {label} »"
            words = set(re.findall(r"[a-zA-Zéèêàùç]+", re.sub(r"\$[^$]*\$", "", label).lower()))
            assert not (words & ENGLISH), f"{name} : étiquette en anglais « {label} »"


@pytest.mark.parametrize("name", sorted(NUMBER_CHECKS))
def test_figure_plots_the_scenario_numbers(name):
    NUMBER_CHECKS[name](drawn(name))


# --------------------------------------------------------------------------- commande


def _run(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "kalman_course.figures", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=600)


def test_cli_list_names_every_figure():
    proc = _run("--list")
    assert proc.returncode == 0, proc.stderr
    listed = [line.split()[0] for line in proc.stdout.splitlines() if line.strip()]
    assert listed == NAMES
    for text, name in zip(proc.stdout.splitlines(), NAMES):  # description et titre du chapitre
        spec = REGISTRY[name]
        assert spec.title in text and f"« {spec.chapter_title} »" in text and f"book/{spec.chapter}.md" in text


def test_cli_in_two_processes_writes_the_bytes_of_the_session_drawing(tmp_path):
    """Deux figures de deux chapitres, deux processus (une figure chacun), trois formats : chaque fichier a
    les octets du dessin fait dans cette session (un autre processus, un autre ordre : mêmes octets)."""
    names = ["gain-limites", "tests-nis"]
    only = [arg for name in names for arg in ("--only", name)]
    proc = _run("--out", str(tmp_path / "cli"), "--jobs", "2", "--format", "png,svg,pdf", *only)
    assert proc.returncode == 0, proc.stderr
    assert "2 processus" in proc.stderr and "100%" in proc.stderr  # barre de progression tqdm
    assert "6 fichier(s) écrit(s)" in proc.stdout
    assert sorted(p.name for p in (tmp_path / "cli").iterdir()) == sorted(
        f"{n}.{fmt}" for n in names for fmt in ("png", "svg", "pdf"))
    (tmp_path / "ici").mkdir()
    for name in names:
        save_figure(drawn(name), name, tmp_path / "ici", ["png", "svg", "pdf"], 150)
        for fmt in ("png", "svg", "pdf"):
            assert (tmp_path / "cli" / f"{name}.{fmt}").read_bytes() == (tmp_path / "ici" / f"{name}.{fmt}").read_bytes()
    assert (tmp_path / "cli" / "gain-limites.pdf").read_bytes()[:5] == b"%PDF-"
    assert b"<svg" in (tmp_path / "cli" / "gain-limites.svg").read_bytes()[:2000]


def test_cli_bad_input_is_refused_by_the_command_itself(tmp_path):
    proc = _run("--out", str(tmp_path), "--format", "gif")
    assert proc.returncode == 2
    assert "format(s) inconnu(s) : gif" in proc.stderr and "erreur :" in proc.stderr and "utilisation :" in proc.stderr
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize(
    "args, message",
    [
        (["--format", "png,gif"], "format(s) inconnu(s) : gif"),
        (["--format", ","], "format(s) inconnu(s)"),
        (["--only", "pas-une-figure"], "figure(s) inconnue(s) : pas-une-figure"),
        (["--jobs", "-1"], "entier ≥ 0 attendu"),
        (["--jobs", "deux"], "entier ≥ 0 attendu"),
        ([], "l'option --out DOSSIER est obligatoire"),
    ],
)
def test_cli_bad_input_gives_french_error_and_nonzero_exit(tmp_path, capsys, args, message):
    out = [] if not args else ["--out", str(tmp_path)]
    with pytest.raises(SystemExit) as stop:
        main([*out, *args])
    assert stop.value.code != 0
    err = capsys.readouterr().err
    assert message in err
    assert "erreur :" in err and "utilisation :" in err
    assert not any(tmp_path.iterdir())  # rien n'est écrit


def test_cli_chapter_groups_keep_each_figure_once_with_its_chapter():
    names = kc.figures.names()
    groups = chapter_groups(names)
    assert sorted(n for g in groups for n in g) == sorted(names)
    for group in groups:
        assert len({kc.figures.REGISTRY[n].chapter for n in group}) == 1
    assert [len(g) for g in groups] == sorted((len(g) for g in groups), reverse=True)


# --------------------------------------------------------------------------- relecture (issue 36)


def _overlapping_texts(fig) -> list[tuple[str, str]]:
    """Les paires d'annotations d'un même axe (``ax.texts`` : repères, étiquettes posées sur le tracé) dont
    les cadres se chevauchent une fois la figure dessinée."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    found = []
    for ax in fig.axes:
        boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in ax.texts if t.get_visible() and t.get_text()]
        for i, (a, ba) in enumerate(boxes):
            for b, bb in boxes[i + 1:]:
                if ba.overlaps(bb):
                    found.append((a, b))
    return found


@pytest.mark.parametrize("name", NAMES)
def test_annotations_of_a_figure_do_not_overlap(name):
    """Sur la carte de l'hélicoptère, « 1 min » et « 4 min » (aller et retour au même endroit) étaient
    écrits l'un sur l'autre : aucune figure n'a deux annotations qui se chevauchent."""
    assert not _overlapping_texts(drawn(name)), name
