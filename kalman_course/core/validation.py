"""Vérification des entrées : toutes les erreurs destinées à l'utilisateur, en français, au même endroit.

Chaque fonction reçoit le *nom* de l'argument tel que l'utilisateur l'a écrit (``"Q"``, ``"P0"``, ``"y"``…)
afin que le message d'erreur le désigne. Rien n'est diffusé (*broadcast*) silencieusement : une forme
incorrecte est une erreur.
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np
import scipy.linalg

__all__ = [
    "KalmanInputError",
    "shape_text",
    "as_float_array",
    "as_vector",
    "as_matrix",
    "as_square_matrix",
    "check_symmetric",
    "check_psd",
    "check_pd",
    "as_gaussian",
    "symmetric_tolerance",
    "as_measurements",
    "as_batch_measurements",
    "as_controls",
    "as_batch_controls",
    "check_control_allowed",
    "check_instance",
    "call_user_function",
    "check_finite_output",
    "as_probability",
    "as_positive_number",
    "as_integer",
]


class KalmanInputError(ValueError):
    """Entrée invalide : le message (en français) nomme l'argument et ce qui était attendu."""


def shape_text(shape: tuple[int, ...]) -> str:
    """La forme d'un tableau reçu, pour un message : « un scalaire », « la forme (2,) », « la forme (3, 4) »."""
    shape = tuple(int(s) for s in shape)
    if len(shape) == 0:
        return "un scalaire"
    return f"la forme {shape}"


def as_float_array(name: str, value: Any, *, allow_nan: bool = False) -> np.ndarray:
    """Convertit ``value`` en tableau ``float64`` (copie), en refusant le non numérique et le non fini.

    ``allow_nan=True`` laisse passer les NaN (mesures manquantes) mais jamais les infinis.
    """
    if value is None:
        raise KalmanInputError(f"« {name} » est absent (None) alors qu'un tableau numérique est attendu.")
    try:
        if np.iscomplexobj(np.asarray(value)):
            raise KalmanInputError(f"« {name} » doit être réel, pas complexe.")
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        if isinstance(exc, KalmanInputError):
            raise
        raise KalmanInputError(
            f"« {name} » doit être un tableau de nombres réels ; conversion impossible ({type(value).__name__})."
        ) from exc
    if allow_nan:
        if np.isinf(arr).any():
            raise KalmanInputError(f"« {name} » contient des valeurs infinies.")
    elif not np.isfinite(arr).all():
        raise KalmanInputError(f"« {name} » contient des valeurs non finies (NaN ou infini).")
    return arr


def as_vector(name: str, value: Any, n: int) -> np.ndarray:
    """Vecteur de taille ``n`` (forme ``(n,)``). Un scalaire est accepté si ``n == 1``.

    Un vecteur colonne ``(n, 1)`` (convention de filterpy) est refusé avec un message explicite.
    """
    arr = as_float_array(name, value)
    if arr.ndim == 0 and n == 1:
        return arr.reshape(1)
    if arr.shape != (n,):
        hint = " (vecteur colonne : utilisez un tableau 1-D, par exemple x.ravel())" if arr.shape == (n, 1) else ""
        raise KalmanInputError(
            f"« {name} » doit être un vecteur de forme ({n},) ; reçu {shape_text(arr.shape)}{hint}."
        )
    return arr


def as_batch_vector(name: str, value: Any, n: int, N: int) -> np.ndarray:
    """Vecteur de ``N`` tirages ``(N, n)`` : ``(n,)`` commun à tous les tirages (scalaire accepté si
    ``n == 1``, comme :func:`as_vector`) ou ``(N, n)`` un par tirage. Renvoie une copie ``(N, n)``."""
    arr = as_float_array(name, value)
    if arr.ndim == 0 and n == 1:
        arr = arr.reshape(1)
    if arr.shape == (n,):
        return np.tile(arr, (N, 1))
    if arr.shape != (N, n):
        raise KalmanInputError(
            f"« {name} » doit être de forme ({n},) (commun) ou ({N}, {n}) (un par tirage) ; reçu {shape_text(arr.shape)}."
        )
    return arr.copy()


def as_matrix(
    name: str, value: Any, rows: int | None, cols: int | None, free_rows: str = "m", free_cols: str = "p"
) -> np.ndarray:
    """Matrice 2-D ``(rows, cols)`` ; ``None`` : dimension libre, nommée ``free_rows``/``free_cols`` dans
    le message. Un scalaire donne ``(1, 1)`` si permis."""
    arr = as_float_array(name, value)
    if arr.ndim == 0 and rows in (1, None) and cols in (1, None):
        return arr.reshape(1, 1)
    expected = f"({rows if rows is not None else free_rows}, {cols if cols is not None else free_cols})"
    if arr.ndim != 2:
        raise KalmanInputError(
            f"« {name} » doit être une matrice 2-D de forme {expected} ; reçu {shape_text(arr.shape)}."
        )
    if (rows is not None and arr.shape[0] != rows) or (cols is not None and arr.shape[1] != cols):
        raise KalmanInputError(
            f"« {name} » doit être de forme {expected} ; reçu {shape_text(arr.shape)}."
        )
    if arr.shape[0] == 0 or arr.shape[1] == 0:
        raise KalmanInputError(f"« {name} » est vide ({shape_text(arr.shape)}).")
    return arr


def as_square_matrix(name: str, value: Any, n: int | None) -> np.ndarray:
    """Matrice carrée ``(n, n)`` ; un scalaire est accepté pour ``n == 1`` (ou ``n`` libre)."""
    arr = as_float_array(name, value)
    if arr.ndim == 0 and n in (1, None):
        return arr.reshape(1, 1)
    if arr.ndim != 2 or arr.shape[0] != arr.shape[1]:
        size = "n" if n is None else str(n)
        raise KalmanInputError(
            f"« {name} » doit être une matrice carrée ({size}, {size}) ; reçu {shape_text(arr.shape)}."
        )
    if n is not None and arr.shape[0] != n:
        raise KalmanInputError(
            f"« {name} » doit être de forme ({n}, {n}) ; reçu {shape_text(arr.shape)}."
        )
    if arr.shape[0] == 0:
        raise KalmanInputError(f"« {name} » est vide.")
    return arr


#: Signe moins typographique, espace fine insécable (milliers, « × ») et exposants des messages.
_MINUS, _NNBSP = "\u2212", "\u202f"
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
_SPEC_DIGITS = re.compile(r"^\.(\d+)g$")


def _fixed_text(x: float, decimals: int, trim: bool = False) -> str:
    """``x`` à ``decimals`` décimales, milliers séparés par une espace fine, virgule décimale."""
    text = f"{round(x, decimals) + 0.0:,.{decimals}f}"
    if trim and "." in text:
        text = text.rstrip("0").rstrip(".")
    return text.replace(",", _NNBSP).replace(".", ",").replace("-", _MINUS)


def _french_number(x: float, *, decimals: int | None = None, significant: int = 3, trim: bool = False) -> str:
    r"""Le nombre d'un message d'erreur écrit à la française, avec les règles de
    :func:`kalman_course.numbers.format_number` (``decimals`` fixes, ou ``significant`` chiffres et
    écriture :math:`m \times 10^n` si :math:`|x| < 10^{-3}` ou :math:`|x| \ge 10^6`), sans Babel : le cœur
    du paquet n'en dépend pas (les tests comparent les deux écritures)."""
    if math.isnan(x):
        return "NaN"
    if math.isinf(x):
        return ("" if x > 0 else _MINUS) + "∞"
    if decimals is not None:
        return _fixed_text(x, decimals, trim)
    exponent = 0 if x == 0 else math.floor(math.log10(abs(x)))
    rounded = 0.0 if x == 0 else round(x, significant - 1 - exponent)
    if rounded != 0:
        exponent = math.floor(math.log10(abs(rounded)))
    if rounded != 0 and (exponent < -3 or exponent >= 6):
        mantissa = _fixed_text(rounded / 10.0**exponent, significant - 1, trim).replace(_NNBSP, "")
        return f"{mantissa}{_NNBSP}×{_NNBSP}10{str(exponent).translate(_SUPERSCRIPT)}"
    return _fixed_text(rounded, max(significant - 1 - exponent, 0), trim)


def number_text(value: Any, spec: str) -> str:
    """Un nombre cité dans un message d'erreur, écrit à la française (« −1,23 × 10⁻³ ») : ``spec`` est un
    format ``.Ng`` (``N`` chiffres significatifs, zéros finals retirés), comme
    ``kalman_course.numbers.format_spec(value, spec)``, qui donne la même écriture."""
    match = _SPEC_DIGITS.match(spec)
    if match is None:
        raise ValueError(f"format de message non pris en charge : {spec!r} (attendu .Ng)")
    return _french_number(float(value), significant=max(int(match[1]), 1), trim=True)


def array_text(value: Any, *, decimals: int | None = None, significant: int = 3, trim: bool = False) -> str:
    """Un vecteur cité dans un message d'erreur, écrit à la française comme
    ``kalman_course.numbers.format_array(value, decimals=…)`` (ou ``significant=…``) : colonnes alignées à
    droite, deux espaces entre elles."""
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        return _french_number(float(arr), decimals=decimals, significant=significant, trim=trim)
    rows = np.atleast_2d(arr)
    cells = [[_french_number(float(v), decimals=decimals, significant=significant, trim=trim) for v in row]
             for row in rows]
    width = max(len(c) for row in cells for c in row)
    lines = ["  ".join(c.rjust(width) for c in row) for row in cells]
    if arr.ndim == 1:
        return f"[{lines[0]}]"
    return "[" + "\n ".join(f"[{line}]" for line in lines) + "]"


def symmetric_tolerance(M: np.ndarray) -> float:
    """Tolérance relative de symétrie : ``1e-9 · max(1, max|M|)``."""
    return 1e-9 * max(1.0, float(np.max(np.abs(M))) if M.size else 1.0)


def check_symmetric(name: str, M: np.ndarray) -> np.ndarray:
    """Vérifie ``M = Mᵀ`` (à la tolérance près) et renvoie la partie symétrique ``(M + Mᵀ)/2``."""
    asym = float(np.max(np.abs(M - M.T)))
    if asym > symmetric_tolerance(M):
        raise KalmanInputError(
            f"« {name} » doit être symétrique (c'est une matrice de covariance) ; "
            f"écart maximal |{name} − {name}ᵀ| = {number_text(asym, '.3g')}."
        )
    return 0.5 * (M + M.T)


def check_psd(name: str, M: np.ndarray) -> np.ndarray:
    """Symétrique semi-définie positive (valeurs propres ≥ −tolérance). Renvoie la partie symétrique."""
    M = check_symmetric(name, M)
    lam_min = float(scipy.linalg.eigvalsh(M)[0])
    if lam_min < -1e-10 * max(1.0, float(np.max(np.abs(M)))):
        raise KalmanInputError(
            f"« {name} » doit être semi-définie positive (covariance) ; "
            f"plus petite valeur propre = {number_text(lam_min, '.3g')} < 0."
        )
    return M


def check_pd(name: str, M: np.ndarray) -> np.ndarray:
    """Symétrique définie positive (la factorisation de Cholesky doit réussir). Renvoie la partie symétrique."""
    M = check_symmetric(name, M)
    try:
        scipy.linalg.cholesky(M, lower=True, check_finite=False)
    except np.linalg.LinAlgError:
        lam_min = float(scipy.linalg.eigvalsh(M)[0])
        raise KalmanInputError(
            f"« {name} » doit être définie positive (covariance inversible) ; "
            f"plus petite valeur propre = {number_text(lam_min, '.3g')}."
        ) from None
    return M


def as_gaussian(x: Any, P: Any, n: int, x_name: str = "x0", P_name: str = "P0") -> tuple[np.ndarray, np.ndarray]:
    """Une estimation gaussienne : ``x`` vecteur (n,), ``P`` covariance (n, n) symétrique semi-définie positive."""
    return as_vector(x_name, x, n), check_psd(P_name, as_square_matrix(P_name, P, n))


def as_measurements(name: str, y: Any, m: int) -> np.ndarray:
    """Mesures empilées ``(T, m)`` ; ``(T,)`` accepté si ``m = 1``.

    Une mesure manquante s'écrit ``None`` ou ``NaN`` (toute la ligne ou seulement certaines composantes).
    Les infinis sont refusés.
    """
    if isinstance(y, (list, tuple)):
        missing = np.nan if m == 1 else [np.nan] * m
        y = [missing if row is None else row for row in y]
    elif hasattr(y, "east") and hasattr(y, "north") and not hasattr(y, "__array__"):
        raise KalmanInputError(
            f"« {name} » est un vol ({type(y).__name__}), pas un tableau de mesures (T, {m}) : donnez ses positions, "
            f"par exemple np.column_stack([vol.east, vol.north]) (m, dans le plan tangent), mesurées aux instants "
            f"vol.t (le modèle suit ces pas irréguliers)."
        )
    arr = as_float_array(name, y, allow_nan=True)
    if arr.ndim == 1 and m == 1:
        arr = arr.reshape(-1, 1)
    if arr.ndim != 2 or arr.shape[1] != m:
        extra = " ou (T,)" if m == 1 else ""
        raise KalmanInputError(
            f"« {name} » doit être de forme (T, {m}){extra} : une ligne de {m} composante(s) par pas de temps ; "
            f"reçu {shape_text(arr.shape)}."
        )
    if arr.shape[0] == 0:
        raise KalmanInputError(f"« {name} » ne contient aucune mesure (T = 0).")
    return arr


def as_batch_measurements(name: str, Y: Any, m: int) -> np.ndarray:
    """Mesures de ``N`` tirages, forme ``(N, T, m)`` exigée (``NaN`` : manquante). Un tableau 2-D est
    refusé, même si ``m = 1`` : ``(30, 1)`` serait-il 30 tirages d'une mesure ou un tirage de 30 mesures ?"""
    arr = as_float_array(name, Y, allow_nan=True)
    if arr.ndim == 3 and arr.shape[2] == m and arr.shape[0] > 0 and arr.shape[1] > 0:
        return arr
    if arr.ndim == 2:
        hint = (f" : pour un seul tirage, filtrez-le sans « _runs » ou donnez {name}[None] ; pour N tirages "
                f"d'une mesure scalaire, donnez {name}[..., None]")
    else:
        hint = ""
    raise KalmanInputError(
        f"« {name} » doit être de forme (N, T, {m}) : N ≥ 1 tirages de T ≥ 1 mesures de {m} composante(s) ; "
        f"reçu {shape_text(arr.shape)}{hint}."
    )


def as_batch_controls(name: str, u: Any, N: int, n_steps: int, p: int) -> np.ndarray | None:
    """Commandes de ``N`` tirages : ``(T, p)`` communes (``(T,)`` accepté si ``p = 1``) ou ``(N, T, p)``, une
    suite par tirage ; ``None`` sans commande. Renvoie ``(T, p)`` ou ``(N, T, p)``."""
    if u is None:
        return None
    check_control_allowed(name, p)
    arr = as_float_array(name, u)
    if arr.ndim == 3:
        if arr.shape != (N, n_steps, p):
            raise KalmanInputError(
                f"« {name} » doit être de forme ({n_steps}, {p}) (commune) ou ({N}, {n_steps}, {p}) (une suite "
                f"par tirage) ; reçu {shape_text(arr.shape)}."
            )
        return arr
    return as_controls(name, arr, n_steps, p)


def as_controls(name: str, u: Any, n_steps: int, p: int) -> np.ndarray | None:
    """Commandes empilées ``(T, p)`` (``(T,)`` accepté si ``p = 1``), ou ``None`` sans commande.

    Une commande fournie à un modèle sans matrice ``B`` (``p = 0``) est une erreur.
    """
    if u is None:
        return None
    check_control_allowed(name, p)
    arr = as_float_array(name, u)
    if arr.ndim == 1 and p == 1:
        arr = arr.reshape(-1, 1)
    if arr.ndim != 2 or arr.shape[1] != p:
        extra = " ou (T,)" if p == 1 else ""
        raise KalmanInputError(
            f"« {name} » doit être de forme (T, {p}){extra} ; reçu {shape_text(arr.shape)}."
        )
    if arr.shape[0] != n_steps:
        raise KalmanInputError(
            f"« {name} » doit avoir une commande par pas de temps : {n_steps} ligne(s) attendue(s), "
            f"{arr.shape[0]} reçue(s)."
        )
    return arr


def check_control_allowed(name: str, p: int) -> None:
    """Une commande n'a de sens que si le modèle a une matrice ``B`` (``p > 0``)."""
    if p == 0:
        raise KalmanInputError(
            f"« {name} » est fourni mais le modèle n'a pas de matrice de commande B : "
            f"construisez le modèle avec B=… ou retirez « {name} »."
        )


def check_instance(name: str, value: Any, cls: type, hint: str = "") -> Any:
    """``value`` doit être une instance de ``cls`` (un modèle, le plus souvent) ; ``hint`` : piste en français."""
    if not isinstance(value, cls):
        extra = f" ({hint})" if hint else ""
        raise KalmanInputError(
            f"« {name} » doit être un {cls.__name__} ; reçu {type(value).__name__}{extra}."
        )
    return value


def call_user_function(name: str, func: Any, x: np.ndarray, args: tuple = ()) -> Any:
    """Appelle une fonction fournie par l'utilisateur (``f``, ``h``, une jacobienne…) en ``x`` ; toute
    exception devient une :class:`KalmanInputError` qui nomme la fonction et le point."""
    try:
        return func(x, *args)
    except KalmanInputError:
        raise
    except Exception as exc:  # noqa: BLE001 — l'erreur de l'utilisateur, rendue lisible
        raise KalmanInputError(
            f"La fonction « {name} » a échoué en x = {np.array2string(np.asarray(x), precision=4)} : "
            f"{type(exc).__name__}: {exc}"
        ) from exc


def check_finite_output(name: str, arr: np.ndarray, x: np.ndarray, what: str = "La fonction") -> np.ndarray:
    """Le résultat ``arr`` d'une fonction de l'utilisateur évaluée en ``x`` doit être fini."""
    if not np.isfinite(arr).all():
        verb = "a renvoyé" if what == "La fonction" else "contient"
        raise KalmanInputError(
            f"{what} « {name} » {verb} des valeurs non finies (NaN ou infini) en "
            f"x = {np.array2string(np.asarray(x), precision=4)}."
        )
    return arr


# --------------------------------------------------------------------------- nombres d'un réglage (issue 37)


def _scalar(name: str, value: Any, expected: str) -> float:
    """Un nombre réel fini (pas un booléen, pas un tableau) ; sinon une erreur qui dit ``expected``."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not math.isfinite(float(value)):
        raise KalmanInputError(f"« {name} » doit être {expected} ; reçu {value!r}.")
    return float(value)


def as_probability(name: str, value: Any, *, one: bool = False) -> float:
    r"""Une probabilité strictement positive : dans :math:`(0, 1)`, ou :math:`(0, 1]` si ``one`` (une
    probabilité de détection peut valoir 1, une probabilité de porte non : la porte serait infinie)."""
    expected = "une probabilité dans ]0, 1]" if one else "une probabilité strictement entre 0 et 1"
    p = _scalar(name, value, expected)
    if not (0.0 < p < 1.0 or (one and p == 1.0)):
        raise KalmanInputError(f"« {name} » doit être {expected} ; reçu {value!r}.")
    return p


def as_positive_number(name: str, value: Any, what: str = "un nombre strictement positif") -> float:
    """Un nombre réel fini strictement positif ; ``what`` précise ce qu'il représente dans le message."""
    x = _scalar(name, value, what)
    if not x > 0.0:
        raise KalmanInputError(f"« {name} » doit être {what} ; reçu {value!r}.")
    return x


def as_integer(name: str, value: Any, low: int, what: str = "") -> int:
    """Un entier (pas un booléen) supérieur ou égal à ``low``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        extra = f" ({what})" if what else ""
        raise KalmanInputError(f"« {name} » doit être un entier ≥ {low}{extra} ; reçu {value!r}.")
    return int(value)
