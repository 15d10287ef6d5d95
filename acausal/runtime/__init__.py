"""The runtime: simulating a compiled model.

:mod:`.hybrid` is the hybrid loop around SUNDIALS IDA (segments between
events, mode switches, consistent re-initialisation by :mod:`.initialize`,
event iteration and the chattering guard); :mod:`.events` the event
bookkeeping; :mod:`.sensitivity` forward sensitivities through events;
:mod:`.batch` many parameter sets; :mod:`.result` the result object;
:mod:`.backends` the segment solvers (scikit-sundae, and generated C with
IDA linked in).
"""
