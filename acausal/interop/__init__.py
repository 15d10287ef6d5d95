"""Exchange with other tools: FMU export (:mod:`acausal.interop.fmu`).

A layer above :mod:`acausal.runtime` and :mod:`acausal.modelfile`; nothing
below imports it."""
