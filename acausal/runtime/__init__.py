"""The runtime: simulating a compiled model.

:mod:`.model` wraps the compiler's frozen artefact into the
:class:`~acausal.runtime.model.CompiledModel` users simulate
(:func:`~acausal.runtime.model.compile_model`). :mod:`.hybrid` is the hybrid
loop around SUNDIALS IDA (segments between events, mode switches,
consistent re-initialisation by :mod:`.initialize` with the linear algebra
of :mod:`.linalg`, event iteration and the chattering guard); it calls the
hooks of one :class:`~acausal.runtime.observer.RunObserver` (:mod:`.observer`),
of which the forward sensitivities through events are one
(:mod:`.sensitivity`, the augmented model; :mod:`.sensitivity_run`, the
observer). :mod:`.events` is what an event action sees; :mod:`.batch` many
parameter sets; :mod:`.result` the result object; :mod:`.backends` the
segment solvers (scikit-sundae, and generated C with IDA linked in). The
runtime's caches of a model (the initialisation's guess rows, sensitivity
models, a backend's library) are its own, keyed by the model: nothing is
written into the compiled artefact.
"""
