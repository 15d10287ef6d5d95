"""The compiler: from a :class:`~acausal.Model` to generated callbacks.

The stages, in order, each a module that takes the previous stage's small
dataclass and returns a new one:

1. :mod:`.flatten` -- connection sets, one flat list of equations;
2. :mod:`.aliases` -- ``x = +-y + c`` removed, parameter bindings;
3. :mod:`.structure` -- matching, Pantelides index reduction (Pantelides 1988),
   dummy derivatives (Mattsson and Soederlind 1993);
4. :mod:`.causalize` -- block triangular form (Tarjan), trivial tearing,
   symbolic solution of linear blocks, semi-explicit index-1 form;
5. :mod:`.codegen` (Python) and :mod:`.codegen_c` (C) -- residual, analytic
   Jacobian, roots, observed variables.

:mod:`.pipeline` runs them (cached on disk by :mod:`acausal.infra.store`).
Nothing here imports the runtime.
"""
