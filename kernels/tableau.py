"""Butcher tableaux as data: the methods the kernels can integrate with.

* ``CASH_KARP``: Cash & Karp 1990 (ACM TOMS 16:201) embedded Runge-Kutta 4(5); the
  coefficients are those of Numerical Recipes 2nd ed. §16.2, exact rationals. The 5th-order
  solution is propagated (local extrapolation) and the difference to the embedded 4th-order
  one estimates the error. The paper's method and the default.
* ``DOP853``: Dormand & Prince's 8th-order pair as in Hairer's DOP853 (Hairer, Nørsett &
  Wanner, *Solving ODEs I*, 2nd ed., §II.10; the coefficients of the authors' published
  dop853.f, 30 significant digits, the same digits as scipy's ``dop853_coefficients.py``).
  12 stages; the derivative at the accepted end point is the next step's first stage (FSAL
  in the sense of the kernel: 12 evaluations per accepted step). Two embedded estimates, of
  orders 5 and 3, combine into err = err5² / sqrt(err5² + 0.01 err3²) per component
  (``integrator.make_error_norm``); the controller exponent is 1/8 (``error_order`` 7).
  Some nodes are irrational (c4, c5 = (6 ∓ √6)/30), so the "exact" data are the published
  decimals as exact decimal fractions: the order conditions hold to about 1e-28
  (tests/test_tableau.py), far below double precision.

A tableau is plain Python floats so that the generic step in ``integrator.py`` unrolls it
with ``ti.static`` (zero entries cost nothing). ``METHODS`` maps the public method names to
tableaux; the step-size policy is ``controller.Controller``.
"""

from dataclasses import dataclass
from decimal import Decimal
from fractions import Fraction as Fr
from typing import Optional, Tuple

from .controller import DEFAULT_CONTROLLER, Controller  # noqa: F401  (re-exported)


@dataclass(frozen=True)
class Tableau:
    """Explicit embedded Runge-Kutta pair.

    ``a[s]`` holds the s coefficients of stage s (row s of the strictly lower triangle),
    ``b`` the propagated weights (order ``order``), ``b_hat`` the embedded weights (order
    ``error_order``, default ``order - 1``); ``c`` are the nodes. ``e`` (default b - b_hat)
    are the error weights: the error estimate is h Σ e_i k_i. ``e3``, when given, are the
    weights of a second, lower-order estimate combined with the first as in DOP853."""

    name: str
    order: int
    c: Tuple[float, ...]
    a: Tuple[Tuple[float, ...], ...]
    b: Tuple[float, ...]
    b_hat: Tuple[float, ...]
    error_weights: Optional[Tuple[float, ...]] = None
    e3: Optional[Tuple[float, ...]] = None
    error_order: Optional[int] = None

    @property
    def stages(self) -> int:
        return len(self.b)

    @property
    def e(self) -> Tuple[float, ...]:
        """Error weights (the error estimate is h Σ e_i k_i): b - b_hat unless given."""
        if self.error_weights is not None:
            return self.error_weights
        return tuple(x - y for x, y in zip(self.b, self.b_hat))

    @property
    def error_exponent(self) -> float:
        """Controller exponent 1 / (q + 1) for an error estimate of order q (the local error
        estimate is O(h^(q+1)))."""
        q = self.order - 1 if self.error_order is None else self.error_order
        return 1.0 / (q + 1)


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


def _dec(text):
    """An exact fraction from a published decimal."""
    return Fr(Decimal(text))


def _rows(sparse, stages):
    """Strictly-lower-triangular rows from {stage: {column: decimal string}}."""
    return tuple(tuple(_dec(sparse.get(s, {}).get(j, "0")) for j in range(s))
                 for s in range(stages))


_DOP_C = ("0", "0.526001519587677318785587544488e-01", "0.789002279381515978178381316732e-01",
          "0.118350341907227396726757197510", "0.281649658092772603273242802490",
          "0.333333333333333333333333333333", "0.25", "0.307692307692307692307692307692",
          "0.651282051282051282051282051282", "0.6", "0.857142857142857142857142857142",
          "1.0")
_DOP_A = {
    1: {0: "5.26001519587677318785587544488e-2"},
    2: {0: "1.97250569845378994544595329183e-2", 1: "5.91751709536136983633785987549e-2"},
    3: {0: "2.95875854768068491816892993775e-2", 2: "8.87627564304205475450678981324e-2"},
    4: {0: "2.41365134159266685502369798665e-1", 2: "-8.84549479328286085344864962717e-1",
        3: "9.24834003261792003115737966543e-1"},
    5: {0: "3.7037037037037037037037037037e-2", 3: "1.70828608729473871279604482173e-1",
        4: "1.25467687566822425016691814123e-1"},
    6: {0: "3.7109375e-2", 3: "1.70252211019544039314978060272e-1",
        4: "6.02165389804559606850219397283e-2", 5: "-1.7578125e-2"},
    7: {0: "3.70920001185047927108779319836e-2", 3: "1.70383925712239993810214054705e-1",
        4: "1.07262030446373284651809199168e-1", 5: "-1.53194377486244017527936158236e-2",
        6: "8.27378916381402288758473766002e-3"},
    8: {0: "6.24110958716075717114429577812e-1", 3: "-3.36089262944694129406857109825",
        4: "-8.68219346841726006818189891453e-1", 5: "2.75920996994467083049415600797e1",
        6: "2.01540675504778934086186788979e1", 7: "-4.34898841810699588477366255144e1"},
    9: {0: "4.77662536438264365890433908527e-1", 3: "-2.48811461997166764192642586468",
        4: "-5.90290826836842996371446475743e-1", 5: "2.12300514481811942347288949897e1",
        6: "1.52792336328824235832596922938e1", 7: "-3.32882109689848629194453265587e1",
        8: "-2.03312017085086261358222928593e-2"},
    10: {0: "-9.3714243008598732571704021658e-1", 3: "5.18637242884406370830023853209",
         4: "1.09143734899672957818500254654", 5: "-8.14978701074692612513997267357",
         6: "-1.85200656599969598641566180701e1", 7: "2.27394870993505042818970056734e1",
         8: "2.49360555267965238987089396762", 9: "-3.0467644718982195003823669022"},
    11: {0: "2.27331014751653820792359768449", 3: "-1.05344954667372501984066689879e1",
         4: "-2.00087205822486249909675718444", 5: "-1.79589318631187989172765950534e1",
         6: "2.79488845294199600508499808837e1", 7: "-2.85899827713502369474065508674",
         8: "-8.87285693353062954433549289258", 9: "1.23605671757943030647266201528e1",
         10: "6.43392746015763530355970484046e-1"},
}
# Propagated 8th-order weights (the row of the 13th stage, c = 1, in dop853.f).
_DOP_B = {0: "5.42937341165687622380535766363e-2", 5: "4.45031289275240888144113950566",
          6: "1.89151789931450038304281599044", 7: "-5.8012039600105847814672114227",
          8: "3.1116436695781989440891606237e-1", 9: "-1.52160949662516078556178806805e-1",
          10: "2.01365400804030348374776537501e-1", 11: "4.47106157277725905176885569043e-2"}
# 5th-order error weights e5 = b - b̂5 ("er" in dop853.f).
_DOP_E5 = {0: "0.1312004499419488073250102996e-1", 5: "-0.1225156446376204440720569753e+1",
           6: "-0.4957589496572501915214079952", 7: "0.1664377182454986536961530415e+1",
           8: "-0.3503288487499736816886487290", 9: "0.3341791187130174790297318841",
           10: "0.8192320648511571246570742613e-1", 11: "-0.2235530786388629525884427845e-1"}
# 3rd-order embedded weights b̂3 ("bhh" in dop853.f): e3 = b - b̂3.
_DOP_B_HAT3 = {0: "0.244094488188976377952755905512", 8: "0.733846688281611857341361741547",
               11: "0.220588235294117647058823529412e-1"}

_DOP_STAGES = 12
_DOP_Bx = tuple(_dec(_DOP_B.get(j, "0")) for j in range(_DOP_STAGES))
_DOP_E5x = tuple(_dec(_DOP_E5.get(j, "0")) for j in range(_DOP_STAGES))
_DOP_B3x = tuple(_dec(_DOP_B_HAT3.get(j, "0")) for j in range(_DOP_STAGES))

#: Exact (decimal-fraction) coefficients, kept for the order-condition tests: b̂ = b - e5
#: (5th order), b_hat3 (3rd order).
DOP853_EXACT = dict(a=_rows(_DOP_A, _DOP_STAGES), b=_DOP_Bx,
                    b_hat=tuple(b - e for b, e in zip(_DOP_Bx, _DOP_E5x)),
                    b_hat3=_DOP_B3x, c=tuple(_dec(x) for x in _DOP_C),
                    e5=_DOP_E5x, e3=tuple(b - b3 for b, b3 in zip(_DOP_Bx, _DOP_B3x)))

DOP853 = Tableau(
    name="Dormand-Prince 8(5,3)",
    order=8,
    c=tuple(float(x) for x in DOP853_EXACT["c"]),
    a=tuple(tuple(float(x) for x in row) for row in DOP853_EXACT["a"]),
    b=tuple(float(x) for x in DOP853_EXACT["b"]),
    b_hat=tuple(float(x) for x in DOP853_EXACT["b_hat"]),
    error_weights=tuple(float(x) for x in DOP853_EXACT["e5"]),
    e3=tuple(float(x) for x in DOP853_EXACT["e3"]),
    error_order=7,
)

#: Public method names (``method=`` of every entry point) -> tableau. "cash-karp" is the
#: paper's method and the default.
METHODS = {"cash-karp": CASH_KARP, "dop853": DOP853}
DEFAULT_METHOD = "cash-karp"


def check_method(method):
    """The method name, validated (one-line error naming the parameter and the choices)."""
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(repr(m) for m in METHODS)} "
                         f"(got {method!r})")
    return method
