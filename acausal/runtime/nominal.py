"""Absolute tolerances from nominal values (Modelica's ``nominal``).

A variable declared with ``nominal=x`` (:class:`acausal.lang.declare.Variable`,
``Component.with_nominal``) gets the absolute tolerance ``rtol * |x|`` on
the solver unknown it is (up to a sign, a numeric scale and an offset; a
state's derivative is the unknown its state row equates it with: see
:func:`nominal_slots`), in place of the run's ``atol``:
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
    """Solver slot -> nominal value, made once per model. A variable with a
    nominal value ``x`` reaches the unknown it is up to a gain and an
    offset (``v = gain*y + offset``: an alias, its sign, an offset, a
    scale), with the nominal ``|x/gain|``; a variable that is a state's
    derivative (``w_rel = der(phi_rel)``) reaches the unknown the state's
    row equates that derivative with. A slot reached by several takes the
    smallest. Variables computed from several unknowns set none."""
    out = _SLOTS.get(cm)
    if out is None:
        out = {}
        for name, var in cm.flat.variables.items():
            if var.nominal is None:
                continue
            hit = cm.scaled_slot_of(name)
            if hit is None:
                continue
            slot, gain = hit
            nom = abs(float(var.nominal) / gain)
            out[slot] = min(out.get(slot, nom), nom)
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
