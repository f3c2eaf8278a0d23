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
from .sampling import PARTICLE_WEIGHTS, SIGMA_POINTS, SYSTEMATIC_RESAMPLE, UNSCENTED_TRANSFORM
from .smoothing import EM_M_STEP, RTS_STEP
from .verdict import Verdict

__all__ = ["Attempt", "Case", "Exercise", "Mistake", "Output", "Verdict", "attempt", "check", "exercise", "exercises",
           "exercise_table"]

_EXERCISES: tuple[Exercise, ...] = (
    KF_PREDICT, KF_UPDATE, JOSEPH_UPDATE, NIS,
    EKF_UPDATE, TAG_JACOBIAN, SO3_EXP,
    SIGMA_POINTS, UNSCENTED_TRANSFORM, SYSTEMATIC_RESAMPLE, PARTICLE_WEIGHTS,
    RTS_STEP, EM_M_STEP,
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


def attempt(run: Callable[[], Any], time_limit: float = 120.0) -> Attempt:
    """Lance ``run()`` — une expérience qui appelle les fonctions de l'étudiant (son filtre sur les
    données d'un TP) — sans jamais lever : une exception devient un message en français qui nomme la
    ligne en cause (« pas encore écrite » pour un squelette)."""
    from .grading import exception_text
    from .student import call

    outcome = call(run, (), time_limit)
    if outcome.timed_out:
        return Attempt(None, f"votre code n'a pas rendu la main après {time_limit:g} s")
    if outcome.error is None:
        return Attempt(outcome.value, None)
    where = f" ({outcome.place.describe()})" if outcome.place is not None else ""
    if isinstance(outcome.error, NotImplementedError):
        return Attempt(None, f"fonction pas encore écrite{where}")
    return Attempt(None, exception_text(outcome.error) + where)
