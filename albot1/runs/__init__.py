"""Running a method on a sequence and keeping the result: the timed runner (``execute``),
the run-folder contract (``folder``, ``tum``) and the evaluation of a stored run (``evaluate``,
which feeds the pure functions of :mod:`albot1.metrics`). The mapper contract itself is
:mod:`albot1.contract`; the method registry is :mod:`albot1.methods.registry`."""
