"""The numba options that make a cold compile cheaper without changing a kernel's code (``compiled.py``).

A cold compile is what the first run after an install waits for (issue 24):
each option here spares numba work whose result nothing uses. The tests fail
when an option is lost (a decorator rewritten, numba imported before the
switch is set), which would only show as a slower first run otherwise.
"""

from __future__ import annotations

import os
import subprocess
import sys

import numba

from albot1.methods.albot1.compiled import KERNEL_OPTIONS, jitable


@jitable
def _double(x: float) -> float:
    return 2.0 * x


def _twice_source(x: float) -> float:
    return _double(x)


# A kernel with :func:`~albot1.methods.albot1.compiled.kernel`'s options but numba's disk cache: compiled in every
# run of the tests, never loaded from an earlier one's cache, which keeps no callee's code to inspect.
_twice = numba.njit(**{**KERNEL_OPTIONS, "cache": False})(_twice_source)


def _defines_a_cfunc_wrapper(llvm_ir: str) -> bool:
    # numba names a function's C-callable twin "cfunc." + the function's mangled name
    return any(line.startswith("define") and "@cfunc." in line for line in llvm_ir.splitlines())


def test_kernels_and_their_callees_are_compiled_without_a_c_callable_twin() -> None:
    """``no_cfunc_wrapper``: neither a kernel nor a jitable it calls gets numba's ``cfunc`` wrapper built."""
    from numba.core.registry import cpu_target

    from albot1.methods.albot1.mapping.kernel_set import MappingKernels
    from albot1.methods.albot1.perception.kernels import PerceptionKernels
    from albot1.methods.albot1.places.kernels import PlacesKernels
    from albot1.methods.albot1.warm_up import kernel_names

    for kernels in (PerceptionKernels(), MappingKernels(), PlacesKernels()):
        for name in kernel_names(kernels):
            assert getattr(kernels, name).targetoptions.get("no_cfunc_wrapper") is True, name
    assert _twice(1.5) == 3.0
    own = _twice.overloads[_twice.signatures[0]].library.get_llvm_str()
    assert "@cfunc." not in own
    callees = [
        cres.library.get_llvm_str()
        for template in cpu_target.typing_context.resolve_value_type(_double).templates
        for impl in template._impl_cache.values()
        if impl[0] is not None
        for cres in impl[0].overloads.values()
    ]
    assert callees, "the jitable was not compiled as a callee"
    assert not any(_defines_a_cfunc_wrapper(ir) for ir in callees)


def test_numba_s_error_highlighting_is_off_once_the_kernels_module_is_imported() -> None:
    """Numba formats a message per rejected overload while typing; plain, it sets no terminal up for each."""
    code = (
        "import albot1.methods.albot1.compiled\n"
        "from numba.core import errors\n"
        "print(type(errors.termcolor()).__name__)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_DISABLE_ERROR_MESSAGE_HIGHLIGHTING"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "NOPColorScheme"
