"""Warm-start fixes for Taichi's Python front end: memoised source text and positions.

Why: every time Taichi turns a kernel's Python AST into its own IR it formats a
source-position hint (file, line, the source line and a caret line, wrapped by
``textwrap.TextWrapper``) for *every* statement and expression it visits, error or not
(``ASTTransformerContext.get_pos_info``, called from ``Builder.__call__``). It does so even
when the compiled kernel then comes from the offline cache, because the cache key is computed
from the traced IR. Our kernels unroll stages and components with ``ti.static`` and inline
the right-hand side, so the same few thousand nodes are visited tens of thousands of times:
on a warm cache this formatting was about a third of a fresh process's time to its first
section (1.2 s -> 0.9 s wall without it, 2-core CPU, Taichi 1.7.4). The Taichi successor
project "quadrants" made the same observation (Genesis-Embodied-AI/quadrants PR 857).

It also reads and re-splits the source of a ``ti.func`` (``inspect.getsourcelines``) at every
call site it inlines, again cached kernel or not: another 0.1 s for the 3-D model.

What: the position string is a pure function of the function's source (file, function name, line
offset, indentation) and the node's type and position, so it is cached on exactly those;
the cached string is the one Taichi would have built (tests/test_taichi_frontend.py checks
it on a real kernel). Error messages are unchanged. The source lines are cached per
function object (a function's source cannot change under it; a reloaded module makes new
function objects).

Applied once by :func:`ti_spinorbit.runtime.init`, only to the Taichi versions it was checked
on (1.7.x) and only when the method is where it was; otherwise nothing is changed.
"""

CHECKED_VERSIONS = ((1, 7),)
_ATTRIBUTE = "_ti_spinorbit_memo"


def _position_key(ctx, node):
    """Everything ``get_pos_info(ctx, node)`` depends on."""
    return (ctx.file, ctx.func.func.__name__, ctx.lineno_offset, ctx.indent, type(node),
            node.lineno, node.col_offset, getattr(node, "end_lineno", None),
            getattr(node, "end_col_offset", None))


def memoise(original, key):
    """``original`` wrapped with a cache on ``key(*args)`` (its result depends on nothing
    else); the wrapper keeps ``__wrapped__`` and its ``cache`` for the tests."""
    cache = {}

    def memoised(*args):
        k = key(*args)
        found = cache.get(k)
        if found is None:
            found = cache[k] = original(*args)
        return found

    memoised.__wrapped__ = original
    memoised.cache = cache
    setattr(memoised, _ATTRIBUTE, True)
    return memoised


def install():
    """Memoise Taichi's ``get_pos_info`` and the front end's ``getsourcelines``
    (idempotent). Returns True when both are in place."""
    import taichi as ti      # Taichi: installed by runtime.init, which has imported it

    if tuple(ti.__version__[:2]) not in CHECKED_VERSIONS:
        return False
    try:                     # Taichi internals, where this version has them
        from taichi.lang import kernel_impl
        from taichi.lang.ast.ast_transformer_utils import ASTTransformerContext
    except ImportError:
        return False
    # get_pos_info: the source-position string of a node; getsourcelines: a function's
    # source (it cannot change under the function object; a reloaded module makes new ones)
    targets = ((ASTTransformerContext, "get_pos_info", _position_key),
               (kernel_impl, "getsourcelines", lambda func: func))
    if any(getattr(owner, name, None) is None for owner, name, _ in targets):
        return False
    for owner, name, key in targets:
        current = getattr(owner, name)
        if not getattr(current, _ATTRIBUTE, False):
            setattr(owner, name, memoise(current, key))
    return True
