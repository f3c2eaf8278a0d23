"""Les grilles précalculées des figures à curseurs de chaque chapitre, contre des calculs indépendants.

Chaque grille est comparée à une référence qui n'est pas la fonction qui l'a remplie : filterpy (boucle
predict()/update()), une forme close écrite ici, scipy (lois normales, moindres carrés), ou une propriété
exacte (linéarité du bruit). La position par défaut de chaque curseur est l'exécution du chapitre.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
import scipy.optimize
import scipy.stats
from filterpy.kalman import KalmanFilter

import kalman_course as kc
import kalman_course.interactive as ki
from kalman_course.core.linalg import covariance_factor
from kalman_course.interactive.static import StaticSliders
from kalman_course.scenarios import engine, intuition as cart

# --------------------------------------------------------------------------- outils


def kf_scalar(y, x0, P0, Q, R, u=None, A=1.0, B=1.0):
    """Boucle filterpy scalaire : renvoie x, P, x_prior, P_prior, innovation y, S (formes (T,))."""
    f = KalmanFilter(dim_x=1, dim_z=1, dim_u=1)
    f.F, f.H, f.Q, f.R, f.B = np.array([[A]]), np.array([[1.0]]), np.array([[Q]]), np.array([[R]]), np.array([[B]])
    f.x, f.P = np.array([[x0]]), np.array([[P0]])
    out = {k: [] for k in ("x", "P", "xp", "Pp", "nu", "S")}
    for k in range(len(y)):
        f.predict(u=None if u is None else np.array([[u[k]]]))
        out["xp"].append(f.x[0, 0])
        out["Pp"].append(f.P[0, 0])
        f.update(np.array([[y[k]]]))
        for key, v in (("x", f.x[0, 0]), ("P", f.P[0, 0]), ("nu", f.y[0, 0]), ("S", f.S[0, 0])):
            out[key].append(v)
    return {k: np.array(v) for k, v in out.items()}


def kf_matrix(model, y, x0, P0, u=None):
    """Boucle filterpy matricielle : x, P, x_prior, P_prior, innovations, S (temps en premier)."""
    n, m = model.n_state, model.n_obs
    f = KalmanFilter(dim_x=n, dim_z=m, dim_u=1 if model.B is not None else 0)
    f.F, f.H, f.Q, f.R = np.array(model.A), np.array(model.C), np.array(model.Q), np.array(model.R)
    if model.B is not None:
        f.B = np.array(model.B)
    f.x, f.P = np.asarray(x0, float).reshape(n, 1), np.asarray(P0, float).copy()
    out = {k: [] for k in ("x", "P", "xp", "Pp", "nu", "S")}
    for k in range(len(y)):
        f.predict(u=None if u is None else np.asarray(u[k], float).reshape(-1, 1))
        out["xp"].append(f.x.ravel().copy())
        out["Pp"].append(f.P.copy())
        f.update(np.asarray(y[k], float).reshape(m, 1))
        for key, v in (("x", f.x.ravel()), ("P", f.P), ("nu", f.y.ravel()), ("S", f.S)):
            out[key].append(v.copy())
    return {k: np.array(v) for k, v in out.items()}


def all_points(grid):
    return list(np.ndindex(*grid.shape))


def sample_points(grid, k: int = 6, seed: int = 0):
    """Quelques points de la grille : les coins, le défaut, et des points tirés au hasard."""
    corners = [tuple(0 if c == 0 else n - 1 for c, n in zip(bits, grid.shape))
               for bits in np.ndindex(*(2,) * len(grid.shape))]
    rng = np.random.default_rng(seed)
    extra = [tuple(int(rng.integers(n)) for n in grid.shape) for _ in range(k)]
    return list(dict.fromkeys(corners + [grid.default_index] + extra))


# --------------------------------------------------------------------------- registre


def test_every_chapter_of_the_book_has_a_registered_slider_figure():
    import yaml

    from conftest import ROOT

    toc = yaml.safe_load((ROOT / "_toc.yml").read_text())
    pages = [toc["root"]] + [c["file"] for part in toc["parts"] for c in part["chapters"]]
    # annexes sans figure ; TD (calcul à la main) et TP (le code de l'étudiant et le verdict du correcteur)
    # n'ont pas de curseurs : voir tests/test_chapter_pedagogy.py
    chapters = {p.split("/")[-1] for p in pages} - {"references", "errata", "glossaire"}
    chapters = {c for c in chapters if not c.startswith(("td-", "tp-"))}
    have = {ki.SLIDER_FIGURES[n][0] for n in ki.slider_names()}
    assert chapters <= have, f"chapitres sans figure à curseurs : {sorted(chapters - have)}"


@pytest.mark.parametrize("name", ki.slider_names())
def test_every_slider_figure_builds_with_labels_units_and_its_default_readout(name):
    spec = ki.slider_spec(name)
    fig = spec.static()
    assert isinstance(fig, StaticSliders)
    grid = spec.grid()
    assert all(np.isfinite(v).any() for v in grid.series.values())
    for axis in grid.axes:
        assert axis.description and axis.symbol
        assert len(axis.labels()) == axis.values.size
    html = fig.html()
    assert f'data-kc-bokeh="{name}"' in html
    for panel in spec.panels:
        for label in (panel.y_label, panel.x_label or spec.x_label):
            counter = label.startswith(("itération", "étape", "pas de temps", "année", "relevé"))
            assert "(" in label or counter, f"{name} : pas d'unité dans « {label} »"
    if spec.readout is not None:
        text = spec.text_at(*grid.default_index)
        assert text and not re.search(r"\d\.\d", text), text  # nombres en français (virgule décimale)
        assert not re.search(r"\de[-+]?\d", text), text  # jamais de notation « e-05 »


@pytest.mark.parametrize("name", ki.slider_names())
def test_a_point_computed_alone_equals_the_grid(name):
    """``run_at`` (une exécution, sans la grille : la relecture du navigateur s'en sert) donne exactement la
    série de la grille, aux coins et au défaut : ``run`` ne dépend pas de l'ordre des appels. (Description
    reconstruite par son registre : sa grille n'est pas encore calculée.)"""
    grid = ki.slider_grid(name)
    fresh = ki.figure.SLIDER_FIGURES[name][1]()
    corners = [tuple(0 if c == 0 else n - 1 for c, n in zip(bits, grid.shape))
               for bits in np.ndindex(*(2,) * len(grid.shape))]
    for index in dict.fromkeys([grid.default_index] + corners[::-1]):
        alone = fresh.run_at(*index)
        assert fresh._grid is None
        assert alone.keys() == grid.series.keys()
        for series, values in grid.run(*index).items():
            np.testing.assert_array_equal(alone[series], values, err_msg=f"{name}, série {series}, point {index}")
    if fresh.readout is not None:
        assert fresh.text_at(*grid.default_index) == ki.slider_spec(name).text_at(*grid.default_index)
    with pytest.raises(kc.KalmanInputError, match="hors de la grille"):
        fresh.run_at(*grid.shape)


def test_grid_cache_is_written_once_and_read_back_by_another_process(tmp_path, monkeypatch):
    """Dossier partagé d'un lancement des tests (``KALMAN_GRID_CACHE``) : la grille calculée par une
    description est écrite, une autre description (un autre processus) la relit sans rien recalculer, et
    ``cached_grid`` ne calcule jamais."""
    name = "intuition-produit"
    monkeypatch.setenv(ki.figure.GRID_CACHE, str(tmp_path / "grilles"))
    first = ki.figure.SLIDER_FIGURES[name][1]()
    assert first.cached_grid() is None  # rien de calculé, rien d'écrit
    computed = first.grid()
    assert [p.name for p in (tmp_path / "grilles").iterdir()] == [f"{name}.npz"]
    second = ki.figure.SLIDER_FIGURES[name][1]()
    second.run = lambda *values: pytest.fail("grille recalculée au lieu d'être relue")
    read = second.cached_grid()
    assert read is not None and read.series.keys() == computed.series.keys()
    for series, values in computed.series.items():
        np.testing.assert_array_equal(read.series[series], values)
        assert not read.series[series].flags.writeable
    assert read.run(*read.default_index).keys() == computed.run(*computed.default_index).keys()
    monkeypatch.delenv(ki.figure.GRID_CACHE)
    assert ki.figure.SLIDER_FIGURES[name][1]().cached_grid() is None  # sans le dossier : rien n'est lu


# --------------------------------------------------------------------------- introduction et intuition


def test_intro_grid_equals_filterpy_on_independently_simulated_data():
    grid = ki.slider_grid("intro-chariot")
    T = cart.TRACKING_STEPS
    expected = cart.CART_SPEED * cart.CART_DT * np.arange(1, T + 1)
    assert grid.values_at(*grid.default_index) == (cart.CART_R, cart.CART_Q)
    for i, j in all_points(grid):
        R, Q = grid.values_at(i, j)
        # simulation refaite ici : mêmes tirages (bruits d'état puis de mesure), racines des variances
        rng = np.random.default_rng(cart.CART_SEED)
        w = np.sqrt(Q) * rng.standard_normal(T)
        v = np.sqrt(R) * rng.standard_normal(T)
        x = np.cumsum(cart.CART_SPEED * cart.CART_DT + w)
        y = x + v
        run = grid.run(i, j)
        np.testing.assert_allclose(run["truth_rel"] + expected, x, rtol=0, atol=1e-12)
        np.testing.assert_allclose(run["y_rel"] + expected, y, rtol=0, atol=1e-12)
        ref = kf_scalar(y, 0.0, cart.CART_P0, Q, R, u=np.full(T, cart.CART_SPEED), B=cart.CART_DT)
        np.testing.assert_allclose(run["x_rel"] + expected, ref["x"], rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(run["upper_rel"] - run["lower_rel"], 4 * np.sqrt(ref["P"]), rtol=1e-9)
        np.testing.assert_allclose(run["rmse_x"], np.sqrt(np.mean((ref["x"] - x) ** 2)), rtol=1e-9)


def test_intuition_product_grid_is_the_gaussian_product_in_closed_form():
    grid = ki.slider_grid("intuition-produit")
    x = ki.intuition.PRODUCT_POSITIONS
    assert grid.values_at(*grid.default_index) == (cart.PRIOR_VAR, cart.MEASUREMENT_VAR)
    for i, j in all_points(grid):
        P, R = grid.values_at(i, j)
        run = grid.run(i, j)
        K = P / (P + R)  # forme close, écrite ici
        m, v = cart.PRIOR_MEAN + K * (cart.MEASUREMENT - cart.PRIOR_MEAN), P * R / (P + R)
        np.testing.assert_allclose(run["K"], K, rtol=1e-14)
        np.testing.assert_allclose(run["x_post"], m, rtol=1e-14)
        np.testing.assert_allclose(run["P_post"], v, rtol=1e-13)
        np.testing.assert_allclose(run["prior"], scipy.stats.norm.pdf(x, cart.PRIOR_MEAN, np.sqrt(P)), rtol=1e-12,
                                   atol=1e-300)
        np.testing.assert_allclose(run["likelihood"], scipy.stats.norm.pdf(cart.MEASUREMENT, x, np.sqrt(R)),
                                   rtol=1e-12, atol=1e-300)
        np.testing.assert_allclose(run["posterior"], scipy.stats.norm.pdf(x, m, np.sqrt(v)), rtol=1e-10, atol=1e-200)
        # le produit normalisé numériquement : la même densité, à l'erreur des trapèzes près
        np.testing.assert_allclose(run["product"], scipy.stats.norm.pdf(x[::5], m, np.sqrt(v)), atol=2e-3)
        curve = ki.intuition.GAIN_CURVE_P / (ki.intuition.GAIN_CURVE_P + R)
        np.testing.assert_allclose(run["gain_curve"], curve, rtol=1e-13)


def test_gaussian_product_formula_against_numerical_integration():
    rng = np.random.default_rng(5)
    for _ in range(20):
        m1, m2 = rng.normal(0, 5, 2)
        v1, v2 = rng.uniform(0.1, 9, 2)
        prod = cart.gaussian_product(m1, v1, m2, v2)
        f = lambda t: scipy.stats.norm.pdf(t, m1, np.sqrt(v1)) * scipy.stats.norm.pdf(t, m2, np.sqrt(v2))  # noqa: E731
        lo, hi = min(m1, m2) - 40, max(m1, m2) + 40
        mass = scipy.integrate.quad(f, lo, hi, points=[m1, m2], limit=200)[0]
        mean = scipy.integrate.quad(lambda t: t * f(t), lo, hi, points=[m1, m2], limit=200)[0] / mass
        var = scipy.integrate.quad(lambda t: (t - mean) ** 2 * f(t), lo, hi, points=[m1, m2], limit=200)[0] / mass
        np.testing.assert_allclose([prod.scale, prod.mean, prod.var], [mass, mean, var], rtol=1e-7)
        # et c'est la correction du filtre de Kalman (filterpy) : a priori (m1, v1), mesure m2 de variance v2
        ref = kf_scalar([m2], m1, v1, 0.0, v2, A=1.0)
        np.testing.assert_allclose([prod.mean, prod.var, prod.gain], [ref["x"][0], ref["P"][0], v1 / (v1 + v2)],
                                   rtol=1e-12)


def test_intuition_cycle_grid_equals_filterpy_half_steps():
    grid = ki.slider_grid("intuition-cycle")
    sim, u = cart.cart_data()
    y = sim.y[:, 0]
    x = ki.intuition.CYCLE_POSITIONS
    for i, j in all_points(grid):
        stage, Q = grid.values_at(i, j)
        k = int(stage)
        ref = kf_scalar(y, cart.CART_X0, cart.CART_P0, Q, cart.CART_R, u=u[:, 0], B=cart.CART_DT)
        means = np.concatenate([[cart.CART_X0], np.ravel(np.column_stack([ref["xp"], ref["x"]]))])
        variances = np.concatenate([[cart.CART_P0], np.ravel(np.column_stack([ref["Pp"], ref["P"]]))])
        run = grid.run(i, j)
        np.testing.assert_allclose(run["std"], np.sqrt(variances), rtol=1e-12)
        np.testing.assert_allclose(run["current"], scipy.stats.norm.pdf(x, means[k], np.sqrt(variances[k])),
                                   rtol=1e-10, atol=1e-300)
        n = (k + 1) // 2
        if k % 2 == 0 and k > 0:  # correction : la vraisemblance de la mesure y_n
            np.testing.assert_allclose(run["likelihood"], scipy.stats.norm.pdf(y[n - 1], x, np.sqrt(cart.CART_R)),
                                       rtol=1e-12, atol=1e-300)
        else:
            assert np.isnan(run["likelihood"]).all()


# --------------------------------------------------------------------------- chapitres linéaires


def test_system_grid_is_linear_in_the_noise_and_deterministic_without_it():
    grid = ki.slider_grid("systeme-bruits")
    model = engine.engine_model()
    u = engine.engine_commands(120)
    # k_φ = 0 : réponse déterministe, récurrence écrite ici
    x = np.zeros(2)
    det = []
    for k in range(120):
        x = model.A @ x + model.B @ u[k]
        det.append(x)
    det = np.array(det)
    phis, psis = grid.axes[0].values, grid.axes[1].values
    j1 = int(np.flatnonzero(psis == 1.0)[0])
    i0, i1 = int(np.flatnonzero(phis == 0.0)[0]), int(np.flatnonzero(phis == 1.0)[0])
    base = grid.run(i1, j1)
    x1 = np.column_stack([base["theta_m"], base["theta_a"]])
    y1 = np.column_stack([base["y1"], base["y2"]])
    for i, j in all_points(grid):
        k_phi, k_psi = grid.values_at(i, j)
        run = grid.run(i, j)
        xs = np.column_stack([run["theta_m"], run["theta_a"]])
        ys = np.column_stack([run["y1"], run["y2"]])
        # l'état ne dépend que de k_φ, linéairement : x(k_φ) = x_det + k_φ (x(1) − x_det)
        np.testing.assert_allclose(xs, det + k_phi * (x1 - det), rtol=1e-9, atol=1e-9)
        # le bruit de mesure ne dépend que de k_ψ : y − C x = k_ψ (y(1) − C x(1))
        np.testing.assert_allclose(ys - xs @ model.C.T, k_psi * (y1 - x1 @ model.C.T), rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(np.column_stack([grid.run(i0, j1)["theta_m"], grid.run(i0, j1)["theta_a"]]), det,
                               atol=1e-12)
    # position par défaut : la simulation de la figure du chapitre
    sim = kc.simulate(model, np.zeros(2), 120, u, rng=engine.ENGINE_SEED)
    assert grid.default_index == (i1, j1)
    np.testing.assert_array_equal(x1, sim.x)
    np.testing.assert_array_equal(y1, sim.y)


def test_estimator_grid_mean_error_is_the_closed_form_and_the_simulations_agree():
    grid = ki.slider_grid("estimateur-gain")
    n = np.arange(grid.time.size)
    floor = ki.estimator.FLOOR
    for i, j in all_points(grid):
        K, A = grid.values_at(i, j)
        run = grid.run(i, j)
        rho = abs((1 - K) * A)  # C = 1 ; e₀ = x̂₀ − x₀ = 1 ; sans commande : E[eₙ] = ((1 − K)A)ⁿ
        np.testing.assert_allclose(run["recursion"], np.maximum(rho**n, floor), rtol=1e-12)
        np.testing.assert_allclose(run["radius_now"], rho, rtol=1e-12)
        np.testing.assert_allclose(run["printed_now"], abs(1 - K), rtol=1e-12)
        # la moyenne de 400 simulations, à l'erreur de Monte-Carlo près (variance de eₙ en forme close)
        var = np.zeros(n.size)
        for k in range(1, n.size):
            var[k] = (1 - K) ** 2 * A**2 * var[k - 1] + (1 - K) ** 2 * 0.01 + K**2 * 0.01
        sem = np.sqrt(var / 400)
        mc = run["monte_carlo"]
        ok = (sem > 0) & (rho**n > floor) & (mc > floor)
        z = np.abs(mc[ok] - rho ** n[ok]) / sem[ok]
        assert (z < 5).all(), (K, A, z.max())
    # défaut : le contre-exemple du chapitre, K = 0,4, A = 2
    assert grid.values_at(*grid.default_index) == (0.4, 2.0)


def test_predictor_grid_equals_filterpy_on_the_chapter_steps():
    grid = ki.slider_grid("predicteur-etapes")
    model = engine.engine_model()
    u = engine.engine_commands(5)
    sim = kc.simulate(model, engine.ENGINE_X0_MEAN, 5, u, rng=engine.ENGINE_SEED)
    theta = ki.predictor.THETA
    for j, s in enumerate(grid.axes[1].values):
        assumed = engine.engine_model(Psi=s * engine.ENGINE_PSI)
        ref = kf_matrix(assumed, sim.y, engine.ENGINE_X0_HAT, engine.ENGINE_P0, u)
        means = [engine.ENGINE_X0_HAT[0]] + [v for n in range(5) for v in (ref["xp"][n, 0], ref["x"][n, 0])]
        variances = [engine.ENGINE_P0[0, 0]] + [v for n in range(5) for v in (ref["Pp"][n, 0, 0], ref["P"][n, 0, 0])]
        for i in range(grid.shape[0]):
            run = grid.run(i, j)
            np.testing.assert_allclose(run["std"], np.sqrt(variances), rtol=1e-6)
            # la densité est tracée sur THETA et autour de sa moyenne (un pic étroit n'échappe pas au tracé)
            assert set(theta) <= set(run["current_x"]) and np.all(np.diff(run["current_x"]) >= 0)
            np.testing.assert_allclose(run["current"], scipy.stats.norm.pdf(run["current_x"], means[i],
                                                                            np.sqrt(variances[i])), rtol=1e-5, atol=1e-9)
    # défaut : la première correction du chapitre (kc.predict puis kc.update, comme sa première cellule)
    pred = kc.predict(model, engine.ENGINE_X0_HAT, engine.ENGINE_P0, u[0])
    corr = kc.update(model, pred.x, pred.P, sim.y[0])
    run = grid.run(*grid.default_index)
    np.testing.assert_allclose(run["mean_now"], corr.x, rtol=1e-13)
    np.testing.assert_allclose(run["std_both"], np.sqrt(np.diag(corr.P)), rtol=1e-13)


def test_gain_grid_is_the_joseph_form_around_filterpy_predictions():
    grid = ki.slider_grid("gain-trace")
    voltage = kc.scenarios.constant_voltage_model()
    R = float(voltage.R[0, 0])
    ref = kf_scalar(kc.scenarios.constant_voltage_measurements(50), 0.0, 1.0, float(voltage.Q[0, 0]), R, A=1.0)
    curve_K = ki.gain.CURVE_K
    for i, j in all_points(grid):
        n, K = grid.values_at(i, j)
        Pp = ref["Pp"][int(n) - 1]
        run = grid.run(i, j)
        K_star = Pp / (Pp + R)
        np.testing.assert_allclose(run["K_star"], K_star, rtol=1e-10)
        np.testing.assert_allclose(run["P_now"], (1 - K) ** 2 * Pp + K**2 * R, rtol=1e-10)
        np.testing.assert_allclose(run["total"], ((1 - curve_K) ** 2 * Pp + curve_K**2 * R) / Pp, rtol=1e-10)
        assert run["P_now"][0] >= run["P_star"][0] * (1 - 1e-12)  # le gain de Kalman est le minimum
    n, K = grid.values_at(*grid.default_index)
    assert n == 10 and K == pytest.approx(ref["P"][9] / R, rel=1e-10)  # K* = P/Ψ, forme a posteriori


def test_practice_grid_innovations_equal_filterpy():
    grid = ki.slider_grid("pratique-capteur")
    u = engine.engine_commands(120)
    for i, j in sample_points(grid):
        true_std, assumed_std = grid.values_at(i, j)
        scale = lambda s: (s / 0.5) ** 2 * engine.ENGINE_PSI  # noqa: E731
        sim = kc.simulate(engine.engine_model(Psi=scale(true_std)), engine.ENGINE_X0_MEAN, 120, u, rng=engine.ENGINE_SEED)
        ref = kf_matrix(engine.engine_model(Psi=scale(assumed_std)), sim.y, engine.ENGINE_X0_HAT, engine.ENGINE_P0, u)
        run = grid.run(i, j)
        np.testing.assert_allclose(run["normalised"], ref["nu"][:, 0] / np.sqrt(ref["S"][:, 0, 0]), rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(run["error"], ref["x"][:, 0] - sim.x[:, 0], rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(run["upper"], 2 * np.sqrt(ref["P"][:, 0, 0]), rtol=1e-8)


def test_consistency_grid_equals_nees_and_nis_recomputed_with_filterpy():
    """Les tirages du Monte-Carlo refaits ici (même générateur, même ordre), filtrés par filterpy ; NEES et NIS
    calculées ici (eᵀP⁻¹e, ν̃ᵀS⁻¹ν̃)."""
    grid = ki.slider_grid("tests-nees-nis")
    true = engine.engine_model()
    T = engine.CONSISTENCY_MC_STEPS
    u = engine.engine_commands(T)
    LQ, LR = covariance_factor(true.Q), covariance_factor(true.R)
    gen = np.random.default_rng(engine.CONSISTENCY_MC_SEED)
    runs = []
    for _ in range(engine.CONSISTENCY_MC_RUNS):
        x0 = engine.ENGINE_X0_MEAN + gen.standard_normal(2)  # P₀ = I
        W = gen.standard_normal((T, 2)) @ LQ.T
        V = gen.standard_normal((T, 2)) @ LR.T
        x, xs = x0, []
        for k in range(T):
            x = true.A @ x + W[k] + true.B @ u[k]
            xs.append(x)
        xs = np.array(xs)
        runs.append((xs, xs @ true.C.T + V))
    for a, b in ((1.0, 1.0), (1.0, 0.1), (10.0, 1.0)):
        i, j = grid.axes[0].index_of(a), grid.axes[1].index_of(b)
        fmodel = engine.engine_model(Phi=engine.ENGINE_PHI if a == 1 else a * engine.ENGINE_PHI,
                                     Psi=engine.ENGINE_PSI if b == 1 else b * engine.ENGINE_PSI)
        nees, nis = [], []
        for xs, ys in runs:
            ref = kf_matrix(fmodel, ys, engine.ENGINE_X0_MEAN, engine.ENGINE_X0_COV, u)
            e = ref["x"] - xs
            nees.append(np.einsum("ti,tij,tj->t", e, np.linalg.inv(ref["P"]), e))
            nis.append(np.einsum("ti,tij,tj->t", ref["nu"], np.linalg.inv(ref["S"]), ref["nu"]))
        run = grid.run(i, j)
        np.testing.assert_allclose(run["nees"], np.mean(nees, axis=0), rtol=1e-6)
        np.testing.assert_allclose(run["nis"], np.mean(nis, axis=0), rtol=1e-6)
    assert grid.values_at(*grid.default_index) == (1.0, 1.0)


# --------------------------------------------------------------------------- non linéaire


def _check_ellipse(xs, ys, mean, cov, scale=2.0):
    """Chaque point du contour vérifie (p − m)ᵀ C⁻¹ (p − m) = scale²."""
    d = np.column_stack([xs, ys]) - mean
    q = np.einsum("ti,ij,tj->t", d, np.linalg.inv(cov), d)
    np.testing.assert_allclose(q, scale**2, rtol=1e-8)


def test_polar_grid_against_closed_forms_and_independent_samples():
    grid = ki.slider_grid("ekf-linearisation-curseurs")
    for i, j in all_points(grid):
        bearing_deg, range_std = grid.values_at(i, j)
        s_t = np.deg2rad(bearing_deg)
        rng = np.random.default_rng(11)
        samples = np.array([10.0, 0.0]) + rng.standard_normal((3000, 2)) * np.array([range_std, s_t])
        mapped = np.column_stack([samples[:, 0] * np.cos(samples[:, 1]), samples[:, 0] * np.sin(samples[:, 1])])
        run = grid.run(i, j)
        np.testing.assert_allclose(run["cloud_x"], mapped[:400, 0], rtol=1e-13)
        # moments exacts, en forme close (θ̂ = 0) : E[r cos θ] = r̂ e^{−σθ²/2}, E[r sin θ] = 0,
        # Var(x) = E[r²] (1 + e^{−2σθ²})/2 − E[x]², Var(y) = E[r²] (1 − e^{−2σθ²})/2, Cov(x, y) = 0
        r2 = 100.0 + range_std**2
        mean = np.array([10.0 * np.exp(-s_t**2 / 2), 0.0])
        cov = np.diag([r2 * (1 + np.exp(-2 * s_t**2)) / 2 - mean[0] ** 2, r2 * (1 - np.exp(-2 * s_t**2)) / 2])
        np.testing.assert_allclose([run["exact_mean_x"][0], run["exact_mean_y"][0]], mean, rtol=1e-12, atol=1e-12)
        _check_ellipse(run["exact_x"], run["exact_y"], mean, cov)
        # les 3000 tirages en sont à l'erreur de Monte-Carlo près
        assert np.all(np.abs(mapped.mean(axis=0) - mean) < 5 * np.sqrt(np.diag(cov) / 3000))
        # EKF en forme close : f(x̂) = (r̂, 0), J P Jᵀ = diag(σr², r̂² σθ²)
        np.testing.assert_allclose([run["ekf_mean_x"][0], run["ekf_mean_y"][0]], [10.0, 0.0], atol=1e-14)
        _check_ellipse(run["ekf_x"], run["ekf_y"], np.array([10.0, 0.0]), np.diag([range_std**2, 100.0 * s_t**2]))
    assert grid.values_at(*grid.default_index) == (20.0, 0.5)  # la figure de linéarisation du chapitre


def test_iekf_grid_is_gauss_newton_written_here_and_reaches_the_map():
    from kalman_course.scenarios.radar import RADAR_PRIOR, radar_update_problem

    grid = ki.slider_grid("ekf-itere-curseurs")
    base = radar_update_problem()
    y, R = base.y, base.model.R

    def h(x):
        return np.array([np.hypot(*x), np.arctan2(x[1], x[0])])

    def H(x):
        r2 = x @ x
        return np.array([[x[0] / np.sqrt(r2), x[1] / np.sqrt(r2)], [-x[1] / r2, x[0] / r2]])

    last = grid.shape[0] - 1
    for j, s0 in enumerate(grid.axes[1].values):
        P = s0**2 * np.eye(2)
        xs = [RADAR_PRIOR.copy()]
        for _ in range(40):  # Gauss–Newton sur J (forme des notes corrigée), écrit ici
            xi = xs[-1]
            Hi = H(xi)
            S = Hi @ P @ Hi.T + R
            K = P @ Hi.T @ np.linalg.inv(S)
            r = y - h(xi) - Hi @ (RADAR_PRIOR - xi)
            r[1] = np.arctan2(np.sin(r[1]), np.cos(r[1]))
            xs.append(RADAR_PRIOR + K @ r)
            if np.linalg.norm(xs[-1] - xs[-2]) < 1e-10:
                break
        xs = np.array(xs)
        run = grid.run(last, j)
        path = np.column_stack([run["path_x"], run["path_y"]])
        k = min(len(xs), path.shape[0])
        np.testing.assert_allclose(path[:k], xs[:k], rtol=0, atol=1e-9)
        # le MAP, par un minimiseur générique de J (scipy), indépendant du filtre
        def J(x):
            d = y - h(x)
            d[1] = np.arctan2(np.sin(d[1]), np.cos(d[1]))
            e = x - RADAR_PRIOR
            return 0.5 * e @ np.linalg.solve(P, e) + 0.5 * d @ np.linalg.solve(R, d)

        best = scipy.optimize.minimize(J, xs[-1], method="Nelder-Mead", options={"xatol": 1e-12, "fatol": 1e-14,
                                                                                 "maxiter": 4000})
        np.testing.assert_allclose([run["map_x"][0], run["map_y"][0]], best.x, atol=1e-6)
        np.testing.assert_allclose(run["distance"][-1], max(np.linalg.norm(xs[-1] - best.x), 1e-16), atol=1e-6)
    assert grid.values_at(*grid.default_index) == (1.0, 3.0)


def test_srif_grid_against_filterpy_and_batch_least_squares():
    from kalman_course.scenarios import diffuse

    grid = ki.slider_grid("srif-a-priori")
    model = diffuse.diffuse_model()
    _, y = diffuse.diffuse_data()
    ref = diffuse.batch_estimates(y)  # moindres carrés en bloc, sans a priori (indépendants du filtre)
    srif = ki.slider_spec("srif-a-priori").fixed["srif"]
    sr = kc.square_root_information_filter(model, y).x
    defined = np.isfinite(sr).all(axis=1)
    gap = np.linalg.norm(sr[defined, :2] - ref[defined, :2], axis=1)
    assert (gap < 1e-9).all() and (srif[defined & (np.arange(len(y)) > 0)] < 1e-9).all()
    # a priori petit : l'écart est le biais de l'a priori (k = 2, au millième près) ; plus grand, il descend
    # vers l'arrondi, où filterpy (forme de Joseph) et le paquet diffèrent de quelques 10⁻¹⁰ m
    for k, rtol, atol in ((2, 1e-3, 2e-11), (4, 0.0, 5e-10)):
        i = grid.axes[0].index_of(k)
        out = kf_matrix(model, y, np.zeros(4), 10.0**k * np.eye(4))
        gap = np.linalg.norm(out["x"][:, :2] - ref[:, :2], axis=1)
        np.testing.assert_allclose(grid.run(i)["kf"][1:], np.maximum(gap[1:], 1e-16), rtol=rtol, atol=atol)
    assert grid.values_at(*grid.default_index) == (10.0,)


def test_se3_grid_reprojection_and_final_pose_against_least_squares():
    from kalman_course.scenarios import camera_noise
    from kalman_course.scenarios.camera_target import CAMERA, TARGET_POINTS

    grid = ki.slider_grid("se3-bruit-pixels")
    last = grid.shape[1] - 1
    for i, sigma in enumerate(grid.axes[0].values):
        p = camera_noise.camera_problem_with_noise(sigma)
        run = grid.run(i, last)
        # pixels mesurés : projection à sténopé écrite ici, plus σ ε avec les tirages de la graine
        Pc = TARGET_POINTS @ p.T_true[:3, :3].T + p.T_true[:3, 3]
        uv = np.column_stack([CAMERA.fx * Pc[:, 0] / Pc[:, 2] + CAMERA.cx, CAMERA.fy * Pc[:, 1] / Pc[:, 2] + CAMERA.cy])
        eps = np.random.default_rng(2024).standard_normal(2 * len(TARGET_POINTS)).reshape(-1, 2)
        np.testing.assert_allclose(np.column_stack([run["pixel_u"], run["pixel_v"]]), uv + sigma * eps, rtol=1e-12)
        # pose finale : le MAP par scipy.optimize.least_squares sur T̂₋ Exp(ξ), écrit ici
        LP = np.linalg.cholesky(p.P_pred)

        def pose(xi):
            X = np.zeros((4, 4))
            X[:3, :3] = [[0, -xi[5], xi[4]], [xi[5], 0, -xi[3]], [-xi[4], xi[3], 0]]
            X[:3, 3] = xi[:3]
            return p.T_pred @ scipy.linalg.expm(X)

        def residuals(xi):
            T = pose(xi)
            Q = TARGET_POINTS @ T[:3, :3].T + T[:3, 3]
            pix = np.column_stack([CAMERA.fx * Q[:, 0] / Q[:, 2] + CAMERA.cx, CAMERA.fy * Q[:, 1] / Q[:, 2] + CAMERA.cy])
            return np.concatenate([np.linalg.solve(LP, xi), (p.y - pix.ravel()) / sigma])

        sol = scipy.optimize.least_squares(residuals, np.zeros(6), xtol=1e-15, ftol=1e-15, gtol=1e-15)
        T_map = pose(sol.x)
        angle = np.degrees(np.arccos(np.clip((np.trace(T_map[:3, :3].T @ p.T_true[:3, :3]) - 1) / 2, -1, 1)))
        position = 100 * np.linalg.norm(T_map[:3, 3] - p.T_true[:3, 3])
        np.testing.assert_allclose(run["angle_now"], angle, rtol=1e-4, atol=1e-6)
        np.testing.assert_allclose(run["position_now"], position, rtol=1e-4, atol=1e-6)
    assert grid.values_at(*grid.default_index)[0] == 1.0


# --------------------------------------------------------------------------- figures d'origine


def test_tension_and_tag_are_in_the_registry_with_their_chapter_grids():
    np.testing.assert_array_equal(ki.slider_grid("tension-curseurs").series["x"], ki.voltage_grid().series["x"])
    np.testing.assert_array_equal(ki.slider_grid("tag-curseurs").series["err"], ki.tag_grid().series["err"])


# --------------------------------------------------------------------------- relecture (issue 36)


@pytest.mark.parametrize("name", ki.slider_names())
def test_each_slider_changes_the_readout(name):
    """Chaque curseur d'une figure qui a une lecture la change : déplacé seul depuis la position par défaut,
    il donne au moins une autre lecture (le curseur σr de l'EKF ne changeait rien à la sienne)."""
    spec = ki.slider_spec(name)
    if spec.readout is None:
        pytest.skip("pas de lecture sous les curseurs")
    grid = spec.grid()
    default = grid.default_index
    reference = spec.text_at(*default)
    for a, n in enumerate(grid.shape):
        texts = {spec.text_at(*(default[:a] + (i,) + default[a + 1:])) for i in range(n) if i != default[a]}
        assert texts - {reference}, f"{name} : le curseur {grid.axes[a].symbol} ne change pas la lecture"


def test_likelihood_readout_gives_the_units_of_the_estimates():
    """« R̂ = 15 099 (10⁸ m³ par an)² » : les estimations citées sous les curseurs du Nil ont leur unité."""
    spec = ki.slider_spec("vraisemblance-nil")
    text = spec.text_at(*spec.grid().default_index)
    for symbol in ("R̂", "Q̂"):
        assert re.search(symbol + r" = [−\d\u202f,]+\u00a0\(10⁸ m³ par an\)²", text), text


def test_figure_details_of_the_newest_chapters():
    """Détails relevés à la relecture (issue 36) : la bande verte de « Quel filtre choisir ? » se voit (sa
    surface était à 5 % d'opacité) et σ₀ = 1 km s'écrit « 1 km » ; « 1 processeur(s) » ; les bandes grises des
    virages couvrent tout l'axe de l'erreur (elles s'arrêtaient à 120 m sur un axe qui monte à 200)."""
    from kalman_course.interactive import tracking

    choice = ki.slider_spec("choix-incertitude")
    band = next(g for p in choice.panels for g in p.glyphs if g.kind == "band")
    assert 0.25 * band.alpha >= 0.2  # opacité de la surface (static.py : 0,25 × alpha)
    assert choice.grid().axes[0].labels()[-1] == "1\u00a0km"
    parallel = ki.slider_spec("parallele-processeurs")
    grid = parallel.grid()
    one = tuple(0 if a == 0 else d for a, d in enumerate(grid.default_index))
    assert parallel.text_at(*one).startswith("un seul processeur") and "(s)" not in parallel.text_at(*one)
    fading = ki.slider_spec("manoeuvre-oubli-curseurs")
    static = fading.static()
    panel = next(k for k, p in enumerate(fading.panels) if any(g.column == "turn" for g in p.glyphs))
    for index in np.ndindex(*static.grid.shape):
        _, (lo, hi) = static.ranges_at(panel, *index)
        assert tracking.TURN_BAND > hi and lo <= 0.0, (index, hi)
