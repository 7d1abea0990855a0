"""Butcher tableaux as data, and the step-size controller constants.

Cash & Karp 1990 (ACM TOMS 16:201) embedded Runge-Kutta 4(5); the coefficients are those
of Numerical Recipes 2nd ed. §16.2. The 5th-order solution is propagated (local
extrapolation) and the difference to the embedded 4th-order one estimates the error.

A tableau is plain Python floats so that the generic step in ``integrator.py`` unrolls it
with ``ti.static`` (zero entries cost nothing). Any other explicit embedded pair can be
added as another instance.
"""

from dataclasses import dataclass
from fractions import Fraction as Fr
from typing import Tuple


@dataclass(frozen=True)
class Tableau:
    """Explicit embedded Runge-Kutta pair.

    ``a[s]`` holds the s coefficients of stage s (row s of the strictly lower triangle),
    ``b`` the propagated weights (order ``order``), ``b_hat`` the embedded weights (order
    ``order - 1``); ``c`` are the nodes."""

    name: str
    order: int
    c: Tuple[float, ...]
    a: Tuple[Tuple[float, ...], ...]
    b: Tuple[float, ...]
    b_hat: Tuple[float, ...]

    @property
    def stages(self) -> int:
        return len(self.b)

    @property
    def e(self) -> Tuple[float, ...]:
        """Error weights b - b_hat (the error estimate is h Σ e_i k_i)."""
        return tuple(x - y for x, y in zip(self.b, self.b_hat))


_CK_A = (
    (),
    (Fr(1, 5),),
    (Fr(3, 40), Fr(9, 40)),
    (Fr(3, 10), Fr(-9, 10), Fr(6, 5)),
    (Fr(-11, 54), Fr(5, 2), Fr(-70, 27), Fr(35, 27)),
    (Fr(1631, 55296), Fr(175, 512), Fr(575, 13824), Fr(44275, 110592), Fr(253, 4096)),
)
_CK_B = (Fr(37, 378), Fr(0), Fr(250, 621), Fr(125, 594), Fr(0), Fr(512, 1771))
_CK_B_HAT = (Fr(2825, 27648), Fr(0), Fr(18575, 48384), Fr(13525, 55296), Fr(277, 14336), Fr(1, 4))
_CK_C = (Fr(0), Fr(1, 5), Fr(3, 10), Fr(3, 5), Fr(1), Fr(7, 8))

#: Exact rational coefficients, kept for the tableau-identity tests.
CASH_KARP_EXACT = dict(a=_CK_A, b=_CK_B, b_hat=_CK_B_HAT, c=_CK_C)

CASH_KARP = Tableau(
    name="Cash-Karp 4(5)",
    order=5,
    c=tuple(float(x) for x in _CK_C),
    a=tuple(tuple(float(x) for x in row) for row in _CK_A),
    b=tuple(float(x) for x in _CK_B),
    b_hat=tuple(float(x) for x in _CK_B_HAT),
)


@dataclass(frozen=True)
class Controller:
    """Step-size controller constants (scipy ``_ivp/rk.py`` naming, NR §16.2 behaviour).

    After a step with error norm ``err`` (tolerance units, max norm):
    accepted if err <= 1, next step h * clip(SAFETY err^(-1/order), MIN_FACTOR, MAX_FACTOR);
    no growth right after a rejection."""

    SAFETY: float = 0.9
    MIN_FACTOR: float = 0.2
    MAX_FACTOR: float = 5.0


DEFAULT_CONTROLLER = Controller()
