r"""Appeler le code de l'étudiant sans jamais laisser passer d'exception, et retrouver ses lignes.

Le correcteur appelle la fonction de l'étudiant sur des cas cachés : une exception, une boucle sans fin,
un avertissement de numpy ou une modification des arguments ne doivent jamais interrompre la
correction. :func:`call` rend un :class:`Outcome` (la valeur, ou l'exception et la ligne du code de
l'étudiant où elle est née) ; :class:`StudentSource` lit le code de la fonction (cellule Jupyter ou
fichier) pour nommer la ligne qui calcule une sortie fausse.
"""

from __future__ import annotations

import ast
import contextlib
import inspect
import linecache
import os
import re
import signal
import sys
import sysconfig
import textwrap
import threading
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

__all__ = ["Place", "Outcome", "StudentSource", "call", "source_of", "where_text"]

#: Temps accordé à un appel de la fonction de l'étudiant sur un cas (s).
TIME_LIMIT = 5.0

_PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
_LIBRARY_DIRS = tuple(
    os.path.realpath(p)
    for p in {sysconfig.get_paths().get(k) for k in ("stdlib", "platstdlib", "purelib", "platlib")}
    if p
)


def where_text(filename: str) -> str:
    """« votre cellule » pour une cellule Jupyter, le nom du fichier sinon."""
    if "ipykernel_" in filename or filename.startswith("<ipython-input") or filename.startswith("<cell"):
        return "votre cellule"
    if filename.startswith("<"):
        return "votre code"
    return os.path.basename(filename)


@dataclass(frozen=True)
class Place:
    """Une ligne du code de l'étudiant : fichier (ou cellule), numéro, texte."""

    filename: str
    lineno: int
    text: str

    def describe(self) -> str:
        """« ligne 4 de votre cellule : `P = A @ P @ A + Q` »."""
        code = self.text.strip()
        head = f"ligne {self.lineno} de {where_text(self.filename)}"
        return f"{head} : `{code}`" if code else head


@dataclass
class Outcome:
    """Ce qu'a donné un appel : ``value``, ou ``error`` (l'exception) et ``place`` (où elle est née dans
    le code de l'étudiant), ou ``timed_out``."""

    value: Any = None
    error: BaseException | None = None
    place: Place | None = None
    timed_out: bool = False
    warnings: list[str] = field(default_factory=list)
    executed: frozenset[int] | None = None
    returned: int | None = None

    @property
    def ok(self) -> bool:
        return self.error is None and not self.timed_out


class _TimeUp(BaseException):
    """Levée par l'alarme quand la fonction de l'étudiant dépasse :data:`TIME_LIMIT`."""


#: Après le temps accordé, l'alarme sonne de nouveau à cet intervalle (s) tant que la fonction n'a pas rendu
#: la main : un ``except:`` (ou ``except BaseException``) de l'étudiant qui avale la première interruption
#: ne bloque pas le noyau, la suivante tombe hors de son ``try``.
_REPEAT = 0.02


class _Clock:
    """L'alarme d'un appel : ``expired`` dit si le temps accordé est écoulé (même si l'interruption a été
    avalée par le code de l'étudiant)."""

    expired = False


@contextlib.contextmanager
def _time_limit(seconds: float):
    """Alarme (SIGALRM) sur le fil principal d'Unix, répétée après l'échéance ; ailleurs, pas de limite."""
    clock = _Clock()
    usable = hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()
    if not usable or seconds <= 0:
        yield clock
        return

    def _raise(signum, frame):  # noqa: ARG001
        clock.expired = True
        raise _TimeUp

    previous = signal.signal(signal.SIGALRM, _raise)
    old_delay, _ = signal.setitimer(signal.ITIMER_REAL, seconds, _REPEAT)
    try:
        yield clock
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        if old_delay:  # une alarme d'un autre était armée : on la réarme (au mieux)
            signal.setitimer(signal.ITIMER_REAL, old_delay)


def _is_student_file(filename: str) -> bool:
    if filename.startswith("<frozen"):
        return False
    if filename.startswith("<"):
        return True
    real = os.path.realpath(filename)
    if real.startswith(_PACKAGE_DIR + os.sep):
        return False
    return not any(real.startswith(d + os.sep) for d in _LIBRARY_DIRS)


def _student_place(exc: BaseException, fn: Callable, fallback: bool = True) -> Place | None:
    """La ligne la plus profonde du code de l'étudiant dans la trace de ``exc`` (sinon, si ``fallback``, la
    première ligne de ``fn``)."""
    tb = exc.__traceback__
    place = None
    while tb is not None:
        code = tb.tb_frame.f_code
        if _is_student_file(code.co_filename):
            line = linecache.getline(code.co_filename, tb.tb_lineno, tb.tb_frame.f_globals)
            place = Place(code.co_filename, tb.tb_lineno, line)
        tb = tb.tb_next
    if place is None and fallback:
        source = source_of(fn)
        if source is not None:
            place = source.place(source.first)
    return place


class _Lines:
    """Les lignes exécutées par la fonction de l'étudiant (son dernier appel terminé) et celle qui a rendu la
    main : le correcteur ne nomme que des lignes qui ont vraiment tourné (une branche ``if`` non prise n'est
    jamais accusée)."""

    def __init__(self, fn: Callable) -> None:
        try:
            self.target = inspect.unwrap(fn).__code__
        except AttributeError:
            self.target = None
        self.executed: frozenset[int] | None = None
        self.returned: int | None = None

    def __enter__(self) -> "_Lines":
        self.previous = sys.gettrace()
        if self.target is not None:
            sys.settrace(self._global)
        return self

    def __exit__(self, *exc) -> None:
        if self.target is not None:
            sys.settrace(self.previous)

    def _global(self, frame, event, arg):  # noqa: ARG002
        if event != "call" or frame.f_code is not self.target:
            return None
        lines: set[int] = set()

        def local(frame, event, arg):  # noqa: ARG001
            if event == "line":
                lines.add(frame.f_lineno)
            elif event == "return":
                self.executed, self.returned = frozenset(lines), frame.f_lineno
            return local

        return local


def call(fn: Callable, args: tuple, time_limit: float | None = None, fallback: bool = True) -> Outcome:
    """Appelle ``fn(*args)`` : jamais d'exception (sauf l'interruption demandée par l'utilisateur), les
    avertissements de numpy sont relevés et tus (les NaN et infinis sont jugés sur le résultat).
    ``fallback`` : si l'exception ne passe par aucune ligne de l'étudiant, nommer la première ligne de ``fn``
    (vrai quand ``fn`` est la fonction de l'étudiant ; faux quand c'est une expérience du paquet qui
    l'appelle)."""
    with warnings.catch_warnings(record=True) as caught, np.errstate(all="ignore"):
        warnings.simplefilter("always")
        lines = _Lines(fn) if fallback else None
        try:
            with _time_limit(TIME_LIMIT if time_limit is None else time_limit) as clock:
                if lines is None:
                    value = fn(*args)
                else:
                    with lines:
                        value = fn(*args)
        except _TimeUp:
            return Outcome(timed_out=True)
        except KeyboardInterrupt:
            raise
        except BaseException as exc:  # noqa: BLE001 — le code de l'étudiant peut lever n'importe quoi
            if clock.expired:  # l'interruption avalée, puis une autre exception : le temps était écoulé
                return Outcome(timed_out=True)
            return Outcome(error=exc, place=_student_place(exc, fn, fallback))
    if clock.expired:  # la fonction a avalé l'interruption puis rendu un résultat : hors délai
        return Outcome(timed_out=True)
    return Outcome(value=value, warnings=[str(w.message) for w in caught],
                   executed=None if lines is None else lines.executed, returned=None if lines is None else lines.returned)


# --------------------------------------------------------------------------- lecture du code


def _code_only(line: str) -> str:
    """La ligne sans son commentaire (approximation : un « # » hors chaîne simple)."""
    out, quote = [], None
    for ch in line:
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch == "#":
            break
        out.append(ch)
    return "".join(out)


class _Assignments(ast.NodeVisitor):
    """Lignes où chaque nom est affecté (hors fonctions imbriquées)."""

    def __init__(self) -> None:
        self.lines: dict[str, list[int]] = {}
        self.returns: list[ast.Return] = []
        self._depth = 0

    def _target(self, node: ast.AST, lineno: int) -> None:
        if isinstance(node, ast.Name):
            self.lines.setdefault(node.id, []).append(lineno)
        elif isinstance(node, (ast.Tuple, ast.List)):
            for elt in node.elts:
                self._target(elt, lineno)
        elif isinstance(node, ast.Starred):
            self._target(node.value, lineno)
        elif isinstance(node, ast.Subscript):  # P[0, 0] = … modifie P
            self._target(node.value, lineno)

    def visit_FunctionDef(self, node):  # noqa: N802
        self._depth += 1
        if self._depth == 1:
            self.generic_visit(node)
        self._depth -= 1

    visit_AsyncFunctionDef = visit_FunctionDef

    def visit_Lambda(self, node):  # noqa: N802
        return

    def visit_Assign(self, node):  # noqa: N802
        for target in node.targets:
            self._target(target, node.lineno)
        self.generic_visit(node)

    def visit_AugAssign(self, node):  # noqa: N802
        self._target(node.target, node.lineno)
        self.generic_visit(node)

    def visit_AnnAssign(self, node):  # noqa: N802
        self._target(node.target, node.lineno)
        self.generic_visit(node)

    def visit_For(self, node):  # noqa: N802
        self._target(node.target, node.lineno)
        self.generic_visit(node)

    def visit_Return(self, node):  # noqa: N802
        self.returns.append(node)
        self.generic_visit(node)


@dataclass
class StudentSource:
    """Le code d'une fonction de l'étudiant : ``lines`` (texte), ``first`` (numéro de la première ligne
    dans sa cellule ou son fichier), ``filename``."""

    filename: str
    first: int
    lines: list[str]
    assigned: dict[str, list[int]]
    returns: list[ast.Return]
    #: lignes exécutées (numérotation du fichier) et ligne qui a rendu la main, au dernier appel jugé
    executed: frozenset[int] | None = None
    returned: int | None = None

    def follow(self, outcome: "Outcome") -> None:
        """Retient les lignes exécutées par l'appel ``outcome`` : les lignes nommées ensuite en font partie."""
        self.executed, self.returned = outcome.executed, outcome.returned

    def _ran(self, lineno: int) -> bool:
        return self.executed is None or lineno in self.executed

    def _return_node(self) -> ast.Return | None:
        """Le ``return`` qui a rendu la main (s'il est connu), sinon le seul ``return`` ; ``None`` si on ne
        peut pas le savoir (plusieurs ``return``)."""
        if self.returned is not None:
            for node in self.returns:
                if self._file_line(node.lineno) == self.returned:
                    return node
        return self.returns[0] if len(self.returns) == 1 else None

    def place(self, lineno: int) -> Place:
        """La ligne ``lineno`` (numérotation de la cellule ou du fichier)."""
        index = lineno - self.first
        text = self.lines[index] if 0 <= index < len(self.lines) else ""
        return Place(self.filename, lineno, text.rstrip("\n"))

    def _file_line(self, snippet_lineno: int) -> int:
        return self.first + snippet_lineno - 1

    def last_line(self) -> Place:
        """La dernière ligne non vide de la fonction."""
        for i in range(len(self.lines) - 1, -1, -1):
            if self.lines[i].strip():
                return self.place(self.first + i)
        return self.place(self.first)

    def return_place(self) -> Place | None:
        """La ligne ``return`` qui a rendu la main (ou la seule de la fonction)."""
        ret = self._return_node()
        if ret is None:
            return None
        return self.place(self._file_line(ret.lineno))

    def output_place(self, index: int, n_outputs: int) -> Place | None:
        """La ligne qui calcule la sortie ``index`` : la dernière affectation exécutée du nom renvoyé à cette
        position (``return x_pred, P_pred`` → la ligne ``P_pred = …``), sinon la ligne ``return`` ; ``None``
        si on ne sait pas quel ``return`` a servi."""
        ret = self._return_node()
        if ret is None:
            return None
        value = ret.value
        if n_outputs > 1 and isinstance(value, (ast.Tuple, ast.List)) and len(value.elts) == n_outputs:
            value = value.elts[index]
        elif n_outputs > 1:
            return self.place(self._file_line(ret.lineno))
        if isinstance(value, ast.Name):
            before = [ln for ln in self.assigned.get(value.id, []) if ln <= ret.lineno
                      and self._ran(self._file_line(ln))]
            if before:
                return self.place(self._file_line(max(before)))
        return self.place(self._file_line(getattr(value, "lineno", ret.lineno)))

    def find(self, patterns: tuple[str, ...]) -> Place | None:
        """La dernière ligne exécutée (hors commentaires) qui correspond à l'un des motifs, essayés dans
        l'ordre."""
        for pattern in patterns:
            regex = re.compile(pattern)
            for i in range(len(self.lines) - 1, -1, -1):
                if self._ran(self.first + i) and regex.search(_code_only(self.lines[i])):
                    return self.place(self.first + i)
        return None

    def mutation_place(self, name: str) -> Place | None:
        """Une ligne qui modifie l'argument ``name`` sur place (``P += Q``, ``P[0] = …``, ``out=P``)."""
        n = re.escape(name)
        return self.find((rf"(?<![\w.]){n}\s*(\[[^\]]*\])?\s*(\+|-|\*|/|@|//|\*\*)=",
                          rf"(?<![\w.]){n}\s*\[[^\]]*\]\s*=(?!=)", rf"out\s*=\s*{n}\b",
                          rf"(?<![\w.]){n}\.(fill|sort|resize|put|itemset)\("))


def source_of(fn: Callable) -> StudentSource | None:
    """Le code de ``fn`` (une fonction définie dans une cellule, un fichier, ou ``exec`` avec son texte
    dans ``linecache``) ; ``None`` s'il est introuvable."""
    try:
        target = inspect.unwrap(fn)
        lines, first = inspect.getsourcelines(target)
        filename = target.__code__.co_filename
    except (OSError, TypeError, AttributeError):
        return None
    first = max(first, 1)
    visitor = _Assignments()
    try:
        tree = ast.parse(textwrap.dedent("".join(lines)))
        visitor.visit(tree)
    except SyntaxError:  # une lambda au milieu d'une ligne, par exemple
        pass
    return StudentSource(filename, first, list(lines), visitor.lines, visitor.returns)
