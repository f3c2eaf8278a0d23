"""Les nombres en français (kalman_course.numbers) : chaque écriture est comparée à une chaîne écrite à
la main (virgule décimale, espace fine insécable U+202F des milliers et autour de « × », signe moins
U+2212, exposants en chiffres supérieurs)."""

from __future__ import annotations

import io

import numpy as np
import pytest

import kalman_course as kc
from kalman_course.numbers import (
    format_array,
    format_integer,
    format_number,
    format_percent,
    format_spec,
    french_figure,
    glue_number,
    matplotlib_formatter,
)

NN = "\u202f"  # espace fine insécable
NB = "\u00a0"  # espace insécable
M = "\u2212"  # signe moins


@pytest.mark.parametrize(
    ("value", "options", "expected"),
    [
        (0.000339, {"significant": 3}, f"3,39{NN}×{NN}10⁻⁴"),
        (1234.5, {"decimals": 1}, f"1{NN}234,5"),
        (-0.5, {"decimals": 2}, f"{M}0,50"),
        (2.5e-15, {"significant": 2}, f"2,5{NN}×{NN}10⁻¹⁵"),
        (3.14159, {}, "3,14"),
        (0.0012345, {"significant": 2}, "0,0012"),
        (1234567.0, {"significant": 3}, f"1,23{NN}×{NN}10⁶"),
        (999999.0, {"significant": 3}, f"1,00{NN}×{NN}10⁶"),  # l'arrondi passe à la puissance suivante
        (0.0, {"significant": 3}, "0,00"),
        (-0.0001, {"decimals": 2}, "0,00"),  # pas de « −0,00 »
        (0.5, {"significant": 3, "trim": True}, "0,5"),
        (20000, {"decimals": 0}, f"20{NN}000"),
        (0.08, {"decimals": 2, "unit": "m"}, f"0,08{NB}m"),
        (20.0, {"decimals": 0, "unit": "°"}, "20°"),  # le degré d'angle collé au nombre
        (0.5, {"decimals": 1, "unit": "°C"}, f"0,5{NB}°C"),  # mais pas le degré Celsius
        (1.5e-5, {"decimals": 1, "scientific": True}, f"1,5{NN}×{NN}10⁻⁵"),
        (12.0, {"significant": 2, "scientific": True}, f"1,2{NN}×{NN}10¹"),
        (float("nan"), {}, "NaN"),
        (float("-inf"), {}, f"{M}∞"),
        (np.float64(2.25), {"decimals": 1}, "2,2"),  # arrondi au pair, comme round() de Python
    ],
)
def test_format_number_writes_french(value, options, expected):
    assert format_number(value, **options) == expected


def test_integer_and_percent():
    assert format_integer(20000) == f"20{NN}000"
    assert format_integer(np.int64(-3)) == f"{M}3"
    assert format_percent(0.256) == f"26{NN}%"
    assert format_percent(0.05, 1) == f"5,0{NN}%"


@pytest.mark.parametrize(
    ("value", "spec", "expected"),
    [
        (0.000339, ".2e", f"3,39{NN}×{NN}10⁻⁴"),
        (0.000339, "{:.2e}", f"3,39{NN}×{NN}10⁻⁴"),
        (3.392e-4, ".3e", f"3,392{NN}×{NN}10⁻⁴"),
        (0.0198, ".4f", "0,0198"),
        (2.0461, ".3f", "2,046"),
        (0.5, ".3g", "0,5"),
        (1109.94, ".4g", f"1{NN}110"),
        (6e-180, ".1g", f"6{NN}×{NN}10⁻¹⁸⁰"),
        (0.25, ".1%", f"25,0{NN}%"),
        (0.0123, "+.2%", f"+1,23{NN}%"),
        (-0.0123, "+.2%", f"{M}1,23{NN}%"),
        (0.0, ".1e", "0"),  # zéro n'a pas d'ordre de grandeur (Python écrit « 0.0e+00 »)
        (0.0, ".3g", "0"),
        (42, "d", "42"),
        (-1.5, "+.1f", f"{M}1,5"),
        (1.5, "+.1f", "+1,5"),
        (7.0, "", "7"),
    ],
)
def test_format_spec_translates_python_formats(value, spec, expected):
    assert format_spec(value, spec) == expected


def test_format_array_aligns_columns():
    assert format_array([[1.5, -0.25], [10, 0]], decimals=2) == f"[[ 1,50  {M}0,25]\n [10,00   0,00]]"
    assert format_array([0.1, 2.0], decimals=1) == "[0,1  2,0]"
    assert format_array(3.0, decimals=1) == "3,0"


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: format_number("abc"), "value"),
        (lambda: format_number(True), "booléen"),
        (lambda: format_number(1.0, decimals=2, significant=2), "pas les deux"),
        (lambda: format_number(1.0, decimals=-1), "decimals"),
        (lambda: format_integer(1.5), "entier"),
        (lambda: format_spec(1.0, ".3x"), "non reconnu"),
        (lambda: format_spec(1.0, 3), "spec"),
        (lambda: format_array(np.zeros((2, 2, 2))), "vecteur ou une matrice"),
    ],
)
def test_bad_input_is_a_french_error(call, match):
    with pytest.raises(kc.KalmanInputError, match=match):
        call()


def _tick_labels(axis):
    return [t.get_text() for t in axis.get_ticklabels() if t.get_text()]


def test_matplotlib_axes_get_french_ticks():
    fig, ax = kc.figures.new_figure()
    ax.plot([0.0, 1.0], [-0.5, 1.5])
    ax.set_ylim(-0.5, 1.5)
    ax.set_xlim(0.0, 1.0)
    second = ax.twinx()
    second.set_yscale("log")
    second.plot([0.0, 1.0], [1e-3, 1.0])
    french_figure(fig)
    fig.savefig(io.BytesIO(), format="png")
    assert _tick_labels(ax.yaxis) == [f"{M}0,50", f"{M}0,25", "0,00", "0,25", "0,50", "0,75", "1,00", "1,25",
                                      "1,50"]
    assert _tick_labels(ax.xaxis)[:3] == ["0,0", "0,2", "0,4"]
    # l'axe logarithmique garde les graduations de matplotlib, écrites en texte (pas en formule)
    assert {"10⁻³", "10⁻²", "10⁻¹", "10⁰"} <= set(_tick_labels(second.yaxis))
    assert not any("$" in t for t in _tick_labels(second.yaxis))


def test_log_axis_minor_labels_are_french():
    fig, ax = kc.figures.new_figure()
    ax.set_yscale("log")
    ax.set_ylim(0.02, 0.08)  # moins d'une décade : matplotlib étiquette aussi les graduations secondaires
    french_figure(fig)
    fig.savefig(io.BytesIO(), format="png")
    minor = [t.get_text() for t in ax.yaxis.get_minorticklabels() if t.get_text()]
    assert f"3{NN}×{NN}10⁻²" in minor and f"6{NN}×{NN}10⁻²" in minor, minor


def test_matplotlib_formatter_writes_a_common_power_of_ten():
    fig, ax = kc.figures.new_figure()
    ax.plot([0.0, 1.0], [0.0, 4e-5])
    ax.set_ylim(0.0, 4e-5)
    ax.yaxis.set_major_formatter(matplotlib_formatter())
    fig.savefig(io.BytesIO(), format="png")
    assert _tick_labels(ax.yaxis) == ["0,0", "0,5", "1,0", "1,5", "2,0", "2,5", "3,0", "3,5", "4,0"]
    assert ax.yaxis.get_offset_text().get_text() == f"×{NN}10⁻⁵"


def test_matplotlib_formatter_groups_thousands():
    fig, ax = kc.figures.new_figure()
    ax.set_ylim(0, 30000)
    ax.yaxis.set_major_formatter(matplotlib_formatter())
    fig.savefig(io.BytesIO(), format="png")
    assert _tick_labels(ax.yaxis) == ["0", f"5{NN}000", f"10{NN}000", f"15{NN}000", f"20{NN}000", f"25{NN}000",
                                      f"30{NN}000"]
    assert ax.yaxis.get_offset_text().get_text() == ""


def test_registry_draw_applies_french_ticks():
    fig = kc.figures.draw("tension-estimation")
    fig.savefig(io.BytesIO(), format="png")
    for ax in fig.get_axes():
        for t in [*ax.get_xticklabels(), *ax.get_yticklabels()]:
            assert "." not in t.get_text(), t.get_text()


def test_glue_number_returns_and_glues_the_french_text(monkeypatch):
    import myst_nb

    glued = {}
    monkeypatch.setattr(myst_nb, "glue", lambda name, value, display=True: glued.update({name: (value, display)}))
    assert glue_number("p50", 3.392e-4, significant=4) == f"3,392{NN}×{NN}10⁻⁴"
    assert glued == {"p50": (f"3,392{NN}×{NN}10⁻⁴", False)}


def test_table_cells_are_french():
    table = kc.Table(["a", "b", "c", "d"], [[0.000339, 2.5], [1234.5, -0.5], [3, 7], ["EKF", "UKF"]],
                     ["{:.2e}", "{:.1f} cm", None, None])
    assert [table.cell(0, c) for c in range(4)] == [f"3,39{NN}×{NN}10⁻⁴", f"1{NN}234,5 cm", "3", "EKF"]
    assert [table.cell(1, c) for c in range(4)] == [f"2,50{NN}×{NN}10⁰", f"{M}0,5 cm", "7", "UKF"]
    floats = kc.Table(["x"], [[0.5, 1234.5678]])
    assert [floats.cell(r, 0) for r in range(2)] == ["0,5", f"1{NN}234,57"]
    assert f"3,39{NN}×{NN}10⁻⁴" in table.to_html() and "." not in table.to_markdown().replace("---:", "")
    with pytest.raises(kc.KalmanInputError, match="champ"):
        kc.Table(["a"], [[1.0]], ["%.3f"])
    # la sortie HTML d'une cellule n'est pas relue par l'extension de typographie : la table s'en charge,
    # hors formules
    typed = kc.Table(["pas sous l'intervalle", "part (%)", "$x'$"], [["l'EKF : 12 %"], [3.0], [1.0]]).to_html()
    assert "pas sous l’intervalle" in typed and "l’EKF\u00a0: 12\u202f%" in typed and "part (%)" in typed
    assert "\\(x'\\)" in typed and "'" not in typed.replace("\\(x'\\)", "")


def test_bokeh_tick_formatter_runs_in_javascript():
    """Le code JavaScript du formateur Bokeh, exécuté par Node.js (celui de mermaid-cli)."""
    import json
    import shutil
    import subprocess

    from kalman_course.numbers import bokeh_tick_formatter

    node = shutil.which("node")
    if node is None:
        pytest.fail("Node.js introuvable : il est requis pour la construction (mermaid-cli).")
    def run(formatter, ticks, axis=True):
        # Bokeh passe les « args » du formateur comme variables nommées du code, avec la graduation
        # (tick), son rang (index) et toutes les graduations de l'axe (ticks)
        names = ", ".join(formatter.args)
        values = ", ".join(json.dumps(v) for v in formatter.args.values())
        script = (f"const f = (tick, index, ticks, {names}) => {{ {formatter.code} }};\n"
                  f"const all = {json.dumps(ticks)};\n"
                  f"console.log(JSON.stringify(all.map((t, i) => {'f(t, i, all, ' if axis else 'f(t, i, [t], '}{values}))));")
        return json.loads(subprocess.run([node, "-e", script], capture_output=True, text=True, check=True).stdout)

    # graduation par graduation (axe d'une seule graduation)
    ticks = [0, 0.5, -0.25, 2, 1500, 25000, 1e-5, 3.5e-7, 2.5e7, -1e-4]
    assert run(bokeh_tick_formatter(), ticks, axis=False) == [
        "0", "0,5", f"{M}0,25", "2", f"1{NN}500", f"25{NN}000", "10⁻⁵",
        f"3,5{NN}×{NN}10⁻⁷", f"2,5{NN}×{NN}10⁷", f"{M}10⁻⁴"]
    # un axe : une seule écriture, en puissances de dix dès qu'une graduation l'exige
    assert run(bokeh_tick_formatter(), [1e-4, 1e-2, 1, 100, 1e4, 1e6]) == [
        "10⁻⁴", "10⁻²", "10⁰", "10²", "10⁴", "10⁶"]
    assert run(bokeh_tick_formatter(), [0, 5e5, 1e6, 1.5e6]) == ["0", f"5{NN}×{NN}10⁵", "10⁶", f"1,5{NN}×{NN}10⁶"]
    assert run(bokeh_tick_formatter(), [10, 100, 1000, 10000, 100000]) == [
        "10", "100", f"1{NN}000", f"10{NN}000", f"100{NN}000"]
    # un axe d'années : sans séparateur de milliers
    assert run(bokeh_tick_formatter(group_thousands=False), [1871, 1880, 1960, 1970.5]) == [
        "1871", "1880", "1960", "1970,5"]


def test_glue_number_accepts_a_python_spec(monkeypatch):
    import myst_nb

    glued = {}
    monkeypatch.setattr(myst_nb, "glue", lambda name, value, display=True: glued.update({name: value}))
    assert glue_number("rel", 0.0134, spec=".1%") == f"1,3{NN}%"
    assert glued == {"rel": f"1,3{NN}%"}
    with pytest.raises(kc.KalmanInputError, match="pas les deux"):
        glue_number("x", 1.0, spec=".1f", decimals=2)


def test_year_axes_of_the_slider_figures_have_no_thousands_separator():
    from kalman_course.interactive.static import _is_year_axis

    assert _is_year_axis("année") and _is_year_axis("années (1871–1970)")
    assert not _is_year_axis("temps (s)") and not _is_year_axis("débit (10⁸ m³ par an)")


# --------------------------------------------------------------------------- relecture (issue 36)


def test_format_fractions_writes_the_hand_computed_fractions():
    from kalman_course.numbers import format_fractions

    assert format_fractions([2 / 3, 17 / 8, 43 / 21]) == "2/3, 17/8, 43/21"
    assert format_fractions(-0.5) == f"{M}1/2"
    assert format_fractions([[0.26]], max_denominator=4) == "1/4"  # la plus proche de dénominateur ≤ 4
    with pytest.raises(kc.KalmanInputError, match="finis"):
        format_fractions([1.0, float("nan")])
    with pytest.raises(kc.KalmanInputError, match="max_denominator"):
        format_fractions([1.0], max_denominator=0)
