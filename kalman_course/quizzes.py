r"""Les quiz du livre lus dans leur source MyST, sans Sphinx : le texte lisible d'une formule
(:func:`tex_to_text`, celui des lecteurs d'écran et des extraits de la recherche), d'une ligne
(:func:`plain_text`), et les questions d'une page (:func:`quiz_questions`).

La directive du livre (:mod:`kalman_course.sphinx.quiz`), les carnets des TP
(:mod:`kalman_course.practice.notebooks`) et les tests font la même lecture.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

__all__ = ["tex_to_text", "plain_text", "QuizQuestion", "quiz_questions"]

_GREEK = {"alpha": "α", "beta": "β", "gamma": "γ", "delta": "δ", "epsilon": "ε", "varepsilon": "ε", "eta": "η",
          "theta": "θ", "kappa": "κ", "lambda": "λ", "mu": "μ", "nu": "ν", "xi": "ξ", "pi": "π", "rho": "ρ",
          "sigma": "σ", "tau": "τ", "phi": "φ", "varphi": "φ", "chi": "χ", "psi": "ψ", "omega": "ω",
          "Gamma": "Γ", "Delta": "Δ", "Theta": "Θ", "Lambda": "Λ", "Sigma": "Σ", "Phi": "Φ", "Psi": "Ψ",
          "Omega": "Ω", "ell": "ℓ", "infty": "∞", "approx": "≈", "le": "≤", "leq": "≤", "ge": "≥", "geq": "≥",
          "neq": "≠", "times": "×", "cdot": "·", "pm": "±", "to": "→", "rightarrow": "→", "in": "∈",
          "sum": "Σ", "partial": "∂", "nabla": "∇", "top": "ᵀ", "star": "*", "mid": "|", "quad": " ",
          "qquad": " ", "ldots": "…", "dots": "…", "lvert": "|", "rvert": "|", "lVert": "‖", "rVert": "‖"}
_SUP = dict(zip("0123456789-+Tnik*", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻⁺ᵀⁿⁱᵏ*"))
_SUB = dict(zip("0123456789-+nkijmaeoxrtps", "₀₁₂₃₄₅₆₇₈₉₋₊ₙₖᵢⱼₘₐₑₒₓᵣₜₚₛ"))


def _script(text: str, table: dict[str, str], mark: str) -> str:
    text = text.replace(" ", "")
    if all(c in table for c in text):
        return "".join(table[c] for c in text)
    return f"{mark}({text})" if len(text) > 1 else f"{mark}{text}"


def tex_to_text(tex: str) -> str:
    r"""Une formule TeX en texte lisible par un lecteur d'écran : ``\hat x_{n}^-`` → « x̂ₙ⁻ »,
    ``K = P^-/(P^- + R)`` → « K = P⁻/(P⁻ + R) » (le même texte que les extraits de la recherche du site)."""
    t = tex
    t = re.sub(r"\\(?:hat|widehat)\s*\{([^{}]*)\}|\\(?:hat|widehat)\s*(\\?[A-Za-z])",
               lambda m: (m.group(1) or m.group(2)) + "\u0302", t)
    t = re.sub(r"\\(?:bar|overline)\s*\{([^{}]*)\}", "\\1\u0304", t)
    t = re.sub(r"\\tilde\s*\{([^{}]*)\}|\\tilde\s*([A-Za-z])", lambda m: (m.group(1) or m.group(2)) + "\u0303", t)
    t = re.sub(r"\\[dt]?frac\s*\{([^{}]*)\}\s*\{([^{}]*)\}", r"(\1)/(\2)", t)
    t = re.sub(r"\\sqrt\s*\{([^{}]*)\}", r"√(\1)", t)
    t = re.sub(r"\\(?:mathrm|mathbf|mathcal|mathbb|text|operatorname|boldsymbol)\s*\{([^{}]*)\}", r"\1", t)
    t = re.sub(r"\\(?:begin|end)\s*\{[^{}]*\}(?:\{[^{}]*\})?", " ", t)  # environnements (aligned…)
    t = re.sub(r"\\(left|right|big|Big|bigl|bigr|Bigl|Bigr)\b", "", t)
    t = re.sub(r"\\([A-Za-z]+)", lambda m: _GREEK.get(m.group(1), ""), t)
    t = re.sub(r"\^\{([^{}]*)\}|\^(\S)", lambda m: _script(m.group(1) if m.group(1) is not None else m.group(2),
                                                           _SUP, "^"), t)
    t = re.sub(r"_\{([^{}]*)\}|_(\S)", lambda m: _script(m.group(1) if m.group(1) is not None else m.group(2),
                                                         _SUB, "_"), t)
    t = re.sub(r"\\[,;:!]", " ", t).replace("{", "").replace("}", "").replace("\\\\", " ").replace("\\", "")
    t = t.replace("&", " ")  # colonnes d'alignement
    return " ".join(t.split())


def plain_text(markdown: str) -> str:
    """Le texte lu d'une ligne MyST : formules ``$…$`` écrites par :func:`tex_to_text`, marques de mise en
    forme (``**``, ``*``, accents graves) retirées, espaces réduites."""
    text = re.sub(r"\$([^$]+)\$", lambda m: tex_to_text(m.group(1)), markdown)
    text = re.sub(r"\*\*|(?<!\w)\*|\*(?!\w)|`", "", text)
    return " ".join(text.split())


@dataclass
class QuizQuestion:
    """Une question lue dans la source d'une page : ``answer`` (numéro de la bonne réponse, à partir de 1),
    ``statement``, ``choices`` (texte de chaque réponse proposée), ``messages`` (message de chaque réponse,
    vide s'il n'y en a pas), ``explanation``, ``line`` (ligne de la question dans la page), ``name`` (option
    ``:name:``, vide sans elle)."""

    answer: int
    statement: str
    choices: list[str] = field(default_factory=list)
    messages: list[str] = field(default_factory=list)
    explanation: str = ""
    line: int = 0
    name: str = ""

    def lengths(self) -> list[int]:
        """Longueur lue de chaque réponse proposée (formules écrites en texte)."""
        return [len(plain_text(c)) for c in self.choices]

    def right_is_longest(self) -> bool:
        """Vrai si la bonne réponse est la plus longue (à égalité comprise) : un élève qui choisit la plus
        longue la trouverait (ou aurait plus de chances de la trouver qu'au hasard). Des réponses toutes de
        même longueur (« $A$ », « $B$ », « $C$ ») ne trahissent rien."""
        lengths = self.lengths()
        return lengths[self.answer - 1] >= max(lengths) and len(set(lengths)) > 1


_QUESTION = re.compile(r"^:::\{question\}[^\n]*\n(.*?)^:::\s*$", re.S | re.M)


def quiz_questions(text: str) -> list[QuizQuestion]:
    """Les questions de quiz d'une page MyST (source), dans l'ordre : la même lecture que la directive
    (énoncé, première liste à puces, explication ; message d'une réponse après une ligne vide, en retrait)."""
    out = []
    for match in _QUESTION.finditer(text):
        lines = match.group(1).splitlines()
        answer = next((int(m.group(1)) for m in (re.match(r":answer:\s*(\d+)", li) for li in lines) if m), 0)
        name = next((m.group(1) for m in (re.match(r":name:\s*(\S+)", li) for li in lines) if m), "")
        body = [li for li in lines if not re.match(r":\w+:", li)]
        first = next((i for i, li in enumerate(body) if li.startswith("- ")), len(body))
        statement = " ".join(li.strip() for li in body[:first])
        choices, messages, explanation, rest = [], [], [], body[first:]
        current: list[str] | None = None
        in_message = False
        for li in rest:
            if li.startswith("- ") and not explanation:
                choices.append(li[2:].strip())
                messages.append("")
                current, in_message = choices, False
            elif not li.strip():
                if current is not None and choices:
                    in_message = True
            elif li.startswith("  ") and choices and not explanation:
                if in_message:
                    messages[-1] = (messages[-1] + " " + li.strip()).strip()
                else:
                    choices[-1] = choices[-1] + " " + li.strip()
            else:
                explanation.append(li.strip())
                current = None
        line = text.count("\n", 0, match.start()) + 1
        out.append(QuizQuestion(answer, statement, choices, messages, " ".join(explanation), line, name))
    return out
