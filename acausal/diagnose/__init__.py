"""Model diagnosis: from measured data to a named cause, an extended model
and the measured gain (``acausal diagnose``; :func:`acausal.diagnose.run.diagnose`)."""
