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
from functools import cached_property
from typing import Any, Callable, Sequence

import numpy as np

from .angles import wrap_angle
from .jacobians import numerical_jacobian
from .linalg import covariance_root, is_positive_definite, square_root_blocks
from .validation import (
    KalmanInputError,
    as_float_array,
    as_matrix,
    as_square_matrix,
    call_user_function,
    check_finite_output,
    check_pd,
    check_psd,
)

__all__ = ["TimeVarying", "LinearGaussianModel", "ModelBatch", "NonlinearModel", "model_steps", "scale_process_noise"]


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float, copy=True)
    a.setflags(write=False)
    return a


class TimeVarying:
    r"""Le protocole des modèles variables dans le temps, commun à :class:`LinearGaussianModel` et aux régimes
    d'un IMM (:class:`~kalman_course.filters.imm.ModeSet`) : ``_n_steps`` (``None`` : constant) et
    ``_steps`` (les modèles des pas, calculés une fois) sont posés par la sous-classe, qui donne
    :meth:`_build_steps` ; le moteur lit :attr:`time_varying` et appelle :meth:`steps` (ou :meth:`at`)."""

    @property
    def time_varying(self) -> bool:
        """``True`` si le modèle porte un axe des temps (modèle variable dans le temps)."""
        return self._n_steps is not None

    @property
    def n_steps(self) -> int | None:
        """Longueur ``T`` de l'axe des temps d'un modèle variable (``None`` pour un modèle constant)."""
        return self._n_steps

    def at(self, k: int):
        r"""Le modèle constant du pas ``k`` ; le modèle lui-même s'il est constant. Les matrices ne sont pas
        revérifiées (elles l'ont été à la construction)."""
        if self._n_steps is None:
            return self
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k < self._n_steps:
            raise KalmanInputError(
                f"« k » doit être un indice de pas entier entre 0 et {self._n_steps - 1} ; reçu {k!r}."
            )
        return self.steps(self._n_steps)[k]

    def steps(self, T: int) -> list:
        """Les ``T`` modèles constants des pas d'un modèle variable (calculés une fois, puis gardés) ;
        une :class:`KalmanInputError` si le modèle n'a pas ``T`` pas."""
        if self._n_steps is None:
            return [self] * T
        if T != self._n_steps:
            raise KalmanInputError(
                f"Le modèle varie dans le temps sur {self._n_steps} pas (A, C, Q, R ou B de forme "
                f"({self._n_steps}, …)) ; reçu {T} mesures. Donnez une ligne de matrices par mesure."
            )
        if self._steps is None:
            object.__setattr__(self, "_steps", self._build_steps(T))
        return self._steps

    def _build_steps(self, T: int) -> list:  # pragma: no cover - interface
        raise NotImplementedError


@dataclass(frozen=True, eq=False, init=False)
class LinearGaussianModel(TimeVarying):
    r"""Système linéaire gaussien discret (notations du cours, :math:`n \to n+1`) :

    .. math::

        x_{n+1} = A x_n + B u_n + \phi_n,\qquad \phi_n \sim \mathcal N(0, Q)\quad(Q = \Phi \text{ du cours})

        y_{n+1} = C x_{n+1} + \psi_{n+1},\qquad \psi_{n+1} \sim \mathcal N(0, R)\quad(R = \Psi \text{ du cours})

    Paramètres
    ----------
    A : (n, n) ou (T, n, n)
        Matrice d'état (``F`` dans filterpy). Un scalaire donne un modèle à un état.
    C : (m, n) ou (T, m, n)
        Matrice d'observation (``H`` dans filterpy). Scalaire accepté si ``n = m = 1``.
    Q : (n, n) ou (T, n, n)
        Covariance du bruit d'état, symétrique semi-définie positive (peut être nulle).
    R : (m, m) ou (T, m, m)
        Covariance du bruit de mesure, symétrique **définie** positive.
    B : (n, p) ou (T, n, p), optionnel
        Matrice de commande ; sans elle, le modèle n'accepte pas de commande ``u``.

    **Modèle variable dans le temps.** N'importe lesquelles de ces matrices peuvent porter un axe des
    temps en tête, de même longueur ``T`` (les autres restent constantes) : la ligne ``k`` sert au pas
    qui mène à la mesure ``y[k]``, :math:`x_k = A_k x_{k-1} + B_k u_k + \phi_k`,
    :math:`\phi_k \sim \mathcal N(0, Q_k)`, :math:`y_k = C_k x_k + \psi_k`,
    :math:`\psi_k \sim \mathcal N(0, R_k)` — exactement ``predict(F=A[k], Q=Q[k])`` puis
    ``update(y[k], R=R[k], H=C[k])`` de filterpy. C'est ainsi qu'on filtre des mesures à instants
    irréguliers (une discrétisation par pas, :func:`~kalman_course.core.motion.discretize`). Un tel
    modèle ne filtre que des séries de ``T`` mesures (:attr:`n_steps`) ; :meth:`at` donne le modèle
    constant du pas ``k``.

    Les tableaux sont copiés et rendus non modifiables : un modèle ne change pas après sa construction.
    """

    A: np.ndarray
    C: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    B: np.ndarray | None

    def __init__(self, A: Any, C: Any, Q: Any, R: Any, B: Any = None) -> None:
        T = _time_axis({"A": A, "C": C, "Q": Q, "R": R, "B": B})
        A_arr = _each_step("A", A, T, lambda name, a: as_square_matrix(name, a, None))
        n = A_arr.shape[-1]

        def observation(name, c):
            c = as_float_array(name, c)
            if c.ndim == 1:
                raise KalmanInputError(
                    f"« {name} » doit être une matrice 2-D de forme (m, {n}) ; reçu un vecteur de forme {c.shape}. "
                    f"Pour une seule mesure, écrivez C = [[…]] (une ligne)."
                )
            return as_matrix(name, c, None, n)

        C_arr = _each_step("C", C, T, observation)
        m = C_arr.shape[-2]
        Q_arr = _each_step("Q", Q, T, lambda name, q: check_psd(name, as_square_matrix(name, q, n)), "psd")
        R_arr = _each_step("R", R, T, lambda name, r: check_pd(name, as_square_matrix(name, r, m)), "pd")
        B_arr = None
        if B is not None:

            def control(name, b):
                b = as_float_array(name, b)
                if b.ndim == 1:
                    raise KalmanInputError(
                        f"« {name} » doit être une matrice 2-D de forme ({n}, p) ; reçu un vecteur de forme {b.shape}. "
                        f"Pour une seule commande, écrivez B = [[…], …] (une colonne)."
                    )
                return as_matrix(name, b, n, None)

            B_arr = _readonly(_each_step("B", B, T, control))
        object.__setattr__(self, "A", _readonly(A_arr))
        object.__setattr__(self, "C", _readonly(C_arr))
        object.__setattr__(self, "Q", _readonly(Q_arr))
        object.__setattr__(self, "R", _readonly(R_arr))
        object.__setattr__(self, "B", B_arr)
        object.__setattr__(self, "_n_steps", T)
        object.__setattr__(self, "_steps", None)

    @property
    def n_state(self) -> int:
        """Dimension ``n`` de l'état."""
        return self.A.shape[-1]

    @property
    def n_obs(self) -> int:
        """Dimension ``m`` de la mesure."""
        return self.C.shape[-2]

    @property
    def n_control(self) -> int:
        """Dimension ``p`` de la commande (0 sans matrice ``B``)."""
        return 0 if self.B is None else self.B.shape[-1]

    def _build_steps(self, T: int) -> list["LinearGaussianModel"]:
        pick = lambda a, k: None if a is None else (a[k] if a.ndim == 3 else a)  # noqa: E731
        return [_constant_model(pick(self.A, k), pick(self.C, k), pick(self.Q, k), pick(self.R, k), pick(self.B, k))
                for k in range(T)]

    def sequence(self, name: str, T: int) -> np.ndarray:
        """La matrice ``name`` (``"A"``, ``"B"``, ``"C"``, ``"Q"`` ou ``"R"``) de chacun des ``T`` pas,
        (T, …) : la pile elle-même pour une matrice variable, la matrice constante répétée sinon (vue en
        lecture seule)."""
        if name not in ("A", "B", "C", "Q", "R"):
            raise KalmanInputError(f"« name » doit valoir A, B, C, Q ou R ; reçu {name!r}.")
        a = getattr(self, name)
        if a is None:
            raise KalmanInputError(f"Le modèle n'a pas de matrice « {name} ».")
        if self._n_steps is not None:
            self.steps(T)  # vérifie T
        if a.ndim == 3:
            return a
        return np.broadcast_to(a, (T, *a.shape))

    @cached_property
    def noise_roots(self) -> tuple[np.ndarray, np.ndarray]:
        r"""Racines triangulaires supérieures :math:`(U_Q, U_R)` des bruits, :math:`U_Q^TU_Q = Q` (n, n) et
        :math:`U_R^TU_R = R` (m, m) (:func:`~kalman_course.core.linalg.covariance_root`), calculées une fois
        pour le filtre de Kalman en racine carrée."""
        return _readonly(covariance_root(self.Q)), _readonly(covariance_root(self.R))

    @cached_property
    def square_root_blocks(self) -> tuple[np.ndarray, np.ndarray]:
        r"""Blocs constants du pré-tableau de la correction en racine carrée d'un modèle constant,
        :math:`[U_R\ \ 0]` (m, m + n) et :math:`[C^T\ \ I_n]` (n, m + n)
        (:func:`~kalman_course.core.linalg.square_root_blocks`), calculés une fois : à chaque pas, les
        lignes :math:`[MC^T\ \ M]` du pré-tableau ne coûtent qu'un produit, :math:`M\,[C^T\ \ I_n]`."""
        return tuple(_readonly(a) for a in square_root_blocks(self.C, self.noise_roots[1]))

    def __repr__(self) -> str:
        extra = "" if self._n_steps is None else f", variable sur {self._n_steps} pas"
        return f"LinearGaussianModel(n={self.n_state}, m={self.n_obs}, p={self.n_control}{extra})"


def _time_axis(matrices: dict[str, Any]) -> int | None:
    """Longueur commune ``T`` des matrices données avec un axe des temps (3-D), ``None`` s'il n'y en a pas."""
    lengths = {}
    for name, value in matrices.items():
        if value is not None and np.ndim(value) == 3:
            lengths[name] = int(np.shape(value)[0])
    if not lengths:
        return None
    if len(set(lengths.values())) > 1:
        detail = ", ".join(f"{name} : {T}" for name, T in lengths.items())
        raise KalmanInputError(
            f"Les matrices variables dans le temps doivent avoir le même nombre de pas T ({detail})."
        )
    T = next(iter(lengths.values()))
    if T == 0:
        raise KalmanInputError("Un modèle variable dans le temps doit avoir au moins un pas (T ≥ 1).")
    return T


def _each_step(name: str, value: Any, T: int | None, check: Callable[[str, Any], np.ndarray],
               covariance: str | None = None) -> np.ndarray:
    """Vérifie une matrice constante, ou chaque ligne ``name[k]`` d'une pile (T, …) ; renvoie le tableau.

    Pile de covariances (``covariance`` = ``"psd"`` ou ``"pd"``) : la forme est vérifiée sur la première
    ligne, symétrie et positivité sur toutes à la fois (mêmes tolérances que
    :func:`~kalman_course.core.validation.check_psd`, :func:`~kalman_course.core.validation.check_pd`) ;
    la première ligne fautive est ensuite vérifiée seule, pour son message d'erreur."""
    if value is None or np.ndim(value) != 3:
        return check(name, value)
    arr = as_float_array(name, value)
    if covariance is None:
        return np.array([check(f"{name}[{k}]", arr[k]) for k in range(T)])
    check(f"{name}[0]", arr[0])  # forme (et première ligne)
    scale = np.maximum(1.0, np.abs(arr).max(axis=(1, 2)))
    asym = np.abs(arr - np.swapaxes(arr, 1, 2)).max(axis=(1, 2))
    sym = 0.5 * (arr + np.swapaxes(arr, 1, 2))
    ok = asym <= 1e-9 * scale
    if ok.all():
        if covariance == "psd":
            ok = np.linalg.eigvalsh(sym)[:, 0] >= -1e-10 * scale
        else:
            try:
                np.linalg.cholesky(sym)
            except np.linalg.LinAlgError:
                ok = np.array([is_positive_definite(M) for M in sym])
    if not ok.all():
        k = int(np.argmin(ok))
        check(f"{name}[{k}]", arr[k])  # lève l'erreur française de cette ligne
    return sym


@dataclass(frozen=True, eq=False, init=False)
class ModelBatch:
    r"""``G`` modèles linéaires gaussiens constants de mêmes dimensions, sans commande, empilés pour être
    filtrés **ensemble sur les mêmes mesures** par le mode en lot du moteur
    (:func:`~kalman_course.filters.engine.run_filter_runs`, un tirage par modèle) : ``A`` (G, n, n), ``C``
    (G, m, n), ``Q`` (G, n, n), ``R`` (G, m, m). Sert aux vraisemblances d'une grille de paramètres
    (:func:`~kalman_course.likelihood.log_likelihoods`)."""

    A: np.ndarray
    C: np.ndarray
    Q: np.ndarray
    R: np.ndarray

    def __init__(self, models: Sequence[LinearGaussianModel]) -> None:
        models = list(models)
        if not models:
            raise KalmanInputError("« models » doit contenir au moins un modèle.")
        for i, model in enumerate(models):
            if not isinstance(model, LinearGaussianModel):
                raise KalmanInputError(
                    f"« models[{i}] » doit être un LinearGaussianModel ; reçu {type(model).__name__} (la "
                    "vraisemblance est celle d'un modèle linéaire gaussien)."
                )
        n, m = models[0].n_state, models[0].n_obs
        for i, model in enumerate(models):
            if model.n_state != n or model.n_obs != m:
                raise KalmanInputError(
                    f"« models[{i}] » a n = {model.n_state}, m = {model.n_obs} ; le premier modèle a n = {n}, "
                    f"m = {m} : le lot demande des modèles de mêmes dimensions."
                )
            if model.B is not None:
                raise KalmanInputError(
                    f"« models[{i}] » a une commande B : le lot n'en prend pas ; utilisez log_likelihood.")
            if model.time_varying:
                raise KalmanInputError(
                    f"« models[{i}] » varie dans le temps : le lot demande des modèles constants ; utilisez "
                    "log_likelihood modèle par modèle."
                )
        for name in ("A", "C", "Q", "R"):
            object.__setattr__(self, name, _readonly(np.stack([getattr(model, name) for model in models])))

    @property
    def n_models(self) -> int:
        """Nombre ``G`` de modèles."""
        return self.A.shape[0]

    @property
    def n_state(self) -> int:
        return self.A.shape[-1]

    @property
    def n_obs(self) -> int:
        return self.C.shape[-2]

    n_control = 0
    time_varying = False
    B = None

    def __repr__(self) -> str:
        return f"ModelBatch({self.n_models} modèles, n={self.n_state}, m={self.n_obs})"


def _constant_model(A, C, Q, R, B) -> LinearGaussianModel:
    """Un modèle constant fait de matrices déjà vérifiées (les pas d'un modèle variable), sans recopie."""
    model = object.__new__(LinearGaussianModel)
    for name, value in (("A", A), ("C", C), ("Q", Q), ("R", R), ("B", B), ("_n_steps", None), ("_steps", None)):
        object.__setattr__(model, name, value)
    return model


def scale_process_noise(model: Any, scale: float) -> Any:
    r"""Le même modèle avec le bruit d'état :math:`sQ` (``scale`` = :math:`s > 0`), sans revérifier ses
    matrices : un :class:`LinearGaussianModel` constant (un pas) ou un :class:`NonlinearModel`. Sert à
    l'adaptation de :math:`Q` du moteur (:class:`~kalman_course.filters.gating.Adaptation`) ; la racine de
    :math:`sQ` est :math:`\sqrt s\,U_Q`."""
    if scale == 1.0:
        return model
    out = object.__new__(type(model))
    state = dict(model.__dict__)
    state.pop("noise_roots", None)  # la racine de sQ, posée plus bas (square_root_blocks ne dépend que de C et R)
    state["Q"] = _readonly(scale * model.Q)
    out.__dict__.update(state)
    if isinstance(model, LinearGaussianModel):
        U_Q, U_R = model.noise_roots
        out.__dict__["noise_roots"] = (_readonly(np.sqrt(scale) * U_Q), U_R)
    return out


def model_steps(model: Any, T: int) -> list | None:
    """Les modèles des ``T`` pas d'un modèle variable dans le temps (``model.steps(T)``), ``None`` pour un
    modèle constant : le moteur des filtres appelle ``model.at(k)`` seulement quand il le faut."""
    if not getattr(model, "time_varying", False):
        return None
    return model.steps(T)


# --------------------------------------------------------------------------- modèle non linéaire


def _noise_jacobian_rows(name: str, value: Any) -> int | None:
    """Nombre de lignes d'une jacobienne de bruit constante (None si absente ou appelable)."""
    if value is None or callable(value):
        return None
    arr = as_float_array(name, value)
    return arr.shape[0] if arr.ndim == 2 else None


@dataclass(frozen=True, eq=False, init=False)
class NonlinearModel:
    r"""Système non linéaire à bruits gaussiens (notations du cours, :math:`n \to n+1`) :

    .. math::

        x_{n+1} = f(x_n, u_n) + W\phi_n,\qquad \phi_n \sim \mathcal N(0, Q)\quad(Q = \Phi \text{ du cours})

        y_{n+1} = h(x_{n+1}) + V\psi_{n+1},\qquad \psi_{n+1} \sim \mathcal N(0, R)\quad(R = \Psi \text{ du cours})

    C'est la forme linéarisée en bruit du modèle général :math:`x_{n+1} = f(x_n, u_n, \phi_n)`,
    :math:`y_{n+1} = h(x_{n+1}, \psi_{n+1})` du cours : :math:`W = \partial f/\partial\phi` et
    :math:`V = \partial h/\partial\psi`, évaluées en bruit nul. Sans ``W`` ni ``V`` les bruits sont additifs
    (:math:`W = I`, :math:`V = I`), comme dans les notes du tag.

    Paramètres
    ----------
    f : appelable ``f(x, u) -> (n,)``
        Dynamique ; ``u`` vaut ``None`` quand il n'y a pas de commande (``n_control = 0``).
    h : appelable ``h(x) -> (m,)``
        Observation.
    Q : (q, q)
        Covariance du bruit d'état (semi-définie positive) ; ``q = n`` sans ``f_noise_jacobian``.
    R : (r, r)
        Covariance du bruit de mesure (définie positive) ; ``r = m`` sans ``h_noise_jacobian``.
    f_jacobian : appelable ``(x, u) -> (n, n)`` ou matrice constante, optionnel
        :math:`J^A = F = \partial f/\partial x`. Absente : différences centrées.
    h_jacobian : appelable ``x -> (m, n)`` ou matrice constante, optionnel
        :math:`J^H = H = \partial h/\partial x`. Absente : différences centrées.
    f_noise_jacobian : appelable ``(x, u) -> (n, q)`` ou matrice constante, optionnel — :math:`W`.
    h_noise_jacobian : appelable ``x -> (m, r)`` ou matrice constante, optionnel — :math:`V`.
    n_state, n_obs : int, optionnels
        Dimensions de l'état et de la mesure, déduites de ``Q``, ``R`` (ou de ``W``, ``V`` constantes) ;
        à donner seulement si ``W`` ou ``V`` sont des fonctions qui changent la dimension.
    n_control : int
        Dimension ``p`` de la commande (0 : pas de commande, ``f`` reçoit ``u = None``).
    angle_indices : indices des composantes de la mesure qui sont des angles (rad) : leurs résidus
        :math:`y - h(x)` sont ramenés dans :math:`(-\pi, \pi]`.
    vectorized : bool
        ``True`` si ``f`` et ``h`` acceptent aussi une **pile** d'états ``X`` de forme (N, n) (une ligne par
        état) et renvoient alors (N, n) et (N, m) ; elles doivent toujours accepter un seul état (n,).
        Les filtres à points (points sigma de l'UKF, particules, membres d'un ensemble) propagent alors
        tous leurs points en **un** appel (:meth:`transition_many`, :meth:`observe_many`). ``False``
        (défaut) : un appel par point, même résultat, plus lent.

    Chaque appel de ``f``, ``h`` et des jacobiennes passe par les méthodes du modèle, qui vérifient la
    forme et la finitude du résultat et lèvent une :class:`KalmanInputError` qui nomme la fonction fautive.
    """

    f: Callable[..., Any]
    h: Callable[..., Any]
    Q: np.ndarray
    R: np.ndarray
    f_jacobian: Any
    h_jacobian: Any
    f_noise_jacobian: Any
    h_noise_jacobian: Any
    n_state: int
    n_obs: int
    n_control: int
    angle_indices: tuple[int, ...]
    vectorized: bool

    def __init__(
        self,
        f: Callable[..., Any],
        h: Callable[..., Any],
        Q: Any,
        R: Any,
        f_jacobian: Any = None,
        h_jacobian: Any = None,
        *,
        f_noise_jacobian: Any = None,
        h_noise_jacobian: Any = None,
        n_state: int | None = None,
        n_obs: int | None = None,
        n_control: int = 0,
        angle_indices: Sequence[int] = (),
        vectorized: bool = False,
    ) -> None:
        if not isinstance(vectorized, (bool, np.bool_)):
            raise KalmanInputError(f"« vectorized » doit être un booléen (True ou False) ; reçu {vectorized!r}.")
        for name, func in (("f", f), ("h", h)):
            if not callable(func):
                raise KalmanInputError(
                    f"« {name} » doit être une fonction (appelable) ; reçu {type(func).__name__}."
                )
        Q_arr = check_psd("Q", as_square_matrix("Q", Q, None))
        R_arr = check_pd("R", as_square_matrix("R", R, None))
        n = _dimension("n_state", n_state, f_noise_jacobian, "f_noise_jacobian", Q_arr.shape[0])
        m = _dimension("n_obs", n_obs, h_noise_jacobian, "h_noise_jacobian", R_arr.shape[0])
        if not isinstance(n_control, (int, np.integer)) or isinstance(n_control, bool) or n_control < 0:
            raise KalmanInputError(f"« n_control » doit être un entier ≥ 0 ; reçu {n_control!r}.")
        angles = tuple(int(i) for i in np.atleast_1d(np.asarray(angle_indices, dtype=int)))
        for i in angles:
            if not 0 <= i < m:
                raise KalmanInputError(
                    f"« angle_indices » doit désigner des composantes de la mesure (0 à {m - 1}) ; reçu {i}."
                )
        q, r = Q_arr.shape[0], R_arr.shape[0]
        object.__setattr__(self, "f", f)
        object.__setattr__(self, "h", h)
        object.__setattr__(self, "Q", _readonly(Q_arr))
        object.__setattr__(self, "R", _readonly(R_arr))
        object.__setattr__(self, "f_jacobian", _constant_or_callable("f_jacobian", f_jacobian, (n, n)))
        object.__setattr__(self, "h_jacobian", _constant_or_callable("h_jacobian", h_jacobian, (m, n)))
        object.__setattr__(
            self, "f_noise_jacobian", _constant_or_callable("f_noise_jacobian", f_noise_jacobian, (n, q))
        )
        object.__setattr__(
            self, "h_noise_jacobian", _constant_or_callable("h_noise_jacobian", h_noise_jacobian, (m, r))
        )
        if f_noise_jacobian is None and q != n:
            raise KalmanInputError(
                f"« Q » doit être de forme ({n}, {n}) (bruit d'état additif) ; reçu ({q}, {q}). "
                f"Pour un bruit de dimension {q}, donnez f_noise_jacobian (W, de forme ({n}, {q}))."
            )
        if h_noise_jacobian is None and r != m:
            raise KalmanInputError(
                f"« R » doit être de forme ({m}, {m}) (bruit de mesure additif) ; reçu ({r}, {r}). "
                f"Pour un bruit de dimension {r}, donnez h_noise_jacobian (V, de forme ({m}, {r}))."
            )
        object.__setattr__(self, "n_state", int(n))
        object.__setattr__(self, "n_obs", int(m))
        object.__setattr__(self, "n_control", int(n_control))
        object.__setattr__(self, "angle_indices", angles)
        object.__setattr__(self, "vectorized", bool(vectorized))

    # ------------------------------------------------------------------ évaluations vérifiées

    def transition(self, x: np.ndarray, u: np.ndarray | None = None) -> np.ndarray:
        r""":math:`f(x, u)`, forme (n,), vérifiée (taille, valeurs finies)."""
        return _checked_vector("f", call_user_function("f", self.f, x, (u,)), self.n_state, "n", x)

    def observe(self, x: np.ndarray) -> np.ndarray:
        r""":math:`h(x)`, forme (m,), vérifiée (taille, valeurs finies)."""
        return _checked_vector("h", call_user_function("h", self.h, x), self.n_obs, "m", x)

    def transition_many(self, X: np.ndarray, u: np.ndarray | None = None) -> np.ndarray:
        r""":math:`f(x_i, u)` pour chaque ligne :math:`x_i` de ``X`` (N, n) ; renvoie (N, n), vérifié.

        Modèle vectorisé : un seul appel ``f(X, u)`` ; sinon un appel par ligne."""
        if not self.vectorized:
            return np.array([self.transition(x, u) for x in X]).reshape(X.shape[0], self.n_state)
        out = call_user_function("f", self.f, X, (u,))
        return _checked_stack("f", out, X, self.n_state, "n")

    def observe_many(self, X: np.ndarray) -> np.ndarray:
        r""":math:`h(x_i)` pour chaque ligne :math:`x_i` de ``X`` (N, n) ; renvoie (N, m), vérifié.

        Modèle vectorisé : un seul appel ``h(X)`` ; sinon un appel par ligne."""
        if not self.vectorized:
            return np.array([self.observe(x) for x in X]).reshape(X.shape[0], self.n_obs)
        out = call_user_function("h", self.h, X)
        return _checked_stack("h", out, X, self.n_obs, "m")

    def transition_jacobian(self, x: np.ndarray, u: np.ndarray | None = None) -> np.ndarray:
        r""":math:`F = J^A = \partial f/\partial x` en :math:`(x, u)`, forme (n, n) (analytique ou différences centrées)."""
        if self.f_jacobian is None:
            return numerical_jacobian(lambda z: self.transition(z, u), x, name="f")
        return _checked_matrix("f_jacobian", self.f_jacobian, x, (u,), (self.n_state, self.n_state))

    def observation_jacobian(self, x: np.ndarray) -> np.ndarray:
        r""":math:`H = J^H = \partial h/\partial x` en :math:`x`, forme (m, n) (analytique ou différences centrées)."""
        if self.h_jacobian is None:
            return numerical_jacobian(self.observe, x, angle_indices=self.angle_indices, name="h")
        return _checked_matrix("h_jacobian", self.h_jacobian, x, (), (self.n_obs, self.n_state))

    def process_noise_gain(self, x: np.ndarray, u: np.ndarray | None = None) -> np.ndarray:
        r""":math:`W = \partial f/\partial\phi` en :math:`(x, u)`, forme (n, q) (identité si le bruit est additif)."""
        if self.f_noise_jacobian is None:
            return np.eye(self.n_state)
        return _checked_matrix("f_noise_jacobian", self.f_noise_jacobian, x, (u,), (self.n_state, self.Q.shape[0]))

    def measurement_noise_gain(self, x: np.ndarray) -> np.ndarray:
        r""":math:`V = \partial h/\partial\psi` en :math:`x`, forme (m, r) (identité si le bruit est additif)."""
        if self.h_noise_jacobian is None:
            return np.eye(self.n_obs)
        return _checked_matrix("h_noise_jacobian", self.h_noise_jacobian, x, (), (self.n_obs, self.R.shape[0]))

    def process_noise(self, x: np.ndarray, u: np.ndarray | None = None) -> np.ndarray:
        r"""Covariance du bruit d'état ramenée à l'état, :math:`W Q W^T` (n, n) (:math:`Q` si bruit additif)."""
        if self.f_noise_jacobian is None:
            return self.Q
        W = self.process_noise_gain(x, u)
        return W.dot(self.Q).dot(W.T)

    def measurement_noise(self, x: np.ndarray) -> np.ndarray:
        r"""Covariance du bruit de mesure ramenée à la mesure, :math:`V R V^T` (m, m) (:math:`R` si additif)."""
        if self.h_noise_jacobian is None:
            return self.R
        V = self.measurement_noise_gain(x)
        return V.dot(self.R).dot(V.T)

    def observed_angles(self, idx: np.ndarray | None = None) -> list[int]:
        r"""Positions des composantes angulaires (``angle_indices``) dans une mesure réduite aux composantes
        observées ``idx`` (indices dans la mesure complète ; ``None`` : toutes) — la seule traduction
        « indice de mesure → position dans la mesure observée » du paquet."""
        if idx is None or not self.angle_indices:
            return list(self.angle_indices)
        return [j for j, i in enumerate(idx) if int(i) in self.angle_indices]

    def residual(self, y: np.ndarray, y_hat: np.ndarray, idx: np.ndarray | None = None) -> np.ndarray:
        r"""Résidu :math:`y - \hat y`, les composantes angulaires ramenées dans :math:`(-\pi, \pi]`.

        ``y``, ``y_hat`` (…, m_k) ; ``idx`` : indices (dans la mesure complète) des composantes qu'ils
        contiennent quand la mesure est partielle (``None`` : toutes)."""
        d = np.asarray(y - y_hat, dtype=float)
        angles = self.observed_angles(idx)
        if angles:
            d[..., angles] = wrap_angle(d[..., angles])
        return d

    @classmethod
    def from_linear(cls, model: LinearGaussianModel) -> "NonlinearModel":
        r"""Le modèle linéaire :math:`f(x, u) = Ax + Bu`, :math:`h(x) = Cx`, vu comme un modèle non linéaire
        (jacobiennes constantes :math:`A` et :math:`C`). Sert à vérifier que l'EKF redonne alors le KF."""
        if model.time_varying:
            raise KalmanInputError(
                "« model » varie dans le temps : NonlinearModel.from_linear n'accepte qu'un modèle constant "
                "(prenez model.at(k) pour un pas)."
            )
        A, B, C = model.A, model.B, model.C

        def f(x, u):  # x (n,) ou pile (N, n) : x Aᵀ (+ uᵀ Bᵀ) ligne par ligne
            return x.dot(A.T) if u is None else x.dot(A.T) + B.dot(u)

        return cls(f, lambda x: x.dot(C.T), model.Q, model.R, f_jacobian=A, h_jacobian=C,
                   n_control=model.n_control, vectorized=True)

    def __repr__(self) -> str:
        extra = ", vectorisé" if self.vectorized else ""
        return f"NonlinearModel(n={self.n_state}, m={self.n_obs}, p={self.n_control}{extra})"


def _dimension(name: str, given: Any, noise_jac: Any, noise_name: str, default: int) -> int:
    if given is not None:
        if not isinstance(given, (int, np.integer)) or isinstance(given, bool) or given < 1:
            raise KalmanInputError(f"« {name} » doit être un entier ≥ 1 ; reçu {given!r}.")
        return int(given)
    rows = _noise_jacobian_rows(noise_name, noise_jac)
    if rows is not None:
        return rows
    if callable(noise_jac):
        raise KalmanInputError(
            f"« {noise_name} » est une fonction : donnez aussi « {name} » (la dimension ne peut pas être déduite)."
        )
    return default


def _constant_or_callable(name: str, value: Any, shape: tuple[int, int]) -> Any:
    """Une jacobienne : ``None``, une fonction, ou une matrice constante de forme ``shape`` (lecture seule)."""
    if value is None or callable(value):
        return value
    return _readonly(as_matrix(name, value, shape[0], shape[1]))


def _checked_vector(name: str, value: Any, size: int, letter: str, x: np.ndarray) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0 and size == 1:
        arr = arr.reshape(1)
    if arr.shape != (size,):
        what = "l'état" if letter == "n" else "la mesure"
        raise KalmanInputError(
            f"La fonction « {name} » doit renvoyer un vecteur de forme ({size},) ({letter} = {size}, "
            f"dimension de {what}) ; elle a renvoyé la forme {arr.shape}."
        )
    return check_finite_output(name, arr, x)


def _checked_stack(name: str, value: Any, X: np.ndarray, size: int, letter: str) -> np.ndarray:
    """Résultat d'une fonction vectorisée sur une pile ``X`` (N, n) : forme (N, size), valeurs finies."""
    arr = np.asarray(value, dtype=float)
    N = X.shape[0]
    if arr.ndim == 1 and size == 1 and arr.shape == (N,):
        arr = arr.reshape(N, 1)
    if arr.shape != (N, size):
        raise KalmanInputError(
            f"La fonction « {name} » d'un modèle vectorisé (vectorized=True) doit renvoyer la forme "
            f"({N}, {size}) pour une pile de {N} états ({letter} = {size}) ; elle a renvoyé la forme {arr.shape}. "
            f"Écrivez-la avec x[..., i] (composantes sur le dernier axe) ou construisez le modèle avec "
            f"vectorized=False."
        )
    if not np.isfinite(arr).all():
        bad = int(np.flatnonzero(~np.isfinite(arr).all(axis=1))[0])
        check_finite_output(name, arr[bad], X[bad])
    return arr


def _checked_matrix(name: str, value: Any, x: np.ndarray, args: tuple, shape: tuple[int, int]) -> np.ndarray:
    if callable(value):
        value = call_user_function(name, value, x, args)
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0 and shape == (1, 1):
        arr = arr.reshape(1, 1)
    if arr.shape != shape:
        raise KalmanInputError(
            f"La jacobienne « {name} » doit être de forme {shape} ; elle a la forme {arr.shape}."
        )
    return check_finite_output(name, arr, x, what="La jacobienne")
