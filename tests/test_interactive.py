"""Interactivité : grilles précalculées (contre kalman_filter et filterpy), figure Bokeh (données exactes
dans le HTML), curseurs interactifs ipywidgets pilotés depuis Python, extension Sphinx, entrées invalides."""

from __future__ import annotations

import base64
import gzip
import json
import re
import types
from pathlib import Path

import ipywidgets
import numpy as np
import pytest
from conftest import ROOT, filterpy_kf

import kalman_course as kc
import kalman_course.interactive as ki
from kalman_course.interactive.static import installed_bokehjs
from kalman_course.sphinx import launch_buttons
from kalman_course.interactive.static import MARKER, PLOTTED_SOURCE
from kalman_course.scenarios import tag

CHAPTER = ROOT / "book" / "tension-constante.md"


@pytest.fixture(scope="module")
def vgrid():
    return ki.voltage_grid()


@pytest.fixture(scope="module")
def tgrid():
    return ki.tag_grid()


def chapter_run():
    """L'exécution du chapitre statique, écrite comme dans sa cellule (valeurs relues dans le .md)."""
    text = CHAPTER.read_text()
    model_call = re.search(r"constant_voltage_model\(Q=([0-9.e+-]+), R=([0-9.e+-]+)\)", text)
    filter_call = re.search(r"kalman_filter\(model, z, x0=([0-9.e+-]+), P0=([0-9.e+-]+)\)", text)
    n_call = re.search(r"constant_voltage_measurements\((\d+)\)", text)
    assert model_call and filter_call and n_call, "la cellule de calcul du chapitre a changé de forme"
    Q, R = float(model_call[1]), float(model_call[2])
    x0, P0 = float(filter_call[1]), float(filter_call[2])
    z = kc.scenarios.constant_voltage_measurements(int(n_call[1]))
    return (Q, R, x0, P0), kc.kalman_filter(kc.scenarios.constant_voltage_model(Q=Q, R=R), z, x0=x0, P0=P0)


# --------------------------------------------------------------------------- grilles


def test_voltage_axes_are_log_spaced_and_centred_on_the_chapter():
    q, r = ki.voltage_axes()
    assert q.values.size == r.values.size == 15
    for axis in (q, r):
        steps = np.diff(np.log10(axis.values))
        np.testing.assert_allclose(steps, 0.5, rtol=1e-12)
    np.testing.assert_allclose([q.values[0], q.values[-1]], [1e-9, 1e-2], rtol=1e-12)
    np.testing.assert_allclose([r.values[0], r.values[-1]], [1e-5, 1e2], rtol=1e-12)
    (Q, R, _, _), _ = chapter_run()
    assert q.default_value == Q and r.default_value == R  # égalité exacte : même figure


def test_voltage_grid_equals_filterpy_at_every_point(vgrid):
    """Chaque point de la grille précalculée contre la référence indépendante (boucle de filterpy) ; le gain
    contre sa forme a posteriori K = P Cᵀ R⁻¹ (ici P/R)."""
    q, r = vgrid.axes
    z = kc.scenarios.constant_voltage_measurements(50)
    assert vgrid.shape == (15, 15) and all(v.shape == (15, 15, 50) for v in vgrid.series.values())
    for i, Q in enumerate(q.values):
        for j, R in enumerate(r.values):
            x, P, _, _ = filterpy_kf(kc.scenarios.constant_voltage_model(Q=Q, R=R), z, [0.0], [[1.0]])
            run = vgrid.run(i, j)
            np.testing.assert_allclose(run["x"], x[:, 0], rtol=1e-9, atol=1e-12)
            np.testing.assert_allclose(run["P"], P[:, 0, 0], rtol=1e-9, atol=1e-15)
            np.testing.assert_allclose(run["K"], P[:, 0, 0] / R, rtol=1e-9, atol=1e-15)
    # l'ordre aplati envoyé au navigateur : l'exécution (i, j) commence à (i·N1 + j)·T
    i, j = 3, 11
    start = (i * 15 + j) * 50
    np.testing.assert_array_equal(vgrid.flat("K")[start : start + 50], vgrid.run(i, j)["K"])


@pytest.mark.parametrize("i, j", [(0, 0), (0, 14), (14, 0), (14, 14), (8, 6), (5, 9)])
def test_voltage_grid_against_filterpy(vgrid, i, j):
    Q, R = vgrid.axes[0].values[i], vgrid.axes[1].values[j]
    z = kc.scenarios.constant_voltage_measurements(50)
    x, P, _, _ = filterpy_kf(kc.scenarios.constant_voltage_model(Q=Q, R=R), z, [0.0], [[1.0]])
    run = vgrid.run(i, j)
    np.testing.assert_allclose(run["x"], x[:, 0], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(run["P"], P[:, 0, 0], rtol=1e-9)
    # gain scalaire en forme fermée : K = P⁻/(P⁻ + R), P⁻ = P_{n-1} + Q
    P_prev = np.concatenate([[1.0], P[:-1, 0, 0]])
    np.testing.assert_allclose(run["K"], (P_prev + Q) / (P_prev + Q + R), rtol=1e-9)


def test_default_grid_point_is_the_static_chapter_run(vgrid):
    (_, _, _, _), res = chapter_run()
    run = vgrid.run(*vgrid.default_index)
    np.testing.assert_array_equal(run["x"], res.x[:, 0])
    np.testing.assert_array_equal(run["P"], res.P[:, 0, 0])
    np.testing.assert_array_equal(run["K"], res.K[:, 0, 0])
    # et ce sont bien les courbes des figures statiques du chapitre
    fig = kc.figures.draw("tension-estimation")
    estimate = [ln for ln in fig.axes[0].get_lines() if "estimation" in ln.get_label()]
    assert len(estimate) == 1
    np.testing.assert_array_equal(estimate[0].get_ydata(), run["x"])
    fig = kc.figures.draw("tension-covariance")
    (cov,) = [ln for ln in fig.axes[0].get_lines() if "P_n" in ln.get_label()]
    np.testing.assert_array_equal(cov.get_ydata(), run["P"])


def test_prose_claims_about_the_gain(vgrid):
    """Le chapitre dit : « augmentez Ψ et le gain s'effondre, augmentez Φ et il reste grand »."""
    K50 = vgrid.series["K"][:, :, -1]
    assert (np.diff(K50, axis=1) < 0).all()  # Ψ croissant → K₅₀ décroissant
    assert (np.diff(K50, axis=0) > 0).all()  # Φ croissant → K₅₀ croissant
    assert K50[0, -1] < 0.01 and K50[-1, 0] > 0.99  # des extrêmes de la grille


def test_tag_grid_equals_the_ekf_and_default_is_the_chapter_run(tgrid):
    data = tag.tag_data()
    a, r = tgrid.axes
    assert (a.default_value, r.default_value) == (tag.TAG_ACCEL_STD, tag.TAG_RANGE_STD)
    np.testing.assert_allclose(np.diff(np.log10(a.values)), 1 / 3, rtol=1e-12)
    points = [(0, 0), (0, 6), (6, 0), (6, 6), tgrid.default_index, (2, 5)]
    for i, j in points:
        res = tag.run_tag_ekf(a.values[i], r.values[j], data=data)
        run = tgrid.run(i, j)
        np.testing.assert_array_equal(run["px"], res.x[:, 0])
        np.testing.assert_array_equal(run["py"], res.x[:, 1])
        err = np.hypot(res.x[:, 0] - data.x_true[:, 0], res.x[:, 1] - data.x_true[:, 1])
        np.testing.assert_allclose(run["err"], err, rtol=1e-14, atol=1e-15)
        np.testing.assert_allclose(run["sigma"] ** 2, res.P[:, 0, 0] + res.P[:, 1, 1], rtol=1e-13)
    chapter = tag.run_tag_ekf()  # les figures du chapitre utilisent les réglages par défaut
    np.testing.assert_array_equal(tgrid.run(*tgrid.default_index)["px"], chapter.x[:, 0])


def test_tag_prose_claim_overconfident_with_small_range_noise(tgrid):
    """Le chapitre dit : « avec σᵣ trop petit, le filtre se croit plus précis qu'il ne l'est »."""
    skip = tag.TAG_TRANSIENT_STEPS
    rms = {k: np.sqrt(np.mean(tgrid.series[k][:, :, skip:] ** 2, axis=2)) for k in ("err", "sigma")}
    ratio = rms["sigma"] / rms["err"]
    assert (ratio[:, 0] < 0.5).all()  # σᵣ = 1 cm (10 fois trop petit) : écart-type annoncé < moitié de l'erreur
    assert 0.7 < ratio[tgrid.default_index] < 1.4  # réglage nominal : cohérent


def test_precompute_grid_is_generic():
    a = ki.ParameterAxis("a", "a", "premier", "m", ki.log_grid(1.0, 1, 1, 1), default=1)
    b = ki.ParameterAxis("b", "b", "second", "s", ki.log_grid(2.0, 0, 1, 2), default=0)
    t = np.arange(4.0)
    g = ki.precompute_grid(lambda u, v: {"s": u * v + t}, a, b, t)
    assert g.shape == (3, 3)
    np.testing.assert_array_equal(g.run(2, 1)["s"], 10.0 * (2.0 * 10**0.5) + t)
    with pytest.raises(ValueError):
        g.series["s"][0, 0, 0] = 1.0  # lecture seule


# --------------------------------------------------------------------------- libellés


@pytest.mark.parametrize(
    "value, unit, text",
    [
        (1e-5, "V²", "1\u202f×\u202f10⁻⁵\u00a0V²"),
        (10**-4.5, "V²", "3,16\u202f×\u202f10⁻⁵\u00a0V²"),
        (0.01, "V²", "0,01\u00a0V²"),
        (0.0316227766, "V²", "0,0316\u00a0V²"),
        (1.0, "V²", "1\u00a0V²"),
        (100.0, "V²", "100\u00a0V²"),
        (9.9999e-5, "", "1\u202f×\u202f10⁻⁴"),
        (2.5e4, "m", "2,5\u202f×\u202f10⁴\u00a0m"),
        (0.5, "m/s²", "0,5\u00a0m/s²"),
    ],
)
def test_format_value_writes_real_values_in_french(value, unit, text):
    assert ki.format_value(value, unit) == text


# --------------------------------------------------------------------------- figure Bokeh (statique)


def _decode_bokeh_arrays(obj, out):
    """Parcourt le JSON d'un document Bokeh et décode les tableaux (base64, éventuellement gzip)."""
    if isinstance(obj, dict):
        if obj.get("type") == "ndarray":
            raw = base64.b64decode(obj["array"]["data"])
            if raw[:2] == b"\x1f\x8b":
                raw = gzip.decompress(raw)
            out.append(np.frombuffer(raw, dtype=obj["dtype"]))
        for v in obj.values():
            _decode_bokeh_arrays(v, out)
    elif isinstance(obj, list):
        for v in obj:
            _decode_bokeh_arrays(v, out)


def test_static_figure_html_carries_the_exact_grid(vgrid):
    fig = ki.voltage_sliders()
    html = fig._repr_html_()
    assert f'{MARKER}="tension-curseurs"' in html
    # BokehJS vient du site, pas de la figure : ni script externe ni adresse réseau
    assert "<script src" not in html and re.search(r"https?://", html) is None
    item = re.search(r'<script type="application/json" id="[^"]+-item">(.*?)</script>', html, re.S)[1]
    doc = json.loads(item)
    arrays = []
    _decode_bokeh_arrays(doc, arrays)
    for name in ("x", "P", "K"):
        flat = vgrid.flat(name)
        assert any(a.shape == flat.shape and np.array_equal(a, flat) for a in arrays), name
    # la source tracée part de la position par défaut = la figure statique du chapitre
    _, res = chapter_run()
    assert any(a.shape == (50,) and np.array_equal(a, res.x[:, 0]) for a in arrays)
    text = json.dumps(doc, ensure_ascii=False)
    assert PLOTTED_SOURCE in text
    for label in vgrid.axes[0].labels() + vgrid.axes[1].labels():
        assert label in text  # le curseur affiche les vraies valeurs
    for words in ("itération n (sans unité)", "tension (V)", "Pₙ (V²)", "Kₙ (sans unité)", "Φ — bruit d’état"):
        assert words in text


def test_static_figure_tells_jupyter_users_where_the_live_sliders_are():
    html = ki.voltage_sliders(n_steps=10)._repr_html_()
    assert "kc.interactive.live_voltage_explorer()" in html
    assert 'class="kc-bokeh-missing"' in html
    # HTML brut, que l'extension de typographie ne voit pas : espace insécable avant « : » (issue 36)
    missing = html.split('class="kc-bokeh-missing">', 1)[1].split("</p>", 1)[0]
    assert "précalculés\u00a0: elle" in missing and " :" not in missing.replace("\u00a0:", "")


# --------------------------------------------------------------------------- curseurs interactifs (ipywidgets)


def test_live_sliders_are_log_sliders_with_real_values():
    explorer = ki.live_voltage_explorer()
    assert set(explorer.sliders) == {"Q", "R", "P0"}
    for name, symbol in (("Q", "Φ"), ("R", "Ψ"), ("P0", "P₀")):
        s = explorer.sliders[name]
        assert isinstance(s, ipywidgets.FloatLogSlider)
        assert s.continuous_update is False
        assert symbol in s.description and "V²" in s.description
        assert s.base == 10
    (Q, R, _, P0), _ = chapter_run()
    assert explorer.values() == {"Q": Q, "R": R, "P0": P0}  # la valeur lue est la vraie valeur
    explorer.sliders["R"].value = 3e-3
    assert explorer.sliders["R"].value == 3e-3
    # la valeur lue est écrite en français à côté du curseur, et suit le curseur
    assert explorer.sliders["R"].readout is False
    assert explorer.readouts["R"].value == "3\u202f×\u202f10⁻³\u00a0V²"  # comme les curseurs du livre
    explorer.sliders["Q"].value = 2.5e-5
    assert explorer.readouts["Q"].value == "2,5\u202f×\u202f10⁻⁵\u00a0V²"
    bundle = explorer._repr_mimebundle_()
    assert "application/vnd.jupyter.widget-view+json" in bundle


@pytest.mark.parametrize("Q, R, P0", [(1e-5, 0.01, 1.0), (3e-4, 1.0, 0.1), (1e-9, 1e-5, 50.0), (1e-2, 100.0, 1e-4)])
def test_live_sliders_redraw_the_filter_output(Q, R, P0):
    explorer = ki.live_voltage_explorer()
    before = explorer.image.value
    explorer.sliders["Q"].value = Q
    explorer.sliders["R"].value = R
    explorer.sliders["P0"].value = P0
    z = kc.scenarios.constant_voltage_measurements(50)
    res = kc.kalman_filter(kc.scenarios.constant_voltage_model(Q=Q, R=R), z, x0=0.0, P0=P0)
    (line_x,) = explorer.lines["x"]
    (line_P,) = explorer.lines["P"]
    (line_K,) = explorer.lines["K"]
    np.testing.assert_array_equal(line_x.get_ydata(), res.x[:, 0])
    np.testing.assert_array_equal(line_P.get_ydata(), res.P[:, 0, 0])
    np.testing.assert_array_equal(line_K.get_ydata(), res.K[:, 0, 0])
    np.testing.assert_array_equal(line_x.get_xdata(), np.arange(1, 51))
    if (Q, R, P0) != (1e-5, 0.01, 1.0):
        assert explorer.image.value != before  # l'image affichée a été redessinée
    assert explorer.image.value[:8] == b"\x89PNG\r\n\x1a\n"


def test_live_tag_explorer_redraws_the_ekf():
    explorer = ki.live_tag_explorer()
    explorer.sliders["range_std"].value = 0.03
    explorer.sliders["accel_std"].value = 2.0
    data = tag.tag_data()
    res = tag.run_tag_ekf(2.0, 0.03, data=data)
    (traj,) = explorer.lines["py"]
    np.testing.assert_array_equal(traj.get_xdata(), res.x[:, 0])
    np.testing.assert_array_equal(traj.get_ydata(), res.x[:, 1])
    (err,) = explorer.lines["err"]
    np.testing.assert_allclose(err.get_ydata(), np.linalg.norm(res.x[:, :2] - data.x_true[:, :2], axis=1),
                               rtol=1e-14)


def test_no_kernel_widget_is_executed_in_the_book():
    """Un curseur ipywidgets exécuté dans le livre serait mort dans la page publiée."""
    for md in (ROOT / "book").glob("*.md"):
        cells = re.findall(r"```\{code-cell\}[^\n]*\n(.*?)```", md.read_text(), re.S)
        for cell in cells:
            live = re.search(r"live_\w*explorer\s*\(|import ipywidgets|from ipywidgets|\binteract\(", cell)
            assert live is None, f"{md.name} : cellule à widget interactif ({live and live[0]})"


# --------------------------------------------------------------------------- extension Sphinx


def _fake_config(url, launch):
    return types.SimpleNamespace(
        html_theme_options={"repository_url": url, "launch_buttons": dict(launch)}, kc_ipynb_download=False
    )


LAUNCH = {"binderhub_url": "https://mybinder.org", "colab_url": "https://colab.research.google.com",
          "jupyterhub_url": "", "thebe": False, "notebook_interface": "jupyterlab"}


@pytest.mark.parametrize("url", ["", "  ", launch_buttons.JUPYTER_BOOK_DEFAULT_REPOSITORY,
                                 launch_buttons.JUPYTER_BOOK_DEFAULT_REPOSITORY + "/"])
def test_launch_buttons_withheld_without_a_repository(url):
    config = _fake_config(url, LAUNCH)
    launch_buttons._guard_launch_buttons(None, config)
    assert config.html_theme_options["launch_buttons"] == {"notebook_interface": "jupyterlab"}
    assert config.kc_ipynb_download is True  # le bouton .ipynb reste


def test_launch_buttons_kept_with_a_repository():
    config = _fake_config("https://github.com/exemple/filtre-de-kalman", LAUNCH)
    launch_buttons._guard_launch_buttons(None, config)
    assert config.html_theme_options["launch_buttons"] == LAUNCH
    assert config.kc_ipynb_download is False


def test_config_declares_the_extension_and_an_explicit_repository():
    import yaml

    cfg = yaml.safe_load((ROOT / "_config.yml").read_text())
    assert {"kalman_course.sphinx.sliders", "kalman_course.sphinx.launch_buttons"} <= set(cfg["sphinx"]["extra_extensions"])
    assert "url" in cfg["repository"]  # jamais l'URL par défaut de Jupyter Book
    assert cfg["launch_buttons"]["binderhub_url"] and cfg["launch_buttons"]["colab_url"]
    vendor = [Path(ROOT, p) for p in cfg["sphinx"]["config"]["html_static_path"]]
    assert all(p.name != "_static" for p in vendor)


def test_vendored_bokehjs_matches_the_installed_bokeh():
    for served, source in installed_bokehjs().items():
        vendored = ROOT / "book" / "vendor" / served
        assert vendored.is_file(), f"{vendored} absent : lancez python scripts/vendor_assets.py"
        assert vendored.read_bytes() == source.read_bytes()


# --------------------------------------------------------------------------- entrées invalides


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: ki.voltage_grid(n_steps=0), "n_steps"),
        (lambda: ki.voltage_grid(n_steps=2.5), "n_steps"),
        (lambda: ki.voltage_grid(P0=-1.0), "P0"),
        (lambda: ki.voltage_sliders(per_decade=0), "per_decade"),
        (lambda: ki.live_voltage_explorer(Q=-1e-5), "« Q » doit être un nombre strictement positif"),
        (lambda: ki.live_voltage_explorer(R=1e6), "hors de la plage du curseur"),
        (lambda: ki.live_voltage_explorer(P0="beaucoup"), "P0"),
        (lambda: ki.live_tag_explorer(range_std=0.0), "range_std"),
        (lambda: ki.log_grid(-1.0, 1, 1), "center"),
        (lambda: ki.log_grid(1.0, 0, 0), "au moins une décade"),
        (lambda: ki.log_grid(1.0, 1.5, 1), "decades_below"),
        (lambda: ki.ParameterAxis("Q", "Φ", "bruit", "V²", [1e-3, 1e-4], default=0), "croissantes"),
        (lambda: ki.ParameterAxis("Q", "Φ", "bruit", "V²", [0.0, 1e-4], default=0), "strictement positives"),
        (lambda: ki.ParameterAxis("Q", "Φ", "bruit", "V²", [1e-4, 1e-3], default=2), "indice par défaut"),
        (lambda: ki.ParameterAxis("Q", "Φ", "bruit", "V²", [1e-4], default=0), "au moins 2 valeurs"),
        (lambda: ki.voltage_axes()[0].index_of(2e-5), "n'est pas un point de la grille"),
        (lambda: ki.voltage_grid().run(15, 0), "hors de la grille"),
        (lambda: ki.Glyph("x", "barres", "red", "x"), "kind"),
        (lambda: ki.Glyph("", "hline", "red", "vraie valeur"), "value"),
        (lambda: ki.Panel("vide", "y (m)", ()), "au moins un Glyph"),
        (lambda: ki.Panel("traj", "y (m)", (ki.Glyph("y", "line", "red", "y", x="x"),)), "x_label"),
    ],
)
def test_bad_arguments_raise_french_errors(call, match):
    with pytest.raises(kc.KalmanInputError, match=match):
        call()


def test_bad_grid_and_figure_arguments():
    a = ki.ParameterAxis("a", "a", "premier", "m", [1.0, 2.0], default=0)
    t = np.arange(3.0)
    with pytest.raises(kc.KalmanInputError, match="mêmes séries"):
        ki.precompute_grid(lambda u, v: {"s": t} if u == 1.0 else {"autre": t}, a, a, t)
    with pytest.raises(kc.KalmanInputError, match=r"forme \(4,\)"):  # longueur changeante d'un appel à l'autre
        ki.precompute_grid(lambda u, v: {"s": np.zeros(4 if u == 1.0 else 5)}, a, a, t)
    with pytest.raises(kc.KalmanInputError, match="ParameterAxis"):
        ki.precompute_grid(lambda u, v: {"s": t}, [1.0, 2.0], a, t)
    grid = ki.precompute_grid(lambda u, v: {"s": t * u}, a, a, t)
    panel = ki.Panel("p", "s (m)", (ki.Glyph("s", "line", "red", "s"),))
    with pytest.raises(kc.KalmanInputError, match="absente"):
        ki.StaticSliders(grid, (ki.Panel("p", "s (m)", (ki.Glyph("inconnue", "line", "red", "s"),)),), "t (s)")
    with pytest.raises(kc.KalmanInputError, match="identifiant court"):
        ki.StaticSliders(grid, (panel,), "t (s)", name="Mon Nom")
    with pytest.raises(kc.KalmanInputError, match="longueurs différentes"):  # tracée contre le temps commun
        ki.StaticSliders(grid, (ki.Panel("p", "z (m)", (ki.Glyph("z", "line", "red", "z"),)),), "t (s)",
                         fixed={"z": np.zeros(5)})
    with pytest.raises(kc.KalmanInputError, match="réservé"):
        ki.StaticSliders(grid, (panel,), "t (s)", fixed={"t": t})
    with pytest.raises(kc.KalmanInputError, match="min_exp"):
        ki.LogParameter("Q", "Φ", "V²", 1e-3, 0.0, -2.0)


def test_static_sliders_print_the_default_run_with_a_caption():
    """Le PDF n'anime pas de curseurs : la figure fournit un PNG (position par défaut) et une légende.
    Le PNG trace l'exécution que donne un appel direct du filtre (voltage_run), pas la grille."""
    from kalman_course.interactive.static import CAPTION_ATTRIBUTE
    from kalman_course.interactive.voltage import VOLTAGE_Q, VOLTAGE_R

    figure = kc.interactive.voltage_sliders()
    data, metadata = figure._repr_mimebundle_()
    assert data["image/png"][:8] == b"\x89PNG\r\n\x1a\n"
    assert metadata["image/png"]["width"] > 0 and metadata["image/png"]["height"] > 0
    assert f'{CAPTION_ATTRIBUTE}="' in data["text/html"]
    expected = kc.interactive.voltage_run(VOLTAGE_Q, VOLTAGE_R)
    plotted = {line.get_label(): np.asarray(line.get_ydata()) for ax in figure.default_figure().axes
               for line in ax.get_lines()}
    np.testing.assert_allclose(plotted["estimation x̂ₙ"], expected["x"], rtol=0, atol=1e-15)
    np.testing.assert_allclose(plotted["Pₙ (a posteriori)"], expected["P"], rtol=0, atol=1e-15)
    np.testing.assert_allclose(plotted["gain Kₙ"], expected["K"], rtol=0, atol=1e-15)
    caption = figure.caption()
    assert "Φ = 1\u202f×\u202f10⁻⁵\u00a0V²" in caption and "Ψ = 0,01\u00a0V²" in caption and "15 × 15" in caption
