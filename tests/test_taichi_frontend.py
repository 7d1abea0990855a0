"""The warm-start memo of Taichi's front end (``ti_spinorbit._taichi_frontend``) changes
nothing but speed: every source-position string and every source listing it returns is the
one Taichi builds itself, error messages keep their source line and caret, and installing is
idempotent."""

import numpy as np
import pytest
import taichi as ti

from ti_spinorbit import _taichi_frontend as frontend
from ti_spinorbit import runtime

pytestmark = pytest.mark.skipif(tuple(ti.__version__[:2]) not in frontend.CHECKED_VERSIONS,
                                reason="memo applies only to the Taichi versions it was checked on")


@pytest.fixture(scope="module")
def installed():
    runtime.ensure_init()
    from taichi.lang import kernel_impl
    from taichi.lang.ast.ast_transformer_utils import ASTTransformerContext

    assert frontend.install()
    return ASTTransformerContext, kernel_impl


def test_install_is_idempotent(installed):
    ctx_class, kernel_impl = installed
    memo, source = ctx_class.get_pos_info, kernel_impl.getsourcelines
    assert frontend.install() and frontend.install()
    assert ctx_class.get_pos_info is memo and kernel_impl.getsourcelines is source
    # wrapped exactly once: the original underneath is Taichi's own function
    assert not getattr(memo.__wrapped__, "_ti_spinorbit_memo", False)
    assert not getattr(source.__wrapped__, "_ti_spinorbit_memo", False)


def _fresh_kernel():
    """A kernel whose nodes the front end visits many times (static loops, a func inlined
    at two call sites): built anew so that Taichi traces it in the test."""

    @ti.func
    def twice(x):
        y = x
        for _ in ti.static(range(3)):
            y = y * 2.0 + 1.0
        return y

    @ti.kernel
    def k(a: ti.types.ndarray(dtype=ti.f64, ndim=1)):
        for i in range(a.shape[0]):
            s = 0.0
            for j in ti.static(range(4)):
                s += twice(a[i] + j) - twice(a[i])
            a[i] = s

    return k


def test_memoised_strings_equal_taichis_own(installed, monkeypatch):
    ctx_class, kernel_impl = installed
    memo = ctx_class.get_pos_info
    original = memo.__wrapped__
    seen = []

    def checked(self, node):
        text = memo(self, node)
        seen.append(text == original(self, node))
        return text

    monkeypatch.setattr(ctx_class, "get_pos_info", checked)
    hits_before = len(memo.cache)
    a = np.arange(5.0)
    _fresh_kernel()(a)
    # the kernel ran, and every string matched; repeated visits were served from the memo
    # twice(x) = 8x + 7, so each element becomes sum_j 8j = 48
    expected = np.full(5, 48.0)
    np.testing.assert_allclose(a, expected, rtol=0, atol=1e-12)
    assert len(seen) > 50 and all(seen)
    assert len(memo.cache) - hits_before < len(seen)


def test_memoised_source_equals_taichis_own(installed):
    _, kernel_impl = installed
    source = kernel_impl.getsourcelines
    for func in (_fresh_kernel, test_memoised_strings_equal_taichis_own):
        assert source(func) == source.__wrapped__(func)
        assert source(func) is source(func)        # served from the memo


def test_error_messages_keep_source_line_and_caret(installed):
    @ti.kernel
    def broken(a: ti.types.ndarray(dtype=ti.f64, ndim=1)):
        for i in range(a.shape[0]):
            a[i] = undefined_name_here + 1.0   # noqa: F821

    with pytest.raises(Exception) as info:
        broken(np.zeros(2))
    text = str(info.value)
    assert "undefined_name_here" in text and "^" in text and "line" in text
