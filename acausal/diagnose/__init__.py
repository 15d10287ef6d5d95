"""Model diagnosis: what a calibrated simulation gets wrong and which
physical cause explains it.

:mod:`.graph` finds the sites of a model where a cause can act (bodies,
joints, springs, contacts, sources); :mod:`.hypotheses` is the library of
causes, each a model extension that inserts a component at a site, with
the parameters to fit. :mod:`.run` is the driver (``acausal diagnose``,
:func:`~acausal.diagnose.run.diagnose`), with :mod:`.stats` (the tests and
criteria), :mod:`.fitting` (output-error fits and leave-one-out),
:mod:`.fingerprints`, :mod:`.report` and :mod:`.synth` (synthetic data for
blind tests). Importing this package has no side effects.
"""
from .graph import KINDS, ModelGraph, Site
from .hypotheses import HYPOTHESES, Hypothesis, ParamSpec, build_extended, write_extended_model

__all__ = ["KINDS", "ModelGraph", "Site", "HYPOTHESES", "Hypothesis", "ParamSpec",
           "build_extended", "write_extended_model"]
