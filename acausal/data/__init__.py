"""Measured data: experiments, instrument and traces read from a folder of CSV files;
and :func:`tube_compare`, csv-compare's tube test of a signal against a reference
(:mod:`acausal.data.tube`).

Folder format (every file: UTF-8, a BOM allowed, comma-separated with a
decimal point, one record per line, blank lines and lines
starting with ``#`` ignored, line numbers in errors count every physical line).
Units in header brackets are pint expressions (``m/s``, ``N/m**1.5``, ``deg``;
``[]``, ``[-]`` or ``[1]`` mean dimensionless).  pint counts angles as
dimensionless, so ``deg`` is converted to rad but cannot be told from a ratio.
Literal ``nan``/``inf`` cells are errors.  Every problem raises
:class:`DataError` (an :class:`~acausal.errors.AcausalError`), whose message
starts ``file:LINE: column 'NAME':``; a byte that is not UTF-8 is named
with its line.  :func:`acausal.calibrate.model_dataset` also checks each
column's dimension against the model's parameter, measure (the model file's
``measure_units``) or variable, and that the dataset sets at least one of
the model file's ``conditions``.

``experiments.csv`` (required)
    One row per experiment.  Column ``name`` names it (unique, no ``/``, not
    ``experiments`` or ``instrument``); the other columns are
    *conditions* (model parameters the experiment sets, e.g. ``v_impact``) or
    *measures* (measured scalars, e.g. ``thrt``).  A unit in brackets in a
    header (``thrt [ms]``) is converted to SI with pint; without one the value
    is SI.  An empty cell means "not measured" and is allowed in measure
    columns only.  Roles come from the ``parameters``/``measures`` mappings of
    :func:`load_dataset`; a column in neither is a measure when ``measures``
    is not given, a condition when only ``measures`` is given, else an error.
    An optional column ``use`` says what ``acausal calibrate`` does with the
    row: ``calibrate`` (fit it; the default, also for an empty cell) or
    ``validate`` (hold it back and report the calibrated model's prediction
    error on it), as a report fits at the rated condition and checks the
    others.  The diagnosis uses every row (it cross-validates itself).
``instrument.csv`` (optional)
    Columns ``signal`` (a measure or a trace variable), ``resolution`` and
    ``noise_std`` (empty cell = 0), and either units in the two value headers
    (``resolution [ms]``) or a ``unit`` column giving the unit of both values
    in that row (needed when signals of different dimensions share the file).
    :meth:`Instrument.floor` combines both into a per-sample standard deviation.
``<name>.csv`` (optional, one per experiment)
    A trace: column ``time`` (``time [ms]`` allowed) strictly increasing, and
    columns named after model variables (``hook.phi [deg]``); no empty cells.
    A CSV file that is none of the above and names no experiment is an error,
    so that a misspelt trace is never silently ignored.
"""

from .load import load_dataset
from .records import DataError, Dataset, Instrument, MeasuredExperiment, Trace
from .tube import TubeResult, tube_compare
from .write import write_dataset

__all__ = ["DataError", "Dataset", "Instrument", "MeasuredExperiment", "Trace",
           "TubeResult", "load_dataset", "tube_compare", "write_dataset"]


def __getattr__(name):
    """``Experiment``: the old name of :class:`MeasuredExperiment` (deprecated:
    ``acausal.Experiment`` is a model file's simulation settings)."""
    if name == "Experiment":
        import warnings
        warnings.warn("acausal.data.Experiment is now acausal.data.MeasuredExperiment (a "
                      "measured experiment; acausal.Experiment is a model file's simulation "
                      "settings)", DeprecationWarning, stacklevel=2)
        return MeasuredExperiment
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
