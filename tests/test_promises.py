"""Chaque promesse des encadrés « À observer » est vérifiée sur la grille précalculée de sa figure.

Un encadré « À observer » dit à l'étudiant où mettre les curseurs et ce qu'il verra. Chaque essai de
chaque encadré (un élément de liste, hors explications) a ici un test, inscrit par ``@promise(page,
encadré, essai)`` : il lit la grille de la figure (``kc.interactive.slider_grid``, exactement les
séries que la page publiée affiche) aux positions que l'encadré nomme et vérifie ce que le texte
annonce (le pic existe, le point est dans l'axe, la part est celle du texte, la bande se voit).
:func:`test_every_observation_item_has_a_test` vérifie qu'aucun essai des chapitres n'est sans test,
et qu'aucun test ne vise un essai disparu.

Les références sont indépendantes de la figure quand c'est possible (formes closes écrites ici, lois
de scipy) ; sinon le test confronte deux positions des curseurs, comme le fait l'étudiant.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
import scipy.stats

import kalman_course.interactive as ki

ROOT = Path(__file__).resolve().parent.parent
BOOK = ROOT / "book"

#: (page, n° de l'encadré dans la page, n° de l'essai) → test
PROMISES: dict[tuple[str, int, int], object] = {}


def promise(page: str, box: int, item: int):
    """Inscrit un test comme la vérification de l'essai ``item`` de l'encadré n° ``box`` de ``page``."""

    def decorator(func):
        key = (page, box, item)
        assert key not in PROMISES, f"essai {key} vérifié deux fois"
        PROMISES[key] = func
        return func

    return decorator


# --------------------------------------------------------------------------- lecture de la grille


def _index_of(axis, value) -> int:
    """Position du curseur : ``"min"``, ``"max"``, ``"default"`` ou la valeur affichée (à 2 % près : le
    texte écrit « 1,58 » pour 1,5811…)."""
    if value == "min":
        return 0
    if value == "max":
        return axis.values.size - 1
    if value == "default":
        return axis.default
    values = np.asarray(axis.values, dtype=float)
    target = float(value)
    k = int(np.argmin(np.abs(values - target)))
    tolerance = 0.02 * max(abs(target), 1e-300) if target != 0 else 1e-12
    assert abs(values[k] - target) <= tolerance, (
        f"« {axis.name} » = {value} n'est pas une position du curseur ({', '.join(axis.labels())})")
    return k


def position(name: str, **values) -> tuple[int, ...]:
    """Le point de grille de la figure ``name`` où les curseurs nommés ont ces valeurs (les autres à
    leur position par défaut). Pour un axe dont les valeurs portent un décalage (κ de l'UKF), donner la
    valeur de la grille."""
    grid = ki.slider_grid(name)
    names = [a.name for a in grid.axes]
    unknown = set(values) - set(names)
    assert not unknown, f"{name} : curseurs inconnus {unknown} (curseurs : {names})"
    return tuple(_index_of(a, values.get(a.name, "default")) for a in grid.axes)


def at(name: str, **values) -> dict[str, np.ndarray]:
    """Les séries affichées par la figure ``name`` quand les curseurs ont ces valeurs (séries fixes comprises)."""
    spec = ki.slider_spec(name)
    grid = spec.grid()
    return {"t": np.asarray(grid.time), **{k: np.asarray(v) for k, v in spec.fixed.items()},
            **grid.run(*position(name, **values))}


def readout(name: str, **values) -> str:
    """Le texte affiché sous les curseurs à cette position."""
    return ki.slider_spec(name).text_at(*position(name, **values))


def y_axis(name: str, panel: int, **values) -> tuple[float, float]:
    """Les bornes de l'ordonnée du panneau n° ``panel`` (à partir de 0) à cette position, telles que la
    page les affiche."""
    return _static(name).y_range_at(panel, *position(name, **values))


_STATIC: dict[str, object] = {}


def _static(name: str):
    if name not in _STATIC:
        _STATIC[name] = ki.slider_spec(name).static()
    return _STATIC[name]


def rms(v) -> float:
    v = np.asarray(v, dtype=float)
    v = v[np.isfinite(v)]
    return float(np.sqrt(np.mean(v ** 2)))


def lag1(v) -> float:
    """Autocorrélation empirique au retard 1 (paires de valeurs finies consécutives)."""
    v = np.asarray(v, dtype=float)
    a, b = v[:-1], v[1:]
    ok = np.isfinite(a) & np.isfinite(b)
    return float(np.corrcoef(a[ok], b[ok])[0, 1])


def roughness(v) -> float:
    """Rugosité d'une courbe : écart quadratique moyen de sa dérivée seconde discrète."""
    return rms(np.diff(np.asarray(v, dtype=float), 2))


# --------------------------------------------------------------------------- les encadrés des chapitres

_BOX = re.compile(r"^(:{3,4})\{admonition\} À observer\n:class: \w+\n(.*?)\n\1\s*$", re.M | re.S)
_EXPLANATIONS = re.compile(r"(```|:::)\{dropdown\}.*?\n\s*\1|:::\{admonition\}[^\n]*\n:class: dropdown.*?\n:::|"
                           r"```\{dropdown\}.*?\n```", re.S)


def observation_items() -> dict[tuple[str, int, int], str]:
    """Les essais de tous les encadrés « À observer » du livre : (page, encadré, essai) → texte."""
    out = {}
    for path in sorted(BOOK.glob("*.md")):
        for b, box in enumerate(_BOX.finditer(path.read_text()), start=1):
            trials = _EXPLANATIONS.sub("", box.group(2))
            items = re.findall(r"^(?:\d+\.|-) (.*(?:\n(?!\s*$)(?!\d+\. |- ).*)*)", trials, re.M)
            for i, text in enumerate(items, start=1):
                out[(path.stem, b, i)] = " ".join(text.split())
    return out


def test_every_observation_item_has_a_test():
    items = observation_items()
    assert len(items) >= 50, f"seulement {len(items)} essais trouvés : l'analyse des encadrés a changé ?"
    missing = sorted(set(items) - set(PROMISES))
    extra = sorted(set(PROMISES) - set(items))
    assert not missing, "essais « À observer » sans test :\n" + "\n".join(f"{k} : {items[k][:90]}" for k in missing)
    assert not extra, f"tests d'essais disparus des chapitres : {extra}"


def test_one_observation_box_per_slider_figure_right_after_it():
    """Chaque figure à curseurs a son encadré « À observer », juste après elle (avant la figure suivante)."""
    call = re.compile(r'kc\.interactive\.sliders\("([^"]+)"\)')
    for path in sorted(BOOK.glob("*.md")):
        text = path.read_text()
        shown = [(m.start(), m.group(1)) for m in call.finditer(text)]
        boxes = [m.start() for m in _BOX.finditer(text)]
        for k, (start, name) in enumerate(shown):
            end = shown[k + 1][0] if k + 1 < len(shown) else len(text)
            inside = [b for b in boxes if start < b < end]
            assert len(inside) == 1, f"{path.stem} : {len(inside)} encadré(s) « À observer » pour la figure {name}"


# --------------------------------------------------------------------------- les axes suivent les données


@pytest.mark.parametrize("name", ki.slider_names())
def test_every_panel_shows_the_series_that_set_its_range(name):
    """À chaque point de la grille, les séries qui fixent l'ordonnée d'un panneau (toutes ses séries, ou
    celles de son ``Follow``) sont dans l'axe affiché : aucun point n'en sort quand on bouge un curseur."""
    spec = ki.slider_spec(name)
    grid = spec.grid()
    static = _static(name)
    problems = []
    for p, panel in enumerate(spec.panels):
        for index in np.ndindex(*grid.shape):
            (x0, x1), (y0, y1) = static.ranges_at(p, *index)
            data = {"t": np.asarray(grid.time), **spec.fixed, **grid.run(*index)}
            checks = [(c, sorted((y0, y1)), panel.y_log) for c in panel.range_columns()]  # un axe peut être inversé
            if panel.own_x:  # abscisses des tracés d'un panneau qui a la sienne (plan, trajectoire)
                checks += [(c, sorted((x0, x1)), panel.x_log) for c in panel.x_columns()]
            for column, (lo, hi), log in checks:
                v = np.asarray(data[column], dtype=float)
                v = v[np.isfinite(v)]
                if log:
                    v = v[v > 0]
                if v.size and (v.min() < lo - 1e-9 * abs(lo) or v.max() > hi + 1e-9 * abs(hi)):
                    problems.append(f"panneau « {panel.title} », {column} ∈ [{v.min():.4g} ; {v.max():.4g}] hors "
                                    f"de l'axe [{lo:.4g} ; {hi:.4g}] au point {index}")
                    break
    assert not problems, "\n".join(problems[:10])


# =========================================================================== introduction


@promise("intro", 1, 1)
def _intro_noisier_sensor():
    base, noisy = at("intro-chariot"), at("intro-chariot", R="max")
    # les croix s'écartent de la position vraie…
    assert rms(noisy["y_rel"] - noisy["truth_rel"]) > 2.5 * rms(base["y_rel"] - base["truth_rel"])
    # … mais l'estimation reste lisse, et bien plus proche de la vérité que les mesures
    assert roughness(noisy["x_rel"]) < 0.25 * roughness(noisy["y_rel"])
    axis = ki.slider_grid("intro-chariot").axes[0]
    for R in axis.values[axis.default:]:  # en augmentant R, le filtre reste nettement meilleur
        run = at("intro-chariot", R=R)
        assert run["rmse_x"][0] < 0.75 * run["rmse_y"][0], f"R = {R}"
    text = readout("intro-chariot", R="max")
    assert "mesures" in text and "filtre de Kalman" in text


@promise("intro", 1, 2)
def _intro_unpredictable_motion():
    base, wild = at("intro-chariot"), at("intro-chariot", Q="max")
    assert np.ptp(wild["truth_rel"]) > 2 * np.ptp(base["truth_rel"])  # loin de la vitesse constante
    assert rms(wild["x_rel"] - wild["y_rel"]) < rms(base["x_rel"] - base["y_rel"])  # suit les mesures
    assert np.mean(wild["upper_rel"] - wild["lower_rel"]) > 1.3 * np.mean(base["upper_rel"] - base["lower_rel"])


@promise("intro", 1, 3)
def _intro_ratio_matters():
    smooth = at("intro-chariot", R=10.0, Q=0.005)
    follow = at("intro-chariot", R=0.1, Q=5.0)
    assert roughness(smooth["x_rel"]) < 0.15 * roughness(smooth["y_rel"])  # lisse fortement
    # recopie presque les mesures : l'écart estimation – mesure est petit devant le bruit (√R)
    assert rms(follow["x_rel"] - follow["y_rel"]) < 0.3 * math.sqrt(0.1)


# =========================================================================== le filtre en images


@promise("intuition", 1, 1)
def _intuition_precise_measurement():
    run = at("intuition-produit", meas_var="min")
    R = float(ki.slider_grid("intuition-produit").axes[1].values[0])
    assert run["K"][0] > 0.95
    assert abs(run["P_post"][0] - R) < 0.05 * R  # P ≈ R
    assert abs(run["x_post"][0] - 13.0) < 0.1  # collée à la mesure y = 13 m
    # la densité a posteriori, haute et étroite, est dans l'axe affiché
    assert run["posterior"].max() <= y_axis("intuition-produit", 0, meas_var="min")[1]


@promise("intuition", 1, 2)
def _intuition_confident_prior():
    run = at("intuition-produit", meas_var=1.0, prior_var="min")
    assert run["K"][0] < 0.1  # le gain devient petit
    assert abs(run["x_post"][0] - 10.0) < 0.1 * abs(13.0 - 10.0)  # l'estimation reste près de 10 m
    # le point glisse vers le bas de la courbe K(P⁻) : c'est le plus petit gain de la courbe tracée
    P = run["P_now"][0]
    assert run["K"][0] == pytest.approx(P / (P + 1.0))
    assert run["K"][0] == pytest.approx(np.interp(P, run["P_curve"], run["gain_curve"]), rel=1e-3)  # sur la courbe
    assert run["K"][0] < at("intuition-produit", meas_var=1.0)["K"][0] / 5


@promise("intuition", 1, 3)
def _intuition_equal_information():
    run = at("intuition-produit", prior_var=4.0, meas_var=4.0)
    assert run["K"][0] == pytest.approx(0.5)
    assert run["x_post"][0] == pytest.approx(11.5)
    assert run["P_post"][0] == pytest.approx(2.0)
    # partout, les points noirs (produit normalisé numériquement) sont sur la courbe bleue
    grid = ki.slider_grid("intuition-produit")
    for index in np.ndindex(*grid.shape):
        r = grid.run(*index)
        np.testing.assert_allclose(r["product"], r["posterior"][::5], atol=2e-3 * r["posterior"].max())


@promise("intuition", 2, 1)
def _intuition_cycle_step_by_step():
    grid = ki.slider_grid("intuition-cycle")
    prev = None
    for k in range(grid.shape[0]):
        run = at("intuition-cycle", stage=k)
        if prev is not None:
            if k % 2 == 1:  # prédiction : avance et s'élargit, pas de mesure
                assert run["mean_now"][0] > prev["mean_now"][0]
                assert run["var_now"][0] > prev["var_now"][0]
                assert np.isnan(run["likelihood"]).all()
            else:  # correction : la vraisemblance apparaît, la loi se resserre entre les deux
                assert np.isfinite(run["likelihood"]).all()
                assert run["var_now"][0] < prev["var_now"][0]
                lo, hi = sorted((prev["mean_now"][0], run["y_now"][0]))
                assert lo <= run["mean_now"][0] <= hi
        prev = run


@promise("intuition", 2, 2)
def _intuition_cycle_regular_motion():
    grid = ki.slider_grid("intuition-cycle")
    q = float(grid.axes[1].values[0])
    std = at("intuition-cycle", Q="min")["std"]
    var = std ** 2
    corrections = var[2::2]
    assert np.all(np.diff(corrections) < 0)  # chaque mesure réduit la variance un peu plus
    assert np.all(var[1::2][1:] - var[2::2][:-1] == pytest.approx(q))  # la prédiction n'ajoute que Q
    assert q < 0.05 * corrections[-1]  # … presque rien
    gains = corrections / 1.0  # K = P / R (R = 1 m²)
    assert np.all(np.diff(gains) < 0)  # le gain diminue


@promise("intuition", 2, 3)
def _intuition_cycle_unpredictable_motion():
    std = at("intuition-cycle", Q="max")["std"]
    after_correction = std[2::2]
    assert np.all((after_correction > 0.85) & (after_correction < 1.0))  # proche de √R = 1 m


# =========================================================================== contrôle d'un système


@promise("controle-systeme", 1, 1)
def _system_perfect_model():
    from kalman_course.scenarios.engine import ENGINE_PSI, engine_commands, engine_model

    still = at("systeme-bruits", phi_scale=0.0)
    model = engine_model()
    u = np.asarray(engine_commands(still["t"].size), dtype=float).reshape(still["t"].size, -1)
    x, states = np.zeros(2), []
    for k in range(still["t"].size):  # xₙ₊₁ = A xₙ + B uₙ, sans bruit, écrit ici
        x = np.asarray(model.A) @ x + np.asarray(model.B) @ u[k]
        states.append(x)
    states = np.array(states)
    np.testing.assert_allclose(still["theta_m"], states[:, 0], rtol=1e-10, atol=1e-10)  # réponse déterministe
    np.testing.assert_allclose(still["theta_a"], states[:, 1], rtol=1e-10, atol=1e-10)
    # les mesures restent bruitées : yₙ − C xₙ a l'écart-type de ψ
    noise = still["y1"] - (states @ np.asarray(model.C).T)[:, 0]
    assert np.std(noise) == pytest.approx(math.sqrt(ENGINE_PSI[0, 0]), rel=0.25)


@promise("controle-systeme", 1, 2)
def _system_poor_sensor():
    grid = ki.slider_grid("systeme-bruits")
    base = at("systeme-bruits", psi_scale="min")
    spreads = []
    for psi in grid.axes[1].values:
        run = at("systeme-bruits", psi_scale=psi)
        np.testing.assert_array_equal(run["theta_m"], base["theta_m"])  # l'état ne bouge pas
        spreads.append(roughness(run["y1"]))
    assert np.all(np.diff(spreads) > 0) and spreads[-1] > 3 * spreads[0]  # les mesures s'éparpillent


@promise("controle-systeme", 1, 3)
def _system_poor_dynamics():
    still = at("systeme-bruits", phi_scale=0.0)
    deviations = [rms(at("systeme-bruits", phi_scale=k)["theta_m"] - still["theta_m"]) for k in (0.5, 1.0, 4.0)]
    assert deviations[0] < deviations[1] < deviations[2]  # l'état devient erratique
    wild = at("systeme-bruits", phi_scale=4.0)
    d = wild["theta_m"] - still["theta_m"]
    assert rms(d[-40:]) > 1.5 * rms(d[:40])  # le bruit d'état s'accumule au fil des pas
    # les mesures suivent l'état : elles s'écartent de la même façon
    assert np.corrcoef(d, wild["y1"] - still["y1"])[0, 1] > 0.8


# =========================================================================== construction d'un estimateur


@promise("estimateur", 1, 1)
def _estimator_printed_condition():
    for K in ki.slider_grid("estimateur-gain").axes[0].values:
        run = at("estimateur-gain", K=K, A=2.0)
        decreasing = run["recursion"][-1] < run["recursion"][0]
        assert decreasing == (0.5 < K < 1.5), f"K = {K}"
        if 0 < K < 2:
            assert run["printed_now"][0] < 1  # la condition imprimée accepte tous ces gains


@promise("estimateur", 1, 2)
def _estimator_copy_the_measurement():
    run = at("estimateur-gain", K=1.0, A=2.0)
    floor = ki.estimator.FLOOR
    assert np.all(run["recursion"][1:] == floor)  # nulle dès le premier pas : tracée au plancher
    lo, hi = y_axis("estimateur-gain", 0, K=1.0, A=2.0)
    assert lo <= floor / 10 and hi > 1  # le plancher est dans l'axe, une décade au-dessus du bas
    mc = run["monte_carlo"][1:]
    assert np.all(mc > floor) and mc.max() < 0.05  # petite devant l'erreur initiale 1, mais pas nulle


@promise("estimateur", 1, 3)
def _estimator_stable_system():
    rec = at("estimateur-gain", K=0.0, A=0.5)["recursion"]
    above = rec > ki.estimator.FLOOR
    np.testing.assert_allclose(rec[1:][above[1:]] / rec[:-1][above[1:]], 0.5, rtol=1e-12)
    for A in (2.0, 3.0):  # un système instable : trop peu de gain, l'erreur explose
        assert at("estimateur-gain", K=0.0, A=A)["recursion"][-1] > 1e3


# =========================================================================== prédicteur–correcteur


@promise("predicteur-correcteur", 1, 1)
def _predictor_step_by_step():
    std = at("predicteur-etapes", stage=0)["std"]
    assert std[0] == pytest.approx(15.0)  # P₀ = 15² I °C² : presque plate
    assert std[2] < std[0] / 10  # la première correction resserre d'un coup
    assert np.all(std[1::2][1:] > std[2::2][:-1])  # chaque prédiction élargit…
    assert np.all(std[2::2] < std[1::2])  # … chaque correction resserre (dents de scie)
    first = at("predicteur-etapes", stage=2)
    assert abs(first["mean_now"][0] - first["inverted_x"][0]) < 3 * first["std_now"][0]


@promise("predicteur-correcteur", 1, 2)
def _predictor_distrustful_filter():
    careful, normal = at("predicteur-etapes", psi_scale=1e6, stage=10), at("predicteur-etapes", stage=10)
    assert careful["gain_norm"][0] < 0.01 * normal["gain_norm"][0]  # K → 0
    std = careful["std"]
    assert np.all(std[2::2] > 0.99 * std[1::2])  # les corrections ne resserrent plus rien
    # l'estimation reste celle du modèle, partie 15 °C trop haut
    assert careful["mean_now"][0] - careful["truth_x"][0] > 10.0


@promise("predicteur-correcteur", 1, 3)
def _predictor_trusting_filter():
    for stage in range(2, 11, 2):  # chaque correction
        run = at("predicteur-etapes", psi_scale=1e-6, stage=stage)
        peak = 1.0 / (math.sqrt(2 * math.pi) * run["std_now"][0])
        top = run["current"].max()
        assert top > 0.9 * peak, f"étape {stage} : pic {top:.3g} au lieu de {peak:.3g}"  # le pic est tracé
        where = run["current_x"][np.argmax(run["current"])]
        assert abs(where - run["inverted_x"][0]) < 0.01  # sur la mesure inversée (trait vert)
        lo, hi = y_axis("predicteur-etapes", 0, psi_scale=1e-6, stage=stage)
        assert lo == 0 and top <= hi <= 1.2 * top  # le pic est dans l'axe, qui s'y ajuste
        assert abs(run["mean_now"][0] - run["inverted_x"][0]) < 1e-3  # recopie la mesure


# =========================================================================== gain optimal


def _voltage_psi() -> float:
    return float(__import__("kalman_course").scenarios.constant_voltage_model().R[0, 0])


@promise("gain-optimal", 1, 1)
def _gain_minimum():
    psi = _voltage_psi()
    grid = ki.slider_grid("gain-trace")
    n10 = at("gain-trace", n=10.0)
    K_star, P_pred = n10["K_star"][0], n10["P_pred"][0]
    assert K_star == pytest.approx(P_pred / (P_pred + psi), rel=1e-12)
    for K in grid.axes[1].values:
        run = at("gain-trace", n=10.0, K=K)
        # P(K) − P(K*) = (K − K*)² S, S = P⁻ + Ψ (l'identité du carré complété)
        assert run["P_now"][0] - run["P_star"][0] == pytest.approx((K - K_star) ** 2 * (P_pred + psi),
                                                                   rel=1e-9, abs=1e-15)


@promise("gain-optimal", 1, 2)
def _gain_two_terms():
    run = at("gain-trace", n=10.0)
    K = run["t"]
    np.testing.assert_allclose(run["prediction"], (1 - K) ** 2, rtol=1e-12)
    np.testing.assert_allclose(run["measurement"], K ** 2 * _voltage_psi() / run["P_pred"][0], rtol=1e-12)
    # au gain de Kalman, les pentes des deux termes sont opposées
    k = run["K_star"][0]
    slope_prediction = -2 * (1 - k)
    slope_measurement = 2 * k * _voltage_psi() / run["P_pred"][0]
    assert slope_prediction + slope_measurement == pytest.approx(0.0, abs=1e-12)
    # la courbe tracée a son minimum au gain de Kalman (au pas de la courbe près)
    assert abs(K[np.argmin(run["total"])] - k) <= (K[1] - K[0])


@promise("gain-optimal", 1, 3)
def _gain_decreases_with_time():
    first, late = at("gain-trace", n=1.0), at("gain-trace", n=50.0)
    assert first["P_pred"][0] == pytest.approx(1.0, rel=0.01)  # P⁻₁ ≈ 1 V²
    assert first["K_star"][0] > 0.98
    assert 0.01 < late["K_star"][0] < 0.1  # quelques centièmes


# =========================================================================== tension constante


@promise("tension-constante", 1, 1)
def _voltage_bad_sensor():
    base, bad = at("tension-curseurs"), at("tension-curseurs", R="max")
    assert bad["K"][:10].mean() < base["K"][:10].mean() / 20  # le gain s'effondre
    assert roughness(bad["x"]) < roughness(base["x"])  # lisse…
    truth = -0.37727  # valeur vraie du chapitre
    assert abs(bad["x"][9] - truth) > 5 * abs(base["x"][9] - truth)  # … mais lente à rejoindre la vraie valeur


@promise("tension-constante", 1, 2)
def _voltage_unstable_voltage():
    base, wild = at("tension-curseurs"), at("tension-curseurs", Q="max")
    assert wild["P"][-1] > 10 * base["P"][-1]  # Pₙ ne descend plus beaucoup
    assert wild["K"][-1] > 0.5  # le gain reste grand
    assert rms(wild["x"] - wild["z"]) < 0.5 * rms(base["x"] - base["z"])  # suit les mesures de près


@promise("tension-constante", 1, 3)
def _voltage_riccati_ignores_the_data():
    # Pₙ et Kₙ de chaque exécution = la récurrence de Riccati scalaire écrite ici, sans aucune mesure
    grid = ki.slider_grid("tension-curseurs")
    for i, j in np.ndindex(*grid.shape):
        Q, R = grid.values_at(i, j)
        run = grid.run(i, j)
        P, Ps, Ks = 1.0, [], []
        for _ in range(grid.time.size):
            Pp = P + Q
            K = Pp / (Pp + R)
            P = (1 - K) * Pp
            Ps.append(P)
            Ks.append(K)
        np.testing.assert_allclose(run["P"], Ps, rtol=1e-9)
        np.testing.assert_allclose(run["K"], Ks, rtol=1e-9)


# =========================================================================== pratique et synthèse


def _practice(true_std, assumed_std):
    run = at("pratique-capteur", true_std=true_std, assumed_std=assumed_std)
    v = run["normalised"]
    inside = np.mean(np.abs(run["error"]) <= run["upper"])
    return run, float(v.std()), float(np.mean(np.abs(v) > 2)), float(inside)


@promise("pratique-synthese", 1, 1)
def _practice_optimistic_maker():
    run, std, outside, inside = _practice(1.58, 0.5)
    assert std > 2 and outside > 0.3  # bien plus souvent hors de ±2
    assert inside < 0.7  # l'erreur déborde de la bande
    lo, hi = y_axis("pratique-capteur", 0, true_std=1.58, assumed_std=0.5)
    assert lo <= run["normalised"].min() and run["normalised"].max() <= hi  # les innovations restent dans l'axe


@promise("pratique-synthese", 1, 2)
def _practice_cautious_filter():
    run, std, outside, inside = _practice(0.5, 1.58)
    good, _, _, good_inside = _practice(0.5, 0.5)
    assert std < 0.5 and outside == 0  # innovations bien trop petites, aucune hors de ±2
    assert inside > 0.98 > good_inside  # presque toute l'erreur dans la bande (99 % au lieu de 95 %)
    # la bande n'est qu'un peu trop large : l'erreur a grandi avec elle (le filtre lisse trop)
    assert rms(run["error"]) > 1.2 * rms(good["error"])
    ratio = np.mean(run["upper"] / 2) / rms(run["error"])
    assert 1.0 < ratio < 1.6
    assert "99,2\u00a0% des instants" in readout("pratique-capteur", true_std=0.5, assumed_std=1.58)


@promise("pratique-synthese", 1, 3)
def _practice_agreement_not_level():
    run, std, outside, inside = _practice(5.0, 5.0)
    assert 0.8 < std < 1.25 and 0.02 < outside < 0.1  # environ 5 % hors de ±2


# =========================================================================== tests statistiques


def _band():
    from kalman_course.diagnostics.consistency import chi2_band
    from kalman_course.scenarios.engine import CONSISTENCY_MC_RUNS

    return chi2_band(2, CONSISTENCY_MC_RUNS)


@promise("tests-statistiques", 1, 1)
def _consistency_optimistic():
    lo, hi = _band()
    run = at("tests-nees-nis", psi_factor=0.1)
    assert run["nees"][10:].mean() > 2 * hi and run["nis"][10:].mean() > 2 * hi


@promise("tests-statistiques", 1, 2)
def _consistency_pessimistic():
    lo, hi = _band()
    run = at("tests-nees-nis", psi_factor=1.0, phi_factor=10.0)
    assert run["nees"][10:].mean() < lo and run["nis"][10:].mean() < lo


@promise("tests-statistiques", 1, 3)
def _consistency_scale():
    base, scaled = at("tests-nees-nis"), at("tests-nees-nis", phi_factor=10.0, psi_factor=10.0)
    for key in ("nees", "nis"):
        ratio = scaled[key][10:].mean() / base[key][10:].mean()
        assert 0.08 < ratio < 0.12, f"{key} : rapport {ratio:.3f}"  # le dixième


# =========================================================================== EKF


@promise("ekf", 1, 1)
def _ekf_small_uncertainty():
    run = at("ekf-linearisation-curseurs", bearing_std_deg=2.5)
    size = np.ptp(run["exact_y"])
    gap = np.hypot(run["exact_mean_x"] - run["ekf_mean_x"], run["exact_mean_y"] - run["ekf_mean_y"])[0]
    assert gap < 0.01 * size  # les deux ellipses se confondent
    assert np.ptp(run["ekf_y"]) == pytest.approx(size, rel=0.02)


@promise("ekf", 1, 2)
def _ekf_large_uncertainty():
    for deg in (45.0, 60.0):
        run = at("ekf-linearisation-curseurs", bearing_std_deg=deg)
        s = math.radians(deg)
        # environ r̂ e^{-σ²/2} (la moyenne « exacte » de la figure est celle de 2 000 tirages)
        assert run["exact_mean_x"][0] == pytest.approx(10.0 * math.exp(-s * s / 2), rel=0.03)
        assert run["ekf_mean_x"][0] == pytest.approx(10.0)  # l'EKF propage f(x̂)
        assert run["ekf_bias"][0] > 1.0
        assert run["cloud_x"].mean() < 9.0  # le croissant recule


@promise("ekf", 1, 3)
def _ekf_flat_tangent():
    grid = ki.slider_grid("ekf-linearisation-curseurs")
    for sr in grid.axes[1].values:
        widths = [np.ptp(at("ekf-linearisation-curseurs", bearing_std_deg=d, range_std=sr)["ekf_x"])
                  for d in grid.axes[0].values]
        # en x, l'ellipse de l'EKF ne dépend que de σr (largeur 2 × 2σr), pas de σθ
        np.testing.assert_allclose(widths, 4 * sr, rtol=2e-3)
    run = at("ekf-linearisation-curseurs", bearing_std_deg=30.0)
    assert run["cloud_x"].max() <= 10.0 + 4 * ki.slider_grid("ekf-linearisation-curseurs").axes[1].default_value


# =========================================================================== suivi du tag


@promise("suivi-tag", 1, 1)
def _tag_overconfident():
    run = at("tag-curseurs", range_std="min")
    assert np.median(run["sigma"]) < 0.5 * np.median(run["err"])


@promise("suivi-tag", 1, 2)
def _tag_too_regular():
    base, stiff = at("tag-curseurs"), at("tag-curseurs", accel_std="min")
    assert rms(stiff["err"]) > 1.5 * rms(base["err"])


@promise("suivi-tag", 1, 3)
def _tag_ratio():
    grid = ki.slider_grid("tag-curseurs")
    i, j = grid.default_index
    base = grid.run(i, j)
    both = grid.run(i + 2, j + 2)  # deux crans chacun : même rapport σa/σr
    span = np.ptp(base["px"])
    assert rms(both["px"] - base["px"]) < 0.1 * span and rms(both["py"] - base["py"]) < 0.1 * span
    assert np.median(both["sigma"]) > 2.5 * np.median(base["sigma"])  # l'écart-type annoncé grandit


# =========================================================================== EKF itéré


@promise("ekf-itere", 1, 1)
def _iekf_iterate():
    run = at("ekf-itere-curseurs")
    d = run["distance"]
    assert 0.4 < d[1] < 1.0  # l'EKF tombe à environ 0,7 m du MAP
    assert d[2] < 0.1 * d[1] and d[3] < 0.01 * d[2]  # chute de plusieurs ordres de grandeur par pas
    assert d[-1] < 1e-9  # jusqu'au seuil d'arrêt


@promise("ekf-itere", 1, 2)
def _iekf_confident_wrong_prior():
    from kalman_course.scenarios.radar_prior import radar_problem_with_prior

    run = at("ekf-itere-curseurs", prior_std=0.3)
    truth = np.array([run["truth_x"][0], run["truth_y"][0]])
    assert np.linalg.norm(radar_problem_with_prior(0.3).x_pred - truth) > 3.0  # l'a priori, à plus de 3 m
    map_to_truth = np.hypot(run["map_x"][0] - truth[0], run["map_y"][0] - truth[1])
    assert 0.3 < map_to_truth < 0.5  # le MAP reste à environ 40 cm
    assert run["distance"][-1] < 1e-9  # l'EKF itéré converge vers le MAP


@promise("ekf-itere", 1, 3)
def _iekf_vague_prior():
    run = at("ekf-itere-curseurs", prior_std=30.0)
    map_to_truth = np.hypot(run["map_x"][0] - run["truth_x"][0], run["map_y"][0] - run["truth_y"][0])
    ekf_to_truth = np.hypot(run["ekf_x"][0] - run["truth_x"][0], run["ekf_y"][0] - run["truth_y"][0])
    assert 0.1 < map_to_truth < 0.3  # une vingtaine de centimètres (le bruit du capteur)
    assert ekf_to_truth > 3 * map_to_truth  # l'EKF reste loin


# =========================================================================== UKF


def _ellipse_area(x, y) -> float:
    return 0.5 * abs(np.dot(x, np.roll(y, 1)) - np.dot(y, np.roll(x, 1)))


def _inside_ellipse(px, py, ex, ey) -> np.ndarray:
    from matplotlib.path import Path as MplPath

    return MplPath(np.column_stack([ex, ey])).contains_points(np.column_stack([px, py]))


@promise("ukf", 1, 1)
def _ukf_small_bearing_uncertainty():
    small = at("ukf-banane-incertitude", bearing_std=2.5)
    size = np.ptp(small["truth_x"])
    truth_area = _ellipse_area(small["truth_x"], small["truth_y"])
    for method in ("lin", "ut"):  # les ellipses se confondent : même centre, même aire, même largeur
        gap = np.hypot(small[f"{method}_mx"][0] - small["truth_mx"][0], small[f"{method}_my"][0] - small["truth_my"][0])
        assert gap < 0.01 * size, method
        assert _ellipse_area(small[f"{method}_x"], small[f"{method}_y"]) == pytest.approx(truth_area, rel=0.03), method
        assert np.ptp(small[f"{method}_x"]) == pytest.approx(size, rel=0.01), method


@promise("ukf", 1, 2)
def _ukf_large_bearing_uncertainty():
    big = at("ukf-banane-incertitude", bearing_std=40.0)
    lin_mean = np.hypot(big["lin_mx"][0], big["lin_my"][0])
    assert lin_mean == pytest.approx(1.0)  # la moyenne linéarisée reste sur l'arc, à 1 m…
    assert big["truth_my"][0] < 0.85  # … loin de la moyenne vraie du nuage
    ut_gap = np.hypot(big["ut_mx"][0] - big["truth_mx"][0], big["ut_my"][0] - big["truth_my"][0])
    assert ut_gap < 0.03  # l'UKF suit la moyenne (à moins de 3 cm)
    inside = _inside_ellipse(big["cloud_x"], big["cloud_y"], big["ut_x"], big["ut_y"]).mean()
    assert inside > 0.9  # et son ellipse englobe le nuage
    # l'ellipse de l'EKF n'a que l'épaisseur radiale de σr : 2 × 2σr = 8 cm
    sr = ki.slider_grid("ukf-banane-incertitude").axes[1].default_value
    assert np.ptp(big["lin_y"]) == pytest.approx(4 * sr, rel=0.01)
    text = readout("ukf-banane-incertitude", bearing_std=40.0)
    assert "EKF (0 ; 1) m" in text and "UKF" in text  # les moyennes se lisent sous les curseurs


@promise("ukf", 2, 1)
def _ukf_small_alpha():
    tight, base = at("ukf-banane-parametres", alpha=0.1), at("ukf-banane-parametres")
    spread = lambda r: np.hypot(r["sig_x"] - r["ut_mx"], r["sig_y"] - r["ut_my"]).max()  # noqa: E731
    assert spread(tight) < 0.2 * spread(base)  # les points sigma se resserrent
    assert _ellipse_area(tight["ut_x"], tight["ut_y"]) < _ellipse_area(base["ut_x"], base["ut_y"])


@promise("ukf", 2, 2)
def _ukf_kappa():
    axis = ki.slider_grid("ukf-banane-parametres").axes[1]
    base = at("ukf-banane-parametres")
    low = at("ukf-banane-parametres", kappa=2 - 1.5)  # valeurs de la grille : n + κ, n = 2
    high = at("ukf-banane-parametres", kappa=2 + 4.0)
    assert axis.labels()[0].startswith("−1,5") and axis.labels()[-1].startswith("4")
    area = lambda r: _ellipse_area(r["ut_x"], r["ut_y"])  # noqa: E731
    assert area(high) > 1.1 * area(base)  # κ = 4 : les points voient les bouts de la banane
    spread = lambda r: np.hypot(r["sig_x"] - r["ut_mx"], r["sig_y"] - r["ut_my"]).max()  # noqa: E731
    assert spread(low) < spread(base) < spread(high)


# =========================================================================== filtre particulaire


def _pf(**values):
    return at("filtre-particulaire-curseurs", **values)


@promise("filtre-particulaire", 1, 1)
def _pf_particle_count():
    few, hundred = _pf(n_particles=10.0), _pf(n_particles=100.0)
    assert np.mean(np.abs(few["gap"]) > few["hi"]) > 0.1  # 10 particules : sort souvent de la bande
    assert np.abs(hundred["gap"]).max() < 0.5 * hundred["hi"].min()  # dès 100 : petit devant l'écart-type
    ratio = rms(hundred["gap"]) / rms(_pf(n_particles=10000.0)["gap"])
    assert 4 < ratio < 25  # en 1/√N : ×100 particules, écart divisé par environ 10


@promise("filtre-particulaire", 1, 2)
def _pf_precise_measurement():
    sharp, base = _pf(R=0.01), _pf()
    assert np.median(sharp["ess"]) < 0.7 * np.median(base["ess"])  # l'ESS relative baisse nettement
    assert np.mean(sharp["ess"] < 0.5) > 0.8  # rééchantillonnage presque à chaque pas (ESS < N/2)


@promise("filtre-particulaire", 1, 3)
def _pf_more_particles():
    big, mid = _pf(R=0.01, n_particles=10000.0), _pf(R=0.01, n_particles=1000.0)
    assert abs(np.median(big["ess"]) - np.median(mid["ess"])) < 0.05  # l'ESS relative ne change guère
    assert rms(big["gap"]) < 0.7 * rms(mid["gap"])  # l'écart se resserre
    for n in (1000.0, 10000.0):  # l'axe montre la bande ±0,2 m (la moitié de sa hauteur au moins)
        lo, hi = y_axis("filtre-particulaire-curseurs", 0, R=0.01, n_particles=n)
        assert (hi - lo) < 4 * big["hi"].max()


# =========================================================================== EnKF


@promise("enkf", 1, 1)
def _enkf_without_perturbations():
    ratios = [at("enkf-ensemble", n_members=n, perturb=0.0)["ratio"][0]
              for n in ki.slider_grid("enkf-ensemble").axes[0].values]
    assert max(ratios) < 0.5  # moins de la moitié de la variance du filtre de Kalman
    assert max(ratios) / min(ratios) < 1.5  # et ce rapport ne dépend pas de N


@promise("enkf", 1, 2)
def _enkf_small_ensemble():
    def wobble(n):
        run = at("enkf-ensemble", n_members=n, perturb=1.0)
        return float(np.std(run["ensemble"] / run["kalman"]))

    assert wobble(10.0) > 3 * wobble(800.0)


@promise("enkf", 1, 3)
def _enkf_large_ensemble():
    big = at("enkf-ensemble", n_members=800.0, perturb=1.0)
    small = at("enkf-ensemble", n_members=10.0, perturb=1.0)
    dev = lambda r: rms(r["ensemble"] / r["kalman"] - 1)  # noqa: E731
    assert dev(big) < 0.1  # la courbe orange se cale sur la noire
    assert 3 < dev(small) / dev(big) < 30  # en 1/√N : √80 ≈ 9


# =========================================================================== lissage


def _nile(**values):
    return at("nil-curseurs", **values)


@promise("lissage", 1, 1)
def _nile_frozen_level():
    run = _nile(Q="min")
    y = run["y"]
    assert np.ptp(run["xs"]) < 0.02 * np.nanmean(y)  # une droite horizontale…
    assert run["xs"].mean() == pytest.approx(np.nanmean(y), rel=0.02)  # … la moyenne de toutes les mesures
    observed = np.isfinite(y)
    running = np.cumsum(np.where(observed, y, 0)) / np.maximum(np.cumsum(observed), 1)
    assert rms((run["xf"] - running)[20:]) < 0.03 * np.nanmean(y)  # une moyenne qui se stabilise


@promise("lissage", 1, 2)
def _nile_wild_level():
    run = _nile(Q="max")
    y = run["y"]
    ok = np.isfinite(y)
    spread = rms(y[ok] - y[ok].mean())
    assert rms(run["xf"][ok] - y[ok]) < 0.3 * spread and rms(run["xs"][ok] - y[ok]) < 0.3 * spread


@promise("lissage", 1, 3)
def _nile_missing_years():
    run = _nile()
    y = run["y"]
    gaps = np.flatnonzero(np.isnan(y))
    first_gap = gaps[: np.argmax(np.diff(gaps) > 1) + 1] if np.any(np.diff(gaps) > 1) else gaps
    a, b = first_gap[0], first_gap[-1]
    assert np.ptp(run["xf"][a:b + 1]) < 1e-9 * run["xf"][a]  # le niveau filtré reste figé
    assert np.all(np.diff(run["sf"][a:b + 1]) > 0)  # son écart-type grandit
    ss = run["ss"][a:b + 1]
    middle = int(np.argmax(ss))
    assert 0 < middle < len(ss) - 1 and ss[middle] > 1.2 * max(ss[0], ss[-1])  # en lentille
    lo, hi = sorted((run["xs"][a - 1], run["xs"][b + 1]))
    assert np.all((run["xs"][a:b + 1] >= lo - 1e-6) & (run["xs"][a:b + 1] <= hi + 1e-6))  # joint les bords


@promise("lissage", 1, 4)
def _nile_scale_free_levels():
    grid = ki.slider_grid("nil-curseurs")
    i, j = grid.default_index
    base, both = grid.run(i, j), grid.run(i + 1, j + 1)
    assert grid.axes[0].values[i + 1] / grid.axes[0].values[i] == pytest.approx(
        grid.axes[1].values[j + 1] / grid.axes[1].values[j])  # un cran chacun : même rapport
    np.testing.assert_allclose(both["xf"], base["xf"], rtol=1e-8)  # les niveaux ne bougent pas
    np.testing.assert_allclose(both["xs"], base["xs"], rtol=1e-8)
    factor = math.sqrt(grid.axes[0].values[i + 1] / grid.axes[0].values[i])
    np.testing.assert_allclose(both["ss"] / base["ss"], factor, rtol=1e-8)  # écarts-types × √facteur


# =========================================================================== vraisemblance


def _ll(**values):
    run = at("vraisemblance-nil", **values)
    v = run["normalised"][np.isfinite(run["normalised"])]
    return run, v


@promise("vraisemblance", 1, 1)
def _likelihood_frozen_level():
    (best, _), (run, v) = _ll(), _ll(Q="min")
    drop = best["ll_now"][0] - run["ll_now"][0]
    assert 20 < drop < 40  # une trentaine de nats
    assert lag1(v) > 0.3  # innovations corrélées d'une année à l'autre
    after = run["normalised"][run["t"] > 1899]
    assert np.mean(after[np.isfinite(after)] < 0) > 0.6  # du même signe après la rupture
    lo, hi = y_axis("vraisemblance-nil", 0, Q="min")
    assert lo <= run["ll_now"][0] <= hi  # le point rouge reste dans l'axe


@promise("vraisemblance", 1, 2)
def _likelihood_wild_level():
    (best, _), (run, v) = _ll(), _ll(Q="max")
    assert v.std() < 0.6  # bien en dessous de 1
    assert lag1(v) < -0.1  # corrélées négativement
    assert best["ll_now"][0] - run["ll_now"][0] > 20  # la vraisemblance baisse aussi
    lo, hi = y_axis("vraisemblance-nil", 0, Q="max")
    assert lo <= run["ll_now"][0] <= hi


@promise("vraisemblance", 1, 3)
def _likelihood_scale():
    grid = ki.slider_grid("vraisemblance-nil")
    i, j = grid.default_index
    best, both = grid.run(i, j), grid.run(i + 1, j + 1)
    v = both["normalised"][np.isfinite(both["normalised"])]
    assert v.std() < 0.8  # sous 1
    assert 15 < best["ll_now"][0] - both["ll_now"][0] < 30  # une vingtaine de nats
    for index in ((0, j), (grid.shape[0] - 1, j), (i, 0), (i, grid.shape[1] - 1)):  # bouts des curseurs
        lo, hi = _static("vraisemblance-nil").y_range_at(0, *index)
        assert lo <= grid.run(*index)["ll_now"][0] <= hi


# =========================================================================== SRIF


def _srif(k):
    return at("srif-a-priori", exponent=float(k))


@promise("srif", 1, 1)
def _srif_small_prior():
    run = _srif(2)
    kf = run["kf"][np.isfinite(run["kf"])]
    assert 1e-7 < run["raw_max"][0] < 1e-5  # de l'ordre du micromètre
    assert kf[0] > 100 * kf[10]  # s'efface à mesure que les relevés arrivent
    # un biais en 10⁻ᵏ : divisé par 10 à chaque cran de k jusqu'à k = 5
    for k in (2, 3, 4):
        assert _srif(k)["raw_max"][0] / _srif(k + 1)["raw_max"][0] == pytest.approx(10.0, rel=0.05)
    srif = ki.slider_spec("srif-a-priori").fixed["srif"]
    assert run["raw_max"][0] > 1e6 * np.nanmax(srif)  # bien plus que le SRIF…
    assert run["raw_max"][0] < 1e-3  # … mais minuscule devant le bruit de mesure (1 mm)


@promise("srif", 1, 2)
def _srif_large_prior():
    best = min(_srif(k)["raw_max"][0] for k in range(2, 10))
    assert _srif(12)["failed"][0] == 1.0  # le filtre s'arrête (croix rouge)
    assert any(_srif(k)["failed"][0] for k in range(12, 17))
    for k in (10, 11):
        assert _srif(k)["raw_max"][0] > 1e4 * best  # les chiffres significatifs perdus


@promise("srif", 1, 3)
def _srif_srif():
    srif = ki.slider_spec("srif-a-priori").fixed["srif"]
    assert np.nanmax(srif) < 1e-12  # à l'arrondi de la double précision
    grid = ki.slider_grid("srif-a-priori")
    best = np.nanmin(grid.series["raw_max"])
    assert np.nanmax(srif) < best / 100  # mieux que le filtre de Kalman, quel que soit k


# =========================================================================== EKF itéré sur SE(3)


@promise("ekf-itere-se3", 1, 1)
def _se3_iterate():
    run = at("se3-bruit-pixels", sigma_px=1.0)
    a, p = run["angle"], run["position"]
    assert a[0] == pytest.approx(10.0, rel=0.01) and p[0] == pytest.approx(20.0, rel=0.01)  # 10° et 20 cm
    assert a[1] < 0.1 * a[0] and p[1] < 0.1 * p[0]  # l'EKF en efface l'essentiel d'un coup
    assert a[2] < a[1]  # l'itération suivante corrige encore l'orientation…
    assert p[2] < 0.1 * p[0]  # … la position reste de l'ordre du centimètre
    n = int(run["n_iter"][0])
    assert np.all(a[n:] == a[n]) and n <= 8  # puis l'EKF itéré s'arrête (convergé)


@promise("ekf-itere-se3", 1, 2)
def _se3_noisy_pixels():
    base, noisy = at("se3-bruit-pixels", sigma_px=1.0), at("se3-bruit-pixels", sigma_px=10.0)
    assert 2.0 < noisy["angle"][-1] < 4.0 and 4.0 < noisy["position"][-1] < 8.0  # près de 3°, environ 6 cm
    assert noisy["angle"][-1] > 3 * base["angle"][-1]
    assert noisy["n_iter"][0] >= 1.5 * base["n_iter"][0]  # environ deux fois plus d'itérations


@promise("ekf-itere-se3", 1, 3)
def _se3_precise_pixels():
    base, fine = at("se3-bruit-pixels", sigma_px=1.0), at("se3-bruit-pixels", sigma_px=0.1)
    assert fine["angle"][-1] < 0.3 * base["angle"][-1] and fine["position"][-1] < 0.3 * base["position"][-1]


# =========================================================================== plusieurs capteurs, temps irrégulier


def _helicopter():
    from kalman_course.scenarios import helicopter as heli

    track = heli.helicopter_track("position")
    rows = np.asarray(track.position_rows)
    return heli, track, rows, np.flatnonzero(rows)[list(heli.OUTLIER_ROWS)]


@promise("capteurs-temps-irregulier", 1, 1)
def _gate_removed():
    _, _, _, bad = _helicopter()
    free, gated = at("capteurs-porte-curseurs", gate=1.0), at("capteurs-porte-curseurs")
    assert free["n_rejected"][0] == 0 and gated["n_outliers"][0] == 6  # la porte les écartait toutes
    for j, k in enumerate(bad):  # à chaque croix rouge, l'estimation sans porte part vers elle
        hook = 1e3 * np.array([free["est_e"][k] - gated["est_e"][k], free["est_n"][k] - gated["est_n"][k]])
        toward = 1e3 * np.array([free["out_e"][j] - gated["est_e"][k], free["out_n"][j] - gated["est_n"][k]])
        assert np.linalg.norm(hook) > 0.5 * np.linalg.norm(toward), f"position {k}"  # plus de la moitié du chemin
        assert hook @ toward > 0.9 * np.linalg.norm(hook) * np.linalg.norm(toward), f"position {k}"


@promise("capteurs-temps-irregulier", 1, 2)
def _gate_tight():
    _, track, rows, bad = _helicopter()
    assert np.isnan(at("capteurs-porte-curseurs", gate=0.999)["lost"][0])  # p = 0,999 : jamais perdue
    tight = at("capteurs-porte-curseurs", gate=0.9)
    lost = tight["lost"][0]
    assert 50.0 <= lost <= 60.0  # à la fin de la première minute
    # … pendant un virage serré : le cap des positions mesurées tourne de plus de 30° entre 55 et 65 s
    t, y = np.asarray(track.t)[rows], np.asarray(track.y)[rows]
    heading = np.unwrap(np.arctan2(np.gradient(y[:, 1], t), np.gradient(y[:, 0], t)))
    window = (t >= 55.0) & (t < 65.0)
    assert abs(np.degrees(heading[window][-1] - heading[window][0])) > 30.0
    good = rows.copy()
    good[bad] = False
    before = good & (np.asarray(track.t) < lost)
    assert np.mean(np.isfinite(tight["rej_n"][before])) <= 0.1  # avant, pas plus d'une bonne mesure sur dix
    assert tight["n_rejected"][0] > 0.5 * rows.sum()  # après, les rejets s'enchaînent


@promise("capteurs-temps-irregulier", 1, 3)
def _gate_small_q():
    _, track, rows, _ = _helicopter()
    run = at("capteurs-porte-curseurs", gate=0.999, q="min")
    q = ki.slider_grid("capteurs-porte-curseurs").axes[1]
    assert q.values[0] == pytest.approx(q.values[q.default] / 100)  # q divisé par 100
    lost = run["lost"][0]
    assert lost < 15.0  # la piste se perd tôt…
    t, nis = np.asarray(track.t), run["nis"]
    seen = rows & (t <= lost + 2.0)  # … avant le premier virage : le cap mesuré n'a pas encore tourné
    step = np.diff(np.asarray(track.y)[seen][:, :2], axis=0)
    heading = np.degrees(np.unwrap(np.arctan2(step[:, 1], step[:, 0])))
    assert np.ptp(heading) < 10.0
    ok = np.isfinite(nis)
    assert np.median(nis[ok & (t < lost)]) < 3.0  # avant : la NIS d'un filtre qui suit (2 attendu)
    assert np.max(nis[ok]) > 1e3  # des milliers
    late = ok & (t > t.max() / 2)
    assert np.median(nis[late]) > 100 * np.median(nis[ok & (t < lost)])  # et elle grimpe


@promise("capteurs-temps-irregulier", 1, 4)
def _gate_tight_large_q():
    q = ki.slider_grid("capteurs-porte-curseurs").axes[1]
    assert q.values[-1] == pytest.approx(10 * q.values[q.default])  # q multiplié par 10
    run, base = at("capteurs-porte-curseurs", gate=0.9, q="max"), at("capteurs-porte-curseurs")
    assert run["n_outliers"][0] == 6 and run["n_rejected"][0] == 7  # les six aberrations et une position
    assert np.isnan(run["lost"][0])
    assert run["rms"][0] > base["rms"][0]  # l'estimation tremble un peu plus


# =========================================================================== cibles qui manœuvrent


def _manoeuvre():
    from kalman_course.scenarios import manoeuvre as man

    study = man.manoeuvre_study()
    return man, study, (study.t > 10.0) & ~study.turning


@promise("cibles-manoeuvrantes", 1, 1)
def _fading_none():
    _, study, _ = _manoeuvre()
    run = at("manoeuvre-oubli-curseurs", alpha=1.0)
    turn = study.turning
    assert np.mean(run["err"][turn] > run["sd"][turn]) > 0.9  # l'erreur passe le 2σ dans presque tout virage
    assert run["err"].max() > 5 * run["sd"].max()  # de loin
    assert y_axis("manoeuvre-oubli-curseurs", 1, alpha=1.0)[1] >= run["err"].max()  # et on la voit
    measured = rms(np.hypot(*(study.y[:, :2] - study.truth[:, :2]).T))
    assert rms(run["err"][turn]) > 5 * measured  # le virage est coupé : bien pire que les relevés


@promise("cibles-manoeuvrantes", 1, 2)
def _fading_moderate():
    _, study, straight = _manoeuvre()
    runs = {a: at("manoeuvre-oubli-curseurs", alpha=a) for a in (1.0, 1.2, 1.5)}
    for run in runs.values():  # la lecture est celle des courbes
        assert run["rms"][0] == pytest.approx(rms(run["err"][straight]))
        assert run["rms"][1] == pytest.approx(rms(run["err"][study.turning]))
    assert runs[1.5]["rms"][1] < runs[1.2]["rms"][1] < 0.2 * runs[1.0]["rms"][1]  # virages : de mieux en mieux
    assert runs[1.2]["rms"][0] < 0.5 * runs[1.0]["rms"][0]  # ligne droite : gain de 1 à 1,2
    assert runs[1.5]["rms"][0] > 1.2 * runs[1.2]["rms"][0]  # … puis l'erreur y remonte


@promise("cibles-manoeuvrantes", 1, 3)
def _fading_strong():
    man, study, straight = _manoeuvre()
    run, mild = at("manoeuvre-oubli-curseurs", alpha=2.0), at("manoeuvre-oubli-curseurs", alpha=1.2)
    one_reading = 2 * math.sqrt(2) * man.POSITION_STD  # 2σ d'un relevé (deux axes de σ chacun)
    assert np.median(run["sd"][straight]) == pytest.approx(one_reading, rel=0.05)
    # l'estimation tremble comme les relevés
    assert roughness(run["est_e"]) > 0.8 * roughness(run["meas_e"])
    assert roughness(run["est_e"]) > 2 * roughness(mild["est_e"])
    assert run["rms"][0] > 1.4 * mild["rms"][0]


def _rise_times(run, study, man) -> list[float]:
    """Secondes entre le début de chaque virage et le premier pas où μ(agité) dépasse 1/2."""
    out = []
    for start, _, _ in man.TURNS:
        k = np.flatnonzero((study.t >= start) & (run["mu"] > 0.5))
        out.append(float(study.t[k[0]] - start) if k.size else math.inf)
    return out


@promise("cibles-manoeuvrantes", 2, 1)
def _imm_switch():
    _, _, straight = _manoeuvre()
    sticky, loose = at("manoeuvre-imm-curseurs", switch=0.005), at("manoeuvre-imm-curseurs", switch=0.2)
    assert np.mean(sticky["mu"][straight]) < 0.2  # collante : μ(agité) reste basse en ligne droite
    assert np.mean(loose["mu"][straight]) > 3 * np.mean(sticky["mu"][straight])  # avec 0,2, elle monte
    assert loose["rms"][0] > 1.3 * sticky["rms"][0]  # et l'erreur hors des virages avec elle
    assert roughness(loose["est_e"]) > roughness(sticky["est_e"])  # l'estimation tremble plus


@promise("cibles-manoeuvrantes", 2, 2)
def _imm_rise():
    man, study, _ = _manoeuvre()
    for switch in ki.slider_grid("manoeuvre-imm-curseurs").axes[0].values:
        rises = _rise_times(at("manoeuvre-imm-curseurs", switch=switch), study, man)
        assert max(rises) <= 8.0, f"π = {switch} : {rises}"  # quelques secondes, quelle que soit π


@promise("cibles-manoeuvrantes", 2, 3)
def _imm_quiet_manoeuvre_regime():
    base = at("manoeuvre-imm-curseurs", switch=0.05, q_quiet=0.05)
    weak = at("manoeuvre-imm-curseurs", switch=0.05, q_quiet=0.05, q_manoeuvre=2.0)
    assert weak["rms"][1] > 1.5 * base["rms"][1]  # l'erreur dans les virages double presque
    assert weak["err"].max() > 1.2 * base["err"].max()  # l'IMM décroche


# =========================================================================== filtrer en parallèle


def _blelloch_combinations(T: int) -> int:
    """Combinaisons du balayage de Blelloch, comptées ici : T − 1 à la montée, T − 1 − ⌊log₂ T⌋ à la
    descente (environ 2T)."""
    return 2 * (T - 1) - int(math.floor(math.log2(T)))


@promise("filtrage-parallele", 1, 1)
def _parallel_one_processor():
    from kalman_course.interactive.parallel import LENGTHS

    for c in ki.slider_grid("parallele-processeurs").axes[1].values:
        run = at("parallele-processeurs", processors=1, cost=c)
        assert np.all(run["parallel"] > run["sequential"])  # la bleue toujours au-dessus de la rouge
        assert np.all(run["speedup"] < 1)
        expected = c * np.array([_blelloch_combinations(int(T)) for T in LENGTHS])
        np.testing.assert_allclose(run["parallel"], expected, rtol=0.1)  # environ 2T combinaisons de coût c
        assert run["parallel"][-1] == pytest.approx(2 * c * LENGTHS[-1], rel=0.01)
        lo, hi = y_axis("parallele-processeurs", 0, processors=1, cost=c)
        assert lo <= run["sequential"].min() and run["parallel"].max() <= hi  # dans l'axe


@promise("filtrage-parallele", 1, 2)
def _parallel_gpu():
    from kalman_course.interactive.parallel import LENGTHS

    cost = ki.slider_grid("parallele-processeurs").axes[1]
    c = float(cost.values[cost.default])
    for P in (1024, 100_000):
        run = at("parallele-processeurs", processors=P)
        few = (LENGTHS >= 100) & (LENGTHS <= P)  # T petit devant P : environ 2c log₂ T
        ratio = run["parallel"][few] / (2 * c * np.log2(LENGTHS[few]))
        assert np.all((ratio > 0.75) & (ratio < 1.1))
        assert np.all(np.diff(run["speedup"]) >= -1e-9 * run["speedup"][1:])  # l'accélération croît
    gpu = at("parallele-processeurs", processors=1024)
    assert gpu["speedup"][-1] == pytest.approx(1024 / (2 * c), rel=0.05)  # T ≫ P : plafond P/(2c)
    assert gpu["speedup"][-1] < 1.2 * gpu["speedup"][np.searchsorted(LENGTHS, 1e5)]  # il plafonne
    assert at("parallele-processeurs", processors=100_000)["speedup"][-1] > 10 * gpu["speedup"][-1]


@promise("filtrage-parallele", 1, 3)
def _parallel_short_series():
    from kalman_course.interactive.parallel import LENGTHS

    run = at("parallele-processeurs", processors=1024)
    short = LENGTHS <= 100
    assert np.all(run["parallel"][short] <= 30) and run["sequential"][short].max() <= 100  # quelques dizaines
    assert np.all(run["speedup"][short] < 5)  # le gain est faible
    assert run["speedup"][np.searchsorted(LENGTHS, 1e4)] > 20 * run["speedup"][short].max()  # à côté des longues


# =========================================================================== un seul filtre gaussien


def _to_polyline(points: np.ndarray, line: np.ndarray) -> np.ndarray:
    """Distance de chaque point (N, 2) à la ligne brisée ``line`` (M, 2)."""
    a, b = line[:-1], line[1:]
    ab = b - a
    t = np.clip(np.einsum("pmk,mk->pm", points[:, None, :] - a[None], ab) / np.einsum("mk,mk->m", ab, ab), 0, 1)
    nearest = a[None] + t[..., None] * ab[None]
    return np.min(np.linalg.norm(points[:, None, :] - nearest, axis=-1), axis=1)


def _contour_gap(run, key: str) -> float:
    """Écart (m, distance de Hausdorff) entre le contour de la règle ``key`` et celui de la vérité."""
    rule = np.column_stack([run[f"{key}_x"], run[f"{key}_y"]])
    truth = np.column_stack([run["truth_x"], run["truth_y"]])
    return float(max(_to_polyline(rule, truth).max(), _to_polyline(truth, rule).max()))


@promise("filtre-gaussien", 1, 1)
def _gaussian_large_uncertainty():
    run = at("gaussien-banane-regles", bearing_std=60.0)
    s = math.radians(60.0)
    assert run["truth_my"][0] == pytest.approx(math.exp(-s ** 2 / 2), rel=1e-3)  # E[sin θ] = e^{−σ²/2}
    assert math.hypot(run["lin_mx"][0], run["lin_my"][0]) == pytest.approx(1.0)  # sur l'arc (r = 1 m)
    assert run["lin_err"][0] > 0.3  # à plusieurs décimètres de la vraie
    assert np.ptp(run["lin_y"]) < 0.1 * np.ptp(run["truth_y"])  # une ellipse plate
    assert 0.01 < run["ckf_err"][0] < 0.05  # quelques centimètres
    assert run["gh_err"][0] < 0.01  # moins d'un centimètre (p = 3 par défaut)
    assert np.ptp(run["gh_y"]) > 1.1 * np.ptp(run["truth_y"])  # mais son ellipse déborde
    (x0, x1), (y0, y1) = _static("gaussien-banane-regles").ranges_at(0, *position("gaussien-banane-regles",
                                                                                    bearing_std=60.0))
    assert x0 <= run["lin_x"].min() and run["lin_x"].max() <= x1 and y0 <= run["gh_y"].min()  # tout est visible
    # le nuage gris est celui de 60° (issue 36) : sa moyenne est la vraie, à l'erreur de Monte-Carlo près
    cloud = np.column_stack([run["cloud_x"], run["cloud_y"]])
    assert np.all(np.abs(cloud.mean(axis=0) - [run["truth_mx"][0], run["truth_my"][0]])
                  < 4 * cloud.std(axis=0) / np.sqrt(len(cloud)))
    assert np.ptp(run["cloud_x"]) > 1.5  # il fait plus du demi-cercle (r = 1 m)


@promise("filtre-gaussien", 1, 2)
def _gaussian_order():
    runs = {p: at("gaussien-banane-regles", bearing_std=60.0, order=p) for p in (2, 3, 4, 5, 8)}
    assert runs[2]["gh_err"][0] > 2 * runs[2]["ckf_err"][0]  # p = 2 se trompe davantage que la cubature
    errors = [runs[p]["gh_err"][0] for p in (2, 3, 4, 5, 8)]
    assert all(b < a for a, b in zip(errors, errors[1:]))  # chaque ordre de plus gagne
    assert _contour_gap(runs[8], "gh") < 0.01 * np.ptp(runs[8]["truth_x"])  # p = 8 : la violette couvre la noire
    assert "8² = 64 points" in readout("gaussien-banane-regles", bearing_std=60.0, order=8)


@promise("filtre-gaussien", 1, 3)
def _gaussian_small_uncertainty():
    run = at("gaussien-banane-regles", bearing_std=5.0)
    size = np.ptp(run["truth_x"])
    for key in ("lin", "ckf", "gh"):  # toutes les ellipses se confondent
        assert _contour_gap(run, key) < 0.05 * size, key
    assert run["lin_err"][0] < 0.05 * size  # même la moyenne linéarisée est à sa place, à cette échelle


# =========================================================================== quel filtre choisir ?

_GAUSSIAN_FILTERS = ("ekf", "iekf", "ukf", "ckf", "ghkf")


def _in_band(run, key: str) -> np.ndarray:
    return (run[f"{key}_nees"] >= run["band_lo"]) & (run[f"{key}_nees"] <= run["band_hi"])


@promise("quel-filtre", 1, 1)
def _choice_small_uncertainty():
    from kalman_course.scenarios.filter_choice import CHOICE_RUNS

    run = at("choix-incertitude", prior_std=10.0)
    lo, hi = scipy.stats.chi2.ppf([0.025, 0.975], 4 * CHOICE_RUNS) / CHOICE_RUNS  # bande de la NEES moyenne
    assert (run["band_lo"][0], run["band_hi"][0]) == pytest.approx((lo, hi))
    for key in _GAUSSIAN_FILTERS + ("enkf",):
        assert np.mean(_in_band(run, key)) >= 0.95, key  # dans la bande verte
    ref = run["ekf_nees"]
    for key in _GAUSSIAN_FILTERS:
        np.testing.assert_allclose(run[f"{key}_nees"], ref, rtol=0.05)  # superposées
    assert np.all(run["pf_nees"] > 100 * hi)  # le filtre particulaire à part


@promise("quel-filtre", 1, 2)
def _choice_where_each_breaks():
    hundred, three, thousand = (at("choix-incertitude", prior_std=s) for s in (100.0, 300.0, 1000.0))
    assert hundred["ekf_nees"][0] > 100 and np.mean(_in_band(hundred, "ekf")) < 0.5  # l'EKF sort nettement
    for key in ("ukf", "ckf"):  # l'UKF et la cubature un peu, au début
        assert hundred["band_hi"][0] < hundred[f"{key}_nees"][0] < 10
        assert np.mean(_in_band(hundred, key)) < 0.75
    for key in ("ghkf", "enkf"):
        assert np.mean(_in_band(hundred, key)) >= 0.95, key
    for key in ("ukf", "ckf", "ghkf", "enkf"):  # à 300 m, tous sortent au début de la série
        assert three[f"{key}_nees"][:10].max() > 100, key
    for s in (10.0, 100.0, 300.0, 1000.0):  # l'EKF itéré reste dans la bande
        assert np.mean(_in_band(at("choix-incertitude", prior_std=s), "iekf")) >= 0.95, s
    assert np.mean(_in_band(thousand, "ukf")) >= 0.9  # à 1 km, l'UKF y revient
    assert thousand["ckf_nees"].max() > 1e3 and thousand["ekf_nees"].min() > 1e3


@promise("quel-filtre", 1, 3)
def _choice_particle_filter():
    for s in ki.slider_grid("choix-incertitude").axes[0].values:
        run = at("choix-incertitude", prior_std=s)
        assert np.all(run["pf_nees"] > run["band_hi"]), s  # partout hors de la bande
        assert run["pf_rmse"][0] > 10 * run["iekf_rmse"][0], s  # et loin de la cible


# =========================================================================== filtrage invariant (issue 35)

_INV = "invariant-curseurs"


def _inv(**values):
    run = at(_INV, **values)
    return {k: float(run[k][0]) for k in ("inv_nees_mean", "std_nees_mean", "inv_rmse_mean", "std_rmse_mean")}


@promise("filtrage-invariant", 1, 1)
def _invariant_heading():
    runs = [_inv(heading_std=h) for h in (0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0)]
    std = [r["std_nees_mean"] for r in runs]
    assert 0.5 < runs[0]["std_nees_mean"] < 1.5 and 0.5 < runs[0]["inv_nees_mean"] < 1.5  # à 0°, cohérents
    assert abs(runs[0]["std_rmse_mean"] - runs[0]["inv_rmse_mean"]) < 1e-3  # et confondus
    assert runs[1]["std_nees_mean"] > 1.5  # dès 15°, la NEES de l'EKF standard dépasse 1
    assert all(b > a for a, b in zip(std[1:], std[2:]))  # puis grimpe…
    assert 1e3 < std[-1] < 1e4  # … jusqu'à plus d'un millier à 90°
    assert all(0.5 < r["inv_nees_mean"] < 1.5 for r in runs)  # l'EKF invariant reste près de 1
    assert "EKF invariant" in readout(_INV, heading_std=90.0) and "NEES" in readout(_INV, heading_std=90.0)


@promise("filtrage-invariant", 1, 2)
def _invariant_gnss_period():
    fast, slow = _inv(heading_std=45.0, gnss_period=0.4), _inv(heading_std=45.0, gnss_period=2.0)
    assert slow["inv_rmse_mean"] > fast["inv_rmse_mean"] and slow["std_rmse_mean"] > fast["std_rmse_mean"]
    assert slow["std_nees_mean"] > 3 * fast["std_nees_mean"]  # plusieurs fois plus forte à 2 s
    for r in (fast, slow, _inv(heading_std=45.0, gnss_period=1.0)):
        assert 0.5 < r["inv_nees_mean"] < 1.5  # l'invariant reste cohérent
        assert r["std_nees_mean"] > 10  # l'EKF standard ne l'est jamais


@promise("filtrage-invariant", 1, 3)
def _invariant_odometry_noise():
    base = _inv(heading_std=45.0)
    noisy, quiet = _inv(heading_std=45.0, odometry_scale=3.0), _inv(heading_std=45.0, odometry_scale=0.3)
    assert 3.0 < base["std_nees_mean"] / noisy["std_nees_mean"] < 8.0  # un facteur 6 environ à × 3
    assert 6.0 < quiet["std_nees_mean"] / base["std_nees_mean"] < 15.0  # environ dix fois plus forte à × 0,3
    for r in (base, noisy, quiet):
        assert 0.5 < r["inv_nees_mean"] < 1.5


# =========================================================================== assimilation de données (issue 33)


def _inflation(N, lam):
    return at("assimilation-inflation", n_members=float(N), inflation=float(lam))["rmse_a"][0]


@promise("assimilation-ensemble", 1, 1)
def _assim_no_inflation():
    run = at("assimilation-inflation", n_members=40.0, inflation=1.0)
    assert run["rmse_a"][0] > 1.0  # au-dessus de l'erreur des observations : dans la région rouge
    assert run["rmse"][-50:].min() > 1.0  # et elle ne redescend pas
    assert run["here_y"][0] == run["rmse_a"][0] and run["here_x"][0] == 1.0


@promise("assimilation-ensemble", 1, 2)
def _assim_little_inflation():
    none, small, dapper = _inflation(40, 1.0), _inflation(40, 1.02), _inflation(40, 1.06)
    assert small < none / 5 and dapper < 0.3 and small < 0.3  # divisée par plus de cinq, sous 0,3
    assert abs(dapper - 0.22) < 0.05  # près du chiffre publié (expérience courte : ± 0,01 d'une graine à l'autre)


@promise("assimilation-ensemble", 1, 3)
def _assim_small_ensemble():
    for lam in ki.slider_grid("assimilation-inflation").axes[1].values:
        assert _inflation(10, lam) > 1.0, lam  # la courbe N = 10 reste dans la région de divergence


@promise("assimilation-ensemble", 1, 4)
def _assim_too_much_inflation():
    values = {lam: _inflation(40, lam) for lam in ki.slider_grid("assimilation-inflation").axes[1].values if lam > 1}
    assert values[1.2] > 1.3 * min(values.values()) and values[1.2] < 1.0  # l'erreur remonte, sans diverger


def _radius(position):
    return at("assimilation-localisation", radius=float(position))


@promise("assimilation-ensemble", 2, 1)
def _assim_no_localization():
    run = _radius(5)
    assert np.isinf(run["radius"][0]) and run["rmse_a"][0] > 1.0  # l'ETKF global à 7 membres diverge
    assert np.all(run["rho"] == 1.0)  # un taper plat : aucune localisation


@promise("assimilation-ensemble", 2, 2)
def _assim_dapper_radius():
    run = _radius(2)
    assert run["radius"][0] == 4.0 and abs(run["rmse_a"][0] - 0.22) < 0.05 and run["rmse_a"][0] < 0.3


@promise("assimilation-ensemble", 2, 3)
def _assim_narrow_and_wide():
    narrow, good, wide = _radius(0), _radius(2), _radius(4)
    assert narrow["radius"][0] == 1.0 and wide["radius"][0] == 16.0
    assert narrow["rmse_a"][0] > 1.2 * good["rmse_a"][0] and narrow["rmse_a"][0] < 1.0  # plus d'erreur, sans diverger
    assert wide["rmse_a"][0] > 1.0  # le filtre diverge
    d = ki.slider_spec("assimilation-localisation").fixed["d"]
    assert np.all(narrow["rho"][d >= 3.64] == 0.0) and wide["rho"][d == 20.0][0] > 0.4  # le taper couvre l'anneau


def _density(k):
    run = at("assimilation-densite", spacing=float(k))
    return {m: run[f"here_{m}"][0] for m in ("letkf", "3dvar", "oi")}


@promise("methodes-variationnelles", 1, 1)
def _var_all_observed():
    r = _density(1)
    assert r["letkf"] < r["3dvar"] < r["oi"] < 1.0


@promise("methodes-variationnelles", 1, 2)
def _var_every_other():
    r = _density(2)
    assert r["3dvar"] > r["oi"] > 1.0  # le 3D-Var diverge, plus loin que l'interpolation optimale
    assert r["letkf"] < 0.5  # le LETKF reste bien sous l'erreur des observations


@promise("methodes-variationnelles", 1, 3)
def _var_one_in_eight():
    assert _density(8)["letkf"] > 1.0


# =========================================================================== plusieurs cibles (issue 37)


def _traffic():
    from kalman_course.scenarios import traffic as tr

    return tr, tr.truth_names()


def _summary(run) -> dict[str, float]:
    """La lecture sous les curseurs : GOSPA moyenne, ses composantes, pistes, changements d'identité."""
    keys = ("gospa", "localisation", "missed", "false", "tracks", "changes")
    return dict(zip(keys, run["summary"]))


def _false_points(run) -> int:
    return int(np.isfinite(run["false_e"]).sum())


@promise("fouillis-association", 1, 1)
def _association_clutter_spawns_false_tracks():
    low, high = at("association-curseurs", clutter=3e-8), at("association-curseurs", clutter=1e-7)
    assert _false_points(low) == 0 and np.all(low["false"] == 0)
    assert _false_points(high) > 0 and _summary(high)["false"] > 0  # des points noirs, une composante
    assert np.all(high["gospa"] + 1e-9 >= high["false"])  # (la composante est dans la GOSPA)
    for name in ("gospa", "localisation", "missed", "false"):  # la lecture est celle des courbes
        assert _summary(high)[name] == pytest.approx(np.mean(high[name]))


@promise("fouillis-association", 1, 2)
def _association_pda_in_dense_clutter():
    jpda, pda = at("association-curseurs", clutter=1e-7), at("association-curseurs", clutter=1e-7, method=2)
    assert _summary(pda)["gospa"] > 1.5 * _summary(jpda)["gospa"]  # de plus de moitié
    assert _summary(pda)["changes"] >= 1 and _summary(jpda)["changes"] == 0  # des pistes changent d'avion


@promise("fouillis-association", 1, 3)
def _association_low_detection_probability():
    base, low = at("association-curseurs"), at("association-curseurs", pd=0.6)
    assert _summary(base)["tracks"] == 5 and _summary(low)["tracks"] > 5  # des pistes renaissent
    tr, _ = _traffic()
    segments = 0
    for a in range(5):  # plusieurs tronçons d'une même couleur (lignes de K relevés, séparées par NaN)
        alive = np.isfinite(low[f"a{a}_e"].reshape(tr.TRACK_SLOTS, tr.N_SCANS + 1)[:, :-1]).any(axis=0)
        segments = max(segments, int(np.sum(np.diff(alive.astype(int)) == 1)) + int(alive[0]))
    assert segments >= 2
    assert _summary(low)["missed"] > 2 * _summary(base)["missed"]  # la composante grandit


@promise("fouillis-association", 1, 4)
def _association_nearest_neighbour_loses_calibra():
    tr, names = _traffic()
    nn, jpda = at("association-curseurs", method=0), at("association-curseurs")
    assert _summary(nn)["changes"] == 1 and _summary(jpda)["changes"] == 0
    run = tr.track_scene("nn")  # la même exécution que la figure
    calibra = run.labels[:, names.index("CALIBRA")]
    k = 3 + int(np.flatnonzero(calibra[3:] != calibra[3])[0])  # CALIBRA perd sa piste…
    assert 130.0 <= tr.DT * k <= 150.0  # … vers t = 140 s, à sa rencontre avec SAVAN03
    savan03 = tr.truth()[:, names.index("SAVAN03")]
    gap = np.linalg.norm(tr.truth()[:, names.index("CALIBRA")] - savan03, axis=1)
    assert gap[k - 2: k + 1].min() < 300.0
    assert _summary(nn)["gospa"] > _summary(jpda)["gospa"]


@promise("gestion-pistes", 1, 1)
def _management_confirmation_rules_against_false_tracks():
    runs = [at("pistes-curseurs", clutter=1e-7, confirm=c) for c in (0.0, 1.0, 2.0)]
    false = [_summary(r)["false"] for r in runs]
    points = [_false_points(r) for r in runs]
    assert false[0] > false[1] > false[2] == 0.0 and points[0] > points[1] > points[2] == 0
    assert _summary(runs[0])["tracks"] - 5 >= 20  # des dizaines de fausses pistes en 3 sur 4


@promise("gestion-pistes", 1, 2)
def _management_confirmation_delay():
    runs = [at("pistes-curseurs", clutter=1e-7, confirm=c) for c in (0.0, 1.0, 2.0)]
    first = [int(np.flatnonzero(r["missed"] < 5 * 500.0 - 1e-9)[0]) for r in runs]  # premier avion confirmé
    assert first[0] < first[1] < first[2]
    early = [r["missed"][:8].sum() for r in runs]
    assert early[0] < early[1] < early[2]


@promise("gestion-pistes", 1, 3)
def _management_narrow_gate_loses_calibra():
    tr, names = _traffic()
    narrow, base = at("pistes-curseurs", gate=0.9, clutter=3e-8), at("pistes-curseurs", clutter=3e-8)
    assert _summary(base)["changes"] == 0 and _summary(base)["tracks"] == 5
    assert _summary(narrow)["changes"] == 1 and _summary(narrow)["tracks"] == 6
    run = tr.track_scene("jpda", tr.DETECTION_PROBABILITY, 3e-8, 0.9, (4, 5))
    calibra = run.labels[:, names.index("CALIBRA")]
    k = 3 + int(np.flatnonzero(calibra[3:] != calibra[3])[0])
    assert 125.0 <= tr.DT * k <= 145.0  # vers t = 135 s
    assert np.all(calibra[k:k + 3] == -1)  # trois relevés sans piste, puis un autre numéro
    assert calibra[-1] not in (-1, calibra[3])


@promise("gestion-pistes", 1, 4)
def _management_wider_gate_more_false_tracks():
    narrow, wide = at("pistes-curseurs", gate=0.9, clutter=1e-7), at("pistes-curseurs", gate=0.99, clutter=1e-7)
    assert _summary(wide)["false"] > 2 * _summary(narrow)["false"] > 0


# --------------------------------------------------------------------------- (en dernier : après les inscriptions)


@pytest.mark.parametrize("key", sorted(PROMISES), ids=lambda k: f"{k[0]}-{k[1]}.{k[2]}")
def test_promise(key):
    PROMISES[key]()
