"""Fixed-size scratch arrays on the stack of a compiled function, for the composed loop
(:mod:`shipgnc.sim.loop_template`).

``stack_empty(n)`` (``n`` a compile-time constant) is ``np.empty(n)`` (float64, C order) whose
memory is an ``alloca`` in the calling function's entry block instead of a heap block. LLVM knows
such memory aliases nothing else, so values the loop stores in it stay in registers across the
other arrays' writes: the applied input ``u`` of a step, read in each of the four RK4 stages, is
loaded once and its sin and cos computed once per step instead of once per stage. The array lives
as long as the function that called it (the loop's parallel body: one per thread, reused for every
ship), never outlives it (no reference count), and is not initialised.
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array


@intrinsic(prefer_literal=True)
def stack_empty(typingctx, n):
    """A 1-D float64 array of ``n`` elements on the caller's stack (``n`` a literal integer)."""
    if not isinstance(n, types.IntegerLiteral) or n.literal_value < 0:
        return None
    size = int(n.literal_value)
    array_type = types.Array(types.float64, 1, "C")

    def codegen(context, builder, signature, args):
        data = cgutils.alloca_once(builder, context.get_value_type(types.float64),
                                   size=max(size, 1))
        intp = context.get_value_type(types.intp)
        array = make_array(array_type)(context, builder)
        populate_array(array, data=data, shape=[ir.Constant(intp, size)],
                       strides=[ir.Constant(intp, 8)], itemsize=ir.Constant(intp, 8), meminfo=None)
        return array._getvalue()

    return array_type(n), codegen
