r"""Travaux pratiques : l'étudiant écrit les filtres, le correcteur répond en français.

.. code-block:: python

    from kalman_course import practice

    def predict(x, P, A, Q):
        return A @ x, A @ P @ A.T + Q

    practice.check("kf-predict", predict)    # encadré vert « ✔ Réussi », ou rouge avec l'explication

* :func:`exercises` liste les exercices (identifiant, titre, chapitre du cours, signature) ;
* :func:`check` corrige une fonction sur les cas cachés de l'exercice (tailles au hasard, :math:`A` non
  symétrique, :math:`h` non linéaire, cas limites) et rend un :class:`Verdict` : ``passed``,
  ``feedback`` (en français), l'erreur classique reconnue et la ligne du code en cause. Il ne lève
  jamais à cause du code de l'étudiant (exception, forme fausse, NaN, covariance non symétrique,
  fonction pas encore écrite, boucle sans fin) ;
* chaque exercice reconnaît au moins trois erreurs classiques (``exercise(id).mistakes``), chacune
  documentée par l'implémentation fausse qu'elle décrit.

Les références sont calculées par les filtres du paquet ou par des formes closes, jamais à partir de
ce qu'écrit l'étudiant. Les pages « Travaux pratiques » du livre appellent ce module.
"""

from __future__ import annotations

from typing import Any, Callable, NamedTuple

from .grading import Case, Exercise, Mistake, Output, grade
from .linear import JOSEPH_UPDATE, KF_PREDICT, KF_UPDATE, NIS
from .multitarget import PDA_UPDATE, PDA_WEIGHTS
from .nonlinear import EKF_UPDATE, SO3_EXP, TAG_JACOBIAN
from .invariant import SE2_EXP, SE2_INVARIANT_PREDICT, SE2_INVARIANT_UPDATE
from .sampling import PARTICLE_WEIGHTS, SIGMA_POINTS, SYSTEMATIC_RESAMPLE, UNSCENTED_TRANSFORM
from .smoothing import EM_M_STEP, RTS_STEP
from .tracking import CV_MODEL, IMM_MERGE, IMM_MIX, MODE_PROBABILITIES, NIS_GATE, VAN_LOAN
from .assimilation import ETKF_UPDATE, GASPARI_COHN  # assimilation de données (issue 33)
from .verdict import Verdict

__all__ = ["Attempt", "Case", "Exercise", "Mistake", "Output", "Verdict", "attempt", "check", "exercise", "exercises",
           "exercise_table", "validated", "wheel_name"]

_EXERCISES: tuple[Exercise, ...] = (
    KF_PREDICT, KF_UPDATE, JOSEPH_UPDATE, NIS,
    EKF_UPDATE, TAG_JACOBIAN, SO3_EXP, SE2_EXP, SE2_INVARIANT_PREDICT, SE2_INVARIANT_UPDATE,
    SIGMA_POINTS, UNSCENTED_TRANSFORM, SYSTEMATIC_RESAMPLE, PARTICLE_WEIGHTS,
    RTS_STEP, EM_M_STEP,
    CV_MODEL, VAN_LOAN, NIS_GATE, IMM_MIX, MODE_PROBABILITIES, IMM_MERGE,
    ETKF_UPDATE, GASPARI_COHN,
    PDA_WEIGHTS, PDA_UPDATE,
)
_BY_ID = {ex.id: ex for ex in _EXERCISES}


def exercises() -> list[Exercise]:
    """Les exercices, dans l'ordre du cours : chacun a ``id``, ``title`` (français), ``chapter`` (la page
    du cours qui l'enseigne), ``signature``, ``mistakes`` (erreurs classiques reconnues)."""
    return list(_EXERCISES)


def exercise(exercise_id: str) -> Exercise:
    """L'exercice ``exercise_id`` ; identifiant inconnu : :class:`~kalman_course.KalmanInputError`."""
    from ..core.validation import KalmanInputError

    try:
        return _BY_ID[exercise_id]
    except (KeyError, TypeError):
        raise KalmanInputError(f"Exercice inconnu « {exercise_id} ». Exercices : {', '.join(_BY_ID)}.") from None


def check(exercise_id: str, fn: Callable[..., Any]) -> Verdict:
    """Corrige la fonction ``fn`` de l'étudiant pour l'exercice ``exercise_id``.

    Renvoie un :class:`Verdict` (``passed``, ``feedback`` en français, ``mistake``, ``line``), affiché
    dans Jupyter en encadré vert ou rouge. Ne lève jamais à cause du code de l'étudiant ; un
    identifiant d'exercice inconnu donne aussi un verdict (rouge) qui liste les identifiants."""
    ex = _BY_ID.get(exercise_id) if isinstance(exercise_id, str) else None
    if ex is None:
        return Verdict(str(exercise_id), "exercice inconnu", False,
                       f"Exercice inconnu « {exercise_id} ». Exercices : {', '.join(_BY_ID)}.", "signature")
    return grade(ex, fn)


def exercise_table():
    """Les exercices en tableau (:class:`~kalman_course.Table`) : identifiant, titre, signature, chapitre,
    nombre d'erreurs classiques reconnues."""
    from ..tables import Table

    return Table(
        ["Identifiant", "Exercice", "Signature", "Chapitre", "Erreurs reconnues"],
        [[f"`{ex.id}`" for ex in _EXERCISES], [ex.title for ex in _EXERCISES],
         [f"`{ex.signature}`" for ex in _EXERCISES], [ex.chapter for ex in _EXERCISES],
         [len(ex.mistakes) for ex in _EXERCISES]],
    )


class Attempt(NamedTuple):
    """Résultat de :func:`attempt` : ``value`` (ou ``None``) et ``message`` (``None`` si tout s'est bien
    passé, sinon l'explication en français, avec la ligne en cause)."""

    value: Any
    message: str | None


def wheel_name() -> str:
    """Le nom de la roue du paquet servie par le site (``kalman_course-<version>-py3-none-any.whl``) : la
    version est celle du paquet installé (``pyproject.toml``)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        number = version("kalman_course")
    except PackageNotFoundError:  # pragma: no cover — paquet lu depuis le dépôt sans installation
        number = "0.1.0"
    return f"kalman_course-{number}-py3-none-any.whl"


def validated(exercise_id: str, fn: Callable[..., Any]) -> Callable[..., Any]:
    """La fonction ``fn`` de l'étudiant pour l'exercice ``exercise_id``, dont chaque résultat est vérifié
    (nombre et nature des sorties) : à passer aux expériences des TP, pour qu'un ``return`` oublié soit
    reproché à la fonction de l'étudiant (voir :func:`attempt`)."""
    from .grading import validated as _validated

    return _validated(exercise(exercise_id), fn)


def attempt(run: Callable[[], Any], time_limit: float = 120.0) -> Attempt:
    """Lance ``run()`` — une expérience qui appelle les fonctions de l'étudiant (son filtre sur les
    données d'un TP) — sans jamais lever : une exception devient un message en français qui nomme la
    ligne en cause (« pas encore écrite » pour un squelette)."""
    from .grading import StudentResultError, exception_text
    from .student import call

    outcome = call(run, (), time_limit, fallback=False)
    if outcome.timed_out:
        return Attempt(None, f"votre code n'a pas rendu la main après {time_limit:g} s")
    if outcome.error is None:
        return Attempt(outcome.value, None)
    if isinstance(outcome.error, StudentResultError):
        return Attempt(None, str(outcome.error))
    if isinstance(outcome.error, NotImplementedError):
        where = f" ({outcome.place.describe()})" if outcome.place is not None else ""
        return Attempt(None, f"fonction pas encore écrite{where}")
    if outcome.place is None:  # l'erreur est née dans le paquet, sur un résultat de l'étudiant
        error = outcome.error
        detail = f"`{type(error).__name__}: {error}`" if str(error) else f"`{type(error).__name__}`"
        return Attempt(None, f"le résultat d'une de vos fonctions n'a pas pu servir au filtre (Python : {detail}) : "
                             f"vérifiez la forme de ce qu'elles renvoient (le correcteur de chacune le dit)")
    return Attempt(None, exception_text(outcome.error) + f" ({outcome.place.describe()})")
