r"""Le moteur du correcteur : un exercice, ses cas cachés, ses erreurs classiques, et :func:`grade`.

Un :class:`Exercise` déclare la signature attendue, ses sorties (nom et nature : vecteur, covariance,
indices…), ses cas cachés (tailles aléatoires, :math:`A` non symétrique, :math:`h` non linéaire, cas
limites ; graine fixe : un verdict se reproduit) avec les sorties de référence calculées par le paquet
ou par une forme close, et ses :class:`Mistake` : chaque erreur classique est une implémentation fausse
écrite comme l'écrirait un étudiant (``example``) ; on la reconnaît quand la sortie de l'étudiant
coïncide avec la sienne sur le cas qui échoue (ou par un prédicat, ou par l'exception levée).

:func:`grade` ne lève jamais à cause du code de l'étudiant : tout devient un :class:`Verdict` en
français qui nomme la ligne en cause.
"""

from __future__ import annotations

import copy
import inspect
import re
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from . import student
from .student import Outcome, Place, StudentSource, call, source_of
from .verdict import Verdict

__all__ = ["Case", "Exercise", "Mistake", "Output", "StudentResultError", "grade", "close", "exception_text",
           "validated"]

#: Tolérance relative des comparaisons (une inverse au lieu d'une résolution reste juste).
RTOL = 1e-6


def close(a: np.ndarray, b: np.ndarray, rtol: float = RTOL) -> bool:
    """Même forme et mêmes valeurs à ``rtol`` près (relatif à la plus grande valeur de ``b``) ; NaN = NaN."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.shape != b.shape:
        return False
    finite = b[np.isfinite(b)]
    scale = max(1.0, float(np.abs(finite).max())) if finite.size else 1.0
    with np.errstate(all="ignore"):
        return bool(np.allclose(a, b, rtol=rtol, atol=1e-9 * scale, equal_nan=True))


@dataclass(frozen=True)
class Output:
    """Une sortie de la fonction : ``name`` (celui de l'énoncé) et ``kind`` : « vecteur », « matrice »,
    « covariance » (symétrique), « indices » (entiers), « poids » (positifs, de somme 1), « scalaire »."""

    name: str
    kind: str = "vecteur"


@dataclass(frozen=True)
class Case:
    """Un cas caché : ``label`` (décrit le cas en français, sans ses valeurs), ``args`` (les arguments),
    ``expected`` (sorties de référence), ``shapes`` (formes attendues), ``info`` (ce dont les
    détecteurs d'erreurs ont besoin)."""

    label: str
    args: tuple
    expected: tuple
    shapes: tuple
    info: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Mistake:
    """Une erreur classique, documentée par l'implémentation fausse ``example`` (même signature que
    l'exercice). Reconnue par ``detect(outputs, case)`` si donné, par ``exception(exc, ligne)`` pour
    une erreur qui lève (``ligne`` : le texte de la ligne de l'étudiant où elle est née), sinon quand
    les sorties de l'étudiant sont celles d'``example`` : toutes (reconnaissance complète), ou
    seulement celles d'indices ``outputs`` si elles diffèrent bien de la référence (reconnaissance
    partielle : l'étudiant a pu faire une autre erreur sur les autres sorties). ``culprit`` : motifs (expressions rationnelles) de la ligne fautive
    typique ; ``output`` : la sortie en cause (pour nommer la ligne qui la calcule). Une ligne trouvée par
    ``culprit`` n'est nommée que si elle porte la trace de l'erreur : elle correspond à chaque motif de
    ``confirm`` et à aucun de ``refute`` (sinon le verdict donne l'explication sans nommer de ligne).

    Une erreur n'est reconnue que si elle explique la fonction de l'étudiant sur **tous** les cas cachés :
    aucun cas où l'étudiant a juste et où l'implémentation fausse se tromperait (voir :func:`grade`)."""

    id: str
    title: str
    hint: str
    example: Callable
    detect: Callable[[tuple, Case], bool] | None = None
    exception: Callable[[BaseException, str], bool] | None = None
    outputs: tuple[int, ...] | None = None
    culprit: tuple[str, ...] = ()
    output: int = 0
    confirm: tuple[str, ...] = ()
    refute: tuple[str, ...] = ()

    def matches(self, outputs: tuple, case: Case) -> int:
        """Les sorties de l'étudiant sur ``case`` sont-elles celles de cette erreur ? 2 : toutes (ou le
        détecteur le dit) ; 1 : celles d'indices ``outputs``, qui diffèrent de la référence ; 0 : non."""
        if self.exception is not None and self.detect is None:
            return 0
        if self.detect is not None:
            try:
                with np.errstate(all="ignore"):
                    return 2 if self.detect(outputs, case) else 0
            except Exception:  # noqa: BLE001 — un détecteur ne fait jamais échouer la correction
                return 0
        outcome = call(self.example, tuple(copy.deepcopy(a) for a in case.args))
        if not outcome.ok:
            return 0
        k = len(case.expected)
        wrong = outcome.value if k > 1 else (outcome.value,)
        try:
            wrong = tuple(np.asarray(w, dtype=float) for w in wrong)
            if len(wrong) == k and all(close(outputs[i], wrong[i]) for i in range(k)):
                return 2
            indices = () if self.outputs is None else self.outputs
            if indices and all(close(outputs[i], wrong[i]) for i in indices) \
                    and any(not close(wrong[i], case.expected[i]) for i in indices):
                return 1
        except (TypeError, ValueError, IndexError):
            pass
        return 0

    def wrong_on(self, case: Case, partial: bool) -> bool | None:
        """L'implémentation fausse (``example``) se trompe-t-elle sur ``case`` ? Pour une reconnaissance
        partielle, seules les sorties d'indices ``outputs`` comptent. ``None`` si on ne peut pas le dire
        (elle lève, ou sa sortie n'est pas un tableau)."""
        outcome = call(self.example, tuple(copy.deepcopy(a) for a in case.args))
        if not outcome.ok:
            return None
        k = len(case.expected)
        wrong = outcome.value if k > 1 else (outcome.value,)
        try:
            wrong = tuple(np.asarray(w, dtype=float) for w in wrong)
            if len(wrong) != k:
                return True
            indices = self.outputs if partial and self.outputs else range(k)
            return any(not close(wrong[i], case.expected[i]) for i in indices)
        except (TypeError, ValueError, IndexError):
            return None


@dataclass(frozen=True)
class Exercise:
    """Un exercice : ``id``, titre et chapitre (nom de la page du livre), ``signature`` (texte),
    ``parameters`` (noms des paramètres), ``outputs``, ``make_cases`` (fonction qui construit les cas
    cachés), ``mistakes``, ``solution`` (une implémentation de référence qui appelle le paquet, pour
    les figures des TP), ``judge`` (juge sur mesure : renvoie ``None`` si c'est juste, sinon un message),
    ``shapes_hint`` (rappel des formes, pour les messages)."""

    id: str
    title: str
    chapter: str
    signature: str
    parameters: tuple[str, ...]
    outputs: tuple[Output, ...]
    make_cases: Callable[[], list[Case]]
    mistakes: tuple[Mistake, ...]
    solution: Callable
    shapes_hint: str = ""
    judge: Callable[[tuple, Case], str | None] | None = None
    deterministic: bool = True

    def cases(self) -> list[Case]:
        """Les cas cachés (construits à chaque appel, à graine fixe)."""
        return self.make_cases()

    def __repr__(self) -> str:
        return f"<Exercice {self.id} : {self.title} — {self.signature}>"


# --------------------------------------------------------------------------- messages


def _number(x: float) -> str:
    from ..numbers import format_number

    return format_number(float(x), significant=3)


def _array(a: np.ndarray) -> str:
    from ..numbers import format_array, format_number

    a = np.asarray(a, dtype=float)
    if a.ndim == 0:
        return format_number(float(a), significant=4)
    return format_array(a, significant=4)


def _shape(shape: tuple) -> str:
    if shape == ():
        return "un scalaire"
    return "(" + ", ".join(str(s) for s in shape) + (",)" if len(shape) == 1 else ")")


def _place_text(place: Place | None) -> str:
    return f"À regarder : {place.describe()}." if place is not None else ""


def exception_text(exc: BaseException, ex: Exercise | None = None) -> str:
    """L'exception de l'étudiant expliquée en français (le message original de Python est cité)."""
    from ..core.validation import KalmanInputError

    name, message = type(exc).__name__, str(exc)
    original = f"`{name}: {message}`" if message else f"`{name}`"
    if isinstance(exc, KalmanInputError):
        return f"Un appel de votre fonction a été refusé : {message}"
    if isinstance(exc, NameError):
        missing = getattr(exc, "name", None) or message
        return (f"Nom inconnu « {missing} » : faute de frappe, variable jamais définie, ou cellule "
                f"(import, définition) pas encore exécutée ? (Python : {original}.)")
    if isinstance(exc, np.linalg.LinAlgError):
        return (f"Une matrice est singulière (ou pas définie positive) là où vous l'inversez ou la "
                f"factorisez : est-ce bien la bonne matrice ? (Python : {original}.)")
    if isinstance(exc, (ValueError, TypeError)) and any(
        s in message for s in ("matmul", "not aligned", "broadcast", "shapes", "dimension", "size")
    ):
        hint = f" Rappel des formes : {ex.shapes_hint}." if ex is not None and ex.shapes_hint else ""
        return (f"Dimensions incompatibles : un produit ou une somme de tableaux de formes qui ne vont "
                f"pas ensemble. Écrivez la forme de chaque terme de la ligne en cause.{hint} (Python : {original}.)")
    if isinstance(exc, TypeError) and "function" in message:
        return (f"Une fonction est utilisée comme un tableau : appelez-la d'abord sur un point, par "
                f"exemple `h(x_pred)`. (Python : {original}.)")
    if isinstance(exc, IndexError):
        return f"Indice hors des limites d'un tableau. (Python : {original}.)"
    if isinstance(exc, ZeroDivisionError):
        return f"Division par zéro. (Python : {original}.)"
    if isinstance(exc, SystemExit):
        return "Votre fonction appelle `sys.exit()` (ou `exit()`) : elle doit renvoyer son résultat."
    return f"Votre fonction a levé une exception : {original}."


# --------------------------------------------------------------------------- correction


class _Stop(Exception):
    """Interrompt la correction avec un verdict."""

    def __init__(self, verdict: Verdict):
        super().__init__(verdict.feedback)
        self.verdict = verdict


def _fail(ex: Exercise, kind: str, text: str, place: Place | None = None, mistake: str | None = None,
          case: tuple[int, Case] | None = None) -> Verdict:
    lines = [text]
    if place is not None:
        lines.append(_place_text(place))
    if case is not None:
        number, c = case
        lines.append(f"(Cas caché n° {number} : {c.label}.)")
    return Verdict(ex.id, ex.title, False, "\n".join(lines), kind, mistake, None if place is None else place.lineno)


def _signature_problem(ex: Exercise, fn: Callable) -> str | None:
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return None
    try:
        sig.bind(*ex.parameters)
    except TypeError:
        own = ", ".join(sig.parameters)
        name = getattr(fn, "__name__", "votre fonction")
        return (f"Votre fonction `{name}({own})` ne peut pas être appelée avec les {len(ex.parameters)} "
                f"arguments de l'exercice : la signature attendue est `{ex.signature}`.")
    return None


def _outputs(ex: Exercise, value: Any, source: StudentSource | None) -> tuple:
    """Les sorties de l'étudiant en tableaux ``float`` (une par sortie déclarée) ; lève :class:`_Stop`."""
    k = len(ex.outputs)
    names = ", ".join(o.name for o in ex.outputs)
    place = source.return_place() if source is not None else None
    if value is None:
        where = source.last_line() if source is not None else None
        raise _Stop(_fail(ex, "forme", f"Votre fonction ne renvoie rien (`None`) : il manque `return {names}`.",
                          place or where))
    if k > 1:
        if not isinstance(value, (tuple, list)) or len(value) != k:
            got = (f"{len(value)} valeurs" if isinstance(value, (tuple, list))
                   else f"un seul objet ({type(value).__name__})")
            raise _Stop(_fail(ex, "forme", f"Votre fonction doit renvoyer {k} valeurs, `return {names}` ; "
                                            f"elle renvoie {got}.", place))
        items = tuple(value)
    else:
        items = (value,)
    arrays = []
    for output, item in zip(ex.outputs, items):
        try:
            arr = np.asarray(item, dtype=float)
        except (TypeError, ValueError):
            raise _Stop(_fail(ex, "forme", f"La sortie « {output.name} » doit être un tableau de nombres ; "
                                            f"votre fonction renvoie un objet {type(item).__name__}.", place)) from None
        arrays.append(arr)
    return tuple(arrays)


def _structure_problem(ex: Exercise, outs: tuple, case: Case, source: StudentSource | None,
                       number: int) -> Verdict | None:
    """Forme, valeurs non finies, symétrie, entiers : les défauts qui se voient sans la référence."""
    k = len(ex.outputs)
    for i, (output, arr, shape) in enumerate(zip(ex.outputs, outs, case.shapes)):
        place = source.output_place(i, k) if source is not None else None
        if arr.shape != tuple(shape):
            extra = ""
            if arr.size == int(np.prod(shape)) and arr.ndim != len(shape):
                extra = (" Les valeurs y sont, mais pas la forme : un vecteur (n,) n'est ni une colonne (n, 1) "
                         "ni une ligne (1, n) (`.ravel()`, ou évitez `np.outer`/`reshape` inutiles).")
            elif arr.ndim == len(shape) == 2 and arr.shape == tuple(shape)[::-1]:
                extra = " C'est la forme transposée : une transposée en trop ou en moins ?"
            hint = f" Rappel des formes : {ex.shapes_hint}." if ex.shapes_hint else ""
            return _fail(ex, "forme", f"La sortie « {output.name} » a la forme {_shape(arr.shape)} ; attendu "
                                       f"{_shape(tuple(shape))}.{extra}{hint}", place, case=(number, case))
        if not np.isfinite(arr).all():
            return _fail(ex, "valeur", f"La sortie « {output.name} » contient des valeurs non finies (NaN ou "
                                        f"infini) : une division par zéro, une exponentielle qui déborde, une "
                                        f"racine d'un nombre négatif ?", place, case=(number, case))
        if output.kind == "covariance" and arr.ndim == 2:
            scale = max(1.0, float(np.abs(arr).max()))
            if np.abs(arr - arr.T).max() > 1e-8 * scale:
                return _fail(ex, "valeur", f"La covariance « {output.name} » n'est pas symétrique, alors qu'une "
                                            f"covariance l'est toujours : chaque terme qui la forme doit être "
                                            f"symétrique (M P Mᵀ, covariance). Vérifiez-les un à un, en dimension "
                                            f"n ≥ 2.", place, case=(number, case))
        if output.kind == "indices" and not np.array_equal(arr, np.round(arr)):
            return _fail(ex, "valeur", f"« {output.name} » doit contenir des indices entiers.", place,
                         case=(number, case))
    return None


def _value_problem(ex: Exercise, outs: tuple, case: Case, source: StudentSource | None, number: int) -> Verdict:
    k = len(ex.outputs)
    wrong = [i for i in range(k) if not close(outs[i], case.expected[i])]
    i = wrong[0] if wrong else 0
    place = source.output_place(i, k) if source is not None else None
    names = " et ".join(f"« {ex.outputs[j].name} »" for j in wrong)
    expected, got = np.asarray(case.expected[i], dtype=float), outs[i]
    error = float(np.max(np.abs(got - expected))) if got.shape == expected.shape and got.size else float("nan")
    text = f"Valeur fausse pour {names} (plus grand écart : {_number(error)})."
    if expected.size <= 9:
        text += (f"\nAttendu pour « {ex.outputs[i].name} » : {_array(expected)} ; "
                 f"obtenu : {_array(got)}.")
    return _fail(ex, "valeur", text, place, case=(number, case))


def _mistake_place(mistake: Mistake, source: StudentSource | None, k: int) -> Place | None:
    """La ligne à nommer pour ``mistake``, seulement si elle est sûre : la ligne typique de l'erreur
    (``culprit``) quand elle en porte la trace (``confirm``, ``refute``) ; sinon, pour une erreur sans motif
    de ligne, celle qui calcule la sortie en cause ; sinon aucune."""
    if source is None:
        return None
    if mistake.culprit:
        place = source.find(mistake.culprit)
        if place is None:
            return None
        code = place.text.split("#", 1)[0]
        sure = all(re.search(p, code) for p in mistake.confirm) and not any(re.search(p, code) for p in mistake.refute)
        return place if sure else None
    return source.output_place(mistake.output, k)


def _student_outputs(ex: Exercise, fn: Callable, case: Case, source: StudentSource | None) -> tuple | None:
    """Les sorties de l'étudiant sur ``case`` (tableaux), ou ``None`` si l'appel échoue."""
    outcome = call(fn, tuple(copy.deepcopy(a) for a in case.args))
    if not outcome.ok:
        return None
    try:
        return _outputs(ex, outcome.value, source)
    except _Stop:
        return None


def _recognise(ex: Exercise, fn: Callable, source: StudentSource | None, cases: list[Case], number: int,
               outs: tuple) -> Mistake | None:
    """L'erreur classique qui explique la fonction de l'étudiant, ou ``None``.

    Candidates : les erreurs dont la sortie coïncide avec celle de l'étudiant sur le premier cas qui échoue
    (le cas n° ``number``). Une candidate est écartée dès qu'un autre cas la contredit : l'étudiant y a juste
    alors que l'implémentation fausse s'y tromperait (et que le détecteur de l'erreur, qui connaît ses
    variantes, ne reconnaît pas la sortie de l'étudiant) (une erreur dans une seule branche du code de
    l'étudiant — petits angles, n = 1 — n'est pas prise pour une erreur de la formule générale). Parmi les
    autres : la reconnaissance complète d'abord, puis celle qui explique le plus de cas faux, puis l'ordre de
    déclaration."""
    case = cases[number - 1]
    scores = [m.matches(outs, case) for m in ex.mistakes]
    if not any(scores):
        return None
    others = []
    for j, c in enumerate(cases, 1):
        if j == number:
            continue
        theirs = _student_outputs(ex, fn, c, source)
        if theirs is None:
            continue
        right = all(close(o, e) for o, e in zip(theirs, c.expected)) if ex.judge is None \
            else ex.judge(theirs, c) is None
        others.append((c, theirs, right))
    best, best_key = None, None
    for order, (mistake, score) in enumerate(zip(ex.mistakes, scores)):
        if not score:
            continue
        explained = 1
        contradicted = False
        for c, theirs, right in others:
            agrees = mistake.matches(theirs, c) > 0
            if right:
                # juste ici, alors que l'erreur se tromperait (et que sa variante reconnue ne l'explique pas)
                if not agrees and mistake.wrong_on(c, partial=score == 1):
                    contradicted = True
                    break
            elif agrees:
                explained += 1
        if contradicted:
            continue
        key = (score, explained, -order)
        if best_key is None or key > best_key:
            best, best_key = mistake, key
    return best


def _judge(ex: Exercise, fn: Callable, source: StudentSource | None, names: list[str]) -> Verdict:
    k = len(ex.outputs)
    cases = ex.cases()
    for number, case in enumerate(cases, 1):
        args = tuple(copy.deepcopy(a) for a in case.args)
        outcome: Outcome = call(fn, args)
        if source is not None:
            source.follow(outcome)
        if outcome.timed_out:
            raise _Stop(_fail(ex, "temps", f"Votre fonction n'a pas rendu la main après {student.TIME_LIMIT:g} s : une boucle sans fin ?",
                              None, case=(number, case)))
        if outcome.error is not None:
            exc = outcome.error
            if isinstance(exc, NotImplementedError):
                raise _Stop(_fail(ex, "pas écrite", "Fonction pas encore écrite : remplacez `raise "
                                  "NotImplementedError` par votre code, exécutez la cellule de la fonction, puis "
                                  "relancez cette vérification.", outcome.place))
            for mistake in ex.mistakes:
                line = outcome.place.text if outcome.place is not None else ""
                if mistake.exception is not None and mistake.exception(exc, line):
                    raise _Stop(_fail(ex, "erreur classique", f"Erreur classique : {mistake.title}.\n{mistake.hint}",
                                      outcome.place, mistake.id, (number, case)))
            raise _Stop(_fail(ex, "exception", exception_text(exc, ex), outcome.place, case=(number, case)))
        for i, (before, after) in enumerate(zip(case.args, args)):
            if isinstance(before, np.ndarray) and not (after is not None and isinstance(after, np.ndarray)
                                                       and after.shape == before.shape
                                                       and np.array_equal(after, before, equal_nan=True)):
                name = names[i] if i < len(names) else ex.parameters[i]
                place = source.mutation_place(name) if source is not None else None
                raise _Stop(_fail(ex, "effet de bord", f"Votre fonction modifie son argument « {name} » sur place "
                                  f"(`{name} += …`, `{name}[…] = …`) : l'appelant perd sa valeur. Travaillez sur une "
                                  f"nouvelle variable (`{name}_new = {name} + …`) ou sur `{name}.copy()`.",
                                  place, case=(number, case)))
        outs = _outputs(ex, outcome.value, source)
        if ex.deterministic and number == 1:  # même appel, même résultat : pas de hasard caché
            again = call(fn, tuple(copy.deepcopy(a) for a in case.args))
            try:
                same = again.ok and all(close(a, b, rtol=1e-12) for a, b in zip(_outputs(ex, again.value, source), outs))
            except _Stop:
                same = False
            if not same:
                raise _Stop(_fail(ex, "valeur", "Deux appels avec les mêmes arguments donnent deux résultats "
                                  "différents : n'utilisez pas de tirage aléatoire ni de variable globale modifiée "
                                  "(ici, tout le hasard est dans les arguments).", None, case=(number, case)))
        if ex.judge is not None:
            message = ex.judge(outs, case)
            correct = message is None
        else:
            correct = all(close(o, e) for o, e in zip(outs, case.expected))
            message = None
        if correct:
            continue
        mistake = _recognise(ex, fn, source, cases, number, outs)
        if mistake is not None:
            raise _Stop(_fail(ex, "erreur classique", f"Erreur classique : {mistake.title}.\n{mistake.hint}",
                              _mistake_place(mistake, source, k), mistake.id, (number, case)))
        structure = _structure_problem(ex, outs, case, source, number)
        if structure is not None:
            raise _Stop(structure)
        if message is not None:
            raise _Stop(_fail(ex, "valeur", message, source.return_place() if source is not None else None,
                              case=(number, case)))
        raise _Stop(_value_problem(ex, outs, case, source, number))
    labels = "\n".join(f"- {c.label}" for c in cases)
    return Verdict(ex.id, ex.title, True,
                   f"Bravo : votre fonction donne le bon résultat sur les {len(cases)} cas cachés :\n{labels}",
                   "réussi")


class StudentResultError(Exception):
    """Levée par une fonction de l'étudiant enveloppée par :func:`validated` quand son résultat n'a pas la
    forme de l'exercice (rien, trop de valeurs, pas des nombres) ; le message, en français, nomme sa ligne."""


def validated(ex: Exercise, fn: Callable) -> Callable:
    """``fn`` (une fonction de l'étudiant pour l'exercice ``ex``) dont le résultat est vérifié à chaque appel :
    rendu en tableaux ``float`` (un tuple s'il y a plusieurs sorties) ; un résultat sans la forme attendue
    lève :class:`StudentResultError`, qui nomme la fonction et sa ligne (et non le code du paquet qui
    l'appelle)."""
    source = source_of(fn)
    name = getattr(fn, "__name__", "votre fonction")

    def checked(*args):
        value = fn(*args)
        try:
            outs = _outputs(ex, value, source)
        except _Stop as stop:
            lines = stop.verdict.feedback.split("\n")
            raise StudentResultError(f"`{name}` : " + " ".join(lines)) from None
        return outs if len(outs) > 1 else outs[0]

    checked.__name__ = name
    return checked


def grade(ex: Exercise, fn: Any) -> Verdict:
    """Corrige ``fn`` sur les cas cachés de ``ex`` ; ne lève jamais à cause du code de l'étudiant."""
    if not callable(fn):
        return _fail(ex, "signature", f"Donnez la fonction elle-même, sans l'appeler : "
                                      f"`practice.check(\"{ex.id}\", {ex.signature.split('(')[0]})` "
                                      f"(reçu un objet {type(fn).__name__}).")
    problem = _signature_problem(ex, fn)
    source = source_of(fn)
    if problem is not None:
        return _fail(ex, "signature", problem, source.place(source.first) if source is not None else None)
    try:
        names = list(inspect.signature(fn).parameters)
    except (TypeError, ValueError):
        names = list(ex.parameters)
    try:
        return _judge(ex, fn, source, names)
    except _Stop as stop:
        return stop.verdict
    except KeyboardInterrupt:
        raise
    except Exception as exc:  # noqa: BLE001 — un objet renvoyé si étrange que l'analyse échoue
        return _fail(ex, "forme", f"Le correcteur n'a pas pu analyser le résultat de votre fonction "
                                  f"(`{type(exc).__name__}: {exc}`) : renvoie-t-elle bien des tableaux numpy ?")
