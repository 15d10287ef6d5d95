"""Model diagnosis: what a calibrated simulation gets wrong and which
physical cause explains it.

:mod:`.graph` finds the sites of a model where a cause can act (bodies,
joints, springs, contacts, sources: each component class declares its
``diagnosis_site``); :mod:`.domain` describes the mechanical domains once;
:mod:`.hypotheses` is the library of causes, each a model extension that
inserts a component at a site, with the parameters to fit.

The diagnosis is a chain of typed stages (:mod:`.stages`: calibrate ->
candidates -> fit -> decide -> cross-validate -> rank -> extend -> views)
over picklable dataclasses (:mod:`.problem`, :mod:`.stages.tasks`), each
``stage(ctx, state) -> state``, chained by :mod:`.run` (``acausal
diagnose``, :func:`~acausal.diagnose.run.diagnose`, with one
:class:`~.options.DiagnosisOptions`) into a
:class:`~.report.result.Diagnosis`, of which :mod:`.report` is a pure view.
:mod:`.stages.stats` holds the tests and criteria, :mod:`.stages.fitting`
the output-error fits (on the residuals of :mod:`acausal.studies.residuals`),
:mod:`.synth` synthetic data for blind tests. Importing this package has no
side effects.
"""
from .library.graph import KINDS, ModelGraph, Site
from .library.hypotheses import HYPOTHESES, Hypothesis, ParamSpec, build_extended, write_extended_model

__all__ = ["KINDS", "ModelGraph", "Site", "HYPOTHESES", "Hypothesis", "ParamSpec",
           "build_extended", "write_extended_model"]
