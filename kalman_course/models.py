r"""Modèles d'état : immuables, vérifiés à la construction.

Correspondance des notations (voir aussi le tableau de l'introduction du livre) :

=========================  ==========  ===========  ===========
grandeur                   paquet      cours        filterpy
=========================  ==========  ===========  ===========
matrice d'état             ``A``       :math:`A`    ``F``
matrice de commande        ``B``       :math:`B`    ``B``
matrice d'observation      ``C``       :math:`C`    ``H``
covariance bruit d'état    ``Q``       :math:`\Phi` ``Q``
covariance bruit de mesure ``R``       :math:`\Psi` ``R``
=========================  ==========  ===========  ===========
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .validation import (
    KalmanInputError,
    as_float_array,
    as_matrix,
    as_square_matrix,
    check_pd,
    check_psd,
)

__all__ = ["LinearGaussianModel"]


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float, copy=True)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False, init=False)
class LinearGaussianModel:
    r"""Système linéaire gaussien discret (notations du cours, :math:`n \to n+1`) :

    .. math::

        x_{n+1} = A x_n + B u_n + \phi_n,\qquad \phi_n \sim \mathcal N(0, Q)\quad(Q = \Phi \text{ du cours})

        y_{n+1} = C x_{n+1} + \psi_{n+1},\qquad \psi_{n+1} \sim \mathcal N(0, R)\quad(R = \Psi \text{ du cours})

    Paramètres
    ----------
    A : (n, n)
        Matrice d'état (``F`` dans filterpy). Un scalaire donne un modèle à un état.
    C : (m, n)
        Matrice d'observation (``H`` dans filterpy). Scalaire accepté si ``n = m = 1``.
    Q : (n, n)
        Covariance du bruit d'état, symétrique semi-définie positive (peut être nulle).
    R : (m, m)
        Covariance du bruit de mesure, symétrique **définie** positive.
    B : (n, p), optionnel
        Matrice de commande ; sans elle, le modèle n'accepte pas de commande ``u``.

    Les tableaux sont copiés et rendus non modifiables : un modèle ne change pas après sa construction.
    """

    A: np.ndarray
    C: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    B: np.ndarray | None

    def __init__(self, A: Any, C: Any, Q: Any, R: Any, B: Any = None) -> None:
        A_arr = as_square_matrix("A", A, None)
        n = A_arr.shape[0]
        C_arr = as_float_array("C", C)
        if C_arr.ndim == 1:
            raise KalmanInputError(
                f"« C » doit être une matrice 2-D de forme (m, {n}) ; reçu un vecteur de forme {C_arr.shape}. "
                f"Pour une seule mesure, écrivez C = [[…]] (une ligne)."
            )
        C_arr = as_matrix("C", C_arr, None, n)
        m = C_arr.shape[0]
        Q_arr = check_psd("Q", as_square_matrix("Q", Q, n))
        R_arr = check_pd("R", as_square_matrix("R", R, m))
        B_arr = None
        if B is not None:
            B_raw = as_float_array("B", B)
            if B_raw.ndim == 1:
                raise KalmanInputError(
                    f"« B » doit être une matrice 2-D de forme ({n}, p) ; reçu un vecteur de forme {B_raw.shape}. "
                    f"Pour une seule commande, écrivez B = [[…], …] (une colonne)."
                )
            B_arr = _readonly(as_matrix("B", B_raw, n, None))
        object.__setattr__(self, "A", _readonly(A_arr))
        object.__setattr__(self, "C", _readonly(C_arr))
        object.__setattr__(self, "Q", _readonly(Q_arr))
        object.__setattr__(self, "R", _readonly(R_arr))
        object.__setattr__(self, "B", B_arr)

    @property
    def n_state(self) -> int:
        """Dimension ``n`` de l'état."""
        return self.A.shape[0]

    @property
    def n_obs(self) -> int:
        """Dimension ``m`` de la mesure."""
        return self.C.shape[0]

    @property
    def n_control(self) -> int:
        """Dimension ``p`` de la commande (0 sans matrice ``B``)."""
        return 0 if self.B is None else self.B.shape[1]

    def __repr__(self) -> str:
        return f"LinearGaussianModel(n={self.n_state}, m={self.n_obs}, p={self.n_control})"
