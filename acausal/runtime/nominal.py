"""Absolute tolerances from nominal values (Modelica's ``nominal``).

A variable declared with ``nominal=x`` (:class:`acausal.lang.declare.Variable`,
``Component.with_nominal``) gets the absolute tolerance ``rtol * |x|`` on
the solver unknown it is (up to sign), in place of the run's ``atol``:
the Modelica Specification's recommendation (section 4.8.7, non-normative:
an integrator tolerance ``rtol*(|nominal| + |x|)``), which OpenModelica
applies to IDA and DASSL. IDA's error weight for the unknown is then
``1/(rtol*(|y| + |nominal|))``: the variable is integrated to ``rtol`` of
its own scale, not to a fixed SI tolerance. Unknowns without a nominal
keep ``atol``; an unknown named in an ``atol`` dict keeps that value.
"""
import weakref

import numpy as np

_SLOTS = weakref.WeakKeyDictionary()   # compiled model -> {solver slot: nominal value}


def nominal_slots(cm):
    """Solver slot -> nominal value (the smallest of the variables that
    are, up to sign, that slot), made once per model."""
    out = _SLOTS.get(cm)
    if out is None:
        out = {}
        variables = cm.flat.variables
        for i, names in enumerate(cm.slot_names()):
            noms = [variables[n].nominal for n in names
                    if n in variables and variables[n].nominal is not None]
            if noms:
                out[i] = min(noms)
        _SLOTS[cm] = out
    return out


def nominal_atol(cm, atol, rtol, given=None):
    """``atol`` (a scalar or a vector over the solver unknowns) with
    ``rtol*|nominal|`` on the unknowns that have a nominal value, except
    those named in ``given`` (an atol dict: explicit values win)."""
    noms = nominal_slots(cm)
    if not noms:
        return atol
    n = len(cm.dae.y)
    vec = np.broadcast_to(np.asarray(atol, dtype=float), (n,)).copy()
    named = set()
    if isinstance(given, dict):
        slots = cm.slot_names()
        named = {i for i, names in enumerate(slots) if any(k in names for k in given)}
    for i, nom in noms.items():
        if i not in named:
            vec[i] = float(rtol) * nom
    return vec
