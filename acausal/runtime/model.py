"""A compiled model ready to simulate: :func:`compile_model` and
:class:`CompiledModel`, the public face of a compiled model.

The compiler makes a frozen :class:`~acausal.compiler.artefact.Artefact`
(:func:`acausal.compiler.pipeline.compile_artefact`); this wrapper adds what
the runtime does with it (:meth:`CompiledModel.simulate`, the hybrid loop of
:mod:`.hybrid`; :meth:`CompiledModel.simulate_batch`, :mod:`.batch`; the IDA
linear solver its structure calls for, :mod:`.backends`) and reads the
artefact's records by the names users know (``cm.dae``, ``cm.params``,
``cm.param_vector(...)``). Nothing is written into the artefact: the
runtime's caches of a model (the initialisation's guess rows, a backend's
compiled library, sensitivity models) are kept by the runtime modules,
keyed by the model.
"""
from operator import attrgetter

from ..compiler.pipeline import compile_artefact
from .backends import choose_linear_solver
from .batch import simulate_batch
from .hybrid import simulate


def compile_model(model, cache=True):
    """Compile ``model`` (flatten, reduce, generate) for simulation. With
    ``cache`` (and the store not disabled by ``ACAUSAL_CACHE=off``) the
    compiled stages are read from / written to the on-disk store
    (:mod:`acausal.infra.store`, namespace ``compile``)."""
    return CompiledModel(compile_artefact(model, cache=cache))


def _view(path, doc):
    """A read-only attribute: ``path`` in the artefact."""
    get = attrgetter(path)
    return property(lambda self: get(self.artefact), doc=doc)


class CompiledModel:
    """A model turned into solver callbacks. Use :meth:`simulate`.

    ``artefact`` is the compiler's frozen record; the attributes below read
    it (parameters, start values and names are its
    :class:`~acausal.compiler.artefact.ParameterSpace`,
    :class:`~acausal.compiler.artefact.StartPlan` and slot lookups)."""

    model = _view("model", "the Model it was compiled from")
    flat = _view("flat", "the flattened model")
    reduced = _view("reduced", "the equations after alias elimination")
    graph = _view("graph", "the matching graph after index reduction")
    dae = _view("dae", "the reduced DAE: unknowns y, y', residuals, origins")
    source = _view("code.source", "the generated Python source")
    sparsity = _view("code.sparsity", "the iteration matrix's structure")
    params = _view("parameters.entries", "the free parameters (ParamEntry), in vector order")
    param_syms = _view("parameters.symbols", "the free parameters' symbols, in vector order")
    structural = _view("parameters.structural", "structural parameter name -> value")
    bound = _view("parameters.bound", "bound parameter name -> value expression")
    var_names = _view("var_names", "every variable's dotted name")
    discretes = _view("discretes", "the discrete values' declarations")
    disc_syms = _view("disc_syms", "the discrete values' symbols")
    events = _view("events", "the events (root functions first)")
    assertions = _view("assertions", "the assertions (root functions after the events)")
    n_roots = _view("n_roots", "number of root functions: events, then assertions")
    stage_s = _view("build.stage_s", "wall time of each compile stage [s]")
    compile_s = _view("build.compile_s", "wall time of the compile [s]")
    cache_hit = _view("build.cache_hit", "whether the compile was read from the store")

    def __init__(self, artefact):
        self.artefact = artefact

    # -- parameters and start values -----------------------------------------------
    def param_index(self, name):
        """Position of free parameter ``name`` in the parameter vector."""
        return self.artefact.parameters.index(name)

    def param_vector(self, overrides=None):
        """Free parameter values with ``overrides`` (name -> value) applied and
        checked against each parameter's bounds."""
        return self.artefact.parameters.vector(overrides)

    def split_overrides(self, overrides):
        """(parameter overrides, start overrides) of a run's ``params``: see
        :meth:`acausal.compiler.artefact.ParameterSpace.split`."""
        return self.artefact.parameters.split(overrides, self.artefact.flat.variables)

    def with_defaults(self, values):
        """A compiled model whose free parameters default to ``values`` (name
        -> value, checked against their bounds), sharing the generated code."""
        return CompiledModel(self.artefact.with_defaults(values))

    def fixed_starts(self, p, starts=None):
        """(index in var_names, value, name) of every fixed start value."""
        return self.artefact.starts.fixed_values(p, starts)

    def guess_vector(self, p, starts=None):
        """Initial guess of y from the start values of the variables."""
        return self.artefact.starts.guess_vector(p, starts)

    def state_guess_order(self):
        """State slots in the order their guesses are imposed."""
        return self.artefact.starts.guess_order()

    def discrete_start(self):
        """The discrete values' start values."""
        return self.artefact.discrete_start()

    def identity(self):
        """A digest that fixes the compiled equations (the compiled backend's
        libraries and the sensitivity models are stored under it:
        :meth:`~acausal.compiler.artefact.Artefact.identity`)."""
        return self.artefact.identity()

    # -- symbols and slots ---------------------------------------------------------------
    def resolve(self, expr):
        """``expr`` in the DAE's unknowns, free parameters, discrete values and time."""
        return self.artefact.resolve(expr)

    def observed_exprs(self):
        """Every variable of :attr:`var_names`, resolved."""
        return self.artefact.observed_exprs()

    def state_slot_of(self, name):
        """(slot, sign) when variable ``name`` is ±(one state slot), else None."""
        return self.artefact.state_slot_of(name)

    def y_column(self, name):
        """The column of y that variable ``name`` is, else None."""
        return self.artefact.y_column(name)

    def scaled_slot_of(self, name):
        """(slot, gain) when variable ``name`` is ``gain*y[slot] + offset``
        (a state's derivative followed to the unknown it equals), else None."""
        return self.artefact.scaled_slot_of(name)

    def slot_names(self):
        """For each solver unknown, the names that denote it up to sign."""
        return self.artefact.slot_names()

    def dynamic_discretes(self):
        """Indices of the discrete values the residual equations use."""
        return self.artefact.dynamic_discretes()

    # -- callbacks and solving ---------------------------------------------------------
    def callbacks(self, p, d):
        """The generated :class:`~acausal.compiler.codegen.Callbacks` for
        parameter vector ``p`` and discrete values ``d``."""
        return self.artefact.callbacks(p, d)

    def fixed_jacobian(self, sparse=False):
        """d(fixed-start variables)/d(y, y'_states) (see
        :meth:`acausal.compiler.artefact.Artefact.fixed_jacobian`)."""
        return self.artefact.fixed_jacobian(sparse)

    def linear_solver(self, kind="auto"):
        """The IDA linear solver for this model's iteration matrix, chosen from
        its structure (:attr:`sparsity`): a
        :class:`acausal.runtime.backends.LinearSolver`.

        ``kind``: ``"dense"``, ``"band"`` (bandwidths from the pattern),
        ``"sparse"`` (SuperLU_MT on the CSC pattern; the Jacobian callback is
        then ``callbacks(...).jac_csc``) or ``"auto"``: dense below
        :data:`acausal.runtime.backends.BAND_MIN_SIZE` unknowns or when the
        band is not narrow, else band."""
        return choose_linear_solver(self.sparsity, kind)

    def simulate(self, **kw):
        """Simulate: see :func:`acausal.runtime.hybrid.simulate`."""
        return simulate(self, **kw)

    def simulate_batch(self, param_sets, **kw):
        """One simulation per parameter set, in parallel worker processes that
        hold this compiled model: see :func:`acausal.runtime.batch.simulate_batch`."""
        return simulate_batch(self, param_sets, **kw)
